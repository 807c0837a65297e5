// Board seam of one stepper axis (the TMCM-142's axis, each of the TMCM-3216's three): the
// motor driver stage and the motor-side sensors, as plain data read and written once per
// control tick, like the registers of a real driver chip and encoder counter. The per-tick path
// has no virtual call and no knowledge of the plant.
//
// The simulated board (sim::StepperPlant and the module's sim board) fills `feedback` before
// each tick and applies `drive` after it; a real board would fill the same fields from its
// peripherals.
#pragma once

#include <cstdint>

namespace motwin::board {

// One electrical revolution of a two-phase stepper is four full steps.
inline constexpr uint64_t kElectricalAngleFullCircle = uint64_t{1} << 32;
inline constexpr uint32_t kElectricalAnglePerFullStep = uint32_t{1} << 30;

// Sampled at the start of each control tick.
struct StepperFeedback {
  // ABN encoder: the quadrature counter (free running, wraps at 32 bits), the number of N pulses
  // seen so far (wraps) and the counter value latched by the last N pulse.
  int32_t encoder_count = 0;
  uint32_t encoder_index_events = 0;
  int32_t encoder_index_count = 0;
  // Switch inputs as electrical levels: bit 0 right limit, bit 1 left limit, bit 2 home.
  uint8_t switches = 0;
  // Motor supply voltage, mV.
  int32_t supply_millivolt = 24000;
  // What a TMC driver chip measures and flags (TMCM-3216; the TMCM-142 leaves them at 0).
  // StallGuard2 result SG_RESULT 0..1023 (high: light load, 0: at the torque limit), updated once
  // per full step and meaningless at standstill; StallGuard4 result SG4_RESULT 0..510 (StealthChop).
  uint16_t stallguard2_result = 0;
  uint16_t stallguard4_result = 0;
  // Counts every new StallGuard result (wrapping): a change is the "new measurement" edge.
  uint32_t stallguard_measurements = 0;
  // DRV_STATUS error bits (kDriver* below), as the TMCM-3216 shows them in object 2102.
  uint8_t driver_status = 0;

  bool operator==(const StepperFeedback&) const = default;
};

// feedback.driver_status bits (TMCM-3216 manual table 159).
inline constexpr uint8_t kDriverOvercurrentA = 1u << 0;     // short on bridge A
inline constexpr uint8_t kDriverOvercurrentB = 1u << 1;     // short on bridge B
inline constexpr uint8_t kDriverOpenLoadA = 1u << 2;
inline constexpr uint8_t kDriverOpenLoadB = 1u << 3;
inline constexpr uint8_t kDriverOvercurrentHighSide = 1u << 4;
inline constexpr uint8_t kDriverUndervoltage = 1u << 5;
inline constexpr uint8_t kDriverTemperatureWarning = 1u << 6;
inline constexpr uint8_t kDriverOvertemperature = 1u << 7;

// Applied from the next tick on.
struct StepperDrive {
  // false: the bridges are open and the motor freewheels.
  bool enabled = false;
  // The driver's microstep counter as an electrical angle: 2^32 per electrical revolution
  // (4 full steps), wrapping. Moves by at most a quarter revolution per tick.
  uint32_t electrical_angle = 0;
  // Coil current targets from the microstep table at the present current amplitude, signed, mA
  // (peak). Coil A follows the cosine, coil B the sine of the electrical angle.
  int32_t coil_a_ma = 0;
  int32_t coil_b_ma = 0;
  // Driver chip settings the simulated measurements depend on (TMCM-3216; the TMCM-142 leaves
  // them at their defaults): StealthChop instead of SpreadCycle, StallGuard2 threshold SGT
  // (209E) and filter (209D), StallGuard4 filter (20A9) and angle offset (20AA), and the polarity
  // the encoder interface expects of the N channel (200B sub 1: true = active low).
  bool stealth_chop = false;
  int8_t stallguard2_threshold = 0;
  bool stallguard2_filter = false;
  bool stallguard4_filter = false;
  bool stallguard4_angle_offset = false;
  bool encoder_index_active_low = false;

  bool operator==(const StepperDrive&) const = default;
};

struct StepperPowerStage {
  StepperFeedback feedback;
  StepperDrive drive;
};

}  // namespace motwin::board
