// `motwin disasm`: a `.bin` program, or the program memory of a module (read with command
// 134), back to TMCL-IDE source on stdout (docs/assembler.md).
#include <algorithm>
#include <chrono>
#include <iostream>
#include <memory>
#include <optional>
#include <string>
#include <vector>

#include <fmt/format.h>

#include "cli/cli_errors.h"
#include "cli/commands.h"
#include "cli/module_connection.h"
#include "tools/program_transfer.h"
#include "tools/tmcl_assembler.h"
#include "tools/tmcl_binary.h"
#include "tools/tmcl_client.h"
#include "tools/tmcl_disassembler.h"

namespace motwin::cli {
namespace {

struct DisasmOptions {
  std::string binary;
  ModuleConnection connection;
  uint32_t start = 0;
  std::optional<uint32_t> count;
  uint32_t program_memory = static_cast<uint32_t>(tools::kDefaultProgramMemorySize);
  bool no_addresses = false;
  bool keep_final_stop = false;
};

Result<std::vector<tmcl::Instruction>> read_from_module(const DisasmOptions& options) {
  Result<tools::TmclClient> client = connect(options.connection);
  if (!client) return Error{client.error()};
  const uint8_t module_address = options.connection.address();
  if (options.count) return tools::read_program(client.value(), options.start, *options.count, module_address);
  const uint32_t remaining = options.program_memory - std::min(options.start, options.program_memory);
  return tools::read_stored_program(client.value(), options.start, remaining, module_address);
}

int run_disasm(const DisasmOptions& options) {
  const int sources = (options.binary.empty() ? 0 : 1) + (options.connection.tcp_address.empty() ? 0 : 1) +
                      (options.connection.serial_device.empty() ? 0 : 1);
  if (sources != 1) return usage_error("give exactly one of PROGRAM.bin, --tcp HOST:PORT or --serial DEVICE");
  if (!options.binary.empty() && (options.count || options.start != 0)) {
    return usage_error("--start and --count apply to reading a module's memory (--tcp or --serial)");
  }
  const Result<std::vector<tmcl::Instruction>> program =
      options.binary.empty() ? read_from_module(options) : tools::read_program_binary(options.binary);
  if (!program) return usage_error(program.error());
  tools::DisassemblyOptions disassembly;
  disassembly.address_comments = !options.no_addresses;
  disassembly.omit_final_stop = !options.keep_final_stop;
  std::cout << tools::disassemble(program.value(), disassembly);
  return kExitSuccess;
}

}  // namespace

void add_disasm_command(CLI::App& app, int& exit_status) {
  auto options = std::make_shared<DisasmOptions>();
  CLI::App* command =
      app.add_subcommand("disasm", "Turn a .bin program or a module's program memory back into TMCL mnemonics");
  command->add_option("program", options->binary, "The .bin file (8 bytes per instruction)");
  add_connection_options(*command, options->connection,
                         {"Read a module's memory over TCP, HOST:PORT",
                          "Read a module's memory over a serial device or pseudo-terminal"});
  command->add_option("--start", options->start, "First address to read from the module")->capture_default_str();
  command->add_option("--count", options->count,
                      "Number of instructions to read (default: up to the first NOP, command 0, that ends a download)");
  command->add_option("--program-memory", options->program_memory, "Module's program memory size in instructions")
      ->capture_default_str()
      ->check(CLI::Range(1, 1 << 24));
  command->add_flag("--no-addresses", options->no_addresses, "Leave out the '// ADDRESS' comments");
  command->add_flag("--keep-final-stop", options->keep_final_stop,
                    "Write a final STOP as an instruction (by default it is a comment, as the assembler appends it)");
  command->footer(
      "Examples:\n"
      "  motwin disasm program.bin\n"
      "  motwin disasm --tcp 127.0.0.1:5000            (reads program memory with command 134)\n"
      "\n"
      "The output assembles (motwin asm) to the same bytes: jump, call and vector targets get\n"
      "labels L<address>, and the final STOP, which the assembler appends, is a comment.\n"
      "Exit status: 0 success, 2 usage error, unreadable or corrupt file, no connection or an\n"
      "error status from the module.\n");
  command->callback([options, &exit_status] { exit_status = run_disasm(*options); });
}

}  // namespace motwin::cli
