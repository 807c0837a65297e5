// The TMCL ASCII interface: bytes typed at a terminal into AsciiLink, each completed line run by
// serve_ascii_command, as src/host/tmcl_host_service.cpp does for an ASCII connection, on a
// TMCM-1636 (where the interface is a Motwin extension) or a TMCM-142 (whose manual has it).
//
// Input: byte 0 bit 0 picks the module (0 TMCM-1636, 1 TMCM-142), bits 4-5 the echo mode (GP 67
// bits 4-5); the rest is what the terminal sends. Invariants, against a model of the line rules
// of docs/ascii-mode.md (settings read afresh for every byte, as the link reads them):
// - a line starts with the module's address letter (either case) after line ends, blanks, NULs
//   and erases; a line starting otherwise is ignored to its CR or LF without echo or reply;
//   backspace or DEL erases a character, and erasing the letter abandons the line;
// - every addressed line gets exactly one reply, at its CR or LF, and nothing else is answered;
// - the echo is exactly what the echo mode gives: each character of an addressed line as typed
//   (BS blank BS for an erase, nothing for invalid bytes and characters beyond 80), the edited
//   line once at CR, or nothing;
// - every reply is `<host letter><module letter> <status> <value>CR` ('?' for an address above
//   26), with a TMCL status and a decimal value that fits 32 bits; a line with an invalid byte,
//   more than 80 characters or nothing after the letter is answered with status 2, value 0;
// - every writable parameter stays inside its row's range.
#include <cstddef>
#include <cstdint>
#include <cstdlib>
#include <cstring>
#include <memory>
#include <string>

#include "core/tmcl/ascii_link.h"
#include "fuzz_support.h"
#include "tmcm142_rig.h"

namespace {

using namespace motwin;

// An address above 26 has no letter: the reply shows '?' (docs/ascii-mode.md).
uint8_t letter_or_question_mark(uint8_t address) {
  const char letter = tmcl::ascii_address_letter(address);
  return static_cast<uint8_t>(letter != '\0' ? letter : '?');
}

bool is_reply_line(const tmcl::AsciiResponse& response, const tmcl::AsciiSettings& settings) {
  const uint8_t* b = response.bytes;
  const size_t n = response.length;
  if (n < 7 || b[n - 1] != '\r') return false;
  if (b[0] != letter_or_question_mark(settings.host_address)) return false;
  if (b[1] != letter_or_question_mark(settings.module_address)) return false;
  if (b[2] != ' ') return false;
  size_t i = 3;
  long status = 0;
  size_t digits = 0;
  while (i < n && b[i] >= '0' && b[i] <= '9') status = status * 10 + (b[i++] - '0'), ++digits;
  if (digits == 0 || digits > 3 || i >= n || b[i++] != ' ') return false;
  if (!tmcl::is_status_code(status)) return false;
  if (i < n && b[i] == '-') ++i;
  long long value = 0;
  digits = 0;
  while (i < n && b[i] >= '0' && b[i] <= '9') value = value * 10 + (b[i++] - '0'), ++digits;
  return digits >= 1 && digits <= 10 && value <= 2147483648LL && i == n - 1;
}

// The line rules of docs/ascii-mode.md, byte by byte: what the echo is and whether a line ends.
class LineModel {
 public:
  std::string echo;
  bool complete = false;
  bool unreadable = false;  // the completed line: an invalid byte, too long, or nothing after the letter

  void push(uint8_t byte, const tmcl::AsciiSettings& settings) {
    echo.clear();
    complete = false;
    const bool each = settings.echo == tmcl::AsciiEcho::kEachCharacter;
    const bool line_end = byte == '\r' || byte == '\n';
    switch (state_) {
      case State::kBetweenLines: {
        if (line_end || byte == ' ' || byte == '\t' || byte == 0 || byte == 0x08 || byte == 0x7F) return;
        const char own = tmcl::ascii_address_letter(settings.module_address);
        if (own != '\0' && (byte == own || byte == own - 'A' + 'a')) {
          state_ = State::kOurs;
          letter_ = static_cast<char>(byte);
          line_.clear();
          invalid_ = overlong_ = false;
          if (each) echo.push_back(static_cast<char>(byte));
        } else {
          state_ = State::kOthers;
        }
        return;
      }
      case State::kOthers:
        if (line_end) state_ = State::kBetweenLines;
        return;
      case State::kOurs:
        break;
    }
    if (line_end) {
      if (each) echo.push_back(static_cast<char>(byte));
      if (settings.echo == tmcl::AsciiEcho::kWholeLine) echo = letter_ + line_ + '\r';
      complete = true;
      unreadable = invalid_ || overlong_ || line_.find_first_not_of(' ') == std::string::npos;
      state_ = State::kBetweenLines;
    } else if (byte == 0x08 || byte == 0x7F) {
      if (line_.empty()) {
        state_ = State::kBetweenLines;
      } else {
        line_.pop_back();
      }
      if (each) echo = "\b \b";
    } else if (byte != '\t' && (byte < 0x20 || byte > 0x7E)) {
      invalid_ = true;
    } else if (line_.size() == tmcl::AsciiLink::kMaxLineLength) {
      overlong_ = true;
    } else {
      line_.push_back(byte == '\t' ? ' ' : static_cast<char>(byte));
      if (each) echo.push_back(line_.back());
    }
  }
  void reset() { state_ = State::kBetweenLines; }

