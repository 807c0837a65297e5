// `motwin run`: runs a TMCL program headless on an in-process virtual module at full simulation
// speed and writes a CSV trace of chosen parameters against simulated time
// (docs/tmcl-programs.md "motwin run").
//
// The module is made as `motwin serve` makes it (module registry, --set, --scenario, --motor),
// the program is downloaded through the TMCL engine exactly as a host would download it (132,
// instructions, NOP, 133), started with 129 type 1, and the ticks run back to back without
// pacing. Samples are direct-mode reads through the engine (GAP, GGP), so they never disturb
// the program's accumulator.
#include <algorithm>
#include <chrono>
#include <cmath>
#include <cstdio>
#include <fstream>
#include <iostream>
#include <memory>
#include <optional>
#include <string>
#include <string_view>
#include <vector>

#include <fmt/format.h>

#include "cli/cli_errors.h"
#include "cli/commands.h"
#include "cli/program_source.h"
#include "core/tmcl/engine.h"
#include "core/tmcl/interpreter.h"
#include "core/tmcl/status.h"
#include "host/host_runtime.h"
#include "host/module_registry.h"
#include "host/pacing.h"
#include "host/state_dir.h"
#include "sim/scenario.h"
#include "sim/signals.h"
#include "tools/tmcl_mnemonics.h"

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
  std::string trace = "trace.csv";
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
  bool until_stopped = false;
};

