#include "host/can_bit_timing.h"

#include <array>

namespace motwin::host {
namespace {

// Unstuffed fields after the CRC: delimiter 1, ACK slot and delimiter 2, EOF 7, intermission 3.
constexpr uint32_t kTrailerBits = 13;
constexpr uint32_t kMaxStuffedBits = 1 + 32 + 6 + 64 + 15;

struct BitString {
  std::array<uint8_t, kMaxStuffedBits> bits{};
  uint32_t length = 0;

  void append(uint32_t value, uint32_t count) {
    for (uint32_t i = count; i-- > 0;) bits[length++] = static_cast<uint8_t>((value >> i) & 1u);
  }
};

uint16_t crc15(const BitString& bits) {
  uint16_t crc = 0;
  for (uint32_t i = 0; i < bits.length; ++i) {
    const bool feedback = (((crc >> 14) & 1u) ^ bits.bits[i]) != 0;
    crc = static_cast<uint16_t>((crc << 1) & 0x7FFF);
    if (feedback) crc ^= 0x4599;
  }
  return crc;
}

BitString stuffed_region(const can::CanFrame& frame) {
  BitString bits;
  const uint8_t dlc = frame.dlc > can::kMaxDataLength ? can::kMaxDataLength : frame.dlc;
  bits.append(0, 1);  // SOF
  if (frame.extended) {
    bits.append(frame.id >> 18, 11);
    bits.append(1, 1);  // SRR
    bits.append(1, 1);  // IDE
    bits.append(frame.id & 0x3FFFF, 18);
    bits.append(frame.rtr ? 1 : 0, 1);
    bits.append(0, 2);  // r1, r0
  } else {
    bits.append(frame.id & 0x7FF, 11);
    bits.append(frame.rtr ? 1 : 0, 1);
    bits.append(0, 2);  // IDE, r0
  }
  bits.append(frame.dlc & 0xF, 4);
  if (!frame.rtr) {
    for (uint8_t i = 0; i < dlc; ++i) bits.append(frame.data[i], 8);
  }
  bits.append(crc15(bits), 15);
  return bits;
}

uint32_t stuff_bits_of(const BitString& bits) {
  uint32_t stuffed = 0;
  uint32_t run = 0;
  uint8_t last = 2;
  for (uint32_t i = 0; i < bits.length; ++i) {
    if (bits.bits[i] == last) {
      ++run;
    } else {
      last = bits.bits[i];
      run = 1;
    }
    if (run == 5) {
      // The stuff bit is the complement and starts the next run.
      ++stuffed;
      last = static_cast<uint8_t>(1 - last);
      run = 1;
    }
  }
  return stuffed;
}

}  // namespace

uint32_t can_stuff_bits(const can::CanFrame& frame) { return stuff_bits_of(stuffed_region(frame)); }

uint32_t can_frame_bits(const can::CanFrame& frame) {
  // Built once: the bus asks for every frame it carries.
  const BitString bits = stuffed_region(frame);
  return bits.length + stuff_bits_of(bits) + kTrailerBits;
}

}  // namespace motwin::host
