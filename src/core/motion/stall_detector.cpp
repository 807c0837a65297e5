#include "core/motion/stall_detector.h"

namespace motwin::motion {
namespace {

uint32_t magnitude(int32_t v) { return v < 0 ? 0u - static_cast<uint32_t>(v) : static_cast<uint32_t>(v); }

}  // namespace

bool StallDetector::step(const StallDetectorConfig& config, const StallDetectorInputs& inputs) {
  if (stalled_ || !inputs.new_measurement || config.stop_velocity_pps == 0) return false;
  // "Below this speed the motor is not stopped. Above this speed ..." (manual 4.2.37): strictly above.
  if (magnitude(inputs.velocity_pps) <= config.stop_velocity_pps) return false;
  const bool at_limit = inputs.stealth_chop
                            ? inputs.stallguard4_result < config.stallguard4_threshold
                            : inputs.stallguard2_result == 0;
  if (!at_limit) return false;
  stalled_ = true;
  stall_velocity_pps_ = inputs.velocity_pps;
  return true;
}

}  // namespace motwin::motion
