// How long a classic CAN frame occupies the bus: its exact bit count including the stuff bits
// the controller inserts (computed from the real bit sequence: SOF, arbitration and control
// fields, data and CRC-15 are stuffed; CRC delimiter, ACK, EOF and the 3-bit intermission are
// not). Used by the virtual bus for its load accounting (host/can_bus.h).
#pragma once

#include <cstdint>

#include "types/can_frame.h"

namespace motwin::host {

// Bits from SOF to the end of the intermission, stuff bits included (a standard 8-byte frame:
// 111 without stuffing, up to 135 with the worst case).
uint32_t can_frame_bits(const can::CanFrame& frame);
// Stuff bits alone (0 .. 24 for a standard 8-byte frame).
uint32_t can_stuff_bits(const can::CanFrame& frame);

}  // namespace motwin::host
