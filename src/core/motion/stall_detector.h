// Stop on stall of a TMC StallGuard driver (as the TMCM-3216 uses it, manual 4.2.37, 4.2.39,
// 4.2.40): a stall is a fresh StallGuard measurement showing the motor at its torque limit while
// the axis runs faster than the stop-on-stall velocity:
//   SpreadCycle (StallGuard2): the load value reaches 0 ("in case the StallGuard2 load value
//     reaches zero"; the driver's SGT offset is applied in the measurement);
//   StealthChop (StallGuard4): the result falls below the threshold (the driver compares its
//     result with twice its 8-bit SGTHRS; the threshold is that doubled value, 0..511).
// The stall is latched until clear(): the axis reports it and its owner stops the motor,
// entering FAULT or just stopping (`reaction`). A stop velocity of 0 disables stop on stall; at
// standstill and at or below the stop velocity nothing is detected (StallGuard is not valid at
// low speed). Which objects set these values is the module's business (the TMCM-3216:
// 20A4, 20A7, 20A8; tmcm3216_stepper.h).
#pragma once

#include <cstdint>

namespace motwin::motion {

enum class StallReaction : uint8_t {
  kFault,  // the PDS state machine goes to FAULT
  kStop,   // the motor stops, the state stays OPERATION ENABLED
};

struct StallDetectorConfig {
  uint32_t stop_velocity_pps = 0;      // microsteps/s; 0: stop on stall off
  StallReaction reaction = StallReaction::kFault;
  uint16_t stallguard4_threshold = 0;  // 0..511; 0: no StallGuard4 stall
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

// StealthChop is on when the PWM threshold speed is > 0, the PWM gradient is not 0 and the speed
// is below the threshold (TMCM-3216 manual 4.2.43, 4.2.44); SpreadCycle (and StallGuard2)
// otherwise.
inline bool stealth_chop_active(uint32_t pwm_threshold_pps, uint8_t pwm_gradient, int32_t velocity_pps) {
  const uint32_t speed = velocity_pps < 0 ? 0u - static_cast<uint32_t>(velocity_pps) : static_cast<uint32_t>(velocity_pps);
  return pwm_threshold_pps > 0 && pwm_gradient != 0 && speed < pwm_threshold_pps;
}

}  // namespace motwin::motion
