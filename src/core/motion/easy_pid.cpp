#include "core/motion/easy_pid.h"

namespace motwin::motion {
namespace {

int64_t clip(int64_t value, int64_t limit) {
  if (value > limit) return limit;
  if (value < -limit) return -limit;
  return value;
}

}  // namespace

int32_t EasyPid::step(const EasyPidConfig& config, EasyPidState& state, int64_t encoder_minus_actual,
                      int32_t samples_per_tick, uint32_t d_ticks) {
  const auto error = static_cast<int32_t>(clip(encoder_minus_actual, kErrorClip));
  state.error = error;
  const int64_t sum_limit = static_cast<int64_t>(config.i_clip) << 16;
  state.error_sum = clip(state.error_sum + static_cast<int64_t>(error) * samples_per_tick, sum_limit);
  if (++state.ticks_since_d >= (d_ticks == 0 ? 1u : d_ticks)) {
    state.ticks_since_d = 0;
    const int64_t delta = clip(static_cast<int64_t>(state.last_d_error) - error, kDeltaClip);
    state.last_d_error = error;
    state.d_part = static_cast<int32_t>(clip(delta * config.d, INT32_MAX));
  }
  const int64_t p_part = -static_cast<int64_t>(error) * config.p / 256;
  const int64_t i_part = -state.error_sum * config.i / 65536;
  const int64_t result = p_part + i_part + state.d_part;
  state.correction = static_cast<int32_t>(clip(result, config.velocity_clip));
  return state.correction;
}

}  // namespace motwin::motion
