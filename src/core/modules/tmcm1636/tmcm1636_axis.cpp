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

double Tmcm1636Axis::counts_per_second(double velocity_rpm) const {
  return velocity_rpm * static_cast<double>(config.encoder_steps) / 60.0;
}

double Tmcm1636Axis::rpm(double counts_per_second) const {
  if (config.encoder_steps == 0) return 0.0;
  return counts_per_second * 60.0 / static_cast<double>(config.encoder_steps);
}

void Tmcm1636Axis::set_target_velocity(int32_t velocity_rpm) {
  state.mode = MotionMode::kVelocity;
  state.target_velocity_rpm = velocity_rpm;
  ramp_.set_velocity_target(counts_per_second(velocity_rpm));
}

void Tmcm1636Axis::set_target_position(int32_t position) {
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
  state.mode = MotionMode::kTorque;
  state.target_torque_ma = torque_ma;
  ramp_.halt();
}

void Tmcm1636Axis::set_target_flux(int32_t flux_ma) {
  state.mode = MotionMode::kTorque;
  state.target_flux_ma = flux_ma;
  ramp_.halt();
}

// A disabled driver lets the ideal motor stop where it is.
void Tmcm1636Axis::set_driver_enabled(bool enabled) {
  state.driver_enabled = enabled ? 1 : 0;
  if (!enabled) {
    const MotionMode mode = state.mode;
    const int32_t target = ramp_.target_position();
    ramp_.halt();
    if (mode == MotionMode::kPosition) ramp_.set_position_target(target);
  }
}

void Tmcm1636Axis::reset_state() {
  state = AxisState{};
  ramp_ = motion::TrapezoidRamp{};
}

void Tmcm1636Axis::update_switches(const board::Tmcm1636Io& io) {
  const auto active = [&](board::ReferenceSwitch which) {
    const int bit = static_cast<int>(which);
    const bool high_active = ((config.reference_switch_polarity >> bit) & 1) != 0;
    return io.reference_switch_level(which) == high_active;
  };
  state.right_switch_active = active(board::ReferenceSwitch::kRight) ? 1 : 0;
  state.left_switch_active = active(board::ReferenceSwitch::kLeft) ? 1 : 0;
  state.home_switch_active = active(board::ReferenceSwitch::kHome) ? 1 : 0;
}

void Tmcm1636Axis::tick(const board::Tmcm1636Io& io, double dt_s) {
  update_switches(io);
  if (state.driver_enabled != 0 && state.mode != MotionMode::kTorque) {
    const motion::TrapezoidRampConfig ramp_config{
        counts_per_second(config.max_velocity_rpm),
        counts_per_second(config.acceleration_rpm_per_s),
        config.velocity_ramp_enabled != 0,
    };
    // Re-derived every tick: AP 100 (counts per revolution) may have changed.
    if (state.mode == MotionMode::kVelocity) ramp_.set_velocity_target(counts_per_second(state.target_velocity_rpm));
    ramp_.step(ramp_config, dt_s);
    // An enabled reference switch stops motion towards it at once (AP 209).
    const double velocity = ramp_.velocity();
    const bool right_blocked = (config.reference_switch_enable & 1) != 0 && state.right_switch_active != 0 && velocity > 0.0;
    const bool left_blocked = (config.reference_switch_enable & 2) != 0 && state.left_switch_active != 0 && velocity < 0.0;
    if (right_blocked || left_blocked) {
      ramp_.halt();
      state.target_velocity_rpm = 0;
      state.mode = MotionMode::kVelocity;
    }
  }
  // The ideal motor is wherever the ramp is.
  state.actual_position = ramp_.position();
  state.ramp_velocity_rpm = round_to_int32(rpm(ramp_.velocity()));
  state.actual_velocity_rpm = state.driver_enabled != 0 ? state.ramp_velocity_rpm : 0;
  update_position_reached();
}

// AP 55: |target - actual| <= AP 53 and |actual velocity| <= AP 54.
void Tmcm1636Axis::update_position_reached() {
  const double distance = std::fabs(ramp_.distance_to_target());
  const bool near = distance <= static_cast<double>(config.position_reached_distance);
  const bool slow = std::abs(state.actual_velocity_rpm) <= config.position_reached_velocity_rpm;
  state.position_reached = near && slow ? 1 : 0;
}

}  // namespace motwin::modules::tmcm1636
