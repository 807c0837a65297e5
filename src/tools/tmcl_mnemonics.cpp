#include "tools/tmcl_mnemonics.h"

#include <algorithm>
#include <array>
#include <cctype>
#include <charconv>
#include <limits>
#include <vector>

#include <fmt/format.h>

#include "tools/text.h"

namespace motwin::tools {
namespace {

using tmcl::Instruction;
namespace cmd = tmcl::command;

// --- Symbolic operand names (TMCM-1636 manual 2.6, notes/tmcl.md "Code tables") -----------

constexpr Symbol kMoveTypes[] = {{"ABS", 0}, {"REL", 1}, {"COORD", 2}};
constexpr Symbol kCalcOperations[] = {{"ADD", 0}, {"SUB", 1}, {"MUL", 2}, {"DIV", 3}, {"MOD", 4},
                                      {"AND", 5}, {"OR", 6},  {"XOR", 7}, {"NOT", 8}, {"LOAD", 9}};
constexpr Symbol kCalcxOperations[] = {{"ADD", 0}, {"SUB", 1}, {"MUL", 2}, {"DIV", 3},  {"MOD", 4}, {"AND", 5},
                                       {"OR", 6},  {"XOR", 7}, {"NOT", 8}, {"LOAD", 9}, {"SWAP", 10}};
constexpr Symbol kJumpConditions[] = {{"ZE", 0}, {"NZ", 1},  {"EQ", 2},   {"NE", 3},   {"GT", 4},
                                      {"GE", 5}, {"LT", 6},  {"LE", 7},   {"ETO", 8},  {"EAL", 9},
                                      {"EDV", 10}, {"EPO", 11}, {"ESD", 12}};
constexpr Symbol kWaitConditions[] = {{"TICKS", 0}, {"POS", 1}, {"REFSW", 2}, {"LIMSW", 3}, {"RFS", 4}};
constexpr Symbol kErrorFlags[] = {{"ALL", 0}, {"ETO", 1}, {"EAL", 2}, {"EDV", 3}, {"EPO", 4}, {"ESD", 5}};
constexpr Symbol kReferenceSearchActions[] = {{"START", 0}, {"STOP", 1}, {"STATUS", 2}};

// --- Operand layouts -----------------------------------------------------------------------

constexpr OperandSpec kMotorVelocity[] = {{"motor", Field::kMotorBank}, {"velocity", Field::kValue}};
constexpr OperandSpec kMotor[] = {{"motor", Field::kMotorBank}};
constexpr OperandSpec kMoveTypeMotorValue[] = {
    {"type", Field::kType, kMoveTypes}, {"motor", Field::kMotorBank}, {"value", Field::kValue}};
constexpr OperandSpec kParamMotorValue[] = {
    {"param", Field::kType}, {"motor", Field::kMotorBank}, {"value", Field::kValue}};
constexpr OperandSpec kParamMotor[] = {{"param", Field::kType}, {"motor", Field::kMotorBank}};
constexpr OperandSpec kParamBankValue[] = {
    {"param", Field::kType}, {"bank", Field::kMotorBank}, {"value", Field::kValue}};
constexpr OperandSpec kParamBank[] = {{"param", Field::kType}, {"bank", Field::kMotorBank}};
constexpr OperandSpec kReferenceSearch[] = {{"action", Field::kType, kReferenceSearchActions},
                                            {"motor", Field::kMotorBank}};
constexpr OperandSpec kPortBankValue[] = {{"port", Field::kType}, {"bank", Field::kMotorBank}, {"value", Field::kValue}};
constexpr OperandSpec kPortBank[] = {{"port", Field::kType}, {"bank", Field::kMotorBank}};
constexpr OperandSpec kCalc[] = {{"operation", Field::kType, kCalcOperations}, {"operand", Field::kValue}};
constexpr OperandSpec kCompare[] = {{"operand", Field::kValue}};
constexpr OperandSpec kJumpConditional[] = {{"condition", Field::kType, kJumpConditions}, {"address", Field::kValue}};
constexpr OperandSpec kAddress[] = {{"address", Field::kValue}};
constexpr OperandSpec kInterrupt[] = {{"interrupt", Field::kType}};
constexpr OperandSpec kWait[] = {
    {"condition", Field::kType, kWaitConditions}, {"motor", Field::kMotorBank}, {"ticks", Field::kValue}};
constexpr OperandSpec kCoordinateMotorPosition[] = {
    {"coordinate", Field::kType}, {"motor", Field::kMotorBank}, {"position", Field::kValue}};
constexpr OperandSpec kCoordinateMotor[] = {{"coordinate", Field::kType}, {"motor", Field::kMotorBank}};
constexpr OperandSpec kCalcx[] = {{"operation", Field::kType, kCalcxOperations}};
constexpr OperandSpec kClearErrorFlag[] = {{"flag", Field::kType, kErrorFlags}};
constexpr OperandSpec kVector[] = {{"interrupt", Field::kType}, {"address", Field::kValue}};

constexpr std::span<const OperandSpec> kNone{};

// --- The mnemonics, by command number (manual table 4; notes/tmcl.md for 13, 25, 26, 30-32,
// 37-39) -------------------------------------------------------------------------------------

constexpr MnemonicSpec kMnemonics[] = {
    {"ROR", cmd::kRor, kMotorVelocity},
    {"ROL", cmd::kRol, kMotorVelocity},
    {"MST", cmd::kMst, kMotor},
    {"MVP", cmd::kMvp, kMoveTypeMotorValue},
    {"SAP", cmd::kSap, kParamMotorValue},
    {"GAP", cmd::kGap, kParamMotor},
    {"STAP", cmd::kStap, kParamMotor},
    {"RSAP", cmd::kRsap, kParamMotor},
    {"SGP", cmd::kSgp, kParamBankValue},
    {"GGP", cmd::kGgp, kParamBank},
    {"STGP", cmd::kStgp, kParamBank},
    {"RSGP", cmd::kRsgp, kParamBank},
    {"RFS", cmd::kRfs, kReferenceSearch},
    {"SIO", cmd::kSio, kPortBankValue},
    {"GIO", cmd::kGio, kPortBank},
    {"CALC", cmd::kCalc, kCalc},
    {"COMP", cmd::kComp, kCompare},
    {"JC", cmd::kJc, kJumpConditional},
    {"JA", cmd::kJa, kAddress},
    {"CSUB", cmd::kCsub, kAddress},
    {"RSUB", cmd::kRsub, kNone},
    {"EI", cmd::kEi, kInterrupt},
    {"DI", cmd::kDi, kInterrupt},
    {"WAIT", cmd::kWait, kWait},
    {"STOP", cmd::kStop, kNone},
    {"SCO", cmd::kSco, kCoordinateMotorPosition},
    {"GCO", cmd::kGco, kCoordinateMotor},
    {"CCO", cmd::kCco, kCoordinateMotor},
    {"CALCX", cmd::kCalcx, kCalcx},
    {"AAP", cmd::kAap, kParamMotor},
    {"AGP", cmd::kAgp, kParamBank},
    {"CLE", cmd::kCle, kClearErrorFlag},
    {"VECT", cmd::kVect, kVector},
    {"RETI", cmd::kReti, kNone},
    {"ACO", cmd::kAco, kCoordinateMotor},
};

constexpr bool table_is_consistent() {
  for (size_t i = 0; i < std::size(kMnemonics); ++i) {
    if (i > 0 && kMnemonics[i - 1].command >= kMnemonics[i].command) return false;
    if (kMnemonics[i].operands.size() > 3) return false;
    // Each field at most once per mnemonic.
    int used[3] = {0, 0, 0};
    for (const OperandSpec& operand : kMnemonics[i].operands) {
      if (++used[static_cast<int>(operand.field)] > 1) return false;
    }
  }
  return true;
}
static_assert(table_is_consistent(), "mnemonic table: sorted by command, at most one operand per field");

// --- Text helpers ----------------------------------------------------------------------------

bool is_blank(char c) { return c == ' ' || c == '\t' || c == '\r' || c == '\n'; }

// Splits "MVP ABS, 0, 90000" into words; commas are optional separators, but an empty operand
// ("GAP 52,,0" or a trailing comma) is an error rather than a silent 0.
Result<std::vector<std::string_view>> split_words(std::string_view text) {
  if (const size_t comment = text.find("//"); comment != std::string_view::npos) text = text.substr(0, comment);
  std::vector<std::string_view> words;
  bool comma_pending = false;
  size_t i = 0;
  while (i < text.size()) {
    const char c = text[i];
    if (is_blank(c)) {
      ++i;
    } else if (c == ',') {
      if (words.empty()) return Error{"expected a mnemonic or a command number before ','"};
      if (comma_pending) return Error{fmt::format("empty operand after '{}'", words.back())};
      comma_pending = true;
      ++i;
    } else {
      const size_t start = i;
      while (i < text.size() && !is_blank(text[i]) && text[i] != ',') ++i;
      words.push_back(text.substr(start, i - start));
      comma_pending = false;
    }
  }
  if (comma_pending) return Error{fmt::format("empty operand after '{}'", words.back())};
  return words;
}

std::string symbol_alternatives(std::span<const Symbol> symbols, std::string_view separator) {
  std::string out;
  for (const Symbol& symbol : symbols) {
    if (!out.empty()) out += separator;
    out += symbol.name;
  }
  return out;
}

std::string_view field_description(Field field) {
  switch (field) {
    case Field::kType: return "type";
    case Field::kMotorBank: return "motor/bank";
    case Field::kValue: return "value";
  }
  return "";
}

constexpr int64_t kByteMax = 255;
constexpr int64_t kValueMin = std::numeric_limits<int32_t>::min();
constexpr int64_t kValueMax = std::numeric_limits<uint32_t>::max();

// One operand word to a field value: a number, one of the operand's symbols, or an identifier
// the caller resolves. `what` names the operand in error messages.
Result<int64_t> operand_value(std::string_view word, std::span<const Symbol> symbols, const ParseOptions& options,
                              std::string_view what) {
  if (const std::optional<int64_t> number = parse_integer(word)) return *number;
  if (const std::optional<uint8_t> code = find_symbol(symbols, word)) return static_cast<int64_t>(*code);
  if (options.resolve_identifier) {
    if (const std::optional<int64_t> resolved = options.resolve_identifier(word)) return *resolved;
  }
  const char first = word.front();
  if (std::isdigit(static_cast<unsigned char>(first)) || first == '-' || first == '+') {
    return Error{fmt::format("{}: '{}' is not a number (decimal or 0x hexadecimal, at most 64 bits)", what, word)};
  }
  if (!symbols.empty()) {
    return Error{fmt::format("{}: unknown symbol '{}', expected {} or a number", what, word,
                             symbol_alternatives(symbols, ", "))};
  }
  return Error{fmt::format("{}: unknown symbol '{}', expected a number", what, word)};
}

// Range check and store into the instruction field.
std::optional<Error> store_field(Instruction& instruction, Field field, int64_t value, std::string_view what) {
  if (field == Field::kValue) {
    if (value < kValueMin || value > kValueMax) {
      return Error{fmt::format("{}: {} is out of range for the 32-bit value field ({}..{})", what, value, kValueMin,
                               kValueMax)};
    }
    instruction.value = static_cast<int32_t>(static_cast<uint32_t>(value));
    return std::nullopt;
  }
  if (value < 0 || value > kByteMax) {
    return Error{fmt::format("{}: {} is out of range for the byte field {} (0..{})", what, value,
                             field_description(field), kByteMax)};
  }
  if (field == Field::kType) {
    instruction.type = static_cast<uint8_t>(value);
  } else {
    instruction.motor_bank = static_cast<uint8_t>(value);
  }
  return std::nullopt;
}

// "CMD [TYPE [MOTOR [VALUE]]]": the form for control commands, which have no mnemonic.
Result<Instruction> parse_numeric_form(std::span<const std::string_view> words, const ParseOptions& options) {
  static constexpr std::string_view kNames[] = {"command number", "type", "motor/bank", "value"};
  static constexpr Field kFields[] = {Field::kType, Field::kMotorBank, Field::kValue};
  if (words.size() > std::size(kNames)) {
    return Error{fmt::format("the numeric form takes at most 4 numbers (CMD TYPE MOTOR VALUE), got {}", words.size())};
  }
  Instruction instruction;
  for (size_t i = 0; i < words.size(); ++i) {
    Result<int64_t> value = operand_value(words[i], {}, options, kNames[i]);
    if (!value) return Error{value.error()};
    if (i == 0) {
      if (value.value() < 0 || value.value() > kByteMax) {
        return Error{fmt::format("command number {} is out of range (0..{})", value.value(), kByteMax)};
      }
      instruction.command = static_cast<uint8_t>(value.value());
      continue;
    }
    if (std::optional<Error> error = store_field(instruction, kFields[i - 1], value.value(), kNames[i])) {
      return *error;
    }
  }
  return instruction;
}

std::string operand_label(const OperandSpec& operand) {
  return operand.symbols.empty() ? std::string(operand.name) : symbol_alternatives(operand.symbols, "|");
}

}  // namespace

std::span<const MnemonicSpec> mnemonic_table() { return kMnemonics; }

const MnemonicSpec* find_mnemonic(std::string_view mnemonic) {
  for (const MnemonicSpec& spec : kMnemonics) {
    if (equals_ignore_case(spec.mnemonic, mnemonic)) return &spec;
  }
  return nullptr;
}

const MnemonicSpec* find_command(uint8_t command) {
  for (const MnemonicSpec& spec : kMnemonics) {
    if (spec.command == command) return &spec;
  }
  return nullptr;
}

std::optional<uint8_t> find_symbol(std::span<const Symbol> symbols, std::string_view name) {
  for (const Symbol& symbol : symbols) {
    if (equals_ignore_case(symbol.name, name)) return symbol.code;
  }
  return std::nullopt;
}

std::string operand_synopsis(const MnemonicSpec& spec) {
  std::string out;
  for (const OperandSpec& operand : spec.operands) {
    if (!out.empty()) out += ", ";
    out += operand_label(operand);
  }
  return out;
}

std::optional<int64_t> parse_integer(std::string_view text) {
  bool negative = false;
  if (!text.empty() && (text.front() == '-' || text.front() == '+')) {
    negative = text.front() == '-';
    text.remove_prefix(1);
  }
  int base = 10;
  if (text.size() > 2 && text[0] == '0' && (text[1] == 'x' || text[1] == 'X')) {
    base = 16;
    text.remove_prefix(2);
  }
  if (text.empty()) return std::nullopt;
  uint64_t magnitude = 0;
  const auto [end, error] = std::from_chars(text.data(), text.data() + text.size(), magnitude, base);
  if (error != std::errc{} || end != text.data() + text.size()) return std::nullopt;
  if (magnitude > static_cast<uint64_t>(std::numeric_limits<int64_t>::max())) return std::nullopt;
  const auto signed_magnitude = static_cast<int64_t>(magnitude);
  return negative ? -signed_magnitude : signed_magnitude;
}

Result<Instruction> parse_instruction(std::string_view text, const ParseOptions& options) {
  Result<std::vector<std::string_view>> split = split_words(text);
  if (!split) return Error{split.error()};
  const std::vector<std::string_view>& words = split.value();
  if (words.empty()) return Error{"empty instruction: expected a mnemonic (such as MVP, SAP, GAP) or a command number"};

  const std::string_view head = words.front();
  if (parse_integer(head)) return parse_numeric_form(words, options);

  const MnemonicSpec* spec = find_mnemonic(head);
  if (spec == nullptr) {
    return Error{fmt::format("unknown mnemonic '{}': expected a TMCL mnemonic (such as MVP, SAP, GAP) or a "
                             "command number",
                             head)};
  }
  const std::span<const std::string_view> operands{words.begin() + 1, words.end()};
  if (operands.size() != spec->operands.size()) {
    if (spec->operands.empty()) {
      return Error{fmt::format("{} takes no operands, got {}", spec->mnemonic, operands.size())};
    }
    return Error{fmt::format("{} takes {} operand{} ({}), got {}", spec->mnemonic, spec->operands.size(),
                             spec->operands.size() == 1 ? "" : "s", operand_synopsis(*spec), operands.size())};
  }
  Instruction instruction;
  instruction.command = spec->command;
  for (size_t i = 0; i < operands.size(); ++i) {
    const OperandSpec& operand = spec->operands[i];
    const std::string what = fmt::format("{} operand {} ({})", spec->mnemonic, i + 1, operand_label(operand));
    Result<int64_t> value = operand_value(operands[i], operand.symbols, options, what);
    if (!value) return Error{value.error()};
    if (std::optional<Error> error = store_field(instruction, operand.field, value.value(), what)) return *error;
  }
  return instruction;
}

std::string format_instruction(const Instruction& instruction) {
  const auto numeric_form = [&] {
    return fmt::format("{} {} {} {}", instruction.command, instruction.type, instruction.motor_bank,
                       instruction.value);
  };
  const MnemonicSpec* spec = find_command(instruction.command);
  if (spec == nullptr) return numeric_form();

  const auto field_value = [&](Field field) -> int64_t {
    switch (field) {
      case Field::kType: return instruction.type;
      case Field::kMotorBank: return instruction.motor_bank;
      case Field::kValue: return instruction.value;
    }
    return 0;
  };
  bool shown[3] = {false, false, false};
  std::string out(spec->mnemonic);
  for (size_t i = 0; i < spec->operands.size(); ++i) {
    const OperandSpec& operand = spec->operands[i];
    shown[static_cast<int>(operand.field)] = true;
    const int64_t value = field_value(operand.field);
    out += i == 0 ? " " : ", ";
    const auto symbol = std::find_if(operand.symbols.begin(), operand.symbols.end(),
                                     [&](const Symbol& s) { return s.code == value; });
    out += symbol != operand.symbols.end() ? std::string(symbol->name) : std::to_string(value);
  }
  // A field the mnemonic cannot express would be lost: fall back to the numeric form.
  for (const Field field : {Field::kType, Field::kMotorBank, Field::kValue}) {
    if (!shown[static_cast<int>(field)] && field_value(field) != 0) return numeric_form();
  }
  return out;
}

}  // namespace motwin::tools
