// Stop on stall (TMCM-3216 manual 4.2.37, 4.2.39, 4.2.40; objects 20A4, 20A7, 20A8): a stall is
// a fresh StallGuard measurement showing the motor at its torque limit while the axis runs faster
// than the stop-on-stall velocity:
//   SpreadCycle (StallGuard2): the load value 2101 reaches 0 ("in case the StallGuard2 load value
//     reaches zero"; the threshold 209E is the driver's SGT offset, applied in the measurement);
//   StealthChop (StallGuard4): the result 210A falls below 20A8 (the driver compares its result
//     with twice its 8-bit SGTHRS; the object holds that doubled value, 0..511).
// The stall is latched until clear(): the axis reports it (EMCY 3230) and its owner stops the
// motor, entering FAULT (20A7 = 0) or just stopping (20A7 = 1). 20A4 = 0 disables stop on stall;
// at standstill and below 20A4 nothing is detected (StallGuard is not valid at low speed).
#pragma once

#include <cstdint>

namespace motwin::motion {

enum class StallReaction : uint8_t {
  kFault = 0,  // 20A7 = 0: the PDS state machine goes to FAULT
  kStop = 1,   // 20A7 = 1: the motor stops, the state stays OPERATION ENABLED
};

struct StallDetectorConfig {
  uint32_t stop_velocity_pps = 0;      // 20A4, microsteps/s; 0: stop on stall off
  StallReaction reaction = StallReaction::kFault;  // 20A7
  uint16_t stallguard4_threshold = 0;  // 20A8, 0..511; 0: no StallGuard4 stall

  // 20A7's object value (0/1) to the reaction; false for a value out of range.
  static bool reaction_of(uint8_t option_code, StallReaction& out);
};

struct StallDetectorInputs {
  int32_t velocity_pps = 0;         // actual (ramp) velocity, microsteps/s
  uint16_t stallguard2_result = 0;  // 0..1023
  uint16_t stallguard4_result = 0;  // 0..511
  bool new_measurement = false;     // the driver produced a new result since the last tick
  bool stealth_chop = false;        // which of the two results is valid
};

class StallDetector {
 public:
  // Once per control tick. Returns true in the tick a stall is detected (the latch's rising edge).
  bool step(const StallDetectorConfig& config, const StallDetectorInputs& inputs);

  bool stalled() const { return stalled_; }  // latched
  void clear() { stalled_ = false; }         // fault reset / new move
  // Velocity at which the latched stall was detected, microsteps/s (diagnostics).
  int32_t stall_velocity_pps() const { return stall_velocity_pps_; }

 private:
  bool stalled_ = false;
  int32_t stall_velocity_pps_ = 0;
};

// StealthChop is on when 20B0 (PWM threshold speed) > 0, the PWM gradient 20B1 is not 0 and the
// speed is below 20B0 (manual 4.2.43, 4.2.44); SpreadCycle (and StallGuard2) otherwise.
inline bool stealth_chop_active(uint32_t pwm_threshold_pps, uint8_t pwm_gradient, int32_t velocity_pps) {
  const uint32_t speed = velocity_pps < 0 ? 0u - static_cast<uint32_t>(velocity_pps) : static_cast<uint32_t>(velocity_pps);
  return pwm_threshold_pps > 0 && pwm_gradient != 0 && speed < pwm_threshold_pps;
}

}  // namespace motwin::motion
