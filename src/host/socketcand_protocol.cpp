#include "host/socketcand_protocol.h"

#include <charconv>
#include <cstdio>

namespace motwin::host {
namespace {

bool parse_hex(std::string_view text, uint32_t& value) {
  if (text.empty() || text.size() > 8) return false;
  const auto result = std::from_chars(text.data(), text.data() + text.size(), value, 16);
  return result.ec == std::errc{} && result.ptr == text.data() + text.size();
}

bool is_blank(char c) { return c == ' ' || c == '\t' || c == '\r' || c == '\n'; }

}  // namespace

void SocketcandElementParser::push(std::string_view bytes, std::vector<std::string>& out) {
  for (const char c : bytes) {
    switch (state_) {
      case State::kOutside:
        if (c == '<') {
          element_.clear();
          state_ = State::kInside;
        }
        break;
      case State::kInside:
        if (c == '<') {
          ++dropped_;
          element_.clear();
        } else if (c == '>') {
          out.push_back(element_);
          element_.clear();
          state_ = State::kOutside;
        } else if (element_.size() >= kMaxElementLength) {
          ++dropped_;
          element_.clear();
          state_ = State::kSkipping;
        } else {
          element_.push_back(c);
        }
        break;
      case State::kSkipping:
        if (c == '<') {
          element_.clear();
          state_ = State::kInside;
        } else if (c == '>') {
          state_ = State::kOutside;
        }
        break;
    }
  }
}

std::vector<std::string_view> socketcand_words(std::string_view element) {
  // Counted first: one allocation per element instead of one per doubling (a `send` of 8 bytes
  // has 11 words).
  size_t count = 0;
  for (size_t i = 0; i < element.size(); ++i) {
    if (!is_blank(element[i]) && (i == 0 || is_blank(element[i - 1]))) ++count;
  }
  std::vector<std::string_view> words;
  words.reserve(count);
  size_t i = 0;
  while (i < element.size()) {
    while (i < element.size() && is_blank(element[i])) ++i;
    const size_t start = i;
    while (i < element.size() && !is_blank(element[i])) ++i;
    if (i > start) words.push_back(element.substr(start, i - start));
  }
  return words;
}

Result<can::CanFrame> parse_socketcand_send(const std::vector<std::string_view>& words) {
  if (words.size() < 3 || words[0] != "send") return Error{"send needs an ID and a length"};
  can::CanFrame frame;
  uint32_t id = 0;
  if (!parse_hex(words[1], id) || id > can::kMaxExtendedId) return Error{"bad CAN ID"};
  frame.id = id;
  frame.extended = words[1].size() == 8 || id > can::kMaxStandardId;
  uint32_t length = 0;
  if (!parse_hex(words[2], length) || length > can::kMaxDataLength) return Error{"bad length"};
  if (words.size() != 3 + length) return Error{"length does not match the data"};
  frame.dlc = static_cast<uint8_t>(length);
  for (uint32_t i = 0; i < length; ++i) {
    uint32_t byte = 0;
    if (words[3 + i].size() > 2 || !parse_hex(words[3 + i], byte)) return Error{"bad data byte"};
    frame.data[i] = static_cast<uint8_t>(byte);
  }
  return frame;
}

Result<can::CanFrame> parse_socketcand_frame(const std::vector<std::string_view>& words) {
  if (words.size() < 3 || words.size() > 4 || words[0] != "frame") return Error{"frame needs an ID and a time"};
  can::CanFrame frame;
  uint32_t id = 0;
  if (!parse_hex(words[1], id) || id > can::kMaxExtendedId) return Error{"bad CAN ID"};
  frame.id = id;
  frame.extended = words[1].size() == 8 || id > can::kMaxStandardId;
  const std::string_view time = words[2];
  const size_t dot = time.find('.');
  const auto all_digits = [](std::string_view text) {
    return !text.empty() && text.find_first_not_of("0123456789") == std::string_view::npos;
  };
  if (dot == std::string_view::npos || !all_digits(time.substr(0, dot)) || !all_digits(time.substr(dot + 1))) {
    return Error{"bad time"};
  }
  const std::string_view data = words.size() == 4 ? words[3] : std::string_view{};
  if (data.size() % 2 != 0 || data.size() > 2 * can::kMaxDataLength) return Error{"bad data"};
  frame.dlc = static_cast<uint8_t>(data.size() / 2);
  for (uint8_t i = 0; i < frame.dlc; ++i) {
    uint32_t byte = 0;
    if (!parse_hex(data.substr(2 * i, 2), byte)) return Error{"bad data"};
    frame.data[i] = static_cast<uint8_t>(byte);
  }
  return frame;
}

std::string format_socketcand_send(const can::CanFrame& frame) {
  const uint8_t length = frame.dlc > can::kMaxDataLength ? can::kMaxDataLength : frame.dlc;
  char text[80];
  int used = std::snprintf(text, sizeof(text), frame.extended ? "< send %08X %u" : "< send %03X %u",
                           static_cast<unsigned>(frame.id), static_cast<unsigned>(length));
  for (uint8_t i = 0; i < length; ++i) {
    used += std::snprintf(text + used, sizeof(text) - static_cast<size_t>(used), " %02X", frame.data[i]);
  }
  return std::string(text, static_cast<size_t>(used)) + " >";
}

std::string format_socketcand_frame(const can::CanFrame& frame, uint64_t timestamp_us) {
  char head[64];
  std::snprintf(head, sizeof(head), frame.extended ? " < frame %08X %llu.%06llu " : " < frame %03X %llu.%06llu ",
                static_cast<unsigned>(frame.id), static_cast<unsigned long long>(timestamp_us / 1'000'000u),
                static_cast<unsigned long long>(timestamp_us % 1'000'000u));
  std::string text = head;
  static constexpr char kHex[] = "0123456789ABCDEF";
  if (!frame.rtr) {
    for (uint8_t i = 0; i < frame.dlc && i < can::kMaxDataLength; ++i) {
      text.push_back(kHex[frame.data[i] >> 4]);
      text.push_back(kHex[frame.data[i] & 0x0F]);
    }
  }
  text += " >";
  return text;
}

}  // namespace motwin::host
