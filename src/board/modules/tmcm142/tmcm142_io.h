// Board seam of the TMCM-142 for everything that is not the stepper power stage
// (board/stepper_drive.h): the general-purpose inputs and outputs of connector 3 (TMCM-142 manual
// table 5.2). Raw levels and raw ADC counts only.
#pragma once

#include <cstdint>

namespace motwin::board {

class Tmcm142Io {
 public:
  static constexpr uint8_t kDigitalInputCount = 9;   // IN0..IN8 (IN0..IN2 read as digital levels; bank 0)
  static constexpr uint8_t kAnalogInputCount = 3;    // IN0..IN2 A/D (bank 1), 12 bit: 0..4095
  static constexpr uint8_t kDigitalOutputCount = 3;  // OUT_0..OUT_2 (bank 2)

  virtual bool digital_input(uint8_t port) const = 0;
  virtual uint16_t analog_input(uint8_t channel) const = 0;
  virtual void set_digital_output(uint8_t port, bool on) = 0;
  virtual bool digital_output(uint8_t port) const = 0;

 protected:
  ~Tmcm142Io() = default;
};

}  // namespace motwin::board
