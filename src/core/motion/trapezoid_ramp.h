// A trapezoidal ramp generator for velocity and position modes: acceleration-limited
// velocity changes, a braking point recomputed every tick so that the target, the maximum
// velocity and the acceleration may change during a move, and exact arrival at the target.
// Units are the caller's: position in counts, velocity in counts/s, acceleration in
// counts/s². Position is kept in Q16 fixed point (1/65536 count) so that it never drifts and
// wraps like the firmware's 32-bit position counter.
#pragma once

#include <cstdint>

namespace motwin::motion {

struct TrapezoidRampConfig {
  double max_velocity = 0.0;   // counts/s, >= 0
  double acceleration = 0.0;   // counts/s², >= 0; also the deceleration
  bool ramp_enabled = true;    // false: velocity jumps to its target at once
};

class TrapezoidRamp {
 public:
  enum class Mode : uint8_t { kVelocity, kPosition };

  static constexpr int kFractionBits = 16;

  void set_velocity_target(double velocity) {
    mode_ = Mode::kVelocity;
    target_velocity_ = velocity;
  }
  void set_position_target(int32_t position) {
    mode_ = Mode::kPosition;
    target_position_ = position;
  }
  // Sets the position counter without moving (and, in position mode, the target with it,
  // so that the axis does not run off to the old target).
  void set_position(int32_t position);
  // Sets position and velocity, keeping mode and target: a servo re-seeds its reference from
  // the measured motion when it changes mode or its driver comes back on.
  void set_state(int32_t position, double velocity) {
    position_q16_ = static_cast<int64_t>(position) * (int64_t{1} << kFractionBits);
    velocity_ = velocity;
  }
  // Stops at once: velocity 0, position kept.
  void halt() {
    velocity_ = 0.0;
    target_velocity_ = 0.0;
    mode_ = Mode::kVelocity;
  }

  void step(const TrapezoidRampConfig& config, double dt_s);

  Mode mode() const { return mode_; }
  double velocity() const { return velocity_; }               // counts/s
  double target_velocity() const { return target_velocity_; }  // counts/s (velocity mode)
  int32_t target_position() const { return target_position_; }
  int32_t position() const { return static_cast<int32_t>(static_cast<uint32_t>(static_cast<uint64_t>(position_q16_) >> kFractionBits)); }
  int64_t position_q16() const { return position_q16_; }
  // Signed distance to the target along the shorter way round the 32-bit counter (MVP note
  // in the manual: more than 2^31 apart runs the other way).
  double distance_to_target() const;

 private:
  void step_velocity_mode(const TrapezoidRampConfig& config, double dt_s);
  void step_position_mode(const TrapezoidRampConfig& config, double dt_s);
  void advance(double previous_velocity, double dt_s);

  Mode mode_ = Mode::kVelocity;
  double velocity_ = 0.0;
  double target_velocity_ = 0.0;
  int32_t target_position_ = 0;
  int64_t position_q16_ = 0;  // only the low 48 bits matter: the counter wraps at 2^32 counts
};

}  // namespace motwin::motion
