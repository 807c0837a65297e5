// The socketcand session state machine (src/host/socketcand_session.*, what SocketcandServer runs
// per TCP connection): `< hi >`, open, rawmode, bcmmode, echo, send and the errors, with frames
// from the bus arriving between the client's TCP chunks and the connection closing at any write.
//
// Input: byte 0 cuts the stream into chunks (0: one chunk; else pseudo-random lengths 1..byte 0),
// byte 1 the bus (0: no frames; n: a frame from the bus after every n-th chunk), byte 2 the
// connection (0: stays open; n: closing from its n-th write on); the rest is the client's stream.
// Invariants, against a model of the rules written from docs/canopen.md and socketcand_session.h
// (elements found by their own rule: the text between a `<` and the next `>` with no bracket in
// between, at most 256 characters):
// - every write is one well-formed server element (` < ... >` or `< ... >`), and the writes
//   split into exactly that many elements; `< hi >` comes first;
// - before `open` every element is answered ` < error expected open >`, and nothing reaches the
//   bus;
// - every complete element gets exactly the answer the rules give (`< ok >`, ` < ok >`,
//   ` < echo >`, ` < error TEXT >`, nothing for a good `send`), in order;
// - a frame reaches the bus exactly for each valid `send` after `open`, as the element says;
// - a frame from the bus reaches the client exactly in raw mode, as format_socketcand_frame
//   writes it; the server is told once per entry into raw mode (it holds its output then);
// - once the connection is closing, nothing more is written or sent.
#include <algorithm>
#include <cstddef>
#include <cstdint>
#include <optional>
#include <string>
#include <string_view>
#include <variant>
#include <vector>

#include "fuzz_support.h"
#include "host/socketcand_protocol.h"
#include "host/socketcand_session.h"

namespace {

using namespace motwin;
using Mode = host::SocketcandSession::Mode;

// What the session did, in order: a write, a frame to the bus, or the raw-mode notice.
struct RawModeEntered {
  bool operator==(const RawModeEntered&) const = default;
};
using Event = std::variant<std::string, can::CanFrame, RawModeEntered>;

bool same_events(const std::vector<Event>& a, const std::vector<Event>& b) {
  if (a.size() != b.size()) return false;
  for (size_t i = 0; i < a.size(); ++i) {
    if (a[i].index() != b[i].index()) return false;
    if (const auto* frame = std::get_if<can::CanFrame>(&a[i])) {
      const auto& other = std::get<can::CanFrame>(b[i]);
      if (!(*frame == other) || frame->extended != other.extended || frame->rtr != other.rtr) return false;
    } else if (a[i] != b[i]) {
      return false;
    }
  }
  return true;
}

std::string describe(const Event& event) {
  if (const auto* text = std::get_if<std::string>(&event)) return "write '" + *text + "'";
  if (const auto* frame = std::get_if<can::CanFrame>(&event)) {
    return "bus frame " + std::to_string(frame->id) + " dlc " + std::to_string(frame->dlc);
  }
  return "raw mode entered";
}

// The session's Io: records every event; closing from the `close_at`-th write on (0: never).
class RecordingIo final : public host::SocketcandSession::Io {
 public:
  explicit RecordingIo(size_t close_at) : close_at_(close_at) {}
  std::vector<Event> events;

  void write(const std::string& element) override {
    FUZZ_CHECK(!closing(), "a write while the connection is closing: '%s'", element.c_str());
    events.emplace_back(element);
    ++writes_;
  }
  void send_to_bus(const can::CanFrame& frame) override {
    FUZZ_CHECK(!closing(), "a frame sent while the connection is closing");
    events.emplace_back(frame);
  }
  void raw_mode_entered() override { events.emplace_back(RawModeEntered{}); }
  bool closing() const override { return close_at_ != 0 && writes_ >= close_at_; }

 private:
  size_t close_at_;
  size_t writes_ = 0;
};

// The model: the same rules, from the documentation.
class Model {
 public:
  explicit Model(size_t close_at) : close_at_(close_at) { write("< hi >"); }
  std::vector<Event> events;
  Mode mode = Mode::kAwaitOpen;

  void element(std::string_view text) {
    if (closing()) return;
    const std::vector<std::string_view> words = host::socketcand_words(text);
    const std::string_view command = words.empty() ? std::string_view{} : words[0];
    const bool alone = words.size() == 1;
    if (mode == Mode::kAwaitOpen) {
      if (command == "open" && words.size() == 2) {
        mode = Mode::kBcm;
        write("< ok >");
      } else {
        write(" < error expected open >");
      }
      return;
    }
    if (command == "send") {
      if (const Result<can::CanFrame> frame = host::parse_socketcand_send(words)) {
        events.emplace_back(*frame);
      } else {
        write(" < error " + frame.error() + " >");
      }
    } else if (command == "rawmode" && alone) {
      const bool entering = mode != Mode::kRaw;
      mode = Mode::kRaw;
      write("< ok >");
      if (entering) events.emplace_back(RawModeEntered{});
    } else if (command == "bcmmode" && alone) {
      mode = Mode::kBcm;
      write(" < ok >");
    } else if (command == "echo" && alone) {
      write(" < echo >");
    } else {
      write(" < error unknown command >");
    }
  }

  void frame_from_bus(const can::CanFrame& frame, uint64_t timestamp_us) {
    if (!closing() && mode == Mode::kRaw) write(host::format_socketcand_frame(frame, timestamp_us));
  }

