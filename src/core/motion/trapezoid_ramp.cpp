#include "core/motion/trapezoid_ramp.h"

#include <cmath>

namespace motwin::motion {
namespace {

constexpr double kQ16 = 65536.0;

double clamp(double v, double lo, double hi) { return v < lo ? lo : (v > hi ? hi : v); }

// Moves `current` towards `target` by at most `max_change`.
double approach(double current, double target, double max_change) {
  if (current < target) return current + max_change < target ? current + max_change : target;
  return current - max_change > target ? current - max_change : target;
}

}  // namespace

void TrapezoidRamp::set_position(int32_t position) {
  position_q16_ = static_cast<int64_t>(position) * static_cast<int64_t>(kQ16);
  if (mode_ == Mode::kPosition) target_position_ = position;
}

double TrapezoidRamp::distance_to_target() const {
  const int64_t target_q16 = static_cast<int64_t>(target_position_) * static_cast<int64_t>(kQ16);
  // Both wrap at 2^48 in Q16; take the difference modulo 2^48 as a signed value.
  constexpr int kWrapBits = 32 + kFractionBits;
  const uint64_t mask = (uint64_t{1} << kWrapBits) - 1;
  uint64_t diff = static_cast<uint64_t>(target_q16 - position_q16_) & mask;
  int64_t signed_diff = static_cast<int64_t>(diff);
  if (diff >= (uint64_t{1} << (kWrapBits - 1))) signed_diff -= static_cast<int64_t>(uint64_t{1} << kWrapBits);
  return static_cast<double>(signed_diff) / kQ16;
}

void TrapezoidRamp::step(const TrapezoidRampConfig& config, double dt_s) {
  if (mode_ == Mode::kVelocity) {
    step_velocity_mode(config, dt_s);
  } else {
    step_position_mode(config, dt_s);
  }
}

void TrapezoidRamp::step_velocity_mode(const TrapezoidRampConfig& config, double dt_s) {
  const double wanted = clamp(target_velocity_, -config.max_velocity, config.max_velocity);
  const double previous = velocity_;
  velocity_ = config.ramp_enabled ? approach(velocity_, wanted, config.acceleration * dt_s) : wanted;
  advance(previous, dt_s);
}

void TrapezoidRamp::step_position_mode(const TrapezoidRampConfig& config, double dt_s) {
  const double distance = distance_to_target();
  if (distance == 0.0 && (velocity_ == 0.0 || !config.ramp_enabled)) {
    velocity_ = 0.0;
    return;
  }
  const double direction = distance > 0.0 ? 1.0 : (distance < 0.0 ? -1.0 : 0.0);
  const double max_change = config.acceleration * dt_s;
  const double previous = velocity_;
  bool on_braking_curve = false;
  if (!config.ramp_enabled) {
    velocity_ = direction * config.max_velocity;
  } else {
    // Fastest speed from which the axis can still stop at the target.
    const double stopping_speed = std::sqrt(2.0 * config.acceleration * std::fabs(distance));
    const double wanted = direction * (stopping_speed < config.max_velocity ? stopping_speed : config.max_velocity);
    const bool moving_towards_target = velocity_ * direction > 0.0;
    // Accelerating ends up to a tick past the braking point; within a few ticks' worth of
    // velocity the axis joins the braking curve at once, so it arrives without overshoot.
    const double join_tolerance = 3.0 * max_change + 1e-9;
    if (moving_towards_target && std::fabs(velocity_) > std::fabs(wanted) &&
        std::fabs(velocity_) - join_tolerance <= std::fabs(wanted)) {
      velocity_ = wanted;
      on_braking_curve = true;
    } else {
      // Accelerating, or too fast to stop in time after a target change: the deceleration
      // stays limited, the axis overshoots and comes back.
      velocity_ = approach(velocity_, wanted, max_change);
    }
  }
  const double step_distance = 0.5 * (previous + velocity_) * dt_s;
  const bool arrives = step_distance * direction > 0.0 && std::fabs(step_distance) >= std::fabs(distance);
  const bool slow_enough =
      !config.ramp_enabled || on_braking_curve || std::fabs(velocity_) <= 2.0 * max_change + 1e-9;
  if (arrives && slow_enough) {
    // distance is exact (a Q16 difference), so this lands exactly on the target while keeping
    // the wrap count of the counter.
    position_q16_ += static_cast<int64_t>(std::llround(distance * kQ16));
    velocity_ = 0.0;
    return;
  }
  advance(previous, dt_s);
}

// Trapezoidal integration: exact for the piecewise-constant acceleration of the ramp.
void TrapezoidRamp::advance(double previous_velocity, double dt_s) {
  position_q16_ += static_cast<int64_t>(std::llround(0.5 * (previous_velocity + velocity_) * dt_s * kQ16));
}

}  // namespace motwin::motion
