// TMCL instructions as TMCL-IDE writes them ("MVP ABS, 0, 90000"): one declarative table of
// mnemonics, command numbers, operand layouts and symbolic operand names (TMCM-1636 manual
// chapter 2, notes/tmcl.md), and a parser from one line of text to an Instruction. The table is
// shared by the `motwin tmcl` client and the TMCL assembler.
#pragma once

#include <cstdint>
#include <functional>
#include <optional>
#include <span>
#include <string>
#include <string_view>

#include "core/tmcl/instruction.h"
#include "tools/result.h"

namespace motwin::tools {

// The instruction field an operand is encoded into.
enum class Field : uint8_t { kType, kMotorBank, kValue };

// A symbolic operand such as ABS (MVP type 0) or GE (JC type 5).
struct Symbol {
  std::string_view name;
  uint8_t code;
};

struct OperandSpec {
  std::string_view name;  // as the manual names it: "motor", "velocity", "param" ...
  Field field;
  // Names this operand may be written as; a number is accepted as well. Empty: numbers only.
  std::span<const Symbol> symbols = {};
};

struct MnemonicSpec {
  std::string_view mnemonic;  // upper case
  uint8_t command;
  std::span<const OperandSpec> operands;  // in source order; fields not listed are 0
};

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

struct ParseOptions {
  // Resolves identifiers that are neither numbers nor the operand's symbols (assembler labels
  // and constants). Unset, or returning std::nullopt: "unknown symbol".
  std::function<std::optional<int64_t>(std::string_view identifier)> resolve_identifier;
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
