// `motwin download`: assembles a TMCL-IDE program, downloads it into a module's program memory
// the way the TMCL-IDE does (132, each instruction answered with 101, a trailing NOP, 133) and
// verifies it by reading every instruction back with 134 (docs/tmcl-programs.md).
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
#include "tools/program_transfer.h"
#include "tools/tmcl_mnemonics.h"

namespace motwin::cli {
namespace {

// The download itself went through, but what the module holds is not what was sent.
constexpr int kExitVerifyMismatch = 1;

struct DownloadOptions {
  std::string program;
  std::vector<std::string> include_dirs;
  ModuleConnection connection;
  uint32_t start = 0;
  bool no_verify = false;
};

std::string describe(const tmcl::Instruction& in) {
  return fmt::format("{} ({} {} {} {})", tools::format_instruction(in), in.command, in.type, in.motor_bank, in.value);
}

int run_download(const DownloadOptions& options) {
  const Result<LoadedProgram> program = load_program(options.program, options.include_dirs);
  if (!program) return usage_error(program.error());
  if (program->has_errors()) return report_program_errors(*program, options.program);
  if (program->instructions.empty()) {
    print_error(fmt::format("{} holds no instruction", options.program));
    return kExitProgramError;
  }
  Result<tools::TmclClient> client = connect(options.connection);
  if (!client) return usage_error(client.error());
  const uint8_t address = options.connection.address();
  const Result<size_t> downloaded =
      tools::download_program(client.value(), program->instructions, options.start, address);
  if (!downloaded) {
    return usage_error(fmt::format("download to {} failed: {}", client->peer_name(), downloaded.error()));
  }
  const size_t count = program->instructions.size();
  const uint32_t last = options.start + static_cast<uint32_t>(count) - 1;
  if (options.no_verify) {
    std::cout << fmt::format("{}: {} instructions downloaded to addresses {}..{} of {} (not verified)\n",
                             options.program, count, options.start, last, client->peer_name());
    return kExitSuccess;
  }

  const Result<std::vector<tmcl::Instruction>> stored =
      tools::read_program(client.value(), options.start, static_cast<uint32_t>(count), address);
  if (!stored) {
    return usage_error(
        fmt::format("downloaded, but reading it back from {} failed: {}", client->peer_name(), stored.error()));
  }
  size_t mismatches = 0;
  for (size_t i = 0; i < count; ++i) {
    const tmcl::Instruction& sent = program->instructions[i];
    const tmcl::Instruction& held = stored.value()[i];
    if (sent.command == held.command && sent.type == held.type && sent.motor_bank == held.motor_bank &&
        sent.value == held.value) {
      continue;
    }
    if (++mismatches <= 10) {
      std::cerr << fmt::format("motwin: address {}: sent {}, the module holds {}\n", options.start + i, describe(sent),
                               describe(held));
    }
  }
  if (mismatches > 0) {
    print_error(fmt::format("verification failed: {} of {} instructions read back with 134 differ from what was "
                            "downloaded to {}",
                            mismatches, count, client->peer_name()));
    return kExitVerifyMismatch;
  }
  std::cout << fmt::format("{}: {} instructions downloaded to addresses {}..{} of {} and verified\n", options.program,
                           count, options.start, last, client->peer_name());
  return kExitSuccess;
}

}  // namespace

void add_download_command(CLI::App& app, int& exit_status) {
  auto options = std::make_shared<DownloadOptions>();
  CLI::App* command =
      app.add_subcommand("download", "Assemble a TMCL program, download it into a module and verify it");
  command->add_option("program", options->program, "The .tmc source (or a .bin file from motwin asm)")->required();
  command->add_option("-I,--include-dir", options->include_dirs,
                      "Directory searched for #include files not found next to the including file (repeatable)");
  add_connection_options(*command, options->connection);
  command->add_option("--start", options->start, "Program memory address of the first instruction")
      ->capture_default_str()
      ->check(CLI::Range(0, 65535));
  command->add_flag("--no-verify", options->no_verify, "Do not read the program back with command 134");
  command->footer(
      "Examples:\n"
      "  motwin download program.tmc --tcp 127.0.0.1:5000\n"
      "  motwin download program.tmc --serial /tmp/tmcm1636 -I lib\n"
      "\n"
      "The download is the TMCL-IDE's: 132 (start address), every instruction (answered with status\n"
      "101), a NOP, 133. The module stops a running program when the download starts and makes the\n"
      "new program permanent at 133. Then every instruction is read back with 134 and compared.\n"
      "Exit status: 0 downloaded and verified, 1 the program has errors or the read-back differs,\n"
      "2 usage error, unreadable file, no connection or an error status from the module.\n"
      "See docs/tmcl-programs.md.\n");
  command->callback([options, &exit_status] { exit_status = run_download(*options); });
}

}  // namespace motwin::cli
