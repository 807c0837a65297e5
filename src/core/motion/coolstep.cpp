#include "core/motion/coolstep.h"

namespace motwin::motion {
namespace {

constexpr uint8_t kMaxScale = 31;
// 209B SEUP: scale steps added per low measurement; 2099 SEDN: high measurements per decrement.
constexpr uint8_t kUpSteps[4] = {1, 2, 4, 8};
constexpr uint8_t kDownMeasurements[4] = {32, 8, 2, 1};

uint32_t magnitude(int32_t v) { return v < 0 ? 0u - static_cast<uint32_t>(v) : static_cast<uint32_t>(v); }

}  // namespace

uint8_t CoolStep::minimum_scale(const CoolStepConfig& config) {
  const uint8_t run = config.run_current_scale > kMaxScale ? kMaxScale : config.run_current_scale;
  const int shift = config.minimum_current != 0 ? 2 : 1;
  const int minimum = ((run + 1) >> shift) - 1;
  return static_cast<uint8_t>(minimum < 0 ? 0 : minimum);
}

uint8_t CoolStep::step(const CoolStepConfig& config, const CoolStepInputs& inputs) {
  const uint8_t run = config.run_current_scale > kMaxScale ? kMaxScale : config.run_current_scale;
  const bool enabled = config.hysteresis_start != 0 && !inputs.stealth_chop;
  // Above the threshold speed only; at 20A5 = 0 whenever the axis moves (StallGuard2 needs motion).
  const bool fast_enough = magnitude(inputs.velocity_pps) > config.threshold_velocity_pps;
  if (!enabled || !fast_enough) {
    // Outside its range the driver runs at the run current; on re-entry it starts from there.
    active_ = false;
    current_scale_ = run;
    high_measurements_ = 0;
    return current_scale_;
  }
  if (!active_) {
    active_ = true;
    current_scale_ = run;
    high_measurements_ = 0;
  }
  const uint8_t floor_scale = minimum_scale(config);
  if (current_scale_ > run) current_scale_ = run;  // the run current was lowered meanwhile
  if (current_scale_ < floor_scale) current_scale_ = floor_scale;
  if (!inputs.new_measurement) return current_scale_;

  const uint16_t sg = inputs.stallguard2_result;
  if (sg < config.lower_threshold()) {
    // Rising load: more current at once, by SEUP steps per measurement.
    high_measurements_ = 0;
    const int raised = current_scale_ + kUpSteps[config.up_step & 3u];
    current_scale_ = static_cast<uint8_t>(raised > run ? run : raised);
  } else if (sg >= config.upper_threshold()) {
    // Light load: one step less after SEDN such measurements in a row.
    if (++high_measurements_ >= kDownMeasurements[config.down_step & 3u]) {
      high_measurements_ = 0;
      if (current_scale_ > floor_scale) --current_scale_;
    }
  } else {
    high_measurements_ = 0;  // within the hysteresis band: hold
  }
  return current_scale_;
}

int32_t CoolStep::scaled_current_ma(const CoolStepConfig& config, int32_t run_current_ma) const {
  const uint8_t run = config.run_current_scale > kMaxScale ? kMaxScale : config.run_current_scale;
  const uint8_t scale = current_scale_ > run ? run : current_scale_;
  return static_cast<int32_t>(static_cast<int64_t>(run_current_ma) * (scale + 1) / (run + 1));
}

void CoolStep::reset() {
  active_ = false;
  current_scale_ = kMaxScale;
  high_measurements_ = 0;
}

}  // namespace motwin::motion
