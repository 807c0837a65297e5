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

namespace motwin::cli {

// The program has errors (assembly errors are printed); nothing was done.
inline constexpr int kExitProgramError = 1;

struct LoadedProgram {
  std::vector<tmcl::Instruction> instructions;
  std::optional<tools::AssemblyResult> assembly;  // for .tmc sources: labels, listing

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

// Loads `path`; on failure prints the errors and sets `exit_status` (1 for assembly errors,
// 2 for an unreadable file).
inline std::optional<LoadedProgram> load_program(const std::string& path, const std::vector<std::string>& include_dirs,
                                                 int& exit_status) {
  LoadedProgram program;
  if (is_binary_program(path)) {
    Result<std::vector<tmcl::Instruction>> binary = tools::read_program_binary(path);
    if (!binary) {
      print_error(binary.error());
      exit_status = kExitUsageError;
      return std::nullopt;
    }
    program.instructions = std::move(binary.value());
    return program;
  }
  tools::AssemblerOptions options;
  options.include_dirs = include_dirs;
  tools::AssemblyResult result = tools::assemble_file(path, options);
  if (!result.ok()) {
    for (const tools::AssemblyError& error : result.errors) std::cerr << tools::format_error(error) << '\n';
    if (result.errors.front().kind == tools::AssemblyErrorKind::kFileNotFound) {
      exit_status = kExitUsageError;
    } else {
      print_error(fmt::format("{} error{} in {}", result.errors.size(), result.errors.size() == 1 ? "" : "s", path));
      exit_status = kExitProgramError;
    }
    return std::nullopt;
  }
  program.instructions = result.instructions;
  program.assembly = std::move(result);
  return program;
}

}  // namespace motwin::cli
