// `motwin run`: runs a TMCL program headless on an in-process virtual module at full simulation
// speed and writes a CSV trace of chosen parameters against simulated time
// (docs/tmcl-programs.md "motwin run").
//
// The module is made as `motwin serve` makes it (module registry, --set, --scenario, --motor),
// the program is downloaded through the TMCL engine exactly as a host would download it (132,
// instructions, NOP, 133), started with 129 type 1, and the ticks run back to back without
// pacing. Samples are direct-mode reads through the engine (GAP, GGP), so they never disturb
// the program's accumulator. With --plot the samples also go into a self-contained HTML page
// (host/web/trace_page.h).
#include <algorithm>
#include <chrono>
#include <cmath>
#include <cstdio>
#include <ctime>
#include <fstream>
#include <iostream>
#include <memory>
#include <optional>
#include <sstream>
#include <string>
#include <string_view>
#include <vector>

#include <fmt/format.h>

#include "cli/cli_errors.h"
#include "cli/commands.h"
#include "cli/module_inputs.h"
#include "cli/program_source.h"
#include "core/tmcl/engine.h"
#include "core/tmcl/interpreter.h"
#include "core/tmcl/status.h"
#include "host/atomic_file.h"
#include "host/host_runtime.h"
#include "host/module_registry.h"
#include "host/pacing.h"
#include "host/state_dir.h"
#include "host/web/trace_page.h"
#include "sim/scenario.h"
#include "sim/signals.h"
#include "tools/tmcl_mnemonics.h"
#include "types/result.h"

