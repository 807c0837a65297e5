#include "tools/tmcl_mnemonics.h"

#include <algorithm>
#include <array>
#include <cctype>
#include <charconv>
#include <limits>
#include <utility>
#include <variant>
#include <vector>

#include <fmt/format.h>

#include "tools/text.h"

namespace motwin::tools {
namespace {

using tmcl::Instruction;
namespace cmd = tmcl::command;

// The table is core data (core/tmcl/mnemonic_table.h), shared with the firmware's ASCII interface.
constexpr std::span<const MnemonicSpec> kMnemonics{tmcl::kMnemonicTable};

// --- Text helpers ----------------------------------------------------------------------------

bool is_blank(char c) { return c == ' ' || c == '\t' || c == '\r' || c == '\n'; }

// A parse error with the kind and position that ParseErrorDetail reports.
struct Failure {
  std::string message;
  ParseErrorKind kind = ParseErrorKind::kSyntax;
  size_t offset = 0;
  size_t length = 0;
};

// Where `word` (a view into `text`) starts in `text`.
size_t offset_in(std::string_view text, std::string_view word) {
  return static_cast<size_t>(word.data() - text.data());
}

// Splits "MVP ABS, 0, 90000" into words (views into `text`); commas are optional separators,
// but an empty operand ("GAP 52,,0" or a trailing comma) is an error rather than a silent 0.
std::variant<std::vector<std::string_view>, Failure> split_words(std::string_view text) {
  if (const size_t comment = text.find("//"); comment != std::string_view::npos) text = text.substr(0, comment);
  std::vector<std::string_view> words;
  bool comma_pending = false;
  size_t i = 0;
  while (i < text.size()) {
    const char c = text[i];
    if (is_blank(c)) {
      ++i;
    } else if (c == ',') {
      if (words.empty()) {
        return Failure{"expected a mnemonic or a command number before ','", ParseErrorKind::kSyntax, i, 1};
      }
      if (comma_pending) {
        return Failure{fmt::format("empty operand after '{}'", words.back()), ParseErrorKind::kSyntax, i, 1};
      }
      comma_pending = true;
      ++i;
    } else {
      const size_t start = i;
      while (i < text.size() && !is_blank(text[i]) && text[i] != ',') ++i;
      words.push_back(text.substr(start, i - start));
      comma_pending = false;
    }
  }
  if (comma_pending) {
    return Failure{fmt::format("empty operand after '{}'", words.back()), ParseErrorKind::kSyntax, text.size(), 0};
  }
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
// the caller resolves. `what` names the operand in error messages. Failure offsets are
// relative to `word`.
std::variant<int64_t, Failure> operand_value(std::string_view word, std::span<const Symbol> symbols,
                                             const ParseOptions& options, std::string_view what) {
  if (const std::optional<int64_t> number = parse_integer(word)) return *number;
  if (const std::optional<uint8_t> code = find_symbol(symbols, word)) return static_cast<int64_t>(*code);
  if (options.resolve_identifier) {
    if (const std::optional<int64_t> resolved = options.resolve_identifier(word)) return *resolved;
  }
  const char first = word.front();
  if (std::isdigit(static_cast<unsigned char>(first)) || first == '-' || first == '+') {
    return Failure{fmt::format("{}: '{}' is not a number (decimal or 0x hexadecimal, at most 64 bits)", what, word),
                   ParseErrorKind::kSyntax, 0, word.size()};
  }
  const std::string alternatives = symbols.empty() ? "" : symbol_alternatives(symbols, ", ") + ", ";
  if (options.resolve_identifier) {
    return Failure{fmt::format("{}: undefined label or constant '{}', expected {}a number, a label or a constant",
                               what, word, alternatives),
                   ParseErrorKind::kUnknownIdentifier, 0, word.size()};
  }
  if (!symbols.empty()) {
    return Failure{fmt::format("{}: unknown symbol '{}', expected {} or a number", what, word,
                               symbol_alternatives(symbols, ", ")),
                   ParseErrorKind::kUnknownIdentifier, 0, word.size()};
  }
  return Failure{fmt::format("{}: unknown symbol '{}', expected a number", what, word),
                 ParseErrorKind::kUnknownIdentifier, 0, word.size()};
}

// Range check and store into the instruction field.
Result<void> store_field(Instruction& instruction, Field field, int64_t value, std::string_view what) {
  if (field == Field::kValue) {
    if (value < kValueMin || value > kValueMax) {
      return Error{fmt::format("{}: {} is out of range for the 32-bit value field ({}..{})", what, value, kValueMin,
                               kValueMax)};
    }
    instruction.value = static_cast<int32_t>(static_cast<uint32_t>(value));
    return {};
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
  return {};
}

// Evaluates `word` (a view into `text`) and stores it; failures point at the word.
std::optional<Failure> evaluate_and_store(std::string_view text, std::string_view word, std::span<const Symbol> symbols,
                                          const ParseOptions& options, std::string_view what,
                                          const std::function<Result<void>(int64_t)>& store) {
  std::variant<int64_t, Failure> value = operand_value(word, symbols, options, what);
  if (Failure* failure = std::get_if<Failure>(&value)) {
    failure->offset += offset_in(text, word);
    return std::move(*failure);
  }
  if (const Result<void> stored = store(*std::get_if<int64_t>(&value)); !stored) {
    return Failure{stored.error(), ParseErrorKind::kOutOfRange, offset_in(text, word), word.size()};
  }
  return std::nullopt;
}

// "CMD [TYPE [MOTOR [VALUE]]]": the form for control commands, which have no mnemonic.
std::variant<Instruction, Failure> parse_numeric_form(std::string_view text, std::span<const std::string_view> words,
                                                      const ParseOptions& options) {
  static constexpr std::string_view kNames[] = {"command number", "type", "motor/bank", "value"};
  static constexpr Field kFields[] = {Field::kType, Field::kMotorBank, Field::kValue};
  if (words.size() > std::size(kNames)) {
    return Failure{
        fmt::format("the numeric form takes at most 4 numbers (CMD TYPE MOTOR VALUE), got {}", words.size()),
        ParseErrorKind::kOperandCount, offset_in(text, words[std::size(kNames)]), words[std::size(kNames)].size()};
  }
  Instruction instruction;
  for (size_t i = 0; i < words.size(); ++i) {
    std::optional<Failure> failure;
    if (i == 0) {
      const auto store_command = [&](int64_t value) -> Result<void> {
        if (value < 0 || value > kByteMax) {
          return Error{fmt::format("command number {} is out of range (0..{})", value, kByteMax)};
        }
        instruction.command = static_cast<uint8_t>(value);
        return {};
      };
      failure = evaluate_and_store(text, words[i], {}, options, kNames[i], store_command);
    } else {
      failure = evaluate_and_store(text, words[i], {}, options, kNames[i], [&](int64_t value) {
        return store_field(instruction, kFields[i - 1], value, kNames[i]);
      });
    }
    if (failure) return std::move(*failure);
  }
  return instruction;
}

std::string operand_label(const OperandSpec& operand) {
  return operand.symbols.empty() ? std::string(operand.name) : symbol_alternatives(operand.symbols, "|");
}

std::variant<Instruction, Failure> parse(std::string_view text, const ParseOptions& options) {
  std::variant<std::vector<std::string_view>, Failure> split = split_words(text);
  if (Failure* failure = std::get_if<Failure>(&split)) return std::move(*failure);
  const std::vector<std::string_view>& words = *std::get_if<std::vector<std::string_view>>(&split);
  if (words.empty()) {
    return Failure{"empty instruction: expected a mnemonic (such as MVP, SAP, GAP) or a command number",
                   ParseErrorKind::kSyntax, 0, 0};
  }

  const std::string_view head = words.front();
  if (parse_integer(head)) return parse_numeric_form(text, words, options);

  const MnemonicSpec* spec = find_mnemonic(head);
  if (spec == nullptr) {
    return Failure{fmt::format("unknown mnemonic '{}': expected a TMCL mnemonic (such as MVP, SAP, GAP) or a "
                               "command number",
                               head),
                   ParseErrorKind::kUnknownMnemonic, offset_in(text, head), head.size()};
  }
  const std::span<const std::string_view> operands{words.begin() + 1, words.end()};
  if (operands.size() != spec->operands.size()) {
    // Point at the first surplus operand, or at the end of the text for a missing one.
    const bool too_many = operands.size() > spec->operands.size();
    const size_t offset = too_many ? offset_in(text, operands[spec->operands.size()])
                                   : offset_in(text, words.back()) + words.back().size();
    const size_t length = too_many ? operands[spec->operands.size()].size() : 0;
    if (spec->operands.empty()) {
      return Failure{fmt::format("{} takes no operands, got {}", spec->mnemonic, operands.size()),
                     ParseErrorKind::kOperandCount, offset, length};
    }
    return Failure{fmt::format("{} takes {} operand{} ({}), got {}", spec->mnemonic, spec->operands.size(),
                               spec->operands.size() == 1 ? "" : "s", operand_synopsis(*spec), operands.size()),
                   ParseErrorKind::kOperandCount, offset, length};
  }
  Instruction instruction;
  instruction.command = spec->command;
  for (size_t i = 0; i < operands.size(); ++i) {
    const OperandSpec& operand = spec->operands[i];
    const std::string what = fmt::format("{} operand {} ({})", spec->mnemonic, i + 1, operand_label(operand));
    std::optional<Failure> failure =
        evaluate_and_store(text, operands[i], operand.symbols, options, what,
                           [&](int64_t value) { return store_field(instruction, operand.field, value, what); });
    if (failure) return std::move(*failure);
  }
  return instruction;
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
  std::variant<Instruction, Failure> parsed = parse(text, options);
  if (Failure* failure = std::get_if<Failure>(&parsed)) {
    if (options.error_detail != nullptr) *options.error_detail = {failure->kind, failure->offset, failure->length};
    return Error{std::move(failure->message)};
  }
  return *std::get_if<Instruction>(&parsed);
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
