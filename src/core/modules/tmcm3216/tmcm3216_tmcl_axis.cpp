#include "core/modules/tmcm3216/tmcm3216_tmcl_axis.h"

#include <cmath>

namespace motwin::modules::tmcm3216 {

motion::EightPointConfig Tmcm3216TmclAxis::ramp_config() const {
  motion::EightPointConfig profile;
  profile.vmax_pps = config.max_velocity_pps;
  profile.amax_pps2 = config.max_acceleration_pps2;
  profile.dmax_pps2 = config.max_deceleration_pps2;
  profile.vstop_pps = config.stop_velocity_pps;
  profile.tvmax_us = static_cast<uint32_t>(config.cruise_minimum_time_us);
  config.shape.shape_profile(profile, config.shape.units());
  return profile;
}

void Tmcm3216TmclAxis::reset_state() {
  state = {};
  ramp_ = motion::EightPointRamp{};
  stepper.reset();
}

int32_t Tmcm3216TmclAxis::actual_velocity_pps() const { return static_cast<int32_t>(std::lround(ramp_.velocity())); }

tmcl::Status Tmcm3216TmclAxis::set_target_position(int32_t position) {
  const motion::EightPointConfig profile = ramp_config();
  if (motion::EightPointRamp::validate(profile) != motion::EightPointConfigError::kNone || profile.vmax_pps <= 0.0) {
    return tmcl::Status::kInvalidValue;
  }
  state.target_position = position;
  ramp_.set_position_target(position);
  return tmcl::Status::kOk;
}

tmcl::Status Tmcm3216TmclAxis::set_target_velocity(int32_t velocity_pps) {
  if (velocity_pps != 0 && motion::EightPointRamp::validate(ramp_config(), motion::EightPointRamp::Mode::kVelocity) !=
                               motion::EightPointConfigError::kNone) {
    return tmcl::Status::kInvalidValue;
  }
  state.target_velocity = velocity_pps;
  ramp_.set_velocity_target(velocity_pps);
  return tmcl::Status::kOk;
}

void Tmcm3216TmclAxis::set_actual_position(int32_t position) {
  ramp_.set_position(position);
  stepper.set_actual_position(position);  // the field does not move
  if (ramp_.mode() == motion::EightPointRamp::Mode::kPosition) state.target_position = position;
}

void Tmcm3216TmclAxis::read_switches() {
  // The stepper reads the levels with every switch enabled and none inverted (2005 = 0): raw bit
  // 0 is the right input, bit 1 the left, bit 2 the home switch.
  const uint8_t raw = stepper.switches().raw;
  const bool right_input = (raw & 1u) != 0;
  const bool left_input = (raw & 2u) != 0;
  const bool swapped = config.limit_switches_swapped != 0;
  const bool right_level = swapped ? left_input : right_input;
  const bool left_level = swapped ? right_input : left_input;
  state.right_switch_active = right_level != (config.right_switch_inverted != 0) ? 1 : 0;
  state.left_switch_active = left_level != (config.left_switch_inverted != 0) ? 1 : 0;
  state.home_switch_active = (raw & 4u) != 0 ? 1 : 0;
}

int Tmcm3216TmclAxis::direction_of_motion() const {
  const double v = ramp_.velocity();
  if (v != 0.0) return v > 0.0 ? 1 : -1;
  switch (ramp_.mode()) {
    case motion::EightPointRamp::Mode::kVelocity: {
      const double target = ramp_.target_velocity();
      return target > 0.0 ? 1 : target < 0.0 ? -1 : 0;
    }
    case motion::EightPointRamp::Mode::kPosition: {
      const double distance = ramp_.distance_to_target();
      return distance > 0.0 ? 1 : distance < 0.0 ? -1 : 0;
    }
    case motion::EightPointRamp::Mode::kStop: break;
  }
  return 0;
}

void Tmcm3216TmclAxis::tick(board::StepperPowerStage& stage, uint32_t dt_us) {
  read_switches();  // the levels the stepper read in the last tick
  const int direction = direction_of_motion();
  const bool right_stop = state.right_switch_active != 0 && config.right_limit_disabled == 0 && direction > 0;
  const bool left_stop = state.left_switch_active != 0 && config.left_limit_disabled == 0 && direction < 0;
  if (right_stop || left_stop) {
    ramp_.halt();  // hard stop, as the driver chip's stop switch input does
    state.target_velocity = 0;
  } else {
    ramp_.step(ramp_config(), static_cast<double>(dt_us) * 1e-6);
  }

  stepper.objects.switch_config = 0;  // read_switches() applies the TMCL polarity and swap
  StepperDemand demand;
  demand.position_usteps = ramp_.position();
  demand.velocity_pps = actual_velocity_pps();
  // The TMCL firmware drives its motors from power-up on (run and standby current, AP 6/7).
  demand.power_enabled = true;
  demand.brake_released_request = true;
  demand.switch_on_disabled = true;  // every stepper setting is writable at any time
  stepper.tick(stage, demand, dt_us);
}

}  // namespace motwin::modules::tmcm3216
