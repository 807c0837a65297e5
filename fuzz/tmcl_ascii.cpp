// The TMCL ASCII interface: bytes typed at a terminal into AsciiLink, each completed line run by
// serve_ascii_command, as src/host/tmcl_host_service.cpp does for an ASCII connection.
//
// Input: byte 0 selects the echo mode (GP 67 bits 4-5), the rest is what the terminal sends.
// Invariants:
// - a line is completed only by CR or LF, so there are never more replies than line ends;
// - the echo of one byte is bounded (AsciiLink::kMaxEchoLength);
// - every reply is `<host letter><module letter> <status> <value>CR` ('?' for an address above
//   26), with a TMCL status and a decimal value that fits 32 bits;
// - every writable parameter stays inside its row's range.
#include <cstddef>
#include <cstdint>
#include <cstdlib>
#include <memory>

#include "core/tmcl/ascii_link.h"
#include "fuzz_support.h"

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
  if (!(status == 100 || status == 101 || status == 128 || (status >= 1 && status <= 6))) return false;
  if (i < n && b[i] == '-') ++i;
  long long value = 0;
  digits = 0;
  while (i < n && b[i] >= '0' && b[i] <= '9') value = value * 10 + (b[i++] - '0'), ++digits;
  return digits >= 1 && digits <= 10 && value <= 2147483648LL && i == n - 1;
}

}  // namespace

extern "C" int LLVMFuzzerTestOneInput(const uint8_t* data, size_t size) {
  if (size < 1) return 0;
  auto rig = std::make_unique<fuzz::Tmcm1636Rig>();
  // GP 67: ASCII mode, echo mode from the first byte (00 each character, 16 whole line, 32 none).
  const int32_t echo_bits = static_cast<int32_t>(data[0] & 0x30);
  const tmcl::CommandResult configured =
      rig->engine.execute(tmcl::Instruction{9, tmcl::ascii_config::kGlobalParameter, 0, 1 | echo_bits},
                          tmcl::Origin::kHost, 0);
  FUZZ_CHECK(configured.status == tmcl::Status::kOk, "SGP 67 failed with status %u", tmcl::to_byte(configured.status));

  tmcl::AsciiLink link;
  size_t line_ends = 0;
  size_t replies = 0;
  for (size_t i = 1; i < size; ++i) {
    if (data[i] == '\r' || data[i] == '\n') ++line_ends;
    const tmcl::AsciiSettings settings = tmcl::ascii_settings(rig->module);
    const bool line_complete = link.push(data[i], settings);
    FUZZ_CHECK(link.echo_length() <= tmcl::AsciiLink::kMaxEchoLength, "echo of %zu bytes", link.echo_length());
    if (!line_complete) continue;
    FUZZ_CHECK(data[i] == '\r' || data[i] == '\n', "a line completed by byte 0x%02x", data[i]);
    const tmcl::AsciiResponse response = tmcl::serve_ascii_command(rig->engine, link.command(), 0);
    if (response.length == 0) continue;
    ++replies;
    const tmcl::AsciiSettings now = tmcl::ascii_settings(rig->module);
    FUZZ_CHECK(is_reply_line(response, now), "malformed reply line '%.*s'", static_cast<int>(response.length),
               reinterpret_cast<const char*>(response.bytes));
    if (response.reset_after_send) {
      rig->engine.complete_reset();
      link.reset();
    }
    if (response.leave_ascii_mode) link.reset();  // a binary host would follow; the terminal keeps typing
    fuzz::check_parameter_ranges(rig->module, "after an ASCII line");
  }
  FUZZ_CHECK(replies <= line_ends, "%zu replies for %zu line ends", replies, line_ends);
  return 0;
}
