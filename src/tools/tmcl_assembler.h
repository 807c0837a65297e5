// The TMCL assembler: `.tmc` source as the TMCL-IDE's TMCL creator reads it (docs/tmcl-protocol.md
// "TMCL-IDE program syntax", TMCM-1636 manual chapters 1.3, 2.6 and 6) to the instructions that
// a download stores in program memory. docs/assembler.md is the syntax reference.
//
//   // comment                      a comment runs from "//" to the end of the line
//   MaxSpeed = 50000                constant: a number or a name defined above
//   #include TMCLParam.tmc          relative to the including file, then the include dirs
//   Loop: MVP ABS, Motor0, MaxSpeed label (alone on its line or before an instruction)
//   JA Loop                         labels may be used before their definition
//
// A label's value is the address (instruction index) of the instruction that follows it.
// Motor0..Motor5 are built in. Like the TMCL-IDE, the assembler appends a STOP after the last
// instruction. Every error is collected (not just the first) with file, line and column; no
// exception escapes these functions.
#pragma once

#include <cstddef>
#include <cstdint>
#include <functional>
#include <optional>
#include <string>
#include <string_view>
#include <vector>

#include "core/tmcl/instruction.h"

namespace motwin::tools {

// Program memory of the TMCM-1636 and TMCM-142 (docs/tmcl-protocol.md "Control commands").
inline constexpr size_t kDefaultProgramMemorySize = 2048;

struct SourceLocation {
  std::string file;  // the path as the assembler resolved it ("dir/TMCLParam.tmc")
  int line = 0;      // 1-based; 0: the file as a whole
  int column = 0;    // 1-based byte column; 0: the line as a whole
};

enum class AssemblyErrorKind : uint8_t {
  kSyntax,           // malformed line, constant definition, directive or number
  kUnknownMnemonic,  // the first word of an instruction is not a TMCL mnemonic
  kOperandCount,     // too few or too many operands
  kUndefinedSymbol,  // a name that is neither a label, a constant, nor the operand's symbol
  kDuplicateSymbol,  // a label or constant defined twice (a constant may repeat its value)
  kOutOfRange,       // byte field outside 0..255, value outside 32 bits
  kFileNotFound,     // the main source file cannot be read
  kIncludeNotFound,  // no #include candidate can be read
  kIncludeCycle,     // a file includes itself, directly or through others
  kProgramTooLong,   // more instructions (with the appended STOP) than program memory holds
  kInternal,         // an unexpected failure (out of memory, a throwing reader)
};

struct AssemblyError {
  AssemblyErrorKind kind = AssemblyErrorKind::kSyntax;
  SourceLocation location;
  std::string message;
};

// "file:line:column: error: message" (without ":line" or ":column" when they are 0).
std::string format_error(const AssemblyError& error);

enum class SymbolKind : uint8_t { kLabel, kConstant };

struct SymbolDefinition {
  std::string name;  // as written at its definition
  SymbolKind kind = SymbolKind::kConstant;
  int64_t value = 0;  // a label's value is its address
  SourceLocation location;
  bool built_in = false;  // Motor0..Motor5
};

// One source line of the listing, or the appended STOP.
struct ListingLine {
  SourceLocation location;          // column 0
  std::string text;                 // the line as written, without its line break
  std::optional<uint32_t> address;  // set on instruction lines and on the appended STOP
  tmcl::Instruction instruction;    // valid when `address` is set
  bool appended = false;            // the STOP the assembler adds (no source line)
};

struct AssemblyResult {
  std::vector<tmcl::Instruction> instructions;  // address = index; ends with the appended STOP
  std::vector<ListingLine> listing;             // every source line, includes expanded in place
  std::vector<SymbolDefinition> symbols;        // in definition order, built-ins first
  std::vector<AssemblyError> errors;            // in source order; empty on success

  bool ok() const { return errors.empty(); }
  // Case-insensitive, as every name is.
  const SymbolDefinition* find_symbol(std::string_view name) const;
  std::optional<uint32_t> label_address(std::string_view name) const;
};

// Returns a file's content, or std::nullopt when it cannot be read (missing, a directory...).
using SourceReader = std::function<std::optional<std::string>(const std::string& path)>;

// Reads from the file system.
SourceReader file_system_reader();

struct AssemblerOptions {
  // Searched in order for an #include that is not found next to the including file.
  std::vector<std::string> include_dirs;
  size_t program_memory_size = kDefaultProgramMemorySize;
  // The TMCL-IDE appends STOP after the last instruction; off only for special uses.
  bool append_stop = true;
  // Unset: file_system_reader(). Tests pass sources from memory.
  SourceReader reader;
};

// Assembles the file at `path`, read through `options.reader`.
AssemblyResult assemble_file(const std::string& path, const AssemblerOptions& options = {});
// Assembles `source` as if it were the file `file_name`; its #includes go through the reader,
// relative to `file_name`'s directory first.
AssemblyResult assemble_source(std::string_view source, const std::string& file_name,
                               const AssemblerOptions& options = {});

// A listing: address, the 8 bytes of the .bin record, line number and source text, with a
// marker where the file changes (#include).
std::string format_listing(const AssemblyResult& result);
// One line per user-defined symbol: "label Func1 0 main.tmc:2" / "constant MaxSpeed 50000
// main.tmc:3" (KIND NAME VALUE FILE:LINE), labels first, in definition order.
std::string format_symbols(const AssemblyResult& result);

}  // namespace motwin::tools
