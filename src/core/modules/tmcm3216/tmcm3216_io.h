// The TMCM-3216's general-purpose I/O as the firmware sees it (manual 4.2.60, 4.2.61, 4.2.67,
// 4.2.68, 5.1.10): the DIO pins DIO0..DIO3 in input or output mode (2711), the inputs (2702, and
// bits 16..19 of each axis's 60FD), the outputs with their mask (2703) and the analog inputs
// (270E). The automatic brake control of motor n (200C) owns output n (2703 note).
#pragma once

#include <cstdint>

#include "board/modules/tmcm3216/tmcm3216_board.h"

namespace motwin::modules::tmcm3216 {

class Tmcm3216GeneralIo {
 public:
  static constexpr uint8_t kDioCount = board::Tmcm3216Io::kDioCount;
  static constexpr uint8_t kFirstBit = 16;  // 2702 / 2703 / 60FD: DIO n at bit 16 + n
  static constexpr uint16_t kIoModeMask = 0x0F0F;  // 2711: bits 0..3 output mode, 8..11 push-pull

  static constexpr uint32_t kOutputBits = ((1u << kDioCount) - 1) << kFirstBit;  // OUT0..OUT3

  // Objects (device-wide, not stored: the manual lists no store sub-index for them).
  uint32_t outputs = 0;      // 2703 sub 1 as last written (what a read returns)
  uint32_t output_mask = 0;  // 2703 sub 2: bits 16..19 say which outputs a write of sub 1 switches
  uint16_t io_mode = 0;      // 2711

  // 2703 sub 1 holds the value written, as CiA-401's write-output object (6200h) with its filter
  // mask (6208h) does: the object reads back as written, and of its bits only those the mask
  // lets through switch their output; the others keep their level (docs/canopen.md "2703 sub 1").
  // Bits that name no output of the module are refused by the dictionary (valid_outputs()).
  void write_outputs(uint32_t value) {
    outputs = value;
    output_levels_ = (output_levels_ & ~output_mask) | (value & output_mask & kOutputBits);
  }
  static constexpr bool valid_outputs(uint32_t value) { return (value & ~kOutputBits) == 0; }
  // The levels OUT0..OUT3 are switched to (bits 16..19).
  uint32_t output_levels() const { return output_levels_; }

  // Before each tick: the pin levels and analog counts (board.io's input fields).
  void sample(const board::Tmcm3216Io& io) {
    uint32_t bits = 0;
    for (uint8_t n = 0; n < kDioCount; ++n) {
      if (io.dio_levels[n]) bits |= 1u << (kFirstBit + n);
    }
    inputs_ = bits;
    for (uint8_t n = 0; n < board::Tmcm3216Io::kAnalogInputCount; ++n) analog_[n] = io.analog_inputs[n];
  }

  // After each tick: the mode and output levels of the pins; brake_duty[n] drives output n while
  // brake_control[n] (the automatic brake control of motor n) is set.
  void drive(board::Tmcm3216Io& io, const bool (&brake_control)[board::kTmcm3216AxisCount],
             const uint8_t (&brake_duty)[board::kTmcm3216AxisCount]) const {
    for (uint8_t n = 0; n < kDioCount; ++n) {
      io.output_mode[n] = (io_mode & (1u << n)) != 0;
      io.push_pull[n] = (io_mode & (1u << (8 + n))) != 0;
      io.output_levels[n] = (output_levels_ & (1u << (kFirstBit + n))) != 0;
    }
    for (uint8_t m = 0; m < board::kTmcm3216AxisCount; ++m) {
      io.brake_control[m] = brake_control[m];
      io.brake_duty[m] = brake_control[m] ? brake_duty[m] : 0;
      // The brake's pin is an output while the brake control drives it.
      if (brake_control[m] && m < kDioCount) {
        io.output_mode[m] = true;
        io.output_levels[m] = brake_duty[m] != 0;
      }
    }
  }

  // 2702: DIO levels at bits 16..19 (pins in output mode read back their level).
  uint32_t digital_inputs() const { return inputs_; }
  // 270E sub 1 / 2: raw 12-bit counts.
  uint16_t analog_input(uint8_t channel) const { return channel < board::Tmcm3216Io::kAnalogInputCount ? analog_[channel] : 0; }

 private:
  uint32_t output_levels_ = 0;
  uint32_t inputs_ = 0;
  uint16_t analog_[board::Tmcm3216Io::kAnalogInputCount] = {};
};

}  // namespace motwin::modules::tmcm3216
