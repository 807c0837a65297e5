// CoolStep (SmartEnergy): load-adaptive current scaling from the StallGuard2 load value, the
// regulation a TMC5160-class driver runs once per StallGuard2 measurement (TMCM-3216 manual
// 1.4.2 and 4.1, objects 2098..209C, 20A5; docs/tmcm-3216-drive.md "CoolStep (2098..209C, 20A5)").
//
// The current is held as the driver's 5-bit current scale CS (0..31, the run current 2003 / 8):
// the run scale is the ceiling, 1/2 or 1/4 of it (2098) the floor. For each measurement below
// SEMIN x 32 (209C) the scale rises by SEUP steps (209B: 1, 2, 4, 8); after SEDN measurements
// (2099: 32, 8, 2, 1) at or above (SEMIN + SEMAX + 1) x 32 (209A) in a row it falls by one.
// CoolStep acts only while the speed is above the threshold 20A5 and the chopper is SpreadCycle
// (StallGuard2 is not measured in StealthChop); SEMIN = 0 disables it. Inactive, the scale is the
// run scale. The current applied is run current x (scale + 1) / (run scale + 1).
#pragma once

#include <cstdint>

namespace motwin::motion {

struct CoolStepConfig {
  uint8_t run_current_scale = 31;     // CS 0..31: object 2003 / 8 (current_scale_of())
  uint8_t minimum_current = 0;        // 2098 SEIMIN: 0 = 1/2, 1 = 1/4 of the run scale
  uint8_t down_step = 0;              // 2099 SEDN 0..3: 32, 8, 2, 1 measurements per decrement
  uint8_t hysteresis = 0;             // 209A SEMAX 0..15
  uint8_t up_step = 0;                // 209B SEUP 0..3: +1, +2, +4, +8 per measurement
  uint8_t hysteresis_start = 0;       // 209C SEMIN 0..15; 0 disables CoolStep
  uint32_t threshold_velocity_pps = 0;  // 20A5, microsteps/s: active when |velocity| is above it

  // The lower StallGuard2 threshold SEMIN x 32 and the upper one (SEMIN + SEMAX + 1) x 32.
  uint16_t lower_threshold() const { return static_cast<uint16_t>(hysteresis_start * 32u); }
  uint16_t upper_threshold() const { return static_cast<uint16_t>((hysteresis_start + hysteresis + 1u) * 32u); }
};

// What the regulation sees each tick.
struct CoolStepInputs {
  int32_t velocity_pps = 0;         // actual (ramp) velocity, microsteps/s
  uint16_t stallguard2_result = 0;  // 0..1023, the driver's latest SG_RESULT
  bool new_measurement = false;     // the driver produced a new result since the last tick
  bool stealth_chop = false;        // chopper in StealthChop: no StallGuard2, no CoolStep
};

class CoolStep {
 public:
  // The 5-bit current scale of a 0..255 current object (2003): "adjusted in 32 steps".
  static constexpr uint8_t current_scale_of(uint8_t current_object) { return static_cast<uint8_t>(current_object >> 3); }
  // The lowest scale CoolStep may reach: (run + 1) / 2 or / 4, minus one (so the current ratio
  // is exactly 1/2 or 1/4 for run scale 31), at least 0.
  static uint8_t minimum_scale(const CoolStepConfig& config);

  // Once per control tick. Returns the current scale to apply now.
  uint8_t step(const CoolStepConfig& config, const CoolStepInputs& inputs);

  bool active() const { return active_; }
  uint8_t current_scale() const { return current_scale_; }  // CSACTUAL 0..31
  // run_current_ma x (scale + 1) / (run scale + 1): the current the driver applies (rounded down).
  int32_t scaled_current_ma(const CoolStepConfig& config, int32_t run_current_ma) const;
  // Back to the run scale (driver disabled, parameters reloaded).
  void reset();

 private:
  bool active_ = false;
  uint8_t current_scale_ = 31;
  uint8_t high_measurements_ = 0;  // consecutive results at or above the upper threshold
};

}  // namespace motwin::motion