namespace motwin::cli {
namespace {

namespace cmd = tmcl::command;

// The program stopped for an error (jump outside memory, invalid instruction ...).
constexpr int kExitProgramFault = 1;

struct RunOptions {
  std::string program;
  std::vector<std::string> include_dirs;
  std::string module;  // default: the first registered module with TMCL
  std::string duration;
  std::string trace;  // empty: trace.csv, or none when --plot is given
  std::string plot;   // the HTML page to write, or empty
  std::string sample = "1ms";
  std::vector<std::string> params;
  std::vector<std::string> variables;
  int motor = 0;
  std::optional<uint32_t> address;
  std::string label;
  std::string state_dir = std::string(host::kNoStateDir);
  std::vector<std::string> assignments;
  std::string scenario_path;
  std::string motor_model;
  std::string firmware;  // empty: the module's default generation
  bool until_stopped = false;
};

// "10s", "1ms", "250us", "2.5s", "1min"; a bare number is seconds.
std::optional<uint64_t> parse_duration_us(std::string_view text) {
  struct Unit {
    std::string_view suffix;
    double microseconds;
  };
  static constexpr Unit kUnits[] = {{"min", 60e6}, {"ms", 1e3}, {"us", 1.0}, {"s", 1e6}};
  double scale = 1e6;
  for (const Unit& unit : kUnits) {
    if (text.size() > unit.suffix.size() && text.substr(text.size() - unit.suffix.size()) == unit.suffix) {
      scale = unit.microseconds;
      text.remove_suffix(unit.suffix.size());
      break;
    }
  }
  const std::optional<double> number = sim::parse_number(text);
  if (!number || !std::isfinite(*number) || *number < 0 || *number * scale > 1e15) return std::nullopt;
  return static_cast<uint64_t>(std::llround(*number * scale));
}

// "52,42" (and repeated options) -> numbers in 0..255.
Result<std::vector<uint8_t>> parse_numbers(const std::vector<std::string>& lists, std::string_view option) {
  std::vector<uint8_t> numbers;
  for (const std::string& list : lists) {
    size_t begin = 0;
    while (begin <= list.size()) {
      const size_t comma = std::min(list.find(',', begin), list.size());
      const std::string word = list.substr(begin, comma - begin);
      const std::optional<int64_t> number = tools::parse_integer(word);
      if (!number || *number < 0 || *number > 255) {
        return Error{fmt::format("{} {}: '{}' is not a parameter number 0..255", option, list, word)};
      }
      numbers.push_back(static_cast<uint8_t>(*number));
      begin = comma + 1;
    }
  }
  return numbers;
}

std::string format_seconds(uint64_t us) {
  return fmt::format("{}.{:06}", us / 1'000'000u, us % 1'000'000u);
}

// "status 5 (Invalid value)".
std::string status_text(tmcl::Status status) {
  return fmt::format("status {} ({})", tmcl::to_byte(status), tmcl::status_name(tmcl::to_byte(status)));
}

// --- Checking the options -------------------------------------------------------------------------

// The options, checked: which module, how long, what to trace.
struct RunPlan {
  host::ModuleDescriptor descriptor{};  // --module running --firmware
  uint64_t duration_us = 0;
  uint64_t sample_us = 0;
  std::vector<uint8_t> params;     // axis parameters of --axis (--param; default: the module's)
  std::vector<uint8_t> variables;  // user variables (--var)
};

Result<RunPlan> check_options(const RunOptions& options) {
  RunPlan plan;
  const host::ModuleDescriptor* module = host::find_module(options.module);
  if (module == nullptr) {
    return Error{fmt::format("unknown module \"{}\" (available: {})", options.module, host::module_names())};
  }
  const auto no_interpreter = [](const std::string& what) {
    return Error{fmt::format("{} has no TMCL interpreter (motwin run takes a TMCL module: {})", what,
                             host::module_names(&host::has_tmcl))};
  };
  if (!module->endpoints.has_tmcl()) return no_interpreter(options.module);
  Result<host::ModuleDescriptor> running = host::with_firmware(*module, options.firmware);
  if (!running) return Error{running.error()};
  plan.descriptor = std::move(*running);
  // A generation that speaks another protocol (a CANopen firmware of a TMCL module).
  if (!plan.descriptor.endpoints.has_tmcl()) return no_interpreter(options.module + " --firmware " + options.firmware);
  const std::optional<uint64_t> duration_us = parse_duration_us(options.duration);
  if (!duration_us) {
    return Error{fmt::format("--for {}: expected a duration such as 10s, 500ms or 2.5s", options.duration)};
  }
  plan.duration_us = *duration_us;
  const std::optional<uint64_t> sample_us = parse_duration_us(options.sample);
  if (!sample_us || *sample_us == 0) {
    return Error{fmt::format("--sample {}: expected a duration such as 1ms, 50us or 0.1s", options.sample)};
  }
  plan.sample_us = *sample_us;
  if (options.address && !options.label.empty()) return Error{"give at most one of --address and --label"};
  Result<std::vector<uint8_t>> params = parse_numbers(options.params, "--param");
  if (!params) return Error{params.error()};
  // Default columns: the module's actual position and velocity.
  plan.params = options.params.empty() ? plan.descriptor.trace_parameters : std::move(*params);
  Result<std::vector<uint8_t>> variables = parse_numbers(options.variables, "--var");
  if (!variables) return Error{variables.error()};
  plan.variables = std::move(*variables);
  return plan;
}

// --address, --label or 0.
Result<uint32_t> start_address(const RunOptions& options, const LoadedProgram& program) {
  if (options.label.empty()) return options.address.value_or(0);
  const std::optional<uint32_t> found = program.label_address(options.label);
  if (!found) return Error{fmt::format("{} defines no label '{}'", options.program, options.label)};
  return *found;
}

// --- The module and the trace ---------------------------------------------------------------------

// The module, as `motwin serve` makes it.
Result<std::unique_ptr<host::VirtualModule>> make_module_to_run(const RunOptions& options,
                                                                const host::ModuleDescriptor& descriptor,
                                                                std::vector<host::InitialInput> initial_inputs) {
  host::ModuleOptions module_options;
  module_options.motor = options.motor_model;
  module_options.firmware = options.firmware;
  module_options.initial_inputs = std::move(initial_inputs);
  if (options.state_dir != host::kNoStateDir) module_options.state_dir = options.state_dir;
  Result<std::unique_ptr<host::VirtualModule>> module = descriptor.make(module_options);
  if (module && !(*module)->has_tmcl()) return Error{fmt::format("{} has no TMCL interpreter", (*module)->name())};
  return module;
}

// The run in the module's control ticks.
struct TickPlan {
  uint64_t per_sample = 0;
  uint64_t total = 0;
};

Result<TickPlan> ticks_of(const RunOptions& options, const RunPlan& plan, uint64_t tick_us) {
  const uint64_t per_sample = plan.sample_us / tick_us;
  if (per_sample == 0 || per_sample * tick_us != plan.sample_us) {
    return Error{fmt::format("--sample {}: must be a whole number of the module's {} us control ticks", options.sample,
                             tick_us)};
  }
  return TickPlan{per_sample, plan.duration_us / tick_us};
}

// One column of the trace: a direct-mode read through the engine.
struct Column {
  std::string name;
  tmcl::Instruction read;
};

// The trace's name for the page's legend and its unit, from the module's parameter listing
// ("AP52 actual position", "counts").
void describe_columns(const RunPlan& plan, std::vector<host::web::TraceColumn>& described) {
  const host::ModuleParameterListing listing = plan.descriptor.listing();
  const auto find = [&listing](host::ParameterKind kind, std::optional<uint8_t> bank,
                               uint8_t number) -> const host::ListedParameter* {
    for (const host::ParameterSection& section : listing.sections) {
      if (section.kind != kind || section.bank != bank) continue;
      for (const host::ListedParameter& parameter : section.parameters) {
        if (number >= parameter.first_number && number <= parameter.last_number) return &parameter;
      }
    }
    return nullptr;
  };
  for (const uint8_t number : plan.params) {
    const host::ListedParameter* parameter = find(host::ParameterKind::kAxis, std::nullopt, number);
    const std::string name = fmt::format("AP{}", number);
    described.push_back({name, parameter ? name + " " + parameter->name : name, parameter ? parameter->unit : ""});
  }
  for (const uint8_t number : plan.variables) {
    const std::string name = fmt::format("var{}", number);
    described.push_back({name, fmt::format("{} (user variable {})", name, number), ""});
  }
}

// "time_s,AP52,AP42,var0".
std::string csv_header(const std::vector<Column>& columns) {
  std::string header = "time_s";
  for (const Column& column : columns) header += "," + column.name;
  return header;
}

// The columns of the plan; each must be readable before the run starts.
Result<std::vector<Column>> trace_columns(tmcl::TmclEngine& engine, std::string_view module_name, const RunPlan& plan,
                                          int motor) {
  std::vector<Column> columns;
  for (const uint8_t number : plan.params) {
    columns.push_back(
        Column{fmt::format("AP{}", number), tmcl::Instruction{cmd::kGap, number, static_cast<uint8_t>(motor), 0}});
  }
  for (const uint8_t number : plan.variables) {
    columns.push_back(Column{fmt::format("var{}", number), tmcl::Instruction{cmd::kGgp, number, 2, 0}});
  }
  for (const Column& column : columns) {
    const tmcl::CommandResult result = engine.execute(column.read, tmcl::Origin::kHost);
    if (result.status != tmcl::Status::kOk) {
      return Error{fmt::format("{} cannot be read on {} motor {}: {}", column.name, module_name, motor,
                               status_text(result.status))};
    }
  }
  return columns;
}

// Where the trace goes (--trace FILE, or - for stdout, or nowhere: --plot without --trace), and
// the report: stdout, or stderr when stdout carries the trace.
class TraceOutput {
 public:
  static Result<TraceOutput> open(const std::string& path) {
    TraceOutput output;
    output.to_stdout_ = path == "-";
    output.enabled_ = !path.empty();
    if (output.enabled_ && !output.to_stdout_) {
      output.file_.open(path, std::ios::trunc);
      if (!output.file_) return Error{fmt::format("cannot write the trace to {}", path)};
    }
    return output;
  }

