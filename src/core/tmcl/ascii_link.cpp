#include "core/tmcl/ascii_link.h"

#include <string_view>

#include "core/tmcl/mnemonic_table.h"

namespace motwin::tmcl {
namespace {

constexpr uint8_t kCarriageReturn = '\r';
constexpr uint8_t kLineFeed = '\n';
constexpr uint8_t kBackspace = 0x08;
constexpr uint8_t kDelete = 0x7F;  // what most terminals send for the backspace key

constexpr bool is_line_end(uint8_t byte) { return byte == kCarriageReturn || byte == kLineFeed; }
constexpr bool is_blank(char c) { return c == ' ' || c == '\t'; }

// At most a mnemonic and three operands; one more word is enough to see "too many".
constexpr size_t kMaxWords = 5;

struct Words {
  std::string_view word[kMaxWords];
  size_t count = 0;
  bool too_many = false;
  bool empty_operand = false;  // ",," or a trailing comma
};

// Blanks and commas separate words, as in TMCL-IDE ("MVP ABS, 0, 5000" or "MVP ABS 0 5000").
Words split_words(std::string_view text) {
  Words words;
  bool comma_pending = false;
  size_t i = 0;
  while (i < text.size()) {
    const char c = text[i];
    if (is_blank(c)) {
      ++i;
    } else if (c == ',') {
      if (comma_pending || words.count == 0) words.empty_operand = true;
      comma_pending = true;
      ++i;
    } else {
      const size_t start = i;
      while (i < text.size() && !is_blank(text[i]) && text[i] != ',') ++i;
      if (words.count == kMaxWords) {
        words.too_many = true;
      } else {
        // Not substr(): it may throw, and the core has no exceptions.
        words.word[words.count++] = std::string_view(text.data() + start, i - start);
      }
      comma_pending = false;
    }
  }
  if (comma_pending) words.empty_operand = true;
  return words;
}

// Decimal or 0x hexadecimal, optionally signed. False for anything else or beyond 2^40 (far
// outside every field, so no overflow while accumulating).
bool parse_number(std::string_view text, int64_t& out) {
  bool negative = false;
  if (!text.empty() && (text.front() == '-' || text.front() == '+')) {
    negative = text.front() == '-';
    text.remove_prefix(1);
  }
  int64_t base = 10;
  if (text.size() > 2 && text[0] == '0' && (text[1] == 'x' || text[1] == 'X')) {
    base = 16;
    text.remove_prefix(2);
  }
  if (text.empty()) return false;
  int64_t magnitude = 0;
  for (const char c : text) {
    int64_t digit = 0;
    if (c >= '0' && c <= '9') {
      digit = c - '0';
    } else if (base == 16 && ascii_upper(c) >= 'A' && ascii_upper(c) <= 'F') {
      digit = ascii_upper(c) - 'A' + 10;
    } else {
      return false;
    }
    if (digit >= base) return false;
    magnitude = magnitude * base + digit;
    if (magnitude > (int64_t{1} << 40)) return false;
  }
  out = negative ? -magnitude : magnitude;
  return true;
}

AsciiCommand error(Status status) { return AsciiCommand{AsciiCommand::Kind::kError, {}, status}; }

bool store_field(Instruction& instruction, OperandField field, int64_t value) {
  if (field == OperandField::kValue) {
    if (value < INT32_MIN || value > int64_t{UINT32_MAX}) return false;
    instruction.value = static_cast<int32_t>(static_cast<uint32_t>(value));
    return true;
  }
  if (value < 0 || value > 255) return false;
  if (field == OperandField::kType) {
    instruction.type = static_cast<uint8_t>(value);
  } else {
    instruction.motor_bank = static_cast<uint8_t>(value);
  }
  return true;
}

// Writes `value` in decimal; returns the number of characters.
size_t format_decimal(int64_t value, uint8_t* out) {
  uint8_t digits[20];
  size_t n = 0;
  const bool negative = value < 0;
  uint64_t magnitude = negative ? static_cast<uint64_t>(-(value + 1)) + 1 : static_cast<uint64_t>(value);
  do {
    digits[n++] = static_cast<uint8_t>('0' + magnitude % 10);
    magnitude /= 10;
  } while (magnitude != 0);
  size_t length = 0;
  if (negative) out[length++] = '-';
  while (n > 0) out[length++] = digits[--n];
  return length;
}

char host_letter(uint8_t address) {
  const char letter = ascii_address_letter(address);
  return letter != '\0' ? letter : '?';
}

}  // namespace

AsciiSettings ascii_settings(TmclDevice& device) {
  AsciiSettings settings;
  const SerialSettings serial = device.serial_settings();
  settings.module_address = serial.module_address;
  settings.host_address = serial.host_address;
  int32_t configuration = 0;
  settings.available =
      device.get_global_parameter(ascii_config::kGlobalParameter, 0, configuration) == Status::kOk;
  if (!settings.available) return settings;
  settings.start_in_ascii_mode = (configuration & ascii_config::kStartInAsciiMode) != 0;
  if ((configuration & ascii_config::kNoEcho) != 0) {
    settings.echo = AsciiEcho::kNone;
  } else if ((configuration & ascii_config::kEchoWholeLine) != 0) {
    settings.echo = AsciiEcho::kWholeLine;
  }
  return settings;
}

AsciiCommand parse_ascii_command(const char* text, size_t length) {
  const Words words = split_words(std::string_view(text, length));
  if (words.count == 0) return error(Status::kInvalidCommand);
  const std::string_view head = words.word[0];
  const size_t operand_count = words.count - 1;
  const bool bad_operands = words.too_many || words.empty_operand;

  // The words that exist only in ASCII mode (TMCM-142 manual 6.6.3).
  if (ascii_equals_ignore_case(head, "BIN") || ascii_equals_ignore_case(head, "STOP")) {
    if (operand_count != 0 || bad_operands) return error(Status::kInvalidValue);
    AsciiCommand command;
    command.kind = ascii_equals_ignore_case(head, "BIN") ? AsciiCommand::Kind::kBinary : AsciiCommand::Kind::kStop;
    command.instruction.command = command::kStopApplication;
    return command;
  }
  if (ascii_equals_ignore_case(head, "RUN")) {
    if (operand_count > 1 || bad_operands) return error(Status::kInvalidValue);
    AsciiCommand command;
    command.kind = AsciiCommand::Kind::kRun;
    command.instruction = Instruction{command::kRunApplication, 1, 0, 0};
    if (operand_count == 1) {
      int64_t address = 0;
      if (!parse_number(words.word[1], address) || !store_field(command.instruction, OperandField::kValue, address)) {
        return error(Status::kInvalidValue);
      }
    }
    return command;
  }

  const MnemonicSpec* spec = find_mnemonic_spec(head);
  if (spec == nullptr) return error(Status::kInvalidCommand);
  if (bad_operands || operand_count != spec->operands.size()) return error(Status::kInvalidValue);
  AsciiCommand command;
  command.kind = AsciiCommand::Kind::kInstruction;
  command.instruction.command = spec->command;
  for (size_t i = 0; i < operand_count; ++i) {
    const OperandSpec& operand = spec->operands[i];
    int64_t value = 0;
    uint8_t code = 0;
    if (parse_number(words.word[i + 1], value)) {
      // a number
    } else if (find_operand_symbol(operand.symbols, words.word[i + 1], code)) {
      value = code;
    } else {
      return error(Status::kInvalidValue);
    }
    if (!store_field(command.instruction, operand.field, value)) return error(Status::kInvalidValue);
  }
  return command;
}

void AsciiLink::reset() {
  state_ = State::kIdle;
  length_ = 0;
  overflow_ = false;
  garbage_ = false;
  echo_length_ = 0;
}

void AsciiLink::emit(uint8_t byte) {
  if (echo_length_ < kMaxEchoLength) echo_[echo_length_++] = byte;
}

bool AsciiLink::push(uint8_t byte, const AsciiSettings& settings) {
  echo_length_ = 0;
  const bool echo_each = settings.echo == AsciiEcho::kEachCharacter;
  switch (state_) {
    case State::kIdle: {
      // Line ends, blanks, NULs and backspaces between lines are not lines (CR LF gives no empty
      // line; backspacing over the address letter and once more is harmless).
      if (is_line_end(byte) || byte == ' ' || byte == '\t' || byte == 0 || byte == kBackspace || byte == kDelete) {
        return false;
      }
      const char own = ascii_address_letter(settings.module_address);
      if (own != '\0' && ascii_upper(static_cast<char>(byte)) == own) {
        state_ = State::kLine;
        address_character_ = byte;
        length_ = 0;
        overflow_ = false;
        garbage_ = false;
        if (echo_each) emit(byte);
        return false;
      }
      // Another module's line on a shared bus, or noise: not ours to echo or answer.
      state_ = State::kSkip;
      return false;
    }
    case State::kSkip:
      if (is_line_end(byte)) state_ = State::kIdle;
      return false;
    case State::kLine:
      break;
  }

  if (is_line_end(byte)) {
    if (echo_each) {
      emit(byte);
    } else if (settings.echo == AsciiEcho::kWholeLine) {
      emit(address_character_);
      for (size_t i = 0; i < length_; ++i) emit(static_cast<uint8_t>(line_[i]));
      emit(kCarriageReturn);
    }
    state_ = State::kIdle;
    command_ = (overflow_ || garbage_) ? error(Status::kInvalidCommand) : parse_ascii_command(line_, length_);
    return true;
  }
  if (byte == kBackspace || byte == kDelete) {
    if (length_ > 0) {
      --length_;
    } else {
      state_ = State::kIdle;  // the address letter itself was erased
    }
    if (echo_each) {
      emit(kBackspace);
      emit(' ');
      emit(kBackspace);
    }
    return false;
  }
  if (byte == '\t') byte = ' ';
  if (byte < 0x20 || byte > 0x7E) {
    garbage_ = true;
    return false;
  }
  if (length_ == kMaxLineLength) {
    overflow_ = true;
    return false;
  }
  line_[length_++] = static_cast<char>(byte);
  if (echo_each) emit(byte);
  return false;
}

AsciiResponse serve_ascii_command(TmclEngine& engine, const AsciiCommand& command, ChannelId channel) {
  AsciiResponse response;
  Status status = command.error;
  int32_t value = 0;
  switch (command.kind) {
    case AsciiCommand::Kind::kError:
      break;
    case AsciiCommand::Kind::kBinary:
      status = Status::kOk;
      response.leave_ascii_mode = true;
      break;
    case AsciiCommand::Kind::kInstruction:
    case AsciiCommand::Kind::kRun:
    case AsciiCommand::Kind::kStop: {
      const CommandResult result = engine.execute(command.instruction, Origin::kHost, channel);
      status = result.status;
      value = result.value;
      if (result.kind == ReplyKind::kNone) {
        response.delay_ms = 0;
        return response;  // no reply (only command 137 asks for that; it has no mnemonic)
      }
      response.reset_after_send = result.kind == ReplyKind::kThenReset;
      break;
    }
  }
  // The addresses may have just changed (SGP 66/76): the reply uses the new ones, as binary does.
  const SerialSettings settings = engine.device().serial_settings();
  response.delay_ms = settings.telegram_pause_ms;
  size_t n = 0;
  response.bytes[n++] = static_cast<uint8_t>(host_letter(settings.host_address));
  response.bytes[n++] = static_cast<uint8_t>(host_letter(settings.module_address));
  response.bytes[n++] = ' ';
  n += format_decimal(to_byte(status), response.bytes + n);
  response.bytes[n++] = ' ';
  n += format_decimal(value, response.bytes + n);
  response.bytes[n++] = kCarriageReturn;
  response.length = static_cast<uint8_t>(n);
  return response;
}

}  // namespace motwin::tmcl
