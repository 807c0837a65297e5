#include "core/motion/pi_regulator.h"

#include <cmath>

namespace motwin::motion {
namespace {

// The integral term alone stays within the limit; the sum also fits the 32-bit AP.
int64_t bounded_sum(const PiConfig& config, const PiScale& scale, int64_t sum, float limit) {
  if (config.i <= 0) return 0;
  // The common case, without the division below.
  const double integral = static_cast<double>(config.i) * scale.integral * static_cast<double>(sum);
  if (integral <= limit && integral >= -limit && sum <= 2147483647 && sum >= -2147483647) return sum;
  double max_sum = static_cast<double>(limit) / (static_cast<double>(config.i) * scale.integral);
  if (max_sum > 2147483647.0) max_sum = 2147483647.0;
  const auto bound = static_cast<int64_t>(max_sum);
  if (sum > bound) return bound;
  if (sum < -bound) return -bound;
  return sum;
}

float clamp(float value, float limit) { return value > limit ? limit : (value < -limit ? -limit : value); }

}  // namespace

float pi_apply(const PiConfig& config, const PiScale& scale, PiState& state, int32_t error, float limit) {
  state.error = error;
  const int64_t previous = config.i == 0 ? 0 : state.error_sum;
  int64_t sum = previous + error;
  float output = pi_output(config, scale, sum, error);
  const bool limited = output > limit || output < -limit;
  if (limited) {
    // Integrate only if this tick's error pulls the output back from the limit.
    if (error != 0 && (output > 0.0f) == (error > 0)) sum = previous;
    output = clamp(pi_output(config, scale, sum, error), limit);
  }
  state.error_sum = static_cast<int32_t>(bounded_sum(config, scale, sum, limit));
  state.output = output;
  state.limited = limited;
  return output;
}

void pi_apply_vector(const PiConfig& config, const PiScale& scale, PiState& d, PiState& q, int32_t error_d,
                     int32_t error_q, float limit) {
  d.error = error_d;
  q.error = error_q;
  const int64_t previous_d = config.i == 0 ? 0 : d.error_sum;
  const int64_t previous_q = config.i == 0 ? 0 : q.error_sum;
  int64_t sum_d = previous_d + error_d;
  int64_t sum_q = previous_q + error_q;
  float vd = pi_output(config, scale, sum_d, error_d);
  float vq = pi_output(config, scale, sum_q, error_q);
  const bool limited = vd * vd + vq * vq > limit * limit;
  if (limited) {
    if (static_cast<float>(error_d) * vd > 0.0f) sum_d = previous_d;
    if (static_cast<float>(error_q) * vq > 0.0f) sum_q = previous_q;
    vd = pi_output(config, scale, sum_d, error_d);
    vq = pi_output(config, scale, sum_q, error_q);
    const float magnitude = std::sqrt(vd * vd + vq * vq);
    if (magnitude > limit && magnitude > 0.0f) {
      const float shrink = limit / magnitude;
      vd *= shrink;
      vq *= shrink;
    }
  }
  d.error_sum = static_cast<int32_t>(bounded_sum(config, scale, sum_d, limit));
  q.error_sum = static_cast<int32_t>(bounded_sum(config, scale, sum_q, limit));
  d.output = vd;
  q.output = vq;
  d.limited = limited;
  q.limited = limited;
}

}  // namespace motwin::motion
