// Board seam of the TMCM-1636 for everything that is not the power stage: general-purpose
// inputs and outputs, the analog channels (TMCM-1636 manual 2.6.13/2.6.14) and the
// reference switch inputs (axis parameters 209..213). Raw levels and raw ADC counts only:
// conversions to volts and degrees belong to the firmware (core/modules/tmcm1636/tmcm1636_hardware.h).
#pragma once

#include <cstdint>

namespace motwin::board {

enum class ReferenceSwitch : uint8_t { kRight = 0, kLeft = 1, kHome = 2 };

class Tmcm1636Io {
 public:
  static constexpr uint8_t kDigitalInputCount = 4;   // GPI0..GPI3 (bank 0)
  static constexpr uint8_t kAnalogInputCount = 4;    // AI0, AI1, ADC_VM, ADC_TEMP (bank 1)
  static constexpr uint8_t kDigitalOutputCount = 2;  // GPO0, GPO1 (bank 2)
  static constexpr uint8_t kAnalogSupplyChannel = 2;
  static constexpr uint8_t kAnalogTemperatureChannel = 3;

  virtual bool digital_input(uint8_t port) const = 0;
  // AI0, AI1, ADC_VM: 12-bit (0..4095); ADC_TEMP: 16-bit (0..65535).
  virtual uint16_t analog_input(uint8_t channel) const = 0;
  virtual void set_digital_output(uint8_t port, bool on) = 0;
  virtual bool digital_output(uint8_t port) const = 0;
  // Electrical level of a reference switch input (true = high); polarity is the firmware's.
  virtual bool reference_switch_level(ReferenceSwitch which) const = 0;

 protected:
  ~Tmcm1636Io() = default;
};

}  // namespace motwin::board
