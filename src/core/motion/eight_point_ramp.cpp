#include "core/motion/eight_point_ramp.h"

#include <cmath>

namespace motwin::motion {
namespace {

using Segment = EightPointRamp::Segment;

constexpr double kQ32 = 4294967296.0;
constexpr double kInfinity = HUGE_VAL;
// Numerical slack of the braking-curve join: the ramp is at or below the curve at the start of
// every tick, so one tick of the segment's deceleration always suffices up to rounding.
constexpr double kRelativeSlack = 1e-6;

double sign_of(double value) { return value > 0.0 ? 1.0 : (value < 0.0 ? -1.0 : 0.0); }
double min_of(double a, double b) { return a < b ? a : b; }
double max_of(double a, double b) { return a > b ? a : b; }

// One band of the profile: the acceleration (or deceleration) used in it, the speed where it ends
// and its name. Accelerating, a band holds speeds [below its top); decelerating (bands_below),
// speeds (above its bottom]; so a speed exactly at V1 accelerates with A2 and decelerates with D1.
struct Band {
  double rate_pps2;
  double edge_pps;  // accelerating: the top; decelerating: the bottom
  Segment segment;
};

// The acceleration band that governs speeds just above `speed_pps` (manual 1.5: A1 below V1,
// A2 below V2, AMAX above; a boundary set to 0 switches its band off).
Band acceleration_band(const EightPointConfig& config, double speed_pps) {
  if (config.v1_pps > 0.0 && speed_pps < config.v1_pps) return {config.a1_pps2, config.v1_pps, Segment::kA1};
  if (config.v2_pps > 0.0 && speed_pps < config.v2_pps) return {config.a2_pps2, config.v2_pps, Segment::kA2};
  return {config.amax_pps2, kInfinity, Segment::kAmax};
}

// The deceleration band that governs speeds just below `speed_pps` (DMAX above V2, D2 down to
// V1, D1 below V1).
Band deceleration_band(const EightPointConfig& config, double speed_pps) {
  if (config.v1_pps > 0.0 && speed_pps <= config.v1_pps) return {config.d1_pps2, 0.0, Segment::kD1};
  if (config.v2_pps > 0.0 && speed_pps <= config.v2_pps) return {config.d2_pps2, config.v1_pps, Segment::kD2};
  return {config.dmax_pps2, max_of(config.v1_pps, config.v2_pps), Segment::kDmax};
}

// The deceleration band above a speed, for walking the braking curve upwards from VSTOP.
Band deceleration_band_above(const EightPointConfig& config, double speed_pps) {
  if (config.v1_pps > 0.0 && speed_pps < config.v1_pps) return {config.d1_pps2, config.v1_pps, Segment::kD1};
  if (config.v2_pps > 0.0 && speed_pps < config.v2_pps) return {config.d2_pps2, config.v2_pps, Segment::kD2};
  return {config.dmax_pps2, kInfinity, Segment::kDmax};
}

// Speed and distance after part of a tick, and the band the tick started in.
struct Motion {
  double speed_pps;
  double distance;  // µsteps along the direction of motion
  Segment segment;
};

// Raises the speed towards `ceiling_pps` through the A bands for dt_s; cruises for the rest.
Motion accelerate(const EightPointConfig& config, double speed_pps, double ceiling_pps, double dt_s) {
  Motion motion{speed_pps, 0.0, Segment::kCruise};
  bool first = true;
  while (dt_s > 0.0 && motion.speed_pps < ceiling_pps) {
    const Band band = acceleration_band(config, motion.speed_pps);
    if (band.rate_pps2 <= 0.0) break;
    if (first) motion.segment = band.segment;
    first = false;
    const double top = min_of(band.edge_pps, ceiling_pps);
    const double to_top_s = (top - motion.speed_pps) / band.rate_pps2;
    if (to_top_s >= dt_s) {
      // Never past the band's top: rate * dt_s can round above what to_top_s said.
      const double end = min_of(motion.speed_pps + band.rate_pps2 * dt_s, top);
      motion.distance += 0.5 * (motion.speed_pps + end) * dt_s;
      motion.speed_pps = end;
      return motion;
    }
    motion.distance += 0.5 * (motion.speed_pps + top) * to_top_s;
    motion.speed_pps = top;
    dt_s -= to_top_s;
  }
  motion.distance += motion.speed_pps * dt_s;
  return motion;
}

// Lowers the speed towards `floor_pps` through the D bands for dt_s; cruises for the rest.
Motion decelerate(const EightPointConfig& config, double speed_pps, double floor_pps, double dt_s) {
  Motion motion{speed_pps, 0.0, Segment::kCruise};
  bool first = true;
  while (dt_s > 0.0 && motion.speed_pps > floor_pps) {
    const Band band = deceleration_band(config, motion.speed_pps);
    if (band.rate_pps2 <= 0.0) break;
    if (first) motion.segment = band.segment;
    first = false;
    const double bottom = max_of(band.edge_pps, floor_pps);
    const double to_bottom_s = (motion.speed_pps - bottom) / band.rate_pps2;
    if (to_bottom_s >= dt_s) {
      // Never below the band's bottom: rate * dt_s can round above what to_bottom_s said, and
      // below a floor of 0 the speed would turn negative, the axis reversing without rest (found
      // by fuzzing: 100 pps at 100000 pps² in 1 ms ended at -3.6e-15 pps).
      const double end = max_of(motion.speed_pps - band.rate_pps2 * dt_s, bottom);
      motion.distance += 0.5 * (motion.speed_pps + end) * dt_s;
      motion.speed_pps = end;
      return motion;
    }
    motion.distance += 0.5 * (motion.speed_pps + bottom) * to_bottom_s;
    motion.speed_pps = bottom;
    dt_s -= to_bottom_s;
  }
  motion.distance += motion.speed_pps * dt_s;
  return motion;
}

// A constant-rate change towards `goal_pps` (velocity mode's AMAX, a stop's given deceleration).
Motion change_linearly(double speed_pps, double goal_pps, double rate_pps2, double dt_s, Segment segment) {
  if (speed_pps == goal_pps || rate_pps2 <= 0.0) return {speed_pps, speed_pps * dt_s, Segment::kCruise};
  const double to_goal_s = std::fabs(goal_pps - speed_pps) / rate_pps2;
  if (to_goal_s >= dt_s) {
    // Never past the goal (as decelerate(): rate * dt_s can round above to_goal_s's rate).
    const double step = speed_pps + sign_of(goal_pps - speed_pps) * rate_pps2 * dt_s;
    const double end = goal_pps > speed_pps ? min_of(step, goal_pps) : max_of(step, goal_pps);
    return {end, 0.5 * (speed_pps + end) * dt_s, segment};
  }
  return {goal_pps, 0.5 * (speed_pps + goal_pps) * to_goal_s + goal_pps * (dt_s - to_goal_s), segment};
}

// Distance to brake from `speed_pps` to VSTOP through the D bands (the stopping distance).
double stopping_distance(const EightPointConfig& config, double speed_pps) {
  double distance = 0.0;
  while (speed_pps > config.vstop_pps) {
    const Band band = deceleration_band(config, speed_pps);
    if (band.rate_pps2 <= 0.0) return kInfinity;
    const double bottom = max_of(band.edge_pps, config.vstop_pps);
    distance += (speed_pps * speed_pps - bottom * bottom) / (2.0 * band.rate_pps2);
    speed_pps = bottom;
  }
  return distance;
}

// The speed at which a tick that starts at `speed_pps`, `distance` before the target, ends on the
// braking curve: v = curve(distance - (speed + v) dt / 2). Solved band by band from VSTOP up
// (the first band whose solution lies below its top holds it). Below VSTOP: even ending the tick
// at VSTOP would reach the target, so the move ends in this tick.
double curve_speed_after_tick(const EightPointConfig& config, double distance, double speed_pps, double dt_s) {
  double base_speed = config.vstop_pps;
  double base_distance = 0.0;
  for (int guard = 0; guard < 4; ++guard) {
    const Band band = deceleration_band_above(config, base_speed);
    if (band.rate_pps2 <= 0.0) return kInfinity;  // no braking: treated as never needing to
    // v² + D dt v - (vb² + 2 D (d - Sb) - D dt s) = 0
    const double d_dt = band.rate_pps2 * dt_s;
    const double c = base_speed * base_speed + 2.0 * band.rate_pps2 * (distance - base_distance) - d_dt * speed_pps;
    const double discriminant = d_dt * d_dt + 4.0 * c;
    const double candidate = discriminant < 0.0 ? -1.0 : 0.5 * (-d_dt + std::sqrt(discriminant));
    if (candidate <= band.edge_pps) return candidate;
    base_distance += (band.edge_pps * band.edge_pps - base_speed * base_speed) / (2.0 * band.rate_pps2);
    base_speed = band.edge_pps;
  }
  return kInfinity;
}

// TVMAX: after this tick's `motion`, a cruise of TVMAX at its speed and the braking still fit
// into the `remaining` distance.
bool tvmax_fits(const EightPointConfig& config, const Motion& motion, double remaining, double tvmax_s) {
  return stopping_distance(config, motion.speed_pps) + motion.speed_pps * tvmax_s <= remaining - motion.distance;
}

// The tick for a move whose full acceleration (up to `too_fast_pps`) leaves no room for the TVMAX
// cruise: accelerates from `speed_pps` to the highest speed that leaves it (bisection; the
// distance grows with the speed), or holds the speed when even that does not fit. From rest this
// is always a speed > 0, so a short move starts and arrives.
Motion accelerate_within_tvmax(const EightPointConfig& config, double speed_pps, double too_fast_pps,
                               double remaining, double tvmax_s, double dt_s) {
  const Motion hold{speed_pps, speed_pps * dt_s, Segment::kCruise};
  if (!tvmax_fits(config, hold, remaining, tvmax_s)) return hold;
  Motion best = hold;
  double low = speed_pps;
  double high = too_fast_pps;
  for (int i = 0; i < 60 && high - low > 1e-12 * (1.0 + high); ++i) {
    const double middle = 0.5 * (low + high);
    const Motion motion = accelerate(config, speed_pps, middle, dt_s);
    if (tvmax_fits(config, motion, remaining, tvmax_s)) {
      best = motion;
      low = middle;
    } else {
      high = middle;
    }
  }
  return best;
}

// The highest speed at the start of a tick from which an axis that reaches its target in the tick
// comes to rest there: one tick of braking down to VSTOP (from where the ramp drops to 0; VSTART
// <= VSTOP), with the slack of the braking-curve join.
double arrival_speed_pps(const EightPointConfig& config, double speed_pps, double dt_s) {
  return config.vstop_pps + deceleration_band(config, speed_pps).rate_pps2 * dt_s * (1.0 + kRelativeSlack) +
         1e-9 * (1.0 + speed_pps);
}

bool valid_number(double value) { return value >= 0.0; }  // false for NaN too

}  // namespace

EightPointConfigError EightPointRamp::validate(const EightPointConfig& config, Mode mode) {
  const double values[] = {config.vstart_pps, config.a1_pps2, config.v1_pps,    config.a2_pps2,
                           config.v2_pps,     config.vmax_pps, config.amax_pps2, config.dmax_pps2,
                           config.d2_pps2,    config.d1_pps2, config.vstop_pps};
  for (double value : values) {
    if (!valid_number(value)) return EightPointConfigError::kNegativeOrNan;
  }
  if (config.amax_pps2 == 0.0) return EightPointConfigError::kZeroAmax;
  if (mode == Mode::kVelocity) return EightPointConfigError::kNone;
  if (config.dmax_pps2 == 0.0) return EightPointConfigError::kZeroDmax;
  if (config.d1_pps2 == 0.0) return EightPointConfigError::kZeroD1;
  if (config.d2_pps2 == 0.0) return EightPointConfigError::kZeroD2;
  if (config.v1_pps > 0.0 && config.a1_pps2 == 0.0) return EightPointConfigError::kZeroA1;
  if (config.v2_pps > 0.0 && config.a2_pps2 == 0.0) return EightPointConfigError::kZeroA2;
  if (config.v1_pps > 0.0 && config.v2_pps > 0.0 && config.v1_pps > config.v2_pps) {
    return EightPointConfigError::kV1AboveV2;
  }
  if (config.vstop_pps < config.vstart_pps) return EightPointConfigError::kVstopBelowVstart;
  return EightPointConfigError::kNone;
}

void EightPointRamp::set_position(int32_t position) {
  position_q32_ = static_cast<uint64_t>(static_cast<uint32_t>(position)) << kFractionBits;
  if (mode_ == Mode::kPosition) target_position_ = position;
}

void EightPointRamp::set_state(int32_t position, double velocity_pps) {
  position_q32_ = static_cast<uint64_t>(static_cast<uint32_t>(position)) << kFractionBits;
  velocity_pps_ = velocity_pps;
  if (velocity_pps != 0.0) wait_remaining_s_ = 0.0;
}

double EightPointRamp::distance_to_target() const {
  const uint64_t target_q32 = static_cast<uint64_t>(static_cast<uint32_t>(target_position_)) << kFractionBits;
  // The 64-bit difference wraps with the 32-bit counter: as signed, it is the shorter way round.
  return static_cast<double>(static_cast<int64_t>(target_q32 - position_q32_)) / kQ32;
}

bool EightPointRamp::position_reached() const {
  return mode_ == Mode::kPosition && velocity_pps_ == 0.0 &&
         position_q32_ == static_cast<uint64_t>(static_cast<uint32_t>(target_position_)) << kFractionBits;
}

bool EightPointRamp::velocity_reached() const {
  switch (mode_) {
    case Mode::kVelocity: {
      const double wanted = target_velocity_ > velocity_limit_pps_
                                ? velocity_limit_pps_
                                : (target_velocity_ < -velocity_limit_pps_ ? -velocity_limit_pps_ : target_velocity_);
      return velocity_pps_ == wanted;
    }
    case Mode::kPosition:
      return position_reached() || (velocity_pps_ != 0.0 && std::fabs(velocity_pps_) == velocity_limit_pps_);
    case Mode::kStop:
      return velocity_pps_ == 0.0;
  }
  return false;
}

void EightPointRamp::step(const EightPointConfig& config, double dt_s) {
  velocity_limit_pps_ = config.vmax_pps;
  if (velocity_pps_ == 0.0 && wait_remaining_s_ > 0.0) {
    // TZEROWAIT: at rest whatever the mode asks (manual 2015: before the next move or a reversal).
    wait_remaining_s_ -= dt_s;
    if (wait_remaining_s_ < 1e-12) wait_remaining_s_ = 0.0;
    segment_ = Segment::kRest;
    acceleration_pps2_ = 0.0;
    return;
  }
  switch (mode_) {
    case Mode::kPosition:
      step_position(config, dt_s);
      break;
    case Mode::kVelocity:
      step_velocity(config, dt_s);
      break;
    case Mode::kStop:
      step_stop(config, dt_s);
      break;
  }
}

void EightPointRamp::step_position(const EightPointConfig& config, double dt_s) {
  const double distance = distance_to_target();
  const double previous_velocity = velocity_pps_;
  double direction = sign_of(velocity_pps_);
  double speed = std::fabs(velocity_pps_);
  if (speed == 0.0) {
    if (distance == 0.0 || config.vmax_pps <= 0.0) {
      segment_ = Segment::kRest;
      acceleration_pps2_ = 0.0;
      return;
    }
    // A move starts with a jump to VSTART (never above VMAX).
    direction = sign_of(distance);
    speed = min_of(config.vstart_pps, config.vmax_pps);
  } else if (distance == 0.0 && speed <= arrival_speed_pps(config, speed, dt_s)) {
    // On the target at an arrival speed (the braking curve ended the last tick exactly there, or
    // at VSTOP = VMAX): at rest here. Braking on as below would end a fraction of a microstep past
    // the target (found by fuzzing: one count beyond at 50 µs).
    come_to_rest(config);
    return;
  } else if (direction * distance <= 0.0) {
    // Moving away from the target (it changed behind the axis, or the axis overshot): brake with
    // the D bands, come to rest, wait TZEROWAIT, then the next tick starts the move back.
    const Motion motion = decelerate(config, speed, 0.0, dt_s);
    advance(direction * motion.distance);
    velocity_pps_ = direction * motion.speed_pps;
    segment_ = motion.segment;
    acceleration_pps2_ = (velocity_pps_ - previous_velocity) / dt_s;
    if (motion.speed_pps <= config.vstop_pps || motion.speed_pps == speed) come_to_rest(config);
    return;
  }
  const double remaining = std::fabs(distance);
  const double start_velocity = direction * speed;  // after a VSTART jump

  // Where the braking curve wants the tick to end; below VSTOP the move ends in this tick.
  const double curve_pps = curve_speed_after_tick(config, remaining, speed, dt_s);
  const double join_allowance = max_of(deceleration_band(config, speed).rate_pps2,
                                       deceleration_band(config, max_of(curve_pps, config.vstop_pps)).rate_pps2) *
                                    dt_s * (1.0 + kRelativeSlack) +
                                1e-9 * (1.0 + speed);
  if (curve_pps < config.vstop_pps) {
    if (speed <= max_of(config.vstop_pps, config.vstart_pps) + join_allowance) {
      // Exactly on the target (the distance is an exact Q32 difference).
      position_q32_ = static_cast<uint64_t>(static_cast<uint32_t>(target_position_)) << kFractionBits;
      come_to_rest(config);
      segment_ = speed > config.vstop_pps ? deceleration_band(config, speed).segment : Segment::kRest;
      return;
    }
  }

  Motion motion = speed > config.vmax_pps ? decelerate(config, speed, config.vmax_pps, dt_s)
                                          : accelerate(config, speed, config.vmax_pps, dt_s);
  if (config.tvmax_us > 0 && motion.speed_pps > speed) {
    const Motion without_tvmax = motion;
    const double tvmax_s = config.tvmax_us * 1e-6;
    // TVMAX, manual 1.5: a constant-velocity segment of at least TVMAX where the ramp turns from
    // decelerating to accelerating (a farther target during braking) ...
    const bool was_braking = segment_ == Segment::kDmax || segment_ == Segment::kD2 || segment_ == Segment::kD1;
    if (was_braking && velocity_pps_ != 0.0) tvmax_hold_s_ = tvmax_s;
    // ... and from accelerating to decelerating: no further acceleration once the cruise before
    // braking would be shorter than TVMAX ("VMAX is automatically reduced for the constant
    // velocity segment").
    const bool no_room = !tvmax_fits(config, motion, remaining, tvmax_s);
    if (tvmax_hold_s_ > 0.0) {
      motion = Motion{speed, speed * dt_s, Segment::kCruise};
      tvmax_hold_s_ = tvmax_hold_s_ - dt_s > 1e-12 ? tvmax_hold_s_ - dt_s : 0.0;
    } else if (no_room) {
      // Accelerate only up to the reduced VMAX whose TVMAX cruise still fits; holding the speed
      // instead would keep a move from rest (VSTART 0) at 0 for ever.
      motion = accelerate_within_tvmax(config, speed, motion.speed_pps, remaining, tvmax_s, dt_s);
    }
    // A TVMAX cruise too slow to move the counter by one Q32 unit a tick would never cover what is
    // left (found by fuzzing: a stop ending 4 units short of the target, then 1e-8 pps for ever):
    // the last fraction of a microstep is driven without it.
    if (motion.distance * kQ32 < 1.0) {
      motion = without_tvmax;
      tvmax_hold_s_ = 0.0;
    }
  } else {
    tvmax_hold_s_ = 0.0;
  }
  const bool braking_to_target = motion.speed_pps > curve_pps;
  if (braking_to_target) {
    if (speed - curve_pps <= join_allowance) {
      // On the braking curve: ends the tick exactly on it. The curve ends at or before the target,
      // so a distance beyond it is a rounding error (found by fuzzing: a residual 0.001 pps and one
      // Q32 unit past the target): it stops on the target, where the next tick comes to rest.
      const Segment segment = curve_pps < speed ? deceleration_band(config, 0.5 * (speed + curve_pps)).segment
                                                : motion.segment;
      motion = Motion{curve_pps, min_of(0.5 * (speed + curve_pps) * dt_s, remaining), segment};
    } else {
      // Too fast for the target (it moved closer): brake as hard as the profile allows and
      // overshoot; the axis comes back after TZEROWAIT.
      motion = decelerate(config, speed, min_of(config.vstop_pps, speed), dt_s);
    }
  }
  if (motion.distance >= remaining &&
      (speed <= arrival_speed_pps(config, speed, dt_s) ||
       stopping_distance(config, speed) <= remaining * (1.0 + kRelativeSlack))) {
    // The tick reaches the target and the axis could brake to VSTOP on the way: it ends there, at
    // rest (VSTOP drops to 0). Going on would pass the target: braked to VSTOP early in a long
    // tick and on at VSTOP for the rest of it (found by fuzzing: 299 µsteps past at 10 ms), or a
    // braking curve missed by a rounding error (a fraction of a microstep, one count at 50 µs).
    // A real overshoot cannot brake in the distance left, passes and comes back.
    position_q32_ = static_cast<uint64_t>(static_cast<uint32_t>(target_position_)) << kFractionBits;
    come_to_rest(config);
    segment_ = motion.speed_pps > 0.0 && motion.speed_pps < speed ? deceleration_band(config, speed).segment
                                                                  : Segment::kRest;
    return;
  }
  if (braking_to_target) {
    // Rounded to the Q32 unit towards the start, never towards the target: the ramp stays at or
    // behind the braking curve, so the next tick finds itself on it or below. Rounded to nearest,
    // half a unit ahead near the end of the curve (where a unit is worth much speed) looked too
    // fast for the target and braked past it (found by fuzzing). A tick of less than one unit is
    // rounded to nearest: rounded down it would never cover the last unit (found by fuzzing too).
    double units = std::floor(motion.distance * kQ32);
    if (units == 0.0) units = std::floor(motion.distance * kQ32 + 0.5);
    position_q32_ += static_cast<uint64_t>(static_cast<int64_t>(direction) * static_cast<int64_t>(units));
  } else {
    advance(direction * motion.distance);
  }
  velocity_pps_ = direction * motion.speed_pps;
  segment_ = motion.segment;
  acceleration_pps2_ = (velocity_pps_ - start_velocity) / dt_s;
}

void EightPointRamp::step_velocity(const EightPointConfig& config, double dt_s) {
  const double wanted = target_velocity_ > config.vmax_pps
                            ? config.vmax_pps
                            : (target_velocity_ < -config.vmax_pps ? -config.vmax_pps : target_velocity_);
  const double previous_velocity = velocity_pps_;
  double direction = sign_of(velocity_pps_);
  double speed = std::fabs(velocity_pps_);
  if (speed == 0.0) {
    if (wanted == 0.0) {
      segment_ = Segment::kRest;
      acceleration_pps2_ = 0.0;
      return;
    }
    // Manual 1.5 note: pv starts at VSTART (never above the target speed).
    direction = sign_of(wanted);
    speed = min_of(config.vstart_pps, std::fabs(wanted));
  }
  const double start_velocity = direction * speed;
  if (wanted * direction > 0.0) {
    // Same direction: AMAX up and down (manual 1.5: pv uses no deceleration parameters).
    const Motion motion = change_linearly(speed, std::fabs(wanted), config.amax_pps2, dt_s, Segment::kAmax);
    advance(direction * motion.distance);
    velocity_pps_ = direction * motion.speed_pps;
    segment_ = motion.segment;
    acceleration_pps2_ = (velocity_pps_ - start_velocity) / dt_s;
    return;
  }
  // Target 0 or the other way: AMAX down to VSTOP, then 0 and TZEROWAIT before a reversal.
  const Motion motion = change_linearly(speed, 0.0, config.amax_pps2, dt_s, Segment::kAmax);
  advance(direction * motion.distance);
  velocity_pps_ = direction * motion.speed_pps;
  segment_ = motion.segment;
  acceleration_pps2_ = (velocity_pps_ - previous_velocity) / dt_s;
  if (motion.speed_pps <= config.vstop_pps) come_to_rest(config);
}

void EightPointRamp::step_stop(const EightPointConfig& config, double dt_s) {
  const double previous_velocity = velocity_pps_;
  const double direction = sign_of(velocity_pps_);
  const double speed = std::fabs(velocity_pps_);
  if (speed == 0.0) {
    segment_ = Segment::kRest;
    acceleration_pps2_ = 0.0;
    return;
  }
  const Motion motion = stop_deceleration_pps2_ > 0.0
                            ? change_linearly(speed, 0.0, stop_deceleration_pps2_, dt_s, Segment::kStopRamp)
                            : decelerate(config, speed, 0.0, dt_s);
  advance(direction * motion.distance);
  velocity_pps_ = direction * motion.speed_pps;
  segment_ = motion.segment;
  acceleration_pps2_ = (velocity_pps_ - previous_velocity) / dt_s;
  // A profile without deceleration (refused by validate()) would never stop: stop at once.
  if (motion.speed_pps <= config.vstop_pps || motion.speed_pps == speed) come_to_rest(config);
}

void EightPointRamp::come_to_rest(const EightPointConfig& config) {
  velocity_pps_ = 0.0;
  tvmax_hold_s_ = 0.0;
  acceleration_pps2_ = 0.0;
  segment_ = Segment::kRest;
  wait_remaining_s_ = config.tzerowait_us * 1e-6;
}

void EightPointRamp::advance(double distance) {
  position_q32_ += static_cast<uint64_t>(static_cast<int64_t>(std::llround(distance * kQ32)));
}

}  // namespace motwin::motion
