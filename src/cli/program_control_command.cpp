// `motwin start|stop|step|status`: control the stored TMCL program of a module with the control
// commands of the TMCM-1636 manual table 10 (129 run, 128 stop, 130 step, 135 application
// status), over TCP or a serial line (docs/tmcl-programs.md).
#include <array>
#include <iostream>
#include <memory>
#include <optional>
#include <string>
#include <vector>

#include <fmt/format.h>

#include "cli/cli_errors.h"
#include "cli/commands.h"
#include "cli/module_connection.h"
#include "cli/program_source.h"
#include "core/tmcl/instruction.h"
#include "core/tmcl/interpreter.h"
#include "core/tmcl/status.h"

namespace motwin::cli {
namespace {

namespace cmd = tmcl::command;

// Sends one control command: its reply, or an error unless the module answers status 100.
Result<tools::TmclReply> control(tools::TmclClient& client, const ModuleConnection& connection,
                                 const tmcl::Instruction& request, const std::string& what) {
  Result<tools::TmclReply> reply = client.request(request, connection.address());
  if (!reply) return reply.error_with_context(what + ": ");
  if (reply->status != tmcl::to_byte(tmcl::Status::kOk)) {
    return Error{fmt::format("{}: the module answered status {} ({})", what, reply->status,
                             tmcl::status_name(reply->status))};
  }
  return reply;
}

// --- start --------------------------------------------------------------------------------------

struct StartOptions {
  ModuleConnection connection;
  std::optional<uint32_t> address;
  std::string label;
  std::string program;
  std::vector<std::string> include_dirs;
  bool resume = false;
};

int run_start(const StartOptions& options) {
  const int choices = (options.address ? 1 : 0) + (options.label.empty() ? 0 : 1) + (options.resume ? 1 : 0);
  if (choices > 1) return usage_error("give at most one of --address, --label and --continue");
  if (options.label.empty() != options.program.empty()) {
    return usage_error(
        "--label NAME needs --program FILE (the source that defines the label), and --program needs --label");
  }
  uint32_t address = options.address.value_or(0);
  if (!options.label.empty()) {
    const Result<LoadedProgram> program = load_program(options.program, options.include_dirs);
    if (!program) return usage_error(program.error());
    if (program->has_errors()) return report_program_errors(*program, options.program);
    const std::optional<uint32_t> found = program->label_address(options.label);
    if (!found) return usage_error(fmt::format("{} defines no label '{}'", options.program, options.label));
    address = *found;
  }
  Result<tools::TmclClient> client = connect(options.connection);
  if (!client) return usage_error(client.error());
  // 129 type 0 continues from the current program counter, type 1 starts at the value's address.
  const tmcl::Instruction request = options.resume ? tmcl::Instruction{cmd::kRunApplication, 0, 0, 0}
                                                   : tmcl::Instruction{cmd::kRunApplication, 1, 0, static_cast<int32_t>(address)};
  const Result<tools::TmclReply> started =
      control(client.value(), options.connection, request, "starting the program (129)");
  if (!started) return usage_error(started.error());
  if (options.resume) {
    std::cout << "program continues from its program counter\n";
  } else if (!options.label.empty()) {
    std::cout << fmt::format("program started at {} (address {})\n", options.label, address);
  } else {
    std::cout << fmt::format("program started at address {}\n", address);
  }
  return kExitSuccess;
}

// --- stop, step ---------------------------------------------------------------------------------

int run_simple(const ModuleConnection& connection, const tmcl::Instruction& request, const std::string& what,
               const std::string& done) {
  Result<tools::TmclClient> client = connect(connection);
  if (!client) return usage_error(client.error());
  if (const Result<tools::TmclReply> reply = control(client.value(), connection, request, what); !reply) {
    return usage_error(reply.error());
  }
  std::cout << done << '\n';
  return kExitSuccess;
}

// --- status -------------------------------------------------------------------------------------

std::string application_status_name(uint32_t mode) {
  switch (mode) {
    case 0: return "stop";
    case 1: return "run";
    case 2: return "step";
    case 3: return "reset";
    default: return "unknown";
  }
}

// Command 135 (docs/tmcl-programs.md), types 0 to 4: 0 = mode << 24 | wait flag << 16 |
// download pointer, 1 = the same with the PC, 2 the accumulator, 3 the X register, 4 (Motwin)
// stop reason << 16 | stop address.
using ApplicationStatus = std::array<int32_t, 5>;

Result<ApplicationStatus> read_application_status(tools::TmclClient& client, const ModuleConnection& connection) {
  ApplicationStatus values{};
  for (uint8_t type = 0; type < values.size(); ++type) {
    const Result<tools::TmclReply> reply =
        control(client, connection, tmcl::Instruction{cmd::kGetApplicationStatus, type, 0, 0},
                fmt::format("reading the application status (135 type {})", type));
    if (!reply) return Error{reply.error()};
    values[type] = reply->value;
  }
  return values;
}

void print_application_status(const ApplicationStatus& values) {
  const auto status = static_cast<uint32_t>(values[1]);
  const uint32_t mode = status >> 24;
  const bool waiting = ((status >> 16) & 0xFF) != 0;
  const uint32_t program_counter = status & 0xFFFF;
  const auto stop = static_cast<uint32_t>(values[4]);
  const auto reason = static_cast<tmcl::StopReason>(stop >> 16);
  const uint32_t stop_address = stop & 0xFFFF;
  std::cout << fmt::format("application status: {} ({})\n", application_status_name(mode), mode);
  std::cout << fmt::format("program counter:    {}\n", program_counter);
  std::cout << fmt::format("accumulator:        {}\n", values[2]);
  std::cout << fmt::format("X register:         {}\n", values[3]);
  std::cout << fmt::format("waiting:            {}\n", waiting ? "yes (WAIT in progress)" : "no");
  std::cout << fmt::format("download pointer:   {}\n", static_cast<uint32_t>(values[0]) & 0xFFFF);
  if (reason == tmcl::StopReason::kNone) {
    std::cout << "stop reason:        none\n";
  } else {
    std::cout << fmt::format("stop reason:        {} ({}) at address {}\n", tmcl::stop_reason_text(reason),
                             static_cast<unsigned>(reason), stop_address);
  }
}

int run_status(const ModuleConnection& connection) {
  Result<tools::TmclClient> client = connect(connection);
  if (!client) return usage_error(client.error());
  const Result<ApplicationStatus> status = read_application_status(client.value(), connection);
  if (!status) return usage_error(status.error());
  print_application_status(*status);
  return kExitSuccess;
}

constexpr const char* kExitFooter =
    "Exit status: 0 success, 2 usage error, no connection or an error status from the module.\n"
    "See docs/tmcl-programs.md.\n";

}  // namespace

void add_program_control_commands(CLI::App& app, int& exit_status) {
  {
    auto options = std::make_shared<StartOptions>();
    CLI::App* command = app.add_subcommand("start", "Start the TMCL program stored in a module (command 129)");
    add_connection_options(*command, options->connection);
    command->add_option("--address", options->address, "Start at this program memory address (default 0)")
        ->check(CLI::Range(0, 65535));
    command->add_option("--label", options->label, "Start at this label of --program");
    command->add_option("--program", options->program, "The .tmc source that defines --label");
    command->add_option("-I,--include-dir", options->include_dirs, "Include directory for assembling --program");
    command->add_flag("--continue", options->resume,
                      "Continue from the current program counter (129 type 0), after stop or step");
    command->footer(std::string("Examples:\n"
                                "  motwin start --tcp 127.0.0.1:5000                      (from address 0)\n"
                                "  motwin start --tcp 127.0.0.1:5000 --address 2\n"
                                "  motwin start --tcp 127.0.0.1:5000 --label Func2 --program jumps.tmc\n\n") +
                    kExitFooter);
    command->callback([options, &exit_status] { exit_status = run_start(*options); });
  }
  {
    auto connection = std::make_shared<ModuleConnection>();
    CLI::App* command = app.add_subcommand("stop", "Stop the TMCL program running on a module (command 128)");
    add_connection_options(*command, *connection);
    command->footer(kExitFooter);
    command->callback([connection, &exit_status] {
      exit_status = run_simple(*connection, tmcl::Instruction{cmd::kStopApplication, 0, 0, 0},
                               "stopping the program (128)", "program stopped");
    });
  }
  {
    auto connection = std::make_shared<ModuleConnection>();
    CLI::App* command =
        app.add_subcommand("step", "Run the next instruction of the stored TMCL program (command 130)");
    add_connection_options(*command, *connection);
    command->footer(std::string("The instruction runs at the module's next control tick; `motwin status` shows\n"
                                "the program counter afterwards.\n") +
                    kExitFooter);
    command->callback([connection, &exit_status] {
      exit_status = run_simple(*connection, tmcl::Instruction{cmd::kStepApplication, 0, 0, 0},
                               "stepping the program (130)", "one instruction stepped");
    });
  }
  {
    auto connection = std::make_shared<ModuleConnection>();
    CLI::App* command = app.add_subcommand(
        "status", "Show a module's TMCL program status: mode, program counter, accumulator, X, wait, stop reason");
    add_connection_options(*command, *connection);
    command->footer(std::string("Reads command 135 types 0 to 4 (docs/tmcl-programs.md).\n") + kExitFooter);
    command->callback([connection, &exit_status] { exit_status = run_status(*connection); });
  }
}

}  // namespace motwin::cli
