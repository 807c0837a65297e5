// Commands of the TMCM-1636 axis and the ideal motor. The regulators that drive a real motor
// through the power stage are in tmcm1636_axis_servo.cpp.
#include "core/modules/tmcm1636/tmcm1636_axis.h"

#include <cmath>

namespace motwin::modules::tmcm1636 {
namespace {

int32_t round_to_int32(double v) {
  if (v >= 2147483647.0) return INT32_MAX;
  if (v <= -2147483648.0) return INT32_MIN;
  return static_cast<int32_t>(std::lround(v));
}

}  // namespace

// A zero product is its own quotient (AP 100 is never negative): a standing axis skips the
// division, which a Cortex-M4F does in software (docs/firmware.md, "Where a tick's
// instructions go").
double Tmcm1636Axis::counts_per_second(double velocity_rpm) const {
  const double product = velocity_rpm * static_cast<double>(config.encoder_steps);
  return product == 0.0 ? product : product / 60.0;
}

double Tmcm1636Axis::rpm(double counts_per_second) const {
  if (config.encoder_steps == 0) return 0.0;
  const double product = counts_per_second * 60.0;
  return product == 0.0 ? product : product / static_cast<double>(config.encoder_steps);
}

const motion::TrapezoidRampConfig& Tmcm1636Axis::ideal_ramp_config() {
  IdealRampLimits& limits = ideal_ramp_limits_;
  if (limits.max_velocity_rpm != config.max_velocity_rpm ||
      limits.acceleration_rpm_per_s != config.acceleration_rpm_per_s || limits.encoder_steps != config.encoder_steps) {
    limits.max_velocity_rpm = config.max_velocity_rpm;
    limits.acceleration_rpm_per_s = config.acceleration_rpm_per_s;
    limits.encoder_steps = config.encoder_steps;
    limits.ramp.max_velocity = counts_per_second(config.max_velocity_rpm);
    limits.ramp.acceleration = counts_per_second(config.acceleration_rpm_per_s);
  }
  limits.ramp.ramp_enabled = config.velocity_ramp_enabled != 0;
  return limits.ramp;
}

// A servo starts a new mode from the motion it measures, so that a mode change is bumpless.
void Tmcm1636Axis::seed_ramp() { ramp_.set_state(state.actual_position, servo_.velocity_counts_per_s); }

void Tmcm1636Axis::follow_position(int32_t position, double velocity_counts_per_s) {
  state.mode = MotionMode::kPosition;
  external_reference_ = true;
  ramp_.set_position_target(position);  // kept as the target (AP 55's window)
  ramp_.set_velocity_target(velocity_counts_per_s);
  ramp_.set_state(position, velocity_counts_per_s);
}

void Tmcm1636Axis::follow_velocity(double velocity_counts_per_s) {
  // AP 40 (target velocity) is not kept: no host of this reference reads it, and the division
  // would cost every tick.
  state.mode = MotionMode::kVelocity;
  external_reference_ = true;
  ramp_.set_velocity_target(velocity_counts_per_s);
}

void Tmcm1636Axis::advance_reference(double dt_s) {
  // Unbounded and without a ramp: the reference's velocity as it was given.
  static constexpr motion::TrapezoidRampConfig kAsGiven{1e12, 0.0, false};
  ramp_.step(kAsGiven, dt_s);
}

void Tmcm1636Axis::set_target_velocity(int32_t velocity_rpm) {
  external_reference_ = false;
  if (power_stage_ != nullptr && state.mode != MotionMode::kVelocity) seed_ramp();
  state.mode = MotionMode::kVelocity;
  state.target_velocity_rpm = velocity_rpm;
  ramp_.set_velocity_target(counts_per_second(velocity_rpm));
}

void Tmcm1636Axis::set_target_position(int32_t position) {
  external_reference_ = false;
  if (power_stage_ != nullptr && state.mode != MotionMode::kPosition) seed_ramp();
  state.mode = MotionMode::kPosition;
  ramp_.set_position_target(position);
  update_position_reached();
}

void Tmcm1636Axis::set_actual_position(int32_t position) {
  ramp_.set_position(position);
  state.actual_position = position;
  update_position_reached();
}

// Torque and flux targets select current regulation (manual table 11, AP 30/32). The ideal
// motor has no torque model: it stands still in this mode (docs/tmcm-1636.md).
void Tmcm1636Axis::set_target_torque(int32_t torque_ma) {
  external_reference_ = false;
  state.mode = MotionMode::kTorque;
  state.target_torque_ma = torque_ma;
  ramp_.halt();
}

void Tmcm1636Axis::set_target_flux(int32_t flux_ma) {
  external_reference_ = false;
  state.mode = MotionMode::kTorque;
  state.target_flux_ma = flux_ma;
  ramp_.halt();
}

// A disabled driver lets the ideal motor stop where it is; a real motor coasts (the bridge is
// off, see servo_tick()).
void Tmcm1636Axis::set_driver_enabled(bool enabled) {
  state.driver_enabled = enabled ? 1 : 0;
  if (!enabled && power_stage_ == nullptr) {
    const MotionMode mode = state.mode;
    const int32_t target = ramp_.target_position();
    ramp_.halt();
    if (mode == MotionMode::kPosition) ramp_.set_position_target(target);
  }
}

void Tmcm1636Axis::set_commutation_mode(CommutationMode mode) {
  config.commutation_mode = mode;
  if (restoring_ || power_stage_ == nullptr) return;
  if (mode == CommutationMode::kAbnEncoder) {
    start_encoder_init(false);
  } else if (mode == CommutationMode::kAbsoluteEncoder &&
             config.absolute_encoder_init == AbsoluteEncoderInit::kEstimateOffset) {
    start_encoder_init(true);
  } else {
    state.encoder_init_state = EncoderInitState::kIdle;
  }
}

void Tmcm1636Axis::set_clear_on_null(int32_t clear) {
  config.clear_on_null = clear;
  servo_.clear_armed = clear != 0;
}

void Tmcm1636Axis::reset_state() {
  external_reference_ = false;
  state = AxisState{};
  ramp_ = motion::TrapezoidRamp{};
  servo_ = Servo{};
  restoring_ = true;
}

void Tmcm1636Axis::update_switches(uint8_t levels) {
  const auto active = [&](board::ReferenceSwitch which) {
    const int bit = static_cast<int>(which);
    const bool high_active = ((config.reference_switch_polarity >> bit) & 1) != 0;
    return (((levels >> bit) & 1) != 0) == high_active;
  };
  state.right_switch_active = active(board::ReferenceSwitch::kRight) ? 1 : 0;
  state.left_switch_active = active(board::ReferenceSwitch::kLeft) ? 1 : 0;
  state.home_switch_active = active(board::ReferenceSwitch::kHome) ? 1 : 0;
}

bool Tmcm1636Axis::switch_blocks(double direction) const {
  if (direction > 0.0) return (config.reference_switch_enable & 1) != 0 && state.right_switch_active != 0;
  if (direction < 0.0) return (config.reference_switch_enable & 2) != 0 && state.left_switch_active != 0;
  return false;
}

void Tmcm1636Axis::stop_at_switch() {
  ramp_.halt();
  state.target_velocity_rpm = 0;
  state.mode = MotionMode::kVelocity;
}

void Tmcm1636Axis::tick(const board::Tmcm1636Io& io, double dt_s) {
  restoring_ = false;
  if (power_stage_ != nullptr) {
    servo_tick(*power_stage_, dt_s);
  } else {
    ideal_tick(io, dt_s);
  }
}

void Tmcm1636Axis::ideal_tick(const board::Tmcm1636Io& io, double dt_s) {
  uint8_t levels = 0;
  if (io.reference_switch_level(board::ReferenceSwitch::kRight)) levels |= 1;
  if (io.reference_switch_level(board::ReferenceSwitch::kLeft)) levels |= 2;
  if (io.reference_switch_level(board::ReferenceSwitch::kHome)) levels |= 4;
  update_switches(levels);
  if (state.driver_enabled != 0 && external_reference_) {
    advance_reference(dt_s);  // the reference is the motion
  } else if (state.driver_enabled != 0 && state.mode != MotionMode::kTorque) {
    // Re-derived every tick: AP 100 (counts per revolution) may have changed.
    if (state.mode == MotionMode::kVelocity) ramp_.set_velocity_target(counts_per_second(state.target_velocity_rpm));
    ramp_.step(ideal_ramp_config(), dt_s);
    // An enabled reference switch stops motion towards it at once (AP 209).
    if (switch_blocks(ramp_.velocity())) stop_at_switch();
  }
  // The ideal motor is wherever the ramp is.
  state.actual_position = ramp_.position();
  state.ramp_velocity_rpm = round_to_int32(rpm(ramp_.velocity()));
  state.actual_velocity_rpm = state.driver_enabled != 0 ? state.ramp_velocity_rpm : 0;
  update_position_reached();
  uint32_t flags = state.driver_enabled != 0 ? status_flag::kDriverEnabled : 0;
  flags |= state.mode == MotionMode::kTorque     ? status_flag::kTorqueMode
           : state.mode == MotionMode::kPosition ? status_flag::kPositionMode
                                                 : status_flag::kVelocityMode;
  if (state.position_reached != 0) flags |= status_flag::kPositionReached;
  if (switch_blocks(1.0)) flags |= status_flag::kRightSwitchStop;
  if (switch_blocks(-1.0)) flags |= status_flag::kLeftSwitchStop;
  state.status_flags = flags;
}

namespace {

// value * numerator / denominator, rounded to the nearest integer (halves away from zero), kept to
// 32 bits as the position counter wraps.
int32_t rescale(int32_t value, int64_t numerator, int64_t denominator) {
  const int64_t product = static_cast<int64_t>(value) * numerator;
  const int64_t half = denominator / 2;
  const int64_t quotient = (product >= 0 ? product + half : product - half) / denominator;
  return static_cast<int32_t>(static_cast<uint32_t>(static_cast<uint64_t>(quotient)));
}

}  // namespace

int32_t Tmcm1636Axis::host_position(int32_t axis_counts) const {
  if (!position_scaler_applies_ || config.encoder_steps <= 0 || config.position_scaler == config.encoder_steps) {
    return axis_counts;
  }
  return rescale(axis_counts, config.position_scaler, config.encoder_steps);
}

int32_t Tmcm1636Axis::axis_position(int32_t host_counts) const {
  if (!position_scaler_applies_ || config.encoder_steps <= 0 || config.position_scaler == config.encoder_steps) {
    return host_counts;
  }
  return rescale(host_counts, config.encoder_steps, config.position_scaler);
}

// AP 53 in the axis' counts: the host gives it in its own (AP 56 on firmware 1.13).
double Tmcm1636Axis::position_reached_distance_counts() const {
  if (!position_scaler_applies_ || config.encoder_steps <= 0 || config.position_scaler <= 0) {
    return static_cast<double>(config.position_reached_distance);
  }
  return static_cast<double>(config.position_reached_distance) * static_cast<double>(config.encoder_steps) /
         static_cast<double>(config.position_scaler);
}

// AP 55: |target - actual| <= AP 53 and |actual velocity| <= AP 54.
void Tmcm1636Axis::update_position_reached() {
  if (power_stage_ != nullptr) {
    update_position_reached_servo();
    return;
  }
  const double distance = std::fabs(ramp_.distance_to_target());
  const bool near = distance <= position_reached_distance_counts();
  const bool slow = std::abs(state.actual_velocity_rpm) <= config.position_reached_velocity_rpm;
  state.position_reached = near && slow ? 1 : 0;
}

void Tmcm1636Axis::update_position_reached_servo() {
  const auto distance =
      static_cast<int32_t>(static_cast<uint32_t>(ramp_.target_position()) - static_cast<uint32_t>(state.actual_position));
  const int64_t magnitude = distance < 0 ? -static_cast<int64_t>(distance) : distance;
  const bool near = static_cast<double>(magnitude) <= position_reached_distance_counts();
  const bool slow = std::abs(state.actual_velocity_rpm) <= config.position_reached_velocity_rpm;
  state.position_reached = near && slow ? 1 : 0;
}

}  // namespace motwin::modules::tmcm1636
