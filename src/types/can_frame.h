// One classic CAN frame as the controller sees it: identifier (11 or 29 bits), remote request
// flag, data length code 0..8 and up to 8 data bytes. Plain data, no behaviour: the CANopen
// services, the virtual bus and the transports all pass this type around.
//
// A leaf header of src/types/: vocabulary that every layer may use (the board seam's CAN
// controller and the core's services alike), so it includes only the C++ standard library
// (docs/architecture.md, "Include directions").
#pragma once

#include <cstdint>

namespace motwin::can {

inline constexpr uint32_t kMaxStandardId = 0x7FF;
inline constexpr uint32_t kMaxExtendedId = 0x1FFF'FFFF;
inline constexpr uint8_t kMaxDataLength = 8;

struct CanFrame {
  uint32_t id = 0;
  bool extended = false;  // 29-bit identifier
  bool rtr = false;       // remote transmission request: dlc counts, data is not sent
  uint8_t dlc = 0;        // 0..8
  uint8_t data[kMaxDataLength] = {};

  constexpr bool operator==(const CanFrame& other) const {
    if (id != other.id || extended != other.extended || rtr != other.rtr || dlc != other.dlc) return false;
    if (rtr) return true;
    for (uint8_t i = 0; i < dlc && i < kMaxDataLength; ++i) {
      if (data[i] != other.data[i]) return false;
    }
    return true;
  }
};

// A standard data frame with the given bytes (at most 8 are used).
constexpr CanFrame make_frame(uint32_t id, const uint8_t* bytes, uint8_t length) {
  CanFrame frame;
  frame.id = id;
  frame.dlc = length > kMaxDataLength ? kMaxDataLength : length;
  for (uint8_t i = 0; i < frame.dlc; ++i) frame.data[i] = bytes[i];
  return frame;
}

}  // namespace motwin::can
