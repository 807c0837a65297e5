// The SLCAN (Lawicel) adapter protocol (src/host/slcan_protocol.*): the host's bytes through an
// SlcanSession, frames to the bus, frames back to text.
//
// Input: byte 0 is the chunk size the bytes arrive in; the rest is what the host sends.
// Invariants:
// - every CR is answered by exactly one CR (ok, possibly after a version or `z`) or BEL (error),
//   and nothing else ends a reply;
// - replies and bus frames do not depend on how the bytes are cut;
// - a frame that reaches the bus is valid, and its SLCAN text parses back to the same frame and
//   formats to the same text.
#include <cstddef>
#include <cstdint>
#include <string>
#include <string_view>
#include <vector>

#include "fuzz_support.h"
#include "host/slcan_protocol.h"

namespace {

using namespace motwin;

struct Run {
  std::string reply;
  std::vector<can::CanFrame> frames;
};

Run run(std::string_view stream, size_t chunk) {
  Run result;
  host::SlcanSession session([&result](const can::CanFrame& frame) { result.frames.push_back(frame); });
  for (size_t at = 0; at < stream.size(); at += chunk) session.push(stream.substr(at, chunk), result.reply);
  return result;
}

}  // namespace

extern "C" int LLVMFuzzerTestOneInput(const uint8_t* data, size_t size) {
  if (size < 1) return 0;
  const size_t chunk = data[0] == 0 ? 1 : data[0];
  const std::string_view stream(reinterpret_cast<const char*>(data + 1), size - 1);

  const Run whole = run(stream, stream.size() == 0 ? 1 : stream.size());
  const Run chunked = run(stream, chunk);
  FUZZ_CHECK(whole.reply == chunked.reply, "replies depend on %zu-byte chunks", chunk);
  FUZZ_CHECK(whole.frames.size() == chunked.frames.size(), "frames depend on %zu-byte chunks", chunk);

  size_t carriage_returns = 0;
  for (char c : stream) carriage_returns += c == '\r' ? 1 : 0;
  size_t reply_ends = 0;
  for (char c : whole.reply) reply_ends += (c == '\r' || c == '\a') ? 1 : 0;
  FUZZ_CHECK(reply_ends == carriage_returns, "%zu replies for %zu CRs", reply_ends, carriage_returns);

  for (size_t i = 0; i < whole.frames.size(); ++i) {
    const can::CanFrame& frame = whole.frames[i];
    FUZZ_CHECK(frame == chunked.frames[i], "frame %zu depends on the chunks", i);
    FUZZ_CHECK(frame.dlc <= can::kMaxDataLength, "dlc %u", frame.dlc);
    FUZZ_CHECK(frame.id <= (frame.extended ? can::kMaxExtendedId : can::kMaxStandardId), "ID %x", frame.id);
    const std::string text = host::format_slcan_frame(frame);
    FUZZ_CHECK(!text.empty() && text.back() == '\r', "formatted frame without CR");
    const auto again = host::parse_slcan_frame(std::string_view(text).substr(0, text.size() - 1));
    FUZZ_CHECK(again && *again == frame && again->extended == frame.extended && again->rtr == frame.rtr,
               "'%s' does not parse back to the frame", text.c_str());
    FUZZ_CHECK(host::format_slcan_frame(*again) == text, "'%s' formats differently the second time", text.c_str());
  }
  return 0;
}