 private:
  enum class State : uint8_t { kBetweenLines, kOurs, kOthers };
  State state_ = State::kBetweenLines;
  char letter_ = 0;
  std::string line_;
  bool invalid_ = false;
  bool overlong_ = false;
};

template <typename Module>
void type_at(Module& module, tmcl::TmclEngine& engine, uint8_t echo_bits, const uint8_t* data, size_t size) {
  // GP 67: ASCII mode, echo mode from the first byte (00 each character, 16 whole line, 32 none).
  const tmcl::CommandResult configured =
      engine.execute(tmcl::Instruction{9, tmcl::ascii_config::kGlobalParameter, 0, 1 | echo_bits},
                     tmcl::Origin::kHost, 0);
  FUZZ_CHECK(configured.status == tmcl::Status::kOk, "SGP 67 failed with status %u", tmcl::to_byte(configured.status));

  tmcl::AsciiLink link;
  LineModel model;
  for (size_t i = 0; i < size; ++i) {
    const tmcl::AsciiSettings settings = tmcl::ascii_settings(module);
    const bool line_complete = link.push(data[i], settings);
    model.push(data[i], settings);
    FUZZ_CHECK(line_complete == model.complete, "byte %zu (0x%02x): the link %s a line, the rules %s", i, data[i],
               line_complete ? "completed" : "did not complete", model.complete ? "complete one" : "do not");
    FUZZ_CHECK(link.echo_length() == model.echo.size() &&
                   std::memcmp(link.echo(), model.echo.data(), model.echo.size()) == 0,
               "byte %zu (0x%02x): echo of %zu bytes '%.*s', the rules echo '%s'", i, data[i], link.echo_length(),
               static_cast<int>(link.echo_length()), reinterpret_cast<const char*>(link.echo()), model.echo.c_str());
    if (!line_complete) continue;
    const tmcl::AsciiResponse response = tmcl::serve_ascii_command(engine, link.command(), 0);
    const tmcl::AsciiSettings now = tmcl::ascii_settings(module);
    FUZZ_CHECK(response.length > 0, "an addressed line ending at byte %zu got no reply", i);
    FUZZ_CHECK(is_reply_line(response, now), "malformed reply line '%.*s'", static_cast<int>(response.length),
               reinterpret_cast<const char*>(response.bytes));
    if (model.unreadable) {
      const char* status_and_value = reinterpret_cast<const char*>(response.bytes) + 3;
      FUZZ_CHECK(std::strncmp(status_and_value, "2 0\r", 4) == 0, "an unreadable line answered '%.*s'",
                 static_cast<int>(response.length), reinterpret_cast<const char*>(response.bytes));
    }
    if (response.reset_after_send) {
      engine.complete_reset();
      link.reset();
      model.reset();
    }
    if (response.leave_ascii_mode) {  // a binary host would follow; the terminal keeps typing
      link.reset();
      model.reset();
    }
    fuzz::check_parameter_ranges(module, "after an ASCII line");
  }
}

}  // namespace

extern "C" int LLVMFuzzerTestOneInput(const uint8_t* data, size_t size) {
  if (size < 1) return 0;
  const uint8_t echo_bits = data[0] & 0x30;
  if ((data[0] & 1) == 0) {
    auto rig = fuzz::fresh_rig<fuzz::Tmcm1636Rig>();
    type_at(rig->module, rig->engine, echo_bits, data + 1, size - 1);
  } else {
    auto rig = fuzz::fresh_rig<fuzz::Tmcm142Rig>();
    type_at(*rig->module, rig->engine(), echo_bits, data + 1, size - 1);
  }
  return 0;
}
