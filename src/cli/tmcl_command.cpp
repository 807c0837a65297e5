// `motwin tmcl`: sends one TMCL instruction to a module over TCP or a serial line and prints
// the reply.
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
#include "core/tmcl/status.h"
#include "tools/tmcl_client.h"
#include "tools/tmcl_mnemonics.h"

namespace motwin::cli {
namespace {

struct TmclOptions {
  ModuleConnection connection;
  std::vector<std::string> instruction_words;
};

std::string help_footer() {
  std::string out =
      "Examples:\n"
      "  motwin tmcl --tcp 127.0.0.1:5000 MVP ABS, 0, 90000\n"
      "  motwin tmcl --tcp 127.0.0.1:5000 MVP REL 0 -10000\n"
      "  motwin tmcl --tcp 127.0.0.1:5000 GAP 52 0\n"
      "  motwin tmcl --serial /dev/pts/4 SGP 77, 0, 0\n"
      "  motwin tmcl --tcp 127.0.0.1:5000 136 0        (control command 136 type 0: version string)\n"
      "\n"
      "Output: 'status CODE (MEANING) value VALUE'; for 136 type 0 'version STRING'.\n"
      "Exit status: 0 success status, 1 error status, 2 usage error, no connection or no valid reply.\n"
      "Operands may be separated by commas and/or blanks; numbers are decimal or 0x hexadecimal.\n"
      "Control commands (128..139, 255) have no mnemonic: give CMD [TYPE [MOTOR [VALUE]]].\n"
      "\nMnemonics:\n";
  for (const tools::MnemonicSpec& spec : tools::mnemonic_table()) {
    out += fmt::format("  {:<6}{:>3}  {}\n", spec.mnemonic, spec.command, tools::operand_synopsis(spec));
  }
  return out;
}

// Joins the words back into one line: the parser, not the shell, splits operands, so that
// "MVP ABS, 0, 90000" and "MVP ABS 0 90000" mean the same.
std::string join_words(const std::vector<std::string>& words) {
  std::string line;
  for (const std::string& word : words) {
    if (!line.empty()) line += ' ';
    line += word;
  }
  return line;
}

int run_tmcl(const TmclOptions& options) {
  const ModuleConnection& connection = options.connection;
  if (connection.tcp_address.empty() == connection.serial_device.empty()) {
    return usage_error("give exactly one of --tcp HOST:PORT or --serial DEVICE");
  }
  if (options.instruction_words.empty()) {
    return usage_error("no instruction given: expected for example 'GAP 52 0' (see motwin tmcl --help)");
  }
  const Result<tmcl::Instruction> instruction = tools::parse_instruction(join_words(options.instruction_words));
  if (!instruction) return usage_error(instruction.error());
  Result<tools::TmclClient> client = connect(connection);
  if (!client) return usage_error(client.error());
  const Result<tools::TmclReply> reply = client->request(instruction.value(), connection.address());
  if (!reply) return usage_error(reply.error());

  switch (reply->kind) {
    case tools::ReplyKind::kNone:
      std::cout << fmt::format("sent; command {} has no reply\n", reply->command);
      return kExitSuccess;
    case tools::ReplyKind::kVersionString:
      std::cout << fmt::format("version {}\n", reply->version_string);
      return kExitSuccess;
    case tools::ReplyKind::kNormal:
      break;
  }
  std::cout << fmt::format("status {} ({}) value {}\n", reply->status, tmcl::status_name(reply->status), reply->value);
  if (!tmcl::is_success(reply->status)) {
    print_error(fmt::format("the module answered status {} ({})", reply->status, tmcl::status_name(reply->status)));
    return kExitModuleError;
  }
  return kExitSuccess;
}

}  // namespace

void add_tmcl_command(CLI::App& app, int& exit_status) {
  auto options = std::make_shared<TmclOptions>();
  CLI::App* command = app.add_subcommand("tmcl", "Send one TMCL instruction to a module and print its reply");
  add_connection_options(*command, options->connection,
                         {"TMCL-over-TCP endpoint, HOST:PORT", "Serial device or pseudo-terminal (115200 bit/s)",
                          "Module address of the request", "How long to wait for the reply (and to connect)"});
  command->add_option("instruction", options->instruction_words,
                      "MNEMONIC OPERANDS... (TMCL-IDE syntax) or CMD [TYPE [MOTOR [VALUE]]]");
  command->footer(help_footer());
  command->callback([options, &exit_status] { exit_status = run_tmcl(*options); });
}

}  // namespace motwin::cli
