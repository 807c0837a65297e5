// TMCL instructions as TMCL-IDE writes them ("MVP ABS, 0, 90000"): the declarative table of
// mnemonics, command numbers, operand layouts and symbolic operand names (TMCM-1636 manual
// chapter 2, docs/tmcl-protocol.md "Code tables"; the data lives in core/tmcl/mnemonic_table.h,
// shared with the firmware's ASCII interface), and a parser from one line of text to an
// Instruction. Used by the `motwin tmcl` client, the TMCL assembler and the disassembler.
#pragma once

#include <cstdint>
#include <functional>
#include <optional>
#include <span>
#include <string>
#include <string_view>

#include "core/tmcl/instruction.h"
#include "core/tmcl/mnemonic_table.h"
#include "types/result.h"

namespace motwin::tools {

// The table itself is core data (core/tmcl/mnemonic_table.h), shared with the ASCII interface
// of the firmware; these are its types under their tool names.
using Field = tmcl::OperandField;      // kType, kMotorBank, kValue
using Symbol = tmcl::OperandSymbol;    // a symbolic operand such as ABS (MVP type 0)
using OperandSpec = tmcl::OperandSpec;
using MnemonicSpec = tmcl::MnemonicSpec;

// Every mnemonic, sorted by command number.
std::span<const MnemonicSpec> mnemonic_table();

// Case-insensitive; nullptr when unknown.
const MnemonicSpec* find_mnemonic(std::string_view mnemonic);
const MnemonicSpec* find_command(uint8_t command);
// Case-insensitive; std::nullopt when `name` is not in `symbols`.
std::optional<uint8_t> find_symbol(std::span<const Symbol> symbols, std::string_view name);

// "ABS, 0, 90000"-style operand synopsis of a spec: "ABS|REL|COORD, motor, value".
std::string operand_synopsis(const MnemonicSpec& spec);

// Decimal, 0x hexadecimal, optionally negative ("-5000", "0x1F", "-0x10"). std::nullopt when
// `text` is not such a number or does not fit in 64 bits.
std::optional<int64_t> parse_integer(std::string_view text);

// Why and where parse_instruction failed, for callers that point at the text (the assembler
// reports file:line:column).
enum class ParseErrorKind : uint8_t {
  kSyntax,             // empty line or operand, malformed number
  kUnknownMnemonic,    // the first word is neither a mnemonic nor a command number
  kOperandCount,       // too few or too many operands
  kUnknownIdentifier,  // neither a number, nor the operand's symbol, nor resolved by the caller
  kOutOfRange,         // a number that does not fit its field
};

struct ParseErrorDetail {
  ParseErrorKind kind = ParseErrorKind::kSyntax;
  size_t offset = 0;  // byte offset in the parsed text of the word (or comma) at fault
  size_t length = 0;  // its length (0: the end of the text, as for a missing operand)
};

struct ParseOptions {
  // Resolves identifiers that are neither numbers nor the operand's symbols (assembler labels
  // and constants). Unset: "unknown symbol"; set but returning std::nullopt: "undefined label
  // or constant".
  std::function<std::optional<int64_t>(std::string_view identifier)> resolve_identifier;
  // When set, receives the kind and position of a parse error.
  ParseErrorDetail* error_detail = nullptr;
};

// One instruction: a mnemonic and its operands, separated by commas and/or blanks
// ("MVP ABS, 0, 90000", "mvp abs 0 90000", "GAP 52 0"), or the numeric form
// "CMD [TYPE [MOTOR [VALUE]]]" for control commands that have no mnemonic ("136 1").
// A trailing "//" comment is ignored. Byte fields take 0..255; the value field takes
// -2147483648..4294967295 (values above INT32_MAX are sent as their 32-bit pattern).
Result<tmcl::Instruction> parse_instruction(std::string_view text, const ParseOptions& options = {});

// The inverse: TMCL-IDE form with symbols where the table has them ("MVP ABS, 0, 90000"), or the
// numeric form when the command has no mnemonic or uses fields its mnemonic does not show.
std::string format_instruction(const tmcl::Instruction& instruction);

}  // namespace motwin::tools