  // nullptr when no CSV is written.
  std::ostream* trace() { return !enabled_ ? nullptr : to_stdout_ ? &std::cout : &file_; }
  std::ostream& report() { return to_stdout_ ? std::cerr : std::cout; }
  bool to_stdout() const { return to_stdout_; }
  bool enabled() const { return enabled_; }

 private:
  std::ofstream file_;
  bool to_stdout_ = false;
  bool enabled_ = false;
};

// --plot: the samples kept for the page, and its file, made before the run so that a path that
// cannot be written fails at once.
struct PlotOutput {
  host::AtomicFile file;
  host::web::TracePageData page;
};

// --- Running the program ----------------------------------------------------------------------------

// Downloads through the engine, as a host would (docs/tmcl-programs.md).
Result<void> download(tmcl::TmclEngine& engine, const std::vector<tmcl::Instruction>& program) {
  // One request of the download, which the module must answer with `expected`.
  const auto send = [&engine](const tmcl::Instruction& in, tmcl::Status expected,
                              const std::string& what) -> Result<void> {
    const tmcl::CommandResult result = engine.execute(in, tmcl::Origin::kHost);
    if (result.status == expected) return {};
    return Error{fmt::format("{}: the module answered {}", what, status_text(result.status))};
  };
  Result<void> sent = send({cmd::kEnterDownloadMode, 0, 0, 0}, tmcl::Status::kOk, "entering download mode (132)");
  for (size_t i = 0; sent && i < program.size(); ++i) {
    sent = send(program[i], tmcl::Status::kStoredInProgram,
                fmt::format("downloading address {} ({})", i, tools::format_instruction(program[i])));
  }
  if (sent) sent = send({cmd::kNop, 0, 0, 0}, tmcl::Status::kStoredInProgram, "downloading the trailing NOP");
  if (sent) sent = send({cmd::kExitDownloadMode, 0, 0, 0}, tmcl::Status::kOk, "leaving download mode (133)");
  return sent;
}

// 129 type 1: the program runs from `address`.
Result<void> start_program(tmcl::TmclEngine& engine, uint32_t address) {
  const tmcl::CommandResult started =
      engine.execute(tmcl::Instruction{cmd::kRunApplication, 1, 0, static_cast<int32_t>(address)}, tmcl::Origin::kHost);
  if (started.status == tmcl::Status::kOk) return {};
  return Error{fmt::format("starting at address {} (129): {}", address, status_text(started.status))};
}

bool is_fault(tmcl::StopReason reason) {
  switch (reason) {
    case tmcl::StopReason::kJumpOutsideProgram:
    case tmcl::StopReason::kEndOfMemory:
    case tmcl::StopReason::kDamagedInstruction:
    case tmcl::StopReason::kInvalidInstruction:
      return true;
    case tmcl::StopReason::kNone:
    case tmcl::StopReason::kStopInstruction:
    case tmcl::StopReason::kHostStop:
      return false;
  }
  return false;
}

// What the sample loop saw.
struct RunSummary {
  uint64_t samples = 0;
  std::optional<uint64_t> stopped_at_us;  // the first sample that saw the program stopped
  uint64_t simulated_us = 0;
  uint64_t instructions = 0;
  double wall_s = 0;
};

// Runs the ticks back to back and takes a sample at the start, after every `ticks.per_sample`
// and at the end: a CSV row on `trace` and/or a point of `plot` (either may be null); with
// `until_stopped` the run ends at the first sample after the program stopped.
RunSummary sample_loop(host::HostRuntime& runtime, tmcl::TmclEngine& engine, const std::vector<Column>& columns,
                       TickPlan ticks, bool until_stopped, std::ostream* trace, host::web::TracePageData* plot) {
  const uint64_t start_us = runtime.sim_time_us();
  if (trace != nullptr) *trace << csv_header(columns) << '\n';
  if (plot != nullptr) plot->values.assign(columns.size(), {});
  std::string row;
  const auto sample = [&] {
    const uint64_t time_us = runtime.sim_time_us() - start_us;
    row = format_seconds(time_us);
    if (plot != nullptr) plot->time_s.push_back(static_cast<double>(time_us) / 1e6);
    for (size_t i = 0; i < columns.size(); ++i) {
      const int32_t value = engine.execute(columns[i].read, tmcl::Origin::kHost).value;
      row += ',';
      row += std::to_string(value);
      if (plot != nullptr) plot->values[i].push_back(value);
    }
    if (trace != nullptr) *trace << row << '\n';
  };
  const auto running = [&] {
    const auto status = engine.device().runtime().application_status;
    return status == tmcl::ApplicationStatus::kRunning || status == tmcl::ApplicationStatus::kStepping;
  };

  const auto wall_start = std::chrono::steady_clock::now();
  const uint64_t instructions_before = engine.interpreter().instructions_executed();
  RunSummary summary;
  sample();
  ++summary.samples;
  uint64_t ticks_done = 0;
  while (ticks_done < ticks.total) {
    const uint64_t batch = std::min(ticks.per_sample, ticks.total - ticks_done);
    runtime.advance_ticks(batch);
    ticks_done += batch;
    sample();
    ++summary.samples;
    if (!summary.stopped_at_us && !running()) {
      summary.stopped_at_us = runtime.sim_time_us() - start_us;
      if (until_stopped) break;
    }
  }
  if (trace != nullptr) trace->flush();
  summary.wall_s = std::chrono::duration<double>(std::chrono::steady_clock::now() - wall_start).count();
  summary.simulated_us = runtime.sim_time_us() - start_us;
  summary.instructions = engine.interpreter().instructions_executed() - instructions_before;
  return summary;
}

// The report after the run; the exit status says whether the program stopped on a fault.
int report_run(const RunOptions& options, std::string_view module_name, tmcl::TmclEngine& engine,
               const std::vector<Column>& columns, const RunSummary& summary, const TraceOutput& output,
               std::ostream& report) {
  report << fmt::format("{}: {} s of simulated time on {} in {:.3f} s ({:.1f}x real time), {} instructions\n",
                        options.program, format_seconds(summary.simulated_us), module_name, summary.wall_s,
                        summary.wall_s > 0 ? static_cast<double>(summary.simulated_us) * 1e-6 / summary.wall_s : 0.0,
                        summary.instructions);
  if (output.enabled()) {
    report << fmt::format("trace: {} samples ({}) every {} to {}\n", summary.samples, csv_header(columns),
                          options.sample, output.to_stdout() ? "stdout" : options.trace);
  }
  if (!options.plot.empty()) {
    report << fmt::format("plot: {} samples ({}) every {} to {}\n", summary.samples, csv_header(columns),
                          options.sample, options.plot);
  }
  const tmcl::StopReason reason = engine.interpreter().stop_reason();
  if (!summary.stopped_at_us) {
    report << fmt::format("program: still running at the end (program counter {})\n",
                          engine.device().runtime().program_counter);
    return kExitSuccess;
  }
  report << fmt::format("program: stopped by t={} s (seen at the first sample after): {} at address {}\n",
                        format_seconds(*summary.stopped_at_us), tmcl::stop_reason_text(reason),
                        engine.interpreter().stop_address());
  return is_fault(reason) ? kExitProgramFault : kExitSuccess;
}

// "2026-11-27 02:40:13 UTC".
std::string utc_now() {
  const std::time_t now = std::chrono::system_clock::to_time_t(std::chrono::system_clock::now());
  std::tm utc{};
  gmtime_r(&now, &utc);
  char text[32];
  std::strftime(text, sizeof text, "%Y-%m-%d %H:%M:%S UTC", &utc);
  return text;
}

// The page's file (made now) and what it says about the run; the samples come later.
Result<PlotOutput> open_plot(const RunOptions& options, const RunPlan& plan, const host::VirtualModule& module) {
  if (options.plot == "-") return Error{"--plot -: the page goes to a file (--plot FILE.html); --trace - prints the CSV"};
  Result<host::AtomicFile> file = host::AtomicFile::create(options.plot);
  if (!file) return Error{file.error()}.with_context("--plot: ");
  PlotOutput plot{std::move(*file), {}};
  host::web::TracePageData& page = plot.page;
  page.module = module.name();
  page.firmware = std::string(plan.descriptor.firmware);
  page.program = options.program;
  page.started_utc = utc_now();
  page.sample_s = static_cast<double>(plan.sample_us) / 1e6;
  const size_t slash = options.program.find_last_of('/');
  page.title = fmt::format("{} on {}, {}", slash == std::string::npos ? options.program : options.program.substr(slash + 1),
                           page.module, page.started_utc);
  describe_columns(plan, page.columns);
  return plot;
}

int run_run(const RunOptions& options) {
  const Result<RunPlan> plan = check_options(options);
  if (!plan) return usage_error(plan.error());
  const Result<LoadedProgram> program = load_program(options.program, options.include_dirs);
  if (!program) return usage_error(program.error());
  if (program->has_errors()) return report_program_errors(*program, options.program);
  const Result<uint32_t> address = start_address(options, *program);
  if (!address) return usage_error(address.error());

  Result<ModuleInputs> inputs =
      read_module_inputs(plan->descriptor.input_signals(), options.assignments, options.scenario_path);
  if (!inputs) return usage_error(inputs.error());
  const Result<std::unique_ptr<host::VirtualModule>> made =
      make_module_to_run(options, plan->descriptor, std::move(inputs->initial_inputs));
  if (!made) return usage_error(made.error());
  host::VirtualModule& module = **made;
  const Result<TickPlan> ticks = ticks_of(options, *plan, module.tick_period_us());
  if (!ticks) return usage_error(ticks.error());
  tmcl::TmclEngine& engine = module.engine();
  const Result<std::vector<Column>> columns = trace_columns(engine, module.name(), *plan, options.motor);
  if (!columns) return usage_error(columns.error());
  // No CSV unless asked for when the page is the output.
  Result<TraceOutput> output =
      TraceOutput::open(!options.trace.empty() ? options.trace : options.plot.empty() ? "trace.csv" : "");
  if (!output) return usage_error(output.error());
  std::optional<PlotOutput> plot;
  if (!options.plot.empty()) {
    Result<PlotOutput> opened = open_plot(options, *plan, module);
    if (!opened) return usage_error(opened.error());
    plot.emplace(std::move(*opened));
  }

  if (const Result<void> downloaded = download(engine, program->instructions); !downloaded) {
    return usage_error(downloaded.error());
  }
  host::HostRuntime runtime(module, host::Pacing::fast());
  if (inputs->scenario) runtime.set_scenario(std::move(*inputs->scenario));
  std::ostream& report = output->report();
  runtime.set_output_listener([&report](const sim::OutputChange& change) {
    report << "output " << change.signal << ' ' << change.level << " at " << format_seconds(change.sim_time_us) << '\n';
  });
  runtime.start();
  if (const Result<void> started = start_program(engine, *address); !started) return usage_error(started.error());
  const RunSummary summary = sample_loop(runtime, engine, *columns, *ticks, options.until_stopped, output->trace(),
                                         plot ? &plot->page : nullptr);
  std::ostringstream report_text;
  const int status = report_run(options, module.name(), engine, *columns, summary, *output, report_text);
  report << report_text.str();
  if (plot) {
    plot->page.duration_s = static_cast<double>(summary.simulated_us) / 1e6;
    plot->page.report = report_text.str();
    const Result<std::string> page = host::web::render_trace_page(plot->page);
    if (!page) return usage_error(page.error());
    if (const Result<void> written = plot->file.commit(*page); !written) {
      return usage_error(Error{written.error()}.with_context("--plot: ").message);
    }
  }
  return status;
}

}  // namespace

void add_run_command(CLI::App& app, int& exit_status) {
  auto options = std::make_shared<RunOptions>();
  std::string default_columns;  // "52,42 on tmcm-1636, ..."
  for (const host::ModuleDescriptor& module : host::registered_modules()) {
    if (module.trace_parameters.empty()) continue;
    if (!default_columns.empty()) default_columns += ", ";
    for (size_t i = 0; i < module.trace_parameters.size(); ++i) {
      default_columns += (i > 0 ? "," : "") + std::to_string(module.trace_parameters[i]);
    }
    default_columns += fmt::format(" on {}", module.name);
  }
  if (const host::ModuleDescriptor* first = host::first_module(&host::has_tmcl)) options->module = std::string(first->name);
  CLI::App* command = app.add_subcommand(
      "run", "Run a TMCL program headless on an in-process virtual module and write a CSV trace");
  command->add_option("program", options->program, "The .tmc source (or a .bin file from motwin asm)")->required();
  command->add_option("-I,--include-dir", options->include_dirs,
                      "Directory searched for #include files not found next to the including file (repeatable)");
  command->add_option("--module", options->module, "Module to run: " + host::module_names(&host::has_tmcl))
      ->type_name("NAME")
      ->capture_default_str();
  command->add_option("--for", options->duration, "Simulated time to run: 10s, 500ms, 2.5s, 1min")
      ->type_name("DURATION")
      ->required();
  command->add_option("--trace", options->trace,
                      "The CSV file to write, - for stdout (default trace.csv; none when --plot is given alone)")
      ->type_name("FILE");
  command->add_option("--plot", options->plot,
                      "Also write the trace as a self-contained HTML page with its curves (opens offline)")
      ->type_name("FILE.html");
  command->add_option("--sample", options->sample, "Sample period in simulated time (a multiple of the control tick)")
      ->type_name("DURATION")
      ->capture_default_str();
  command->add_option("--param", options->params,
                      "Axis parameters to trace, as 52,42 (repeatable; default actual position and velocity: " +
                          default_columns + ")")
      ->type_name("N[,N...]");
  command->add_option("--var", options->variables, "User variables (GGP bank 2) to trace, as 0,1 (repeatable)")
      ->type_name("N[,N...]");
  command->add_option("--axis", options->motor, "Motor number of the traced axis parameters")
      ->capture_default_str()
      ->check(CLI::Range(0, 255));
  command->add_option("--address", options->address, "Start the program at this address (default 0)")
      ->check(CLI::Range(0, 65535));
  command->add_option("--label", options->label, "Start the program at this label");
  command->add_flag("--until-stopped", options->until_stopped, "End the run when the program stops");
  command->add_option("--state-dir", options->state_dir,
                      "Use (and update) the EEPROM image in DIR; default none: factory defaults in memory")
      ->type_name("DIR")
      ->capture_default_str();
  command->add_option("--set", options->assignments, "Set an input before power-up, as motwin serve --set")
      ->type_name("NAME=VALUE");
  command->add_option("--scenario", options->scenario_path, "Change inputs over simulated time, as motwin serve")
      ->type_name("FILE");
  command->add_option("--motor", options->motor_model, "The motor model, as motwin serve --motor")
      ->type_name("MODEL");
  command->add_option("--firmware", options->firmware, "The firmware generation, as motwin serve --firmware")
      ->type_name("VERSION");
  command->footer(
      "Examples:\n"
      "  motwin run program.tmc --for 10s --trace trace.csv\n"
      "  motwin run program.tmc --for 2s --sample 10ms --param 52,42,55 --var 0 --trace - | head\n"
      "  motwin run jumps.tmc --label Func3 --for 8s --until-stopped --trace func3.csv\n"
      "  motwin run step.tmc --for 1s --param 52,42,13 --plot step.html\n"
      "\n"
      "The program is downloaded (132 ... 133) and started with 129 type 1 at address 0 (or --address,\n"
      "--label); then the simulation runs without pacing for --for of simulated time. The CSV has a\n"
      "header 'time_s,AP52,AP42,var0' and one row per sample (at 0, every --sample, and at the end),\n"
      "time in simulated seconds from the start of the program. A program that stops before --for\n"
      "keeps being sampled until --for (motion continues), unless --until-stopped.\n"
      "--plot writes the same samples as one HTML page (curves, zoom, cursor, trigger, CSV and PNG\n"
      "export; nothing loaded from the network); see docs/web-console.md.\n"
      "Exit status: 0 done, 1 the program has errors or stopped on a fault (jump outside memory,\n"
      "invalid instruction ...), 2 usage error or unreadable file. See docs/tmcl-programs.md.\n");
  command->callback([options, &exit_status] { exit_status = run_run(*options); });
}

}  // namespace motwin::cli
