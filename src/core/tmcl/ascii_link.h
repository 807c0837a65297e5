// The TMCL ASCII interface (TMCM-142 manual 6.6, docs/tmcl-protocol.md "ASCII interface"): a
// terminal drives the module line by line in TMCL-IDE syntax instead of 9-byte frames.
//
//   AMVP ABS, 0, 50000<CR>      ->  BA 100 50000<CR>
//   A GAP 52, 0<CR>             ->  BA 100 -5000<CR>
//   ABIN<CR>                    ->  BA 100 0<CR>, then binary frames again
//
// A line is the module's address letter (A = address 1, B = 2 ...), optional blanks, a mnemonic
// and its operands (core/tmcl/mnemonic_table.h), then CR. Backspace edits the line. The reply is
// the host's letter, the module's letter, the status and the value in decimal, then CR. Command
// 139 enters the mode (its binary reply goes out first), the line BIN leaves it, RUN and STOP
// start and stop the stored program. GP 67 configures it: bit 0 starts every connection in
// ASCII mode after power-up; bits 4-5 choose the echo (00 each character as typed, bit 4 the
// whole line after CR, bit 5 none: reply only). Details and decisions: docs/ascii-mode.md.
//
// Firmware-like: a fixed line buffer, no allocation, no exceptions. Over-long and garbage lines
// are answered with an error at CR, never buffered without bound. Which link (serial port, TCP
// connection) is in ASCII mode is the transport's business: one AsciiLink per connection.
#pragma once

#include <cstddef>
#include <cstdint>

#include "core/tmcl/device.h"
#include "core/tmcl/engine.h"
#include "core/tmcl/instruction.h"
#include "core/tmcl/status.h"

namespace motwin::tmcl {

// GP 67 (ASCII interface configuration).
namespace ascii_config {
inline constexpr uint8_t kGlobalParameter = 67;
inline constexpr int32_t kStartInAsciiMode = 1 << 0;
inline constexpr int32_t kEchoWholeLine = 1 << 4;
inline constexpr int32_t kNoEcho = 1 << 5;
}  // namespace ascii_config

enum class AsciiEcho : uint8_t {
  kEachCharacter,  // GP 67 bits 4-5 = 00: every character of an addressed line, as typed
  kWholeLine,      // bit 4: the edited line, once, when CR arrives
  kNone,           // bit 5 (also with bit 4): only the reply
};

// What the link needs to know about the module, read afresh for every byte so that an SGP 67
// or SGP 66 takes effect at once.
struct AsciiSettings {
  bool available = false;  // the module has the ASCII interface (its global table has GP 67)
  bool start_in_ascii_mode = false;
  AsciiEcho echo = AsciiEcho::kEachCharacter;
  uint8_t module_address = 1;
  uint8_t host_address = 2;
};

AsciiSettings ascii_settings(TmclDevice& device);

// 'A' for address 1 ... 'Z' for 26; 0 when the address has no letter.
constexpr char ascii_address_letter(uint8_t address) {
  return address >= 1 && address <= 26 ? static_cast<char>('A' + address - 1) : '\0';
}

// What a complete line asks for.
struct AsciiCommand {
  enum class Kind : uint8_t {
    kInstruction,  // a TMCL instruction, run as a direct-mode command
    kRun,          // RUN [address]: command 129 type 1 (instruction.value = start address)
    kStop,         // STOP: command 128
    kBinary,       // BIN: back to binary frames after the reply
    kError,        // unreadable line: answered with `error`
  };
  Kind kind = Kind::kError;
  Instruction instruction{};
  Status error = Status::kInvalidCommand;
};

// Parses the text of a line after its address letter (no CR). Unknown words are status 2
// (invalid command); a wrong number of operands, a malformed number, an unknown symbol or a
// number that does not fit its field are status 4 (invalid value).
AsciiCommand parse_ascii_command(const char* text, size_t length);

class AsciiLink {
 public:
  // Characters after the address letter. Longer lines are answered with status 2 at CR.
  static constexpr size_t kMaxLineLength = 80;
  static constexpr size_t kMaxEchoLength = kMaxLineLength + 2;

  // Feeds one received byte. Returns true when it completed a line addressed to this module:
  // command() then says what to do. Bytes to send back at once (the echo) are in echo() until
  // the next push.
  bool push(uint8_t byte, const AsciiSettings& settings);

  const AsciiCommand& command() const { return command_; }
  const uint8_t* echo() const { return echo_; }
  size_t echo_length() const { return echo_length_; }
  // Discards a partial line (the host flushed its output, the mode changed).
  void reset();

 private:
  enum class State : uint8_t {
    kIdle,     // between lines: waiting for an address letter
    kLine,     // collecting a line addressed to this module
    kSkip,     // a line for another module (or one not starting with a letter): ignored to CR
  };

  void emit(uint8_t byte);

  State state_ = State::kIdle;
  uint8_t address_character_ = 0;
  char line_[kMaxLineLength] = {};
  size_t length_ = 0;
  bool overflow_ = false;  // more than kMaxLineLength characters were typed
  bool garbage_ = false;   // a byte that is neither printable ASCII nor an editing key
  AsciiCommand command_{};
  uint8_t echo_[kMaxEchoLength] = {};
  size_t echo_length_ = 0;
};

// The reply line to one command, and what the transport does after sending it.
struct AsciiResponse {
  static constexpr size_t kMaxLength = 24;  // "BA 100 -2147483648\r" is 19
  uint8_t bytes[kMaxLength] = {};
  uint8_t length = 0;              // 0: no reply
  bool leave_ascii_mode = false;   // BIN: binary frames from now on
  bool reset_after_send = false;   // call TmclEngine::complete_reset() once sent
  uint8_t delay_ms = 0;            // GP 75 telegram pause before the reply
};

// Runs `command` (from connection `channel`) on the engine and formats its reply with the
// module's current addresses.
AsciiResponse serve_ascii_command(TmclEngine& engine, const AsciiCommand& command, ChannelId channel);

}  // namespace motwin::tmcl
