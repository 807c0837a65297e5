// The socketcand ASCII protocol, as python-can 4.1.0's `socketcand` interface speaks it
// (docs/canopen.md "Reaching a virtual bus without kernel CAN"): elements `< ... >` with no line
// terminator, `< send ID LEN B0 B1 ... >` from the client, `< frame ID SEC.USEC HEXDATA >` to it.
// Pure text handling, no sockets.
#pragma once

#include <cstddef>
#include <cstdint>
#include <string>
#include <string_view>
#include <vector>

#include "types/can_frame.h"
#include "types/result.h"

namespace motwin::host {

// Splits a byte stream into elements. Text outside `< >` is ignored; a `<` inside an element
// starts a new one (the broken one is dropped); an element longer than kMaxElementLength is
// dropped up to the next `<`. Garbage never stops the stream.
class SocketcandElementParser {
 public:
  static constexpr size_t kMaxElementLength = 256;

  SocketcandElementParser() { element_.reserve(kMaxElementLength); }  // never grows afterwards

  // Appends each complete element's inner text (between `<` and `>`) to `out`.
  void push(std::string_view bytes, std::vector<std::string>& out);
  size_t dropped_elements() const { return dropped_; }

 private:
  enum class State : uint8_t { kOutside, kInside, kSkipping };
  State state_ = State::kOutside;
  std::string element_;
  size_t dropped_ = 0;
};

// Whitespace-separated words of an element ("send 601 8 40 0 10 0 0 0 0 0").
std::vector<std::string_view> socketcand_words(std::string_view element);

// `send ID LEN [B]*` words (with "send" first) into a frame. ID in hex; extended when written with
// 8 digits or above 0x7FF. LEN 0..8; exactly LEN data words of 1 or 2 hex digits, any case.
// Anything else fails with the text of socketcand's `< error TEXT >`.
Result<can::CanFrame> parse_socketcand_send(const std::vector<std::string_view>& words);

// ` < frame ID SEC.USEC HEXDATA >` with ID as %03X or %08X and the data as one uppercase hex
// string; an empty frame has two spaces before `>`. The space between two frames is deliberate:
// python-can 4.1.0 drops the character after the last complete element of each read, and when a
// read ends inside the next frame that character is this space instead of its `<` (which would
// lose the frame). The space goes before each frame rather than after it: a read that ends with a
// frame then leaves nothing behind, where a trailing space makes python-can log "Bad data: No
// opening < found" for every read (docs/canopen.md).
std::string format_socketcand_frame(const can::CanFrame& frame, uint64_t timestamp_us);

// The client's side (host/socketcand_client.h), with the same element parser and words:
// `frame ID SEC.USEC [HEXDATA]` words (with "frame" first) into a frame, as socketcand and
// format_socketcand_frame() write it: ID as for `send`, the data one hex string of up to 16 digits
// (even count), absent for an empty frame. The timestamp is checked for its form only (the
// receiving bus stamps the frame with its own clock).
Result<can::CanFrame> parse_socketcand_frame(const std::vector<std::string_view>& words);

// `< send ID LEN B0 B1 ... >`, as python-can writes it: ID %03X or %08X (extended), the bytes %02X.
// Data frames only: socketcand's `send` has no RTR flag (the client does not forward RTR frames).
std::string format_socketcand_send(const can::CanFrame& frame);

}  // namespace motwin::host
