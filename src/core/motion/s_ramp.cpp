#include "core/motion/s_ramp.h"

#include <cmath>

namespace motwin::motion {
namespace detail {

// The limits of one velocity change. An "accelerating" change moves |v| away from zero (AMAX,
// bows 0 and 1), a "decelerating" one towards zero (DMAX, bows 2 and 3). Inverse jerks: 0 is an
// unlimited jerk (a trapezoid corner).
struct ChangeLimits {
  double peak;              // largest |acceleration|
  double inverse_build;     // raising |acceleration| in the direction of the change
  double inverse_reduce;    // lowering it again (also when it is above the peak)
  double inverse_opposing;  // removing an acceleration against the change first
};

// A velocity change as at most four linear pieces of acceleration, in the frame of the change
// (frame acceleration = sign x acceleration): the opposing acceleration to 0, up (or down) to
// the peak, a hold at the peak, back to 0, arriving at the goal velocity.
struct ChangePlan {
  double sign = 1.0;
  double goal = 0.0;  // velocity at the end
  double peak = 0.0;  // frame acceleration held
  double opposing_s = 0.0;
  double to_peak_s = 0.0;
  double hold_s = 0.0;
  double to_zero_s = 0.0;
  bool exact = true;  // false: the forced peak was too high for the change (no hold left)
  double total_s() const { return opposing_s + to_peak_s + hold_s + to_zero_s; }
};

}  // namespace detail

namespace {

using detail::ChangeLimits;
using detail::ChangePlan;

constexpr double kQ32 = 4294967296.0;
// How far (µsteps) a stop's planned end may be from the target: far above the rounding of the
// plans, far below anything a position counter shows.
constexpr double kArrivalTolerance = 1e-6;

double sign_of(double value) { return value > 0.0 ? 1.0 : (value < 0.0 ? -1.0 : 0.0); }

// Motion over part of a tick: distance travelled, velocity and acceleration (µsteps, /s, /s²).
struct Kinematics {
  double distance;
  double velocity;
  double acceleration;
};

// inverse_bow: 1 / bow (0 for an unlimited bow), cached by the ramp.
ChangeLimits limits_for(const SRampConfig& config, const double* inverse_bow, bool accelerating) {
  if (accelerating) return ChangeLimits{config.acceleration, inverse_bow[0], inverse_bow[1], inverse_bow[3]};
  const double deceleration = config.deceleration > 0.0 ? config.deceleration : config.acceleration;
  return ChangeLimits{deceleration, inverse_bow[2], inverse_bow[3], inverse_bow[1]};
}

// The next velocity to aim for on the way to `wanted`: zero first if the sign changes.
double stage_goal(double velocity, double wanted) {
  return velocity * wanted < 0.0 ? 0.0 : wanted;
}

bool is_accelerating_change(double velocity, double goal) {
  return std::fabs(goal) >= std::fabs(velocity);
}

// Plans the change from (velocity, acceleration) to `goal` with acceleration 0. forced_peak >= 0
// replaces the largest feasible peak (braking onto a target with a gentler deceleration).
ChangePlan plan_change(double velocity, double acceleration, double goal, const ChangeLimits& limits,
                       double forced_peak = -1.0) {
  ChangePlan plan;
  plan.goal = goal;
  const double change = goal - velocity;
  plan.sign = change != 0.0 ? sign_of(change) : (acceleration > 0.0 ? -1.0 : 1.0);
  const double needed = plan.sign * change;  // >= 0
  const double start = plan.sign * acceleration;
  const double opposing = start < 0.0 ? start : 0.0;
  const double along = start > 0.0 ? start : 0.0;
  plan.opposing_s = -opposing * limits.inverse_opposing;
  // Velocity gained by ramping from the start to a peak p (>= along) and back to 0 without a
  // hold: p² (kb + kr) / 2 - base.
  const double base = along * along * limits.inverse_build * 0.5 + opposing * opposing * limits.inverse_opposing * 0.5;
  const double curvature = 0.5 * (limits.inverse_build + limits.inverse_reduce);
  const double natural = along * along * limits.inverse_reduce * 0.5;  // just removing `along`
  if (needed <= natural && along > 0.0) {
    // Even removing the acceleration at once reaches the goal: remove it so that the goal is met
    // (a steeper reduction than the bow only when the goal was moved into the reduction).
    plan.peak = along;
    plan.to_peak_s = 0.0;
    plan.to_zero_s = needed > 0.0 ? 2.0 * needed / along : 0.0;
    return plan;
  }
  double peak = forced_peak >= 0.0 ? forced_peak : limits.peak;
  if (forced_peak < 0.0 && curvature > 0.0) {
    const double unlimited = std::sqrt((needed + base) / curvature);
    if (unlimited < peak) peak = unlimited;
  }
  if (peak <= 0.0) {
    // No acceleration allowed (AMAX or DMAX 0): the velocity stays, the acceleration drops.
    plan.goal = velocity;
    plan.peak = 0.0;
    plan.opposing_s = 0.0;
    return plan;
  }
  plan.peak = peak;
  double gained = 0.0;
  if (peak >= along) {
    plan.to_peak_s = (peak - along) * limits.inverse_build;
    gained = peak * peak * curvature - base;
  } else {
    plan.to_peak_s = (along - peak) * limits.inverse_reduce;
    gained = natural - opposing * opposing * limits.inverse_opposing * 0.5;
  }
  const double hold = (needed - gained) / peak;
  plan.hold_s = hold > 0.0 ? hold : 0.0;
  plan.exact = hold > -1e-9;
  plan.to_zero_s = peak * limits.inverse_reduce;
  return plan;
}

// Moves the acceleration linearly to `to` over `duration`, for at most `time_left` of it;
// whether the piece was completed (a piece of no duration, an unlimited jerk, always is).
bool run_piece(Kinematics& k, double to, double duration, double& time_left) {
  if (duration <= 0.0) {
    k.acceleration = to;
    return true;
  }
  if (time_left <= 0.0) return false;
  const bool completes = duration <= time_left;
  const double t = completes ? duration : time_left;
  const double jerk = (to - k.acceleration) / duration;
  k.distance += t * (k.velocity + t * (0.5 * k.acceleration + t * jerk * (1.0 / 6.0)));
  k.velocity += t * (k.acceleration + 0.5 * jerk * t);
  k.acceleration = completes ? to : k.acceleration + jerk * t;
  time_left -= t;
  return completes;
}

// Follows a plan for `time_s` (a very large time runs it to its end); at its end the velocity
// is exactly the goal.
Kinematics follow(const ChangePlan& plan, double velocity, double acceleration, double time_s) {
  Kinematics k{0.0, velocity, acceleration};
  double left = time_s;
  const bool done = (plan.sign * acceleration >= 0.0 || run_piece(k, 0.0, plan.opposing_s, left)) &&
                    run_piece(k, plan.sign * plan.peak, plan.to_peak_s, left) &&
                    run_piece(k, plan.sign * plan.peak, plan.hold_s, left) && run_piece(k, 0.0, plan.to_zero_s, left);
  if (done) {
    k.velocity = plan.goal;
    k.acceleration = 0.0;
    k.distance += plan.goal * left;
  }
  return k;
}

constexpr double kToEnd = 1e30;

// Braking to rest with the deceleration limits.
ChangePlan plan_stop(double velocity, double acceleration, const ChangeLimits& limits, double forced_peak = -1.0) {
  return plan_change(velocity, acceleration, 0.0, limits, forced_peak);
}

// Distance to rest along a stop plan, in the direction of motion (>= 0 normally).
double stop_distance(const ChangePlan& plan, double velocity, double acceleration, double direction) {
  return direction * follow(plan, velocity, acceleration, kToEnd).distance;
}

}  // namespace

void SRamp::set_position(int32_t position) {
  position_q32_ = static_cast<uint64_t>(static_cast<uint32_t>(position)) << kFractionBits;
  if (mode_ == Mode::kPosition) target_position_ = position;
  braking_ = false;
}

void SRamp::set_position_target(int32_t target) {
  if (mode_ != Mode::kPosition || target != target_position_) braking_ = false;
  mode_ = Mode::kPosition;
  target_position_ = target;
}

void SRamp::stop_now() {
  velocity_ = 0.0;
  acceleration_ = 0.0;
  braking_ = false;
  if (mode_ == Mode::kPosition) {
    // Round the position to the nearest microstep and make it the target.
    position_q32_ = (position_q32_ + (uint64_t{1} << (kFractionBits - 1))) & ~((uint64_t{1} << kFractionBits) - 1);
    target_position_ = position();
  } else if (mode_ == Mode::kVelocity) {
    target_velocity_ = 0.0;
  }
}

double SRamp::distance_to_target() const {
  const uint64_t target_q32 = static_cast<uint64_t>(static_cast<uint32_t>(target_position_)) << kFractionBits;
  return static_cast<double>(static_cast<int64_t>(target_q32 - position_q32_)) / kQ32;
}

bool SRamp::position_reached() const {
  return mode_ == Mode::kPosition && velocity_ == 0.0 &&
         position_q32_ == static_cast<uint64_t>(static_cast<uint32_t>(target_position_)) << kFractionBits;
}

bool SRamp::velocity_reached() const {
  switch (mode_) {
    case Mode::kVelocity: {
      const double wanted = target_velocity_ > velocity_limit_
                                ? velocity_limit_
                                : (target_velocity_ < -velocity_limit_ ? -velocity_limit_ : target_velocity_);
      return velocity_ == wanted && acceleration_ == 0.0;
    }
    case Mode::kPosition:
      return (std::fabs(velocity_) == velocity_limit_ && acceleration_ == 0.0) || position_reached();
    case Mode::kHold:
      return true;
  }
  return false;
}

void SRamp::step(const SRampConfig& config, double dt_s) {
  velocity_limit_ = config.max_velocity;
  for (int i = 0; i < 4; ++i) {
    if (config.bow[i] != cached_bow_[i]) {
      cached_bow_[i] = config.bow[i];
      inverse_bow_[i] = config.bow[i] > 0.0 ? 1.0 / config.bow[i] : 0.0;
    }
  }
  switch (mode_) {
    case Mode::kVelocity: {
      const double wanted = target_velocity_ > config.max_velocity
                                ? config.max_velocity
                                : (target_velocity_ < -config.max_velocity ? -config.max_velocity : target_velocity_);
      step_velocity(config, wanted, dt_s);
      break;
    }
    case Mode::kPosition:
      step_position(config, dt_s);
      break;
    case Mode::kHold:
      acceleration_ = 0.0;
      advance(velocity_ * dt_s);
      break;
  }
}

void SRamp::step_velocity(const SRampConfig& config, double wanted_velocity, double dt_s) {
  if (velocity_ == wanted_velocity && acceleration_ == 0.0) {
    advance(velocity_ * dt_s);
    return;
  }
  const double goal = stage_goal(velocity_, wanted_velocity);
  const ChangePlan plan = plan_change(velocity_, acceleration_, goal,
                                      limits_for(config, inverse_bow_, is_accelerating_change(velocity_, goal)));
  const Kinematics k = follow(plan, velocity_, acceleration_, dt_s);
  velocity_ = k.velocity;
  acceleration_ = k.acceleration;
  advance(k.distance);
}

void SRamp::step_position(const SRampConfig& config, double dt_s) {
  const double distance = distance_to_target();
  if (distance == 0.0 && velocity_ == 0.0 && acceleration_ == 0.0) {
    braking_ = false;
    return;
  }
  // Direction towards the target (of the motion when on it).
  const double direction = distance != 0.0 ? sign_of(distance)
                                           : (velocity_ != 0.0 ? sign_of(velocity_) : sign_of(acceleration_));
  const double ahead = direction * distance;  // >= 0
  const double cruise = direction * config.max_velocity;
  if (direction * velocity_ < 0.0 || (velocity_ == 0.0 && direction * acceleration_ < 0.0)) {
    // Moving away (after a target change): stop and turn round, with the velocity-mode profile.
    braking_ = false;
    step_velocity(config, cruise, dt_s);
    return;
  }
  const ChangeLimits stop_limits = limits_for(config, inverse_bow_, false);
  // Rounding in the plans is far below this; a stop within it still ends on the target.
  const double tolerance = kArrivalTolerance + 1e-12 * ahead;
  if (braking_ && braking_peak_ <= stop_limits.peak) {
    // Usually the last tick's stop still ends on the target: follow it.
    const ChangePlan plan = plan_stop(velocity_, acceleration_, stop_limits, braking_peak_);
    if (plan.exact && std::fabs(stop_distance(plan, velocity_, acceleration_, direction) - ahead) <= tolerance) {
      follow_stop(plan, ahead, direction, dt_s);
      return;
    }
  }
  if (!braking_) {
    // Keep heading for VMAX if the axis can still stop in time after this tick.
    Kinematics k{velocity_ * dt_s, velocity_, 0.0};
    double then_stop_distance = 0.0;
    if (velocity_ == cruise && acceleration_ == 0.0) {
      // Cruising: the stop from VMAX is the same every tick until VMAX or the limits change.
      if (cruise_stop_key_[0] != velocity_ || cruise_stop_key_[1] != stop_limits.peak ||
          cruise_stop_key_[2] != stop_limits.inverse_build || cruise_stop_key_[3] != stop_limits.inverse_reduce) {
        cruise_stop_key_[0] = velocity_;
        cruise_stop_key_[1] = stop_limits.peak;
        cruise_stop_key_[2] = stop_limits.inverse_build;
        cruise_stop_key_[3] = stop_limits.inverse_reduce;
        cruise_stop_distance_ = stop_distance(plan_stop(velocity_, 0.0, stop_limits), velocity_, 0.0, direction);
      }
      then_stop_distance = cruise_stop_distance_;
    } else {
      const double goal = stage_goal(velocity_, cruise);
      const ChangePlan plan = plan_change(velocity_, acceleration_, goal,
                                          limits_for(config, inverse_bow_, is_accelerating_change(velocity_, goal)));
      k = follow(plan, velocity_, acceleration_, dt_s);
      then_stop_distance =
          stop_distance(plan_stop(k.velocity, k.acceleration, stop_limits), k.velocity, k.acceleration, direction);
    }
    const double needed = direction * k.distance + then_stop_distance;
    if (needed <= ahead) {
      velocity_ = k.velocity;
      acceleration_ = k.acceleration;
      advance(k.distance);
      return;
    }
  }
  const ChangePlan fastest_stop = plan_stop(velocity_, acceleration_, stop_limits);
  const double shortest_stop = stop_distance(fastest_stop, velocity_, acceleration_, direction);
  if (shortest_stop > ahead + tolerance) {
    // The target came too close to stop on (or DMAX or a bow changed while braking): brake as
    // hard as allowed, stop past the target and come back.
    braking_ = false;
    step_velocity(config, 0.0, dt_s);
    return;
  }
  // Braking onto the target: the gentlest peak deceleration (<= the fastest stop's) whose stop
  // ends exactly there.
  braking_ = true;
  braking_peak_ = braking_peak(stop_limits, fastest_stop.peak, shortest_stop, ahead, direction, tolerance);
  follow_stop(plan_stop(velocity_, acceleration_, stop_limits, braking_peak_), ahead, direction, dt_s);
}

void SRamp::follow_stop(const detail::ChangePlan& plan, double ahead, double direction, double dt_s) {
  if (plan.total_s() <= dt_s) {
    arrive();  // the stop ends within this tick
    return;
  }
  const Kinematics k = follow(plan, velocity_, acceleration_, dt_s);
  velocity_ = k.velocity;
  acceleration_ = k.acceleration;
  if (ahead - direction * k.distance <= kArrivalTolerance) {
    // The last tail of the stop is shorter than the plan's rounding (a slow stop's final ticks
    // move by less than 1e-6 µstep): the position stays on the target while the velocity and
    // acceleration finish their S-curve, so that it is neither passed nor left with a jerk.
    position_q32_ = static_cast<uint64_t>(static_cast<uint32_t>(target_position_)) << kFractionBits;
    return;
  }
  advance(k.distance);
}

double SRamp::braking_peak(const detail::ChangeLimits& limits, double highest, double shortest_stop, double ahead,
                           double direction, double tolerance) const {
  if (shortest_stop >= ahead - tolerance || highest <= 0.0) return highest;
  // Excess stopping distance at a peak (falls as the peak rises).
  auto excess = [&](double peak) {
    return stop_distance(plan_stop(velocity_, acceleration_, limits, peak), velocity_, acceleration_, direction) -
           ahead;
  };
  // Halve from the highest peak until the stop is too long.
  double high = highest;
  double high_excess = shortest_stop - ahead;  // < 0
  double low = high;
  double low_excess = high_excess;
  for (int i = 0; i < 64 && low_excess <= 0.0; ++i) {
    high = low;
    high_excess = low_excess;
    low *= 0.5;
    low_excess = excess(low);
  }
  if (low_excess <= 0.0) return highest;
  // Regula falsi (Illinois) on [low, high]: excess(low) > 0 > excess(high).
  int retained_side = 0;
  for (int i = 0; i < 100; ++i) {
    const double peak = (low * high_excess - high * low_excess) / (high_excess - low_excess);
    const double value = excess(peak);
    if (std::fabs(value) <= tolerance || high - low <= 1e-15 * high) return peak;
    if (value > 0.0) {
      low = peak;
      low_excess = value;
      if (retained_side == 1) high_excess *= 0.5;
      retained_side = 1;
    } else {
      high = peak;
      high_excess = value;
      if (retained_side == -1) low_excess *= 0.5;
      retained_side = -1;
    }
  }
  return 0.5 * (low + high);
}

void SRamp::arrive() {
  position_q32_ = static_cast<uint64_t>(static_cast<uint32_t>(target_position_)) << kFractionBits;
  velocity_ = 0.0;
  acceleration_ = 0.0;
  braking_ = false;
}

void SRamp::advance(double distance) {
  position_q32_ += static_cast<uint64_t>(std::llround(distance * kQ32));
}

}  // namespace motwin::motion
