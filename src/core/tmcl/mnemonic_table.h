// TMCL mnemonics as plain data: mnemonic, command number, operand layout and the symbolic operand
// names (TMCM-1636 manual table 4 and chapter 2.6; docs/tmcl-protocol.md "Code tables" for 13, 25,
// 26, 30-32, 37-39). The one copy of this table: the ASCII interface of the core (ascii_link.h)
// reads lines with it, and the host tools (tools/tmcl_mnemonics.h: `motwin tmcl`, the assembler,
// the disassembler) build their parser and formatter on it.
//
// Freestanding: constexpr arrays of string_view and span, no allocation.
#pragma once

#include <cstddef>
#include <cstdint>
#include <span>
#include <string_view>

#include "core/tmcl/instruction.h"

namespace motwin::tmcl {

// The instruction field an operand is encoded into.
enum class OperandField : uint8_t { kType, kMotorBank, kValue };

// A symbolic operand such as ABS (MVP type 0) or GE (JC type 5).
struct OperandSymbol {
  std::string_view name;  // upper case
  uint8_t code;
};

struct OperandSpec {
  std::string_view name;  // as the manual names it: "motor", "velocity", "param" ...
  OperandField field;
  // Names this operand may be written as; a number is accepted as well. Empty: numbers only.
  std::span<const OperandSymbol> symbols = {};
};

struct MnemonicSpec {
  std::string_view mnemonic;  // upper case
  uint8_t command;
  std::span<const OperandSpec> operands;  // in source order; fields not listed are 0
};

namespace mnemonic_data {

// --- Symbolic operand names ------------------------------------------------------------------

inline constexpr OperandSymbol kMoveTypes[] = {{"ABS", 0}, {"REL", 1}, {"COORD", 2}};
inline constexpr OperandSymbol kCalcOperations[] = {{"ADD", 0}, {"SUB", 1}, {"MUL", 2}, {"DIV", 3}, {"MOD", 4},
                                                    {"AND", 5}, {"OR", 6},  {"XOR", 7}, {"NOT", 8}, {"LOAD", 9}};
inline constexpr OperandSymbol kCalcxOperations[] = {{"ADD", 0}, {"SUB", 1}, {"MUL", 2}, {"DIV", 3},
                                                     {"MOD", 4}, {"AND", 5}, {"OR", 6},  {"XOR", 7},
                                                     {"NOT", 8}, {"LOAD", 9}, {"SWAP", 10}};
inline constexpr OperandSymbol kJumpConditions[] = {{"ZE", 0},  {"NZ", 1},  {"EQ", 2},   {"NE", 3},   {"GT", 4},
                                                    {"GE", 5},  {"LT", 6},  {"LE", 7},   {"ETO", 8},  {"EAL", 9},
                                                    {"EDV", 10}, {"EPO", 11}, {"ESD", 12}};
inline constexpr OperandSymbol kWaitConditions[] = {{"TICKS", 0}, {"POS", 1}, {"REFSW", 2}, {"LIMSW", 3}, {"RFS", 4}};
inline constexpr OperandSymbol kErrorFlags[] = {{"ALL", 0}, {"ETO", 1}, {"EAL", 2}, {"EDV", 3}, {"EPO", 4}, {"ESD", 5}};
inline constexpr OperandSymbol kReferenceSearchActions[] = {{"START", 0}, {"STOP", 1}, {"STATUS", 2}};

// --- Operand layouts -------------------------------------------------------------------------

using F = OperandField;
inline constexpr OperandSpec kMotorVelocity[] = {{"motor", F::kMotorBank}, {"velocity", F::kValue}};
inline constexpr OperandSpec kMotor[] = {{"motor", F::kMotorBank}};
inline constexpr OperandSpec kMoveTypeMotorValue[] = {
    {"type", F::kType, kMoveTypes}, {"motor", F::kMotorBank}, {"value", F::kValue}};
inline constexpr OperandSpec kParamMotorValue[] = {{"param", F::kType}, {"motor", F::kMotorBank}, {"value", F::kValue}};
inline constexpr OperandSpec kParamMotor[] = {{"param", F::kType}, {"motor", F::kMotorBank}};
inline constexpr OperandSpec kParamBankValue[] = {{"param", F::kType}, {"bank", F::kMotorBank}, {"value", F::kValue}};
inline constexpr OperandSpec kParamBank[] = {{"param", F::kType}, {"bank", F::kMotorBank}};
inline constexpr OperandSpec kReferenceSearch[] = {{"action", F::kType, kReferenceSearchActions},
                                                   {"motor", F::kMotorBank}};
inline constexpr OperandSpec kPortBankValue[] = {{"port", F::kType}, {"bank", F::kMotorBank}, {"value", F::kValue}};
inline constexpr OperandSpec kPortBank[] = {{"port", F::kType}, {"bank", F::kMotorBank}};
inline constexpr OperandSpec kCalc[] = {{"operation", F::kType, kCalcOperations}, {"operand", F::kValue}};
inline constexpr OperandSpec kCompare[] = {{"operand", F::kValue}};
inline constexpr OperandSpec kJumpConditional[] = {{"condition", F::kType, kJumpConditions}, {"address", F::kValue}};
inline constexpr OperandSpec kAddress[] = {{"address", F::kValue}};
inline constexpr OperandSpec kInterrupt[] = {{"interrupt", F::kType}};
inline constexpr OperandSpec kWait[] = {
    {"condition", F::kType, kWaitConditions}, {"motor", F::kMotorBank}, {"ticks", F::kValue}};
inline constexpr OperandSpec kCoordinateMotorPosition[] = {
    {"coordinate", F::kType}, {"motor", F::kMotorBank}, {"position", F::kValue}};
inline constexpr OperandSpec kCoordinateMotor[] = {{"coordinate", F::kType}, {"motor", F::kMotorBank}};
inline constexpr OperandSpec kCalcx[] = {{"operation", F::kType, kCalcxOperations}};
inline constexpr OperandSpec kClearErrorFlag[] = {{"flag", F::kType, kErrorFlags}};
inline constexpr OperandSpec kVector[] = {{"interrupt", F::kType}, {"address", F::kValue}};

inline constexpr std::span<const OperandSpec> kNone{};

}  // namespace mnemonic_data

// Every mnemonic, sorted by command number.
inline constexpr MnemonicSpec kMnemonicTable[] = {
    {"ROR", command::kRor, mnemonic_data::kMotorVelocity},
    {"ROL", command::kRol, mnemonic_data::kMotorVelocity},
    {"MST", command::kMst, mnemonic_data::kMotor},
    {"MVP", command::kMvp, mnemonic_data::kMoveTypeMotorValue},
    {"SAP", command::kSap, mnemonic_data::kParamMotorValue},
    {"GAP", command::kGap, mnemonic_data::kParamMotor},
    {"STAP", command::kStap, mnemonic_data::kParamMotor},
    {"RSAP", command::kRsap, mnemonic_data::kParamMotor},
    {"SGP", command::kSgp, mnemonic_data::kParamBankValue},
    {"GGP", command::kGgp, mnemonic_data::kParamBank},
    {"STGP", command::kStgp, mnemonic_data::kParamBank},
    {"RSGP", command::kRsgp, mnemonic_data::kParamBank},
    {"RFS", command::kRfs, mnemonic_data::kReferenceSearch},
    {"SIO", command::kSio, mnemonic_data::kPortBankValue},
    {"GIO", command::kGio, mnemonic_data::kPortBank},
    {"CALC", command::kCalc, mnemonic_data::kCalc},
    {"COMP", command::kComp, mnemonic_data::kCompare},
    {"JC", command::kJc, mnemonic_data::kJumpConditional},
    {"JA", command::kJa, mnemonic_data::kAddress},
    {"CSUB", command::kCsub, mnemonic_data::kAddress},
    {"RSUB", command::kRsub, mnemonic_data::kNone},
    {"EI", command::kEi, mnemonic_data::kInterrupt},
    {"DI", command::kDi, mnemonic_data::kInterrupt},
    {"WAIT", command::kWait, mnemonic_data::kWait},
    {"STOP", command::kStop, mnemonic_data::kNone},
    {"SCO", command::kSco, mnemonic_data::kCoordinateMotorPosition},
    {"GCO", command::kGco, mnemonic_data::kCoordinateMotor},
    {"CCO", command::kCco, mnemonic_data::kCoordinateMotor},
    {"CALCX", command::kCalcx, mnemonic_data::kCalcx},
    {"AAP", command::kAap, mnemonic_data::kParamMotor},
    {"AGP", command::kAgp, mnemonic_data::kParamBank},
    {"CLE", command::kCle, mnemonic_data::kClearErrorFlag},
    {"VECT", command::kVect, mnemonic_data::kVector},
    {"RETI", command::kReti, mnemonic_data::kNone},
    {"ACO", command::kAco, mnemonic_data::kCoordinateMotor},
};

constexpr bool mnemonic_table_is_consistent() {
  for (size_t i = 0; i < std::size(kMnemonicTable); ++i) {
    if (i > 0 && kMnemonicTable[i - 1].command >= kMnemonicTable[i].command) return false;
    if (kMnemonicTable[i].operands.size() > 3) return false;
    // Each field at most once per mnemonic.
    int used[3] = {0, 0, 0};
    for (const OperandSpec& operand : kMnemonicTable[i].operands) {
      if (++used[static_cast<int>(operand.field)] > 1) return false;
    }
  }
  return true;
}
static_assert(mnemonic_table_is_consistent(), "mnemonic table: sorted by command, at most one operand per field");

// ASCII-only case folding (no locale, no C library).
constexpr char ascii_upper(char c) { return c >= 'a' && c <= 'z' ? static_cast<char>(c - 'a' + 'A') : c; }

constexpr bool ascii_equals_ignore_case(std::string_view a, std::string_view b) {
  if (a.size() != b.size()) return false;
  for (size_t i = 0; i < a.size(); ++i) {
    if (ascii_upper(a[i]) != ascii_upper(b[i])) return false;
  }
  return true;
}

// Case-insensitive; nullptr when unknown.
constexpr const MnemonicSpec* find_mnemonic_spec(std::string_view mnemonic) {
  for (const MnemonicSpec& spec : kMnemonicTable) {
    if (ascii_equals_ignore_case(spec.mnemonic, mnemonic)) return &spec;
  }
  return nullptr;
}

constexpr const MnemonicSpec* find_command_spec(uint8_t command_number) {
  for (const MnemonicSpec& spec : kMnemonicTable) {
    if (spec.command == command_number) return &spec;
  }
  return nullptr;
}

// Case-insensitive; false when `name` is not in `symbols`.
constexpr bool find_operand_symbol(std::span<const OperandSymbol> symbols, std::string_view name, uint8_t& code) {
  for (const OperandSymbol& symbol : symbols) {
    if (ascii_equals_ignore_case(symbol.name, name)) {
      code = symbol.code;
      return true;
    }
  }
  return false;
}

}  // namespace motwin::tmcl
