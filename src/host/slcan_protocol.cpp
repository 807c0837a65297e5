#include "host/slcan_protocol.h"

#include <charconv>
#include <cstdio>

namespace motwin::host {
namespace {

constexpr char kOk = '\r';
constexpr char kError = '\a';

bool hex_value(std::string_view text, uint32_t& value) {
  if (text.empty()) return false;
  const auto result = std::from_chars(text.data(), text.data() + text.size(), value, 16);
  return result.ec == std::errc{} && result.ptr == text.data() + text.size();
}

}  // namespace

std::optional<can::CanFrame> parse_slcan_frame(std::string_view line) {
  if (line.empty()) return std::nullopt;
  const char kind = line[0];
  const bool extended = kind == 'T' || kind == 'R';
  const bool rtr = kind == 'r' || kind == 'R';
  if (kind != 't' && kind != 'T' && kind != 'r' && kind != 'R') return std::nullopt;
  const size_t id_digits = extended ? 8 : 3;
  if (line.size() < 1 + id_digits + 1) return std::nullopt;
  can::CanFrame frame;
  uint32_t id = 0;
  if (!hex_value(line.substr(1, id_digits), id)) return std::nullopt;
  if (id > (extended ? can::kMaxExtendedId : can::kMaxStandardId)) return std::nullopt;
  const char dlc_char = line[1 + id_digits];
  if (dlc_char < '0' || dlc_char > '8') return std::nullopt;
  frame.id = id;
  frame.extended = extended;
  frame.rtr = rtr;
  frame.dlc = static_cast<uint8_t>(dlc_char - '0');
  const std::string_view data = line.substr(2 + id_digits);
  if (rtr) return data.empty() ? std::optional<can::CanFrame>(frame) : std::nullopt;
  if (data.size() != static_cast<size_t>(frame.dlc) * 2) return std::nullopt;
  for (uint8_t i = 0; i < frame.dlc; ++i) {
    uint32_t byte = 0;
    if (!hex_value(data.substr(i * 2u, 2), byte)) return std::nullopt;
    frame.data[i] = static_cast<uint8_t>(byte);
  }
  return frame;
}

std::string format_slcan_frame(const can::CanFrame& frame) {
  char text[32];
  int n = 0;
  const char kind = frame.rtr ? (frame.extended ? 'R' : 'r') : (frame.extended ? 'T' : 't');
  const unsigned dlc = frame.dlc > can::kMaxDataLength ? can::kMaxDataLength : frame.dlc;
  if (frame.extended) {
    n = std::snprintf(text, sizeof(text), "%c%08X%u", kind, static_cast<unsigned>(frame.id), dlc);
  } else {
    n = std::snprintf(text, sizeof(text), "%c%03X%u", kind, static_cast<unsigned>(frame.id), dlc);
  }
  std::string out(text, static_cast<size_t>(n));
  if (!frame.rtr) {
    for (unsigned i = 0; i < dlc; ++i) {
      std::snprintf(text, sizeof(text), "%02X", frame.data[i]);
      out += text;
    }
  }
  out.push_back(kOk);
  return out;
}

void SlcanSession::push(std::string_view bytes, std::string& reply) {
  for (const char c : bytes) {
    if (c == '\r') {
      if (overlong_) {
        reply.push_back(kError);
      } else {
        command(line_, reply);
      }
      line_.clear();
      overlong_ = false;
    } else if (c == '\n' || c == '\0') {
      continue;
    } else if (line_.size() >= kMaxLineLength) {
      overlong_ = true;
    } else {
      line_.push_back(c);
    }
  }
}

void SlcanSession::command(std::string_view line, std::string& reply) {
  if (line.empty()) {  // a bare CR: slcand and python-can send them to flush the adapter
    reply.push_back(kOk);
    return;
  }
  switch (line[0]) {
    case 'O':
    case 'L':
      if (line.size() != 1 || open_) break;
      open_ = true;
      listen_only_ = line[0] == 'L';
      reply.push_back(kOk);
      return;
    case 'C':
      if (line.size() != 1) break;
      open_ = false;
      listen_only_ = false;
      reply.push_back(kOk);
      return;
    case 'S':
      if (line.size() != 2 || open_ || line[1] < '0' || line[1] > '8') break;
      bit_rate_code_ = static_cast<uint8_t>(line[1] - '0');
      reply.push_back(kOk);
      return;
    case 's':
      if (line.size() != 5 || open_) break;
      reply.push_back(kOk);
      return;
    case 'V':
      if (line.size() != 1) break;
      reply += "V1013";
      reply.push_back(kOk);
      return;
    case 'N':
      if (line.size() != 1) break;
      reply += "NMOTW";
      reply.push_back(kOk);
      return;
    case 'F':
      if (line.size() != 1) break;
      reply += "F00";
      reply.push_back(kOk);
      return;
    case 'Z':
      if (line.size() != 2 || (line[1] != '0' && line[1] != '1')) break;
      reply.push_back(kOk);
      return;
    case 't':
    case 'T':
    case 'r':
    case 'R': {
      if (!open_ || listen_only_) break;
      const std::optional<can::CanFrame> frame = parse_slcan_frame(line);
      if (!frame) break;
      to_bus_(*frame);
      reply.push_back(frame->extended ? 'Z' : 'z');
      reply.push_back(kOk);
      return;
    }
    default: break;
  }
  reply.push_back(kError);
}

}  // namespace motwin::host
