// The TMC5160/TMC5240-style EightPoint ramp generator of the TMCM-3216 (manual 1.5): start at
// VSTART, accelerate with A1 up to V1, with A2 up to V2, with AMAX up to VMAX, cruise at least
// TVMAX, decelerate with DMAX down to V2, D2 down to V1, D1 down to VSTOP, drop to 0 and stand
// still at least TZEROWAIT before the next move or a reversal. V1 = V2 = 0 gives the trapezoid
// VSTART/AMAX/VMAX/DMAX/VSTOP. Velocity mode (pv) is a trapezoid with AMAX both ways, VSTART and
// VSTOP. The braking point is recomputed every tick, so target, VMAX and every acceleration may
// change during a move; a target that cannot be reached without overshoot: the axis brakes with
// the D segments, stops, waits TZEROWAIT and comes back ("second move"). A move ends exactly on
// the integer target.
// Units (internal, the caller converts with 208C/208E): microsteps, microsteps/s (pps),
// microsteps/s² (pps2). Position is Q32 fixed point (2^-32 µstep) in 64 bits: it never drifts and
// wraps exactly with the firmware's 32-bit counter. Model and decisions: docs/tmcm-3216-drive.md.
#pragma once

#include <cstdint>

namespace motwin::motion {

// All values >= 0; directions come from the targets.
struct EightPointConfig {
  double vstart_pps = 0.0;   // 2010: jumped to when a move starts from rest
  double a1_pps2 = 0.0;      // 2011: VSTART .. V1
  double v1_pps = 0.0;       // 2012: 0 = no A1/D1 segment
  double a2_pps2 = 0.0;      // 2016: V1 .. V2
  double v2_pps = 0.0;       // 2017: 0 = no A2/D2 segment
  double vmax_pps = 0.0;     // 6081 (pp); in velocity mode the bound of the target velocity
  double amax_pps2 = 0.0;    // 6083: V2 .. VMAX (and both ways in velocity mode)
  double dmax_pps2 = 0.0;    // 6084: VMAX .. V2
  double d2_pps2 = 0.0;      // 2018: V2 .. V1
  double d1_pps2 = 0.0;      // 2013: V1 .. VSTOP
  double vstop_pps = 0.0;    // 6082: the speed from which the axis drops to 0
  uint32_t tzerowait_us = 0;  // 2015 (units of 32 µs): rest before the next move or a reversal
  uint32_t tvmax_us = 0;      // shortest cruise between accelerating and braking (no object: 0)
};

// Why validate() refuses a configuration (first rule that fails, in this order).
enum class EightPointConfigError : uint8_t {
  kNone = 0,
  kNegativeOrNan,      // a value < 0 or not a number
  kZeroAmax,           // AMAX = 0: the axis could never leave VSTART
  kZeroDmax,           // position mode: DMAX = 0 could never brake from VMAX
  kZeroD1,             // position mode: D1 = 0 (manual 1.5: never, even with V1 = V2 = 0)
  kZeroD2,             // position mode: D2 = 0 (same note)
  kZeroA1,             // position mode: V1 > 0 with A1 = 0
  kZeroA2,             // position mode: V2 > 0 with A2 = 0
  kV1AboveV2,          // position mode: V1 > V2 with both in use
  kVstopBelowVstart,   // position mode: VSTOP < VSTART (manual 1.5: target might not be reached)
};

class EightPointRamp {
 public:
  enum class Mode : uint8_t { kPosition, kVelocity, kStop };
  // What the last step did (for statusword bits, tests and the docs' figures).
  enum class Segment : uint8_t {
    kRest,     // at rest (also while waiting TZEROWAIT: see waiting())
    kA1,
    kA2,
    kAmax,
    kCruise,   // constant velocity (VMAX, a reduced VMAX, a velocity target, TVMAX hold)
    kDmax,
    kD2,
    kD1,
    kStopRamp, // stop() with a given deceleration
  };

  static constexpr int kFractionBits = 32;

