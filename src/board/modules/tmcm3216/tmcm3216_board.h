// Board seam of the TMCM-3216: the three stepper power stages (board/stepper_drive.h, one per
// motor) and the general-purpose I/O of the module (manual 4.2.60, 4.2.61, 4.2.67, 4.2.68): four
// DIO pins that are inputs or outputs per 2711, two 12-bit analog inputs, and the supply voltage.
// Plain data read and written once per tick, like the registers of the real board's peripherals.
//
// The simulated board (sim/modules/tmcm3216/tmcm3216_sim_board.h) fills every `feedback` and the input fields of
// `io` before each tick and applies every `drive` and the output fields of `io` after it.
#pragma once

#include <array>
#include <cstdint>

#include "board/stepper_drive.h"

namespace motwin::board {

inline constexpr uint8_t kTmcm3216AxisCount = 3;

struct Tmcm3216Io {
  static constexpr uint8_t kDioCount = 4;          // DIO0..DIO3: 2702/2703 bits 16..19, 2711 bits 0..3
  static constexpr uint8_t kAnalogInputCount = 2;  // AIN0, AIN1: 270E sub 1, 2 (0..4095)

  // Sampled before each tick. The level on each DIO pin; a pin in output mode reads back what it
  // drives (a push-pull output) or what the outside pulls it to (a high-side output that is off).
  std::array<bool, kDioCount> dio_levels{};
  std::array<uint16_t, kAnalogInputCount> analog_inputs{};  // raw 12-bit counts
  int32_t supply_millivolt = 24000;
  // The enable signal of the module's shutdown switch (manual table 365, 5441): false while the
  // switch is open; the hardware then keeps every motor driver off.
  bool enable_input = true;

  // Written by the firmware each tick. output_mode: 2711 bit n (the pin is driven);
  // push_pull: 2711 bit 8 + n (else high side: only a high level is driven, low floats).
  std::array<bool, kDioCount> output_mode{};
  std::array<bool, kDioCount> push_pull{};
  std::array<bool, kDioCount> output_levels{};
  // Brake output of motor n (DIO n is its pin while the automatic brake control of 200C is on,
  // manual 4.2.61 note): the brake coil's PWM duty 0..255 (200C apply / release current).
  std::array<bool, kTmcm3216AxisCount> brake_control{};
  std::array<uint8_t, kTmcm3216AxisCount> brake_duty{};
};

struct Tmcm3216Board {
  std::array<StepperPowerStage, kTmcm3216AxisCount> axes{};
  Tmcm3216Io io{};
};

}  // namespace motwin::board