 private:
  bool closing() const { return close_at_ != 0 && writes_ >= close_at_; }
  void write(std::string text) {
    events.emplace_back(std::move(text));
    ++writes_;
  }
  size_t close_at_;
  size_t writes_ = 0;
};

// A server element as python-can reads it: an optional space, `<`, a space, text without
// brackets, a space, `>`.
void check_element_text(const std::string& text) {
  const size_t open = text.size() > 0 && text[0] == ' ' ? 1 : 0;
  FUZZ_CHECK(text.size() >= open + 4 && text[open] == '<' && text[open + 1] == ' ' && text[text.size() - 2] == ' ' &&
                 text.back() == '>' && text.find_first_of("<>", open + 1) == text.size() - 1,
             "malformed element '%s'", text.c_str());
  FUZZ_CHECK(!host::socketcand_words(std::string_view(text).substr(open + 1, text.size() - open - 2)).empty(),
             "empty element '%s'", text.c_str());
}

can::CanFrame bus_frame(uint32_t k) {
  can::CanFrame frame;
  frame.extended = k % 4 == 0;
  frame.id = frame.extended ? (k * 0x9E3779B1u) & can::kMaxExtendedId : (k * 0x2F1u) & can::kMaxStandardId;
  frame.rtr = k % 7 == 3;
  frame.dlc = static_cast<uint8_t>(k % 9);
  for (uint8_t i = 0; i < 8; ++i) frame.data[i] = static_cast<uint8_t>(k * 31 + i * 7);
  return frame;
}

}  // namespace

extern "C" int LLVMFuzzerTestOneInput(const uint8_t* data, size_t size) {
  if (size < 3 || size > 16 * 1024) return 0;
  const unsigned max_chunk = data[0];
  const unsigned frame_every = data[1];
  const size_t close_at = data[2];
  const std::string_view stream(reinterpret_cast<const char*>(data + 3), size - 3);

  // Where each element ends (the position of its `>`), by the model's rule.
  std::vector<std::pair<size_t, std::string_view>> elements;
  std::optional<size_t> last_open;  // the last bracket, when it is a `<`
  for (size_t i = 0; i < stream.size(); ++i) {
    if (stream[i] == '<') {
      last_open = i;
    } else if (stream[i] == '>') {
      if (last_open && i - *last_open - 1 <= host::SocketcandElementParser::kMaxElementLength) {
        elements.emplace_back(i, stream.substr(*last_open + 1, i - *last_open - 1));
      }
      last_open.reset();
    }
  }

  RecordingIo io(close_at);
  host::SocketcandSession session(io);
  Model model(close_at);
  session.start();
  FUZZ_CHECK(!io.events.empty() && std::get_if<std::string>(&io.events[0]) != nullptr &&
                 std::get<std::string>(io.events[0]) == "< hi >",
             "the session does not start with < hi >");

  uint32_t seed = max_chunk * 2654435761u + 1;
  size_t next_element = 0;
  uint32_t chunks = 0;
  for (size_t at = 0; at < stream.size();) {
    size_t length = stream.size() - at;
    if (max_chunk != 0) {
      seed = seed * 1103515245u + 12345u;
      length = std::min<size_t>(length, 1 + (seed >> 16) % max_chunk);
    }
    session.push(stream.substr(at, length));
    at += length;
    while (next_element < elements.size() && elements[next_element].first < at) {
      model.element(elements[next_element++].second);
    }
    ++chunks;
    if (frame_every != 0 && chunks % frame_every == 0) {
      const can::CanFrame frame = bus_frame(chunks);
      const uint64_t timestamp_us = chunks * 1'000'003ull;
      session.frame_from_bus(frame, timestamp_us);
      model.frame_from_bus(frame, timestamp_us);
    }
    FUZZ_CHECK(session.mode() == model.mode, "after %u chunks: mode %d, the rules say %d", chunks,
               static_cast<int>(session.mode()), static_cast<int>(model.mode));
  }

  std::string output;
  size_t writes = 0;
  bool opened = false;
  for (const Event& event : io.events) {
    if (const auto* text = std::get_if<std::string>(&event)) {
      check_element_text(*text);
      if (writes > 0 && !opened) {
        FUZZ_CHECK(*text == "< ok >" || *text == " < error expected open >", "before open: '%s'", text->c_str());
        opened = *text == "< ok >";
      }
      output += *text;
      ++writes;
    } else if (std::get_if<can::CanFrame>(&event) != nullptr) {
      FUZZ_CHECK(opened, "a frame reached the bus before open");
    }
  }
  host::SocketcandElementParser parser;
  std::vector<std::string> read_back;
  parser.push(output, read_back);
  FUZZ_CHECK(read_back.size() == writes && parser.dropped_elements() == 0, "%zu writes read back as %zu elements",
             writes, read_back.size());

  if (!same_events(io.events, model.events)) {
    size_t i = 0;
    while (i < io.events.size() && i < model.events.size() && same_events({io.events[i]}, {model.events[i]})) ++i;
    FUZZ_CHECK(false, "event %zu: the session did %s, the rules say %s (%zu and %zu events)", i,
               i < io.events.size() ? describe(io.events[i]).c_str() : "nothing",
               i < model.events.size() ? describe(model.events[i]).c_str() : "nothing", io.events.size(),
               model.events.size());
  }
  return 0;
}
