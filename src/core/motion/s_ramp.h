// A TMC457-style jerk-limited ("S-shaped") ramp generator for a stepper axis: the acceleration
// itself changes at most at the four bow (jerk) limits, so the velocity follows S-curves between
// rest and VMAX; all bows 0 give a plain trapezoid. Position, velocity and hold modes; the braking
// point is recomputed every tick so that the target, VMAX and the accelerations may change during
// a move (a target that cannot be reached without overshoot: the axis brakes, stops and comes
// back); a move ends exactly on the integer target. Units: microsteps, µsteps/s, µsteps/s²,
// µsteps/s³. Position is kept in Q32 fixed point (2^-32 µstep) in 64 bits, so it never drifts and
// wraps with the firmware's 32-bit counter. Model: docs/stepper-motion.md.
#pragma once

#include <cstdint>

namespace motwin::motion {

namespace detail {
struct ChangeLimits;
struct ChangePlan;
}  // namespace detail

struct SRampConfig {
  double max_velocity = 0.0;  // µsteps/s (VMAX), >= 0
  double acceleration = 0.0;  // µsteps/s² (AMAX), > 0
  double deceleration = 0.0;  // µsteps/s² (DMAX); 0 = same as acceleration
  // Jerk limits, µsteps/s³, of the four changes of acceleration: [0] acceleration build-up at the
  // start, [1] acceleration reduction on reaching VMAX, [2] deceleration build-up, [3] deceleration
  // reduction at the end. 0 = unlimited (a trapezoid corner): all four 0 gives a plain trapezoid.
  double bow[4] = {0.0, 0.0, 0.0, 0.0};
};

class SRamp {
 public:
  enum class Mode : uint8_t { kPosition, kVelocity, kHold };

  static constexpr int kFractionBits = 32;

  // Position mode; the target may change during a move.
  void set_position_target(int32_t target);
  // Velocity mode, signed µsteps/s (bounded by VMAX); accelerates with the bows.
  void set_velocity_target(double velocity) {
    mode_ = Mode::kVelocity;
    target_velocity_ = velocity;
    braking_ = false;
  }
  // Hold mode: keeps the present velocity (acceleration 0 at once), ignores targets.
  void hold() {
    mode_ = Mode::kHold;
    acceleration_ = 0.0;
    braking_ = false;
  }
  // Sets the counter without moving (in position mode, the target with it).
  void set_position(int32_t position);
  // Hard stop (a limit switch's hard stop): velocity and acceleration 0 at once. In position
  // mode the target becomes the present position (rounded to the nearest microstep) so that the
  // axis does not start again; in velocity mode the target velocity becomes 0.
  void stop_now();

  void step(const SRampConfig& config, double dt_s);

  Mode mode() const { return mode_; }
  int32_t position() const { return static_cast<int32_t>(static_cast<uint32_t>(position_q32_ >> kFractionBits)); }
  uint64_t position_q32() const { return position_q32_; }  // the counter with its fraction
  double velocity() const { return velocity_; }            // µsteps/s, signed
  double acceleration() const { return acceleration_; }    // µsteps/s², signed
  int32_t target_position() const { return target_position_; }
  double target_velocity() const { return target_velocity_; }
  // Signed distance from the position to the target, the shorter way round the 32-bit counter.
  double distance_to_target() const;
  // Position mode: exactly at the target and at rest.
  bool position_reached() const;
  // Velocity mode: at the target velocity (bounded by VMAX at the last step); position mode: at
  // VMAX, or at rest on the target; hold mode: always.
  bool velocity_reached() const;
  bool standstill() const { return velocity_ == 0.0; }

 private:
  void step_velocity(const SRampConfig& config, double wanted_velocity, double dt_s);
  void step_position(const SRampConfig& config, double dt_s);
  // The peak deceleration (<= highest_peak) of the stop that ends exactly `ahead` away.
  double braking_peak(const detail::ChangeLimits& limits, double highest_peak, double shortest_stop, double ahead,
                      double direction, double tolerance) const;
  // One tick of a stop onto the target `ahead` away; the tick in which it ends lands exactly on it.
  void follow_stop(const detail::ChangePlan& plan, double ahead, double direction, double dt_s);
  // Exactly on the target, at rest.
  void arrive();
  void advance(double distance);

  Mode mode_ = Mode::kPosition;
  uint64_t position_q32_ = 0;  // µsteps in Q32: the 64 bits wrap exactly with the 32-bit counter
  double velocity_ = 0.0;
  double acceleration_ = 0.0;
  int32_t target_position_ = 0;
  double target_velocity_ = 0.0;
  double velocity_limit_ = 0.0;  // VMAX of the last step (for velocity_reached)
  // Position mode: braking onto the target (kept until it arrives or the target changes, so the
  // axis does not alternate between cruising and braking) with this peak deceleration.
  bool braking_ = false;
  double braking_peak_ = 0.0;
  // 1 / bow of the last config (0: unlimited), recomputed when a bow changes.
  double cached_bow_[4] = {0.0, 0.0, 0.0, 0.0};
  double inverse_bow_[4] = {0.0, 0.0, 0.0, 0.0};
  // Stopping distance from cruising at VMAX, for (velocity, DMAX, 1 / bow 2, 1 / bow 3).
  double cruise_stop_key_[4] = {0.0, -1.0, 0.0, 0.0};
  double cruise_stop_distance_ = 0.0;
};

}  // namespace motwin::motion
