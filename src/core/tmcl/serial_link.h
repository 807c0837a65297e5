// TMCL over a byte stream (RS485, RS232, USB virtual COM port, and TCP as PyTrinamic's
// socket interface speaks it): 9-byte frames, address filter, checksum, reply encoding
// (TMCM-1636 manual 2.1-2.2, docs/tmcl-protocol.md "Serial and TCP framing").
#pragma once

#include <array>
#include <cstddef>
#include <cstdint>

#include "core/tmcl/engine.h"

namespace motwin::tmcl {

inline constexpr size_t kFrameLength = 9;
using Frame = std::array<uint8_t, kFrameLength>;

// 8-bit sum of the first `length` bytes.
constexpr uint8_t checksum(const uint8_t* bytes, size_t length) {
  uint8_t sum = 0;
  for (size_t i = 0; i < length; ++i) sum = static_cast<uint8_t>(sum + bytes[i]);
  return sum;
}

Frame encode_request(uint8_t module_address, const Instruction& instruction);
Instruction decode_instruction(const Frame& frame);
Frame encode_reply(uint8_t host_address, uint8_t module_address, const Reply& reply);

// Collects bytes into frames. A gap longer than `resync_gap_us` between two bytes discards a
// partial frame, so a host that lost byte sync recovers by pausing
// (docs/tmcl-protocol.md "Serial and TCP framing").
class SerialFrameDecoder {
 public:
  static constexpr uint32_t kDefaultResyncGapUs = 5000;

  explicit SerialFrameDecoder(uint32_t resync_gap_us = kDefaultResyncGapUs) : resync_gap_us_(resync_gap_us) {}

  // Returns true when `byte` completed a frame; the frame is then in frame().
  bool push(uint8_t byte, uint64_t now_us);
  const Frame& frame() const { return frame_; }
  size_t pending_bytes() const { return fill_; }
  void reset() { fill_ = 0; }

 private:
  uint32_t resync_gap_us_;
  uint64_t last_byte_us_ = 0;
  size_t fill_ = 0;
  Frame frame_{};
};

struct SerialResponse {
  Frame bytes{};
  uint8_t length = 0;         // 0: no reply (other address, command 137)
  bool reset_after_send = false;  // command 255: call TmclEngine::complete_reset() once sent
  bool enter_ascii_mode = false;  // command 139: the link reads ASCII lines once this is sent
  uint8_t delay_ms = 0;       // GP 75 telegram pause before the reply
};

// Handles one complete frame from `channel`.
SerialResponse serve_serial_frame(TmclEngine& engine, const Frame& frame, ChannelId channel);

// Encodes a delayed reply (command 138) with the module's current addresses.
Frame encode_event_reply(TmclDevice& device, const Reply& reply);

}  // namespace motwin::tmcl