struct RunError {
  std::string message;
  int exit_status = kExitUsageError;
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
std::vector<uint8_t> parse_numbers(const std::vector<std::string>& lists, std::string_view option) {
  std::vector<uint8_t> numbers;
  for (const std::string& list : lists) {
    size_t begin = 0;
    while (begin <= list.size()) {
      const size_t comma = std::min(list.find(',', begin), list.size());
      const std::string word = list.substr(begin, comma - begin);
      const std::optional<int64_t> number = tools::parse_integer(word);
      if (!number || *number < 0 || *number > 255) {
        throw RunError{fmt::format("{} {}: '{}' is not a parameter number 0..255", option, list, word)};
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

// One column of the trace: a direct-mode read through the engine.
struct Column {
  std::string name;
  tmcl::Instruction read;
};

// Downloads through the engine, as a host would (docs/tmcl-programs.md).
void download(tmcl::TmclEngine& engine, const std::vector<tmcl::Instruction>& program) {
  const auto expect = [&](const tmcl::Instruction& in, tmcl::Status status, const std::string& what) {
    const tmcl::CommandResult result = engine.execute(in, tmcl::Origin::kHost);
    if (result.status != status) {
      throw RunError{fmt::format("{}: the module answered status {} ({})", what, tmcl::to_byte(result.status),
                                 tmcl::status_name(tmcl::to_byte(result.status)))};
    }
  };
  expect({cmd::kEnterDownloadMode, 0, 0, 0}, tmcl::Status::kOk, "entering download mode (132)");
  for (size_t i = 0; i < program.size(); ++i) {
    expect(program[i], tmcl::Status::kStoredInProgram,
           fmt::format("downloading address {} ({})", i, tools::format_instruction(program[i])));
  }
  expect({cmd::kNop, 0, 0, 0}, tmcl::Status::kStoredInProgram, "downloading the trailing NOP");
  expect({cmd::kExitDownloadMode, 0, 0, 0}, tmcl::Status::kOk, "leaving download mode (133)");
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

int run_run(const RunOptions& options) {
  const host::ModuleDescriptor* descriptor = host::find_module(options.module);
  if (descriptor == nullptr) {
    throw RunError{fmt::format("unknown module \"{}\" (available: {})", options.module, host::module_names())};
  }
  if (!descriptor->endpoints.has_tmcl()) {
    throw RunError{fmt::format("{} has no TMCL interpreter (motwin run takes a TMCL module: {})", options.module,
                               host::module_names(&host::has_tmcl))};
  }
  const std::optional<uint64_t> duration_us = parse_duration_us(options.duration);
  if (!duration_us) throw RunError{fmt::format("--for {}: expected a duration such as 10s, 500ms or 2.5s", options.duration)};
  const std::optional<uint64_t> sample_us = parse_duration_us(options.sample);
  if (!sample_us || *sample_us == 0) {
    throw RunError{fmt::format("--sample {}: expected a duration such as 1ms, 50us or 0.1s", options.sample)};
  }
  if (options.address && !options.label.empty()) throw RunError{"give at most one of --address and --label"};
  // Default columns: the module's actual position and velocity.
  const std::vector<uint8_t> params =
      options.params.empty() ? descriptor->trace_parameters : parse_numbers(options.params, "--param");
  const std::vector<uint8_t> variables = parse_numbers(options.variables, "--var");

  int exit_status = kExitSuccess;
  const std::optional<LoadedProgram> program = load_program(options.program, options.include_dirs, exit_status);
  if (!program) return exit_status;
  uint32_t start_address = options.address.value_or(0);
  if (!options.label.empty()) {
    const std::optional<uint32_t> found = program->label_address(options.label);
    if (!found) throw RunError{fmt::format("{} defines no label '{}'", options.program, options.label)};
    start_address = *found;
  }

  // The module, as `motwin serve` makes it.
  host::ModuleOptions module_options;
  module_options.motor = options.motor_model;
  for (const std::string& text : options.assignments) {
    const Result<sim::SignalAssignment> assignment = sim::parse_signal_assignment(descriptor->input_signals(), text);
    if (!assignment) throw RunError{"--set " + text + ": " + assignment.error()};
    module_options.initial_inputs.push_back(host::InitialInput{std::string(assignment->signal->name), assignment->value});
  }
  std::optional<std::vector<sim::ScenarioEvent>> scenario;
  if (!options.scenario_path.empty()) {
    Result<std::vector<sim::ScenarioEvent>> events =
        sim::load_scenario_file(options.scenario_path, descriptor->input_signals());
    if (!events) throw RunError{events.error()};
    scenario = std::move(*events);
  }
  if (options.state_dir != host::kNoStateDir) module_options.state_dir = options.state_dir;
  host::MakeModuleResult made = descriptor->make(module_options);
  if (!made) throw RunError{made.error()};
  host::VirtualModule& module = **made;
  if (!module.has_tmcl()) throw RunError{fmt::format("{} has no TMCL interpreter", module.name())};
  const uint64_t tick_us = module.tick_period_us();
  const uint64_t sample_ticks = *sample_us / tick_us;
  if (sample_ticks == 0 || sample_ticks * tick_us != *sample_us) {
    throw RunError{fmt::format("--sample {}: must be a whole number of the module's {} us control ticks", options.sample,
                               tick_us)};
  }
  const uint64_t total_ticks = *duration_us / tick_us;

  tmcl::TmclEngine& engine = module.engine();
  std::vector<Column> columns;
  for (const uint8_t number : params) {
    columns.push_back(Column{fmt::format("AP{}", number),
                             tmcl::Instruction{cmd::kGap, number, static_cast<uint8_t>(options.motor), 0}});
  }
  for (const uint8_t number : variables) {
    columns.push_back(Column{fmt::format("var{}", number), tmcl::Instruction{cmd::kGgp, number, 2, 0}});
  }
  // Every column must be readable before the run starts.
  for (const Column& column : columns) {
    const tmcl::CommandResult result = engine.execute(column.read, tmcl::Origin::kHost);
    if (result.status != tmcl::Status::kOk) {
      throw RunError{fmt::format("{} cannot be read on {} motor {}: status {} ({})", column.name, module.name(),
                                 options.motor, tmcl::to_byte(result.status),
                                 tmcl::status_name(tmcl::to_byte(result.status)))};
    }
  }

  std::ofstream file;
  const bool to_stdout = options.trace == "-";
  if (!to_stdout) {
    file.open(options.trace, std::ios::trunc);
    if (!file) throw RunError{fmt::format("cannot write the trace to {}", options.trace)};
  }
  std::ostream& trace = to_stdout ? std::cout : file;
  std::ostream& report = to_stdout ? std::cerr : std::cout;

  download(engine, program->instructions);
  host::HostRuntime runtime(module, host::Pacing::fast());
  if (scenario) runtime.set_scenario(std::move(*scenario));
  runtime.set_output_listener([&report](const sim::OutputChange& change) {
    report << "output " << change.signal << ' ' << change.level << " at " << format_seconds(change.sim_time_us) << '\n';
  });
  runtime.start();
  const tmcl::CommandResult started =
      engine.execute(tmcl::Instruction{cmd::kRunApplication, 1, 0, static_cast<int32_t>(start_address)}, tmcl::Origin::kHost);
  if (started.status != tmcl::Status::kOk) {
    throw RunError{fmt::format("starting at address {} (129): status {} ({})", start_address,
                               tmcl::to_byte(started.status), tmcl::status_name(tmcl::to_byte(started.status)))};
  }

  const uint64_t start_us = runtime.sim_time_us();
  trace << "time_s";
  for (const Column& column : columns) trace << ',' << column.name;
  trace << '\n';
  std::string row;
  const auto sample = [&] {
    row = format_seconds(runtime.sim_time_us() - start_us);
    for (const Column& column : columns) {
      row += ',';
      row += std::to_string(engine.execute(column.read, tmcl::Origin::kHost).value);
    }
    trace << row << '\n';
  };
  const auto running = [&] {
    const auto status = engine.device().runtime().application_status;
    return status == tmcl::ApplicationStatus::kRunning || status == tmcl::ApplicationStatus::kStepping;
  };

  const auto wall_start = std::chrono::steady_clock::now();
  const uint64_t instructions_before = engine.interpreter().instructions_executed();
  uint64_t samples = 0;
  std::optional<uint64_t> stopped_at_us;
  sample();
  ++samples;
  uint64_t ticks_done = 0;
  while (ticks_done < total_ticks) {
    const uint64_t batch = std::min(sample_ticks, total_ticks - ticks_done);
    runtime.advance_ticks(batch);
    ticks_done += batch;
    sample();
    ++samples;
    if (!stopped_at_us && !running()) {
      stopped_at_us = runtime.sim_time_us() - start_us;
      if (options.until_stopped) break;
    }
  }
  trace.flush();
  const double wall_s = std::chrono::duration<double>(std::chrono::steady_clock::now() - wall_start).count();
  const uint64_t simulated_us = runtime.sim_time_us() - start_us;
  const uint64_t instructions = engine.interpreter().instructions_executed() - instructions_before;

  report << fmt::format("{}: {} s of simulated time on {} in {:.3f} s ({:.1f}x real time), {} instructions\n",
                        options.program, format_seconds(simulated_us), module.name(), wall_s,
                        wall_s > 0 ? static_cast<double>(simulated_us) * 1e-6 / wall_s : 0.0, instructions);
  std::string header = "time_s";
  for (const Column& column : columns) header += "," + column.name;
  report << fmt::format("trace: {} samples ({}) every {} to {}\n", samples, header, options.sample,
                        to_stdout ? "stdout" : options.trace);
  const tmcl::StopReason reason = engine.interpreter().stop_reason();
  if (!stopped_at_us) {
    report << fmt::format("program: still running at the end (program counter {})\n",
                          engine.device().runtime().program_counter);
    return kExitSuccess;
  }
  report << fmt::format("program: stopped by t={} s (seen at the first sample after): {} at address {}\n",
                        format_seconds(*stopped_at_us), tmcl::stop_reason_text(reason),
                        engine.interpreter().stop_address());
  return is_fault(reason) ? kExitProgramFault : kExitSuccess;
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
  command->add_option("--trace", options->trace, "The CSV file to write, - for stdout")->capture_default_str();
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
  command->footer(
      "Examples:\n"
      "  motwin run program.tmc --for 10s --trace trace.csv\n"
      "  motwin run program.tmc --for 2s --sample 10ms --param 52,42,55 --var 0 --trace - | head\n"
      "  motwin run jumps.tmc --label Func3 --for 8s --until-stopped --trace func3.csv\n"
      "\n"
      "The program is downloaded (132 ... 133) and started with 129 type 1 at address 0 (or --address,\n"
      "--label); then the simulation runs without pacing for --for of simulated time. The CSV has a\n"
      "header 'time_s,AP52,AP42,var0' and one row per sample (at 0, every --sample, and at the end),\n"
      "time in simulated seconds from the start of the program. A program that stops before --for\n"
      "keeps being sampled until --for (motion continues), unless --until-stopped.\n"
      "Exit status: 0 done, 1 the program has errors or stopped on a fault (jump outside memory,\n"
      "invalid instruction ...), 2 usage error or unreadable file. See docs/tmcl-programs.md.\n");
  command->callback([options, &exit_status] {
    try {
      exit_status = run_run(*options);
    } catch (const RunError& error) {
      print_error(error.message);
      exit_status = error.exit_status;
    }
  });
}

}  // namespace motwin::cli
