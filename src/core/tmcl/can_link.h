// TMCL over CAN (TMCM-1636 manual 2.1-2.2 notes, docs/tmcl-protocol.md "CAN framing"): a request is
// a frame on the module's receive ID (GP 71) carrying command, type, motor and the value
// (big-endian), 7 data bytes or 8 (PyTrinamic lets the serial checksum byte ride along; it is not
// checked: CAN has its own CRC). The reply goes out on the send ID (GP 70) with the receive ID's
// low byte, status, command and value, as long as the request was (8: padded with 0). Any TMCL
// module with GP 69/70/71 uses this link unchanged; the IDs are read from the module's own
// parameter table, so SGP 70/71 take effect with the very next frame.
#pragma once

#include <cstdint>

#include "core/tmcl/engine.h"
#include "types/can_frame.h"

namespace motwin::tmcl {

inline constexpr uint8_t kCanRequestLength = 7;     // command, type, motor, value[4]
inline constexpr uint8_t kCanLongRequestLength = 8;  // ... plus the checksum byte PyTrinamic sends

// Global parameters of every TMCL module with a CAN interface (TMCM-1636 table 13, TMCM-142).
namespace can_parameter {
inline constexpr uint8_t kBitRate = 69;    // code 2..8 (20 kbit/s .. 1 Mbit/s)
inline constexpr uint8_t kSendId = 70;     // replies
inline constexpr uint8_t kReceiveId = 71;  // requests
}  // namespace can_parameter

struct CanSettings {
  uint32_t receive_id = 1;
  uint32_t send_id = 2;
  uint8_t bit_rate_code = 8;
};

// The module's current settings; false when it has no GP 70/71 (no CAN interface).
bool read_can_settings(TmclDevice& device, CanSettings& settings);

// Bit rate in bit/s of a GP 69 code (2 = 20 kbit/s ... 8 = 1 Mbit/s); 0 for any other code.
uint32_t can_bit_rate_from_code(int32_t code);

struct CanResponse {
  bool addressed = false;         // the frame was for this module (its receive ID)
  bool has_reply = false;         // false: not addressed, or command 137 (no reply)
  can::CanFrame reply{};
  bool reset_after_send = false;  // command 255: call TmclEngine::complete_reset() once sent
};

// Handles one received frame. Frames on other IDs and remote frames are not ours (addressed =
// false). A data frame on the receive ID with fewer than 7 bytes cannot hold a request: it is
// answered with status 2 (invalid command) and the command byte it has, and nothing executes.
// Command 136 type 0 answers with the 8 version characters as the data (always 8 bytes);
// command 139 (ASCII mode) is not available over CAN: status 6, the link stays binary.
CanResponse serve_can_frame(TmclEngine& engine, const can::CanFrame& frame, ChannelId channel);

// A normal reply frame on the module's current send ID; `length` 7 or 8.
can::CanFrame encode_can_reply(const CanSettings& settings, const Reply& reply, uint8_t length, bool extended = false);

// A request frame as a host sends it (7 or 8 data bytes; an 8th byte is the serial checksum).
can::CanFrame encode_can_request(uint32_t receive_id, const Instruction& instruction, uint8_t length = kCanRequestLength);

}  // namespace motwin::tmcl
