// The socketcand text protocol (src/host/socketcand_protocol.*): a client's byte stream split
// into `< ... >` elements, `send` elements parsed into CAN frames, frames formatted back.
//
// Input: byte 0 is the chunk size the stream arrives in (TCP may cut anywhere); the rest is the
// stream. Invariants:
// - the elements do not depend on how the stream is cut;
// - an element never holds `<` or `>` and is never longer than kMaxElementLength;
// - a parsed `send` frame is a valid CAN frame, and writing it back as a `send` element parses
//   to the same frame;
// - the `frame` element the server sends for it reads back (ID, extended flag, data) as that
//   frame.
#include <cstddef>
#include <cstdint>
#include <cstdio>
#include <string>
#include <string_view>
#include <vector>

#include "fuzz_support.h"
#include "host/socketcand_protocol.h"

namespace {

using namespace motwin;

std::string send_element(const can::CanFrame& frame) {
  char text[32];
  std::snprintf(text, sizeof(text), frame.extended ? "send %08X %u" : "send %03X %u", static_cast<unsigned>(frame.id),
                frame.dlc);
  std::string out = text;
  for (uint8_t i = 0; i < frame.dlc; ++i) {
    std::snprintf(text, sizeof(text), " %02x", frame.data[i]);
    out += text;
  }
  return out;
}

void check_frame_element(const can::CanFrame& frame) {
  const std::string text = host::format_socketcand_frame(frame, 1234567890123ull);
  host::SocketcandElementParser parser;
  std::vector<std::string> elements;
  parser.push(text, elements);
  FUZZ_CHECK(elements.size() == 1, "'%s' holds %zu elements", text.c_str(), elements.size());
  const auto words = host::socketcand_words(elements[0]);
  FUZZ_CHECK(words.size() == 4 || (words.size() == 3 && frame.dlc == 0), "'%s': %zu words", text.c_str(), words.size());
  FUZZ_CHECK(words[0] == "frame" && words[2] == "1234567.890123", "'%s'", text.c_str());
  FUZZ_CHECK(words[1].size() == (frame.extended ? 8u : 3u), "'%s': ID digits", text.c_str());
  const uint32_t id = static_cast<uint32_t>(std::stoul(std::string(words[1]), nullptr, 16));
  FUZZ_CHECK(id == frame.id, "'%s': ID %x, frame %x", text.c_str(), id, frame.id);
  const std::string_view hex = words.size() == 4 ? words[3] : std::string_view{};
  FUZZ_CHECK(hex.size() == frame.dlc * 2u, "'%s': %zu hex digits for %u bytes", text.c_str(), hex.size(), frame.dlc);
  for (uint8_t i = 0; i < frame.dlc; ++i) {
    const auto byte = static_cast<uint8_t>(std::stoul(std::string(hex.substr(i * 2u, 2)), nullptr, 16));
    FUZZ_CHECK(byte == frame.data[i], "'%s': byte %u", text.c_str(), i);
  }
}

}  // namespace

extern "C" int LLVMFuzzerTestOneInput(const uint8_t* data, size_t size) {
  if (size < 1) return 0;
  const size_t chunk = data[0] == 0 ? 1 : data[0];
  const std::string_view stream(reinterpret_cast<const char*>(data + 1), size - 1);

  host::SocketcandElementParser whole_parser;
  std::vector<std::string> whole;
  whole_parser.push(stream, whole);
  host::SocketcandElementParser chunk_parser;
  std::vector<std::string> chunked;
  for (size_t at = 0; at < stream.size(); at += chunk) chunk_parser.push(stream.substr(at, chunk), chunked);
  FUZZ_CHECK(whole == chunked, "cut into %zu-byte chunks: %zu elements instead of %zu", chunk, chunked.size(),
             whole.size());
  FUZZ_CHECK(whole_parser.dropped_elements() == chunk_parser.dropped_elements(), "dropped counts differ");

  for (const std::string& element : whole) {
    FUZZ_CHECK(element.size() <= host::SocketcandElementParser::kMaxElementLength, "element of %zu bytes",
               element.size());
    FUZZ_CHECK(element.find_first_of("<>") == std::string::npos, "element '%s' holds a bracket", element.c_str());
    const auto frame = host::parse_socketcand_send(host::socketcand_words(element));
    if (!frame) {
      FUZZ_CHECK(!frame.error().empty(), "'%s' refused without a reason", element.c_str());
      continue;
    }
    FUZZ_CHECK(frame->dlc <= can::kMaxDataLength && !frame->rtr, "'%s': dlc %u", element.c_str(), frame->dlc);
    FUZZ_CHECK(frame->id <= (frame->extended ? can::kMaxExtendedId : can::kMaxStandardId), "'%s': ID %x",
               element.c_str(), frame->id);
    const std::string again_text = send_element(*frame);
    const auto again = host::parse_socketcand_send(host::socketcand_words(again_text));
    FUZZ_CHECK(again && *again == *frame && again->extended == frame->extended,
               "'%s' written back as '%s' does not parse to the same frame", element.c_str(), again_text.c_str());
    check_frame_element(*frame);
  }
  return 0;
}