  // Refusal of invalid settings; velocity mode uses only VSTART, AMAX, VSTOP (and the sign rule).
  static EightPointConfigError validate(const EightPointConfig& config, Mode mode = Mode::kPosition);

  // Position mode; the target may change during a move.
  void set_position_target(int32_t target) {
    mode_ = Mode::kPosition;
    target_position_ = target;
  }
  // Velocity mode, signed pps, bounded by VMAX; AMAX both ways, VSTART from rest, VSTOP to rest.
  void set_velocity_target(double velocity_pps) {
    mode_ = Mode::kVelocity;
    target_velocity_ = velocity_pps;
  }
  // Ramps down to rest and stays there: deceleration_pps2 > 0 linearly with that deceleration
  // (quick stop 6085, a slow-down ramp given by the caller); 0 with the profile's D segments
  // (DMAX/D2/D1, halt 605D). VSTOP applies: from VSTOP or below the velocity drops to 0.
  void stop(double deceleration_pps2 = 0.0) {
    mode_ = Mode::kStop;
    stop_deceleration_pps2_ = deceleration_pps2;
  }
  // Stops at once (velocity 0, no TZEROWAIT) and stays (velocity mode, target 0).
  void halt() {
    velocity_pps_ = 0.0;
    target_velocity_ = 0.0;
    mode_ = Mode::kVelocity;
    wait_remaining_s_ = 0.0;
    segment_ = Segment::kRest;
  }
  // Sets the counter without moving (in position mode, the target with it).
  void set_position(int32_t position);
  // Sets position and velocity, keeping mode and target: re-seeds the ramp from another mode's
  // motion (csp/csv, homing) so that a switch to pp/pv does not jump.
  void set_state(int32_t position, double velocity_pps);

  void step(const EightPointConfig& config, double dt_s);

  Mode mode() const { return mode_; }
  Segment segment() const { return segment_; }
  int32_t position() const { return static_cast<int32_t>(static_cast<uint32_t>(position_q32_ >> kFractionBits)); }
  uint64_t position_q32() const { return position_q32_; }  // the counter with its fraction
  double velocity() const { return velocity_pps_; }         // pps, signed
  double acceleration() const { return acceleration_pps2_; }  // pps2, signed, of the last step
  int32_t target_position() const { return target_position_; }
  double target_velocity() const { return target_velocity_; }
  // Signed distance to the target, the shorter way round the 32-bit counter.
  double distance_to_target() const;
  // Position mode: exactly on the target and at rest.
  bool position_reached() const;
  // Velocity mode: at the (VMAX-bounded) target velocity; position mode: cruising at VMAX or at
  // rest on the target; stop mode: at rest.
  bool velocity_reached() const;
  bool standstill() const { return velocity_pps_ == 0.0; }
  // Resting out TZEROWAIT after the velocity reached 0 on a ramp.
  bool waiting() const { return wait_remaining_s_ > 0.0; }

 private:
  void step_position(const EightPointConfig& config, double dt_s);
  void step_velocity(const EightPointConfig& config, double dt_s);
  void step_stop(const EightPointConfig& config, double dt_s);
  // Comes to rest after a ramp down: velocity 0, TZEROWAIT starts.
  void come_to_rest(const EightPointConfig& config);
  void advance(double distance);

  Mode mode_ = Mode::kPosition;
  Segment segment_ = Segment::kRest;
  uint64_t position_q32_ = 0;  // µsteps in Q32: the 64 bits wrap exactly with the 32-bit counter
  double velocity_pps_ = 0.0;
  double acceleration_pps2_ = 0.0;
  int32_t target_position_ = 0;
  double target_velocity_ = 0.0;
  double velocity_limit_pps_ = 0.0;  // VMAX of the last step (for velocity_reached)
  double stop_deceleration_pps2_ = 0.0;
  double wait_remaining_s_ = 0.0;    // TZEROWAIT left
  double tvmax_hold_s_ = 0.0;        // TVMAX cruise left after braking turned into accelerating
};

}  // namespace motwin::motion
