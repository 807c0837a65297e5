// Fixed facts of the TMCM-1636 board as the firmware sees them: loop timing and the scaling
// of the supply voltage and temperature channels. The simulated board uses the inverse of the
// same formulas, so AP 220/221 and GIO 2/3, 1 always agree.
#pragma once

#include <cstdint>

namespace motwin::modules::tmcm1636 {

// Control tick: the current and velocity regulators run every 50 µs (manual 5.2.1).
inline constexpr uint32_t kControlTickUs = 50;
inline constexpr uint32_t kTicksPerMillisecond = 1000 / kControlTickUs;

// ADC_VM: 12 bits, full scale 66.0 V (a 1:20 divider on a 3.3 V reference).
inline constexpr int32_t kSupplyFullScaleDecivolt = 660;
inline constexpr int32_t kAdc12Max = 4095;

constexpr int32_t supply_decivolt_from_adc(uint16_t raw) {
  return (static_cast<int32_t>(raw) * kSupplyFullScaleDecivolt + kAdc12Max / 2) / kAdc12Max;
}
constexpr uint16_t supply_adc_from_millivolt(int32_t millivolt) {
  int64_t raw = (static_cast<int64_t>(millivolt) * kAdc12Max + kSupplyFullScaleDecivolt * 50) / (kSupplyFullScaleDecivolt * 100);
  if (raw < 0) raw = 0;
  if (raw > kAdc12Max) raw = kAdc12Max;
  return static_cast<uint16_t>(raw);
}

// ADC_TEMP: 16 bits of 3.3 V from a linear sensor with 500 mV at 0 °C and 10 mV/°C.
inline constexpr int32_t kAdc16Max = 65535;
constexpr int32_t temperature_celsius_from_adc(uint16_t raw) {
  const int32_t millivolt = (static_cast<int32_t>(raw) * 3300 + kAdc16Max / 2) / kAdc16Max;
  const int32_t tenths = millivolt - 500;  // 10 mV per °C
  return tenths >= 0 ? (tenths + 5) / 10 : -((-tenths + 5) / 10);
}
constexpr uint16_t temperature_adc_from_celsius(double celsius) {
  double raw = (500.0 + 10.0 * celsius) / 3300.0 * kAdc16Max;
  if (raw < 0) raw = 0;
  if (raw > kAdc16Max) raw = kAdc16Max;
  return static_cast<uint16_t>(raw + 0.5);
}

}  // namespace motwin::modules::tmcm1636
