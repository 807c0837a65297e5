// `motwin asm`: assembles a TMCL-IDE `.tmc` program into a `.bin` file (8 bytes per
// instruction), with an optional listing and symbol file (docs/assembler.md).
#include <filesystem>
#include <fstream>
#include <iostream>
#include <memory>
#include <string>
#include <string_view>
#include <vector>

#include <fmt/format.h>

#include "cli/cli_errors.h"
#include "cli/commands.h"
#include "tools/tmcl_assembler.h"
#include "tools/tmcl_binary.h"
#include "types/result.h"

namespace motwin::cli {
namespace {

constexpr int kExitAssemblyError = 1;  // the program has errors; nothing was written

struct AsmOptions {
  std::string source;
  std::string output;
  std::vector<std::string> include_dirs;
  std::string listing;
  std::string symbols;
  size_t program_memory = tools::kDefaultProgramMemorySize;
};

// Writes the `what` (the listing, the symbols) to `path`; "-" writes to stdout.
Result<void> write_text(const std::string& path, const std::string& text, std::string_view what) {
  bool written = false;
  if (path == "-") {
    std::cout << text << std::flush;
    written = static_cast<bool>(std::cout);
  } else {
    std::ofstream out(path, std::ios::trunc);
    out << text;
    out.close();
    written = static_cast<bool>(out);
  }
  if (written) return {};
  return Error{fmt::format("cannot write the {} to {}", what, path)};
}

int run_asm(const AsmOptions& options) {
  tools::AssemblerOptions assembler_options;
  assembler_options.include_dirs = options.include_dirs;
  assembler_options.program_memory_size = options.program_memory;
  const tools::AssemblyResult result = tools::assemble_file(options.source, assembler_options);
  if (!result.ok()) {
    for (const tools::AssemblyError& error : result.errors) std::cerr << tools::format_error(error) << '\n';
    if (result.errors.front().kind == tools::AssemblyErrorKind::kFileNotFound) return kExitUsageError;
    print_error(fmt::format("{} error{} in {}; nothing written", result.errors.size(),
                            result.errors.size() == 1 ? "" : "s", options.source));
    return kExitAssemblyError;
  }

  const std::string output = options.output.empty()
                                 ? std::filesystem::path(options.source).replace_extension(".bin").string()
                                 : options.output;
  if (std::filesystem::path(output).lexically_normal() == std::filesystem::path(options.source).lexically_normal()) {
    return usage_error(fmt::format("the output {} would overwrite the source; give another name with -o", output));
  }
  const Result<size_t> written = tools::write_program_binary(output, result.instructions);
  if (!written) return usage_error(written.error());
  if (!options.listing.empty()) {
    const Result<void> listed = write_text(options.listing, tools::format_listing(result), "listing");
    if (!listed) return usage_error(listed.error());
  }
  if (!options.symbols.empty()) {
    const Result<void> symbols = write_text(options.symbols, tools::format_symbols(result), "symbols");
    if (!symbols) return usage_error(symbols.error());
  }
  // The summary goes to stderr when stdout carries the listing or the symbols.
  const bool stdout_taken = options.listing == "-" || options.symbols == "-";
  (stdout_taken ? std::cerr : std::cout) << fmt::format("{}: {} instructions (STOP appended), {} bytes written to {}\n",
                                                        options.source, result.instructions.size(), written.value(),
                                                        output);
  return kExitSuccess;
}

}  // namespace

void add_asm_command(CLI::App& app, int& exit_status) {
  auto options = std::make_shared<AsmOptions>();
  CLI::App* command = app.add_subcommand("asm", "Assemble a TMCL-IDE .tmc program into a .bin file");
  command->add_option("program", options->source, "The .tmc source file")->required();
  command->add_option("-o,--output", options->output, "The .bin file to write (default: PROGRAM with .bin)");
  command->add_option("-I,--include-dir", options->include_dirs,
                      "Directory searched for #include files not found next to the including file (repeatable)");
  command->add_option("--listing", options->listing,
                      "Write a listing (address, bytes, source) to FILE, or - for stdout");
  command->add_option("--symbols", options->symbols,
                      "Write the labels (addresses for 129 type 1) and constants to FILE, or - for stdout");
  command->add_option("--program-memory", options->program_memory, "Program memory size in instructions")
      ->capture_default_str()
      ->check(CLI::Range(1, 1 << 24));
  command->footer(
      "Examples:\n"
      "  motwin asm program.tmc                        (writes program.bin)\n"
      "  motwin asm program.tmc -o out.bin -I lib --listing - --symbols program.sym\n"
      "\n"
      "Syntax: TMCL-IDE (// comments, Name = value, #include File.tmc, Label:, symbolic operands);\n"
      "a STOP is appended after the last instruction. See docs/assembler.md.\n"
      "Errors: 'FILE:LINE:COLUMN: error: MESSAGE' on stderr, every error of the program.\n"
      "Exit status: 0 assembled, 1 the program has errors (nothing written), 2 usage error or\n"
      "unreadable/unwritable file.\n");
  command->callback([options, &exit_status] { exit_status = run_asm(*options); });
}

}  // namespace motwin::cli
