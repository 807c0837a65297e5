// A TMCL program given on the command line of `motwin download`, `start --label` and `run`: a
// `.tmc` source (assembled, docs/assembler.md) or a `.bin` file (8 bytes per instruction).
#pragma once

#include <cctype>
#include <filesystem>
#include <iostream>
#include <optional>
#include <string>
#include <vector>

#include <fmt/format.h>

#include "cli/cli_errors.h"
#include "core/tmcl/instruction.h"
#include "tools/tmcl_assembler.h"
#include "tools/tmcl_binary.h"
#include "types/result.h"

namespace motwin::cli {

// The program has errors (assembly errors are printed); nothing was done.
inline constexpr int kExitProgramError = 1;

struct LoadedProgram {
  std::vector<tmcl::Instruction> instructions;
  std::optional<tools::AssemblyResult> assembly;  // for .tmc sources: labels, listing, or the errors

  // The source has errors (assembly->errors): there is nothing to download.
  bool has_errors() const { return assembly && !assembly->ok(); }
  // A label's address; std::nullopt when unknown (or the program is a .bin without labels).
  std::optional<uint32_t> label_address(const std::string& label) const {
    return assembly ? assembly->label_address(label) : std::nullopt;
  }
};

inline bool is_binary_program(const std::string& path) {
  std::string extension = std::filesystem::path(path).extension().string();
  for (char& c : extension) c = static_cast<char>(std::tolower(static_cast<unsigned char>(c)));
  return extension == ".bin";
}

// Reads a .bin file (one that cannot be read or decoded is an error) or assembles a .tmc
// source. A source with errors is the assembler's answer, not an error of loading: has_errors(),
// and report_program_errors() prints them as the assembler words them.
inline Result<LoadedProgram> load_program(const std::string& path, const std::vector<std::string>& include_dirs) {
  LoadedProgram program;
  if (is_binary_program(path)) {
    Result<std::vector<tmcl::Instruction>> binary = tools::read_program_binary(path);
    if (!binary) return Error{binary.error()};
    program.instructions = std::move(binary.value());
    return program;
  }
  tools::AssemblerOptions options;
  options.include_dirs = include_dirs;
  tools::AssemblyResult result = tools::assemble_file(path, options);
  program.instructions = result.instructions;
  program.assembly = std::move(result);
  return program;
}

// Prints the errors of a program that has_errors(), one line each, and gives the exit status: 2
// when a file cannot be read, otherwise 1 after a `motwin: error:` line that counts them.
inline int report_program_errors(const LoadedProgram& program, const std::string& path) {
  const std::vector<tools::AssemblyError>& errors = program.assembly->errors;
  for (const tools::AssemblyError& error : errors) std::cerr << tools::format_error(error) << '\n';
  if (errors.front().kind == tools::AssemblyErrorKind::kFileNotFound) return kExitUsageError;
  print_error(fmt::format("{} error{} in {}", errors.size(), errors.size() == 1 ? "" : "s", path));
  return kExitProgramError;
}

}  // namespace motwin::cli
