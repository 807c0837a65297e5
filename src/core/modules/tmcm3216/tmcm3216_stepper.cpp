#include "core/modules/tmcm3216/tmcm3216_stepper.h"

#include <cmath>

#include "core/motion/microstep_table.h"

namespace motwin::modules::tmcm3216 {
namespace {

// One TMC velocity unit in µsteps/s (fCLK / 2^24).
constexpr double kPpsPerChipVelocityUnit = kDriverClockHz / 16777216.0;
// One power-down ramp step per 2^18 clocks of 20B9 (IHOLDDELAY).
constexpr double kPowerDownStepUsPerUnit = 262144.0 / kDriverClockHz * 1e6;
constexpr int32_t kMeasuredVelocityMax = 16777215;  // 2122's range
constexpr uint8_t kShortFlags =
    board::kDriverOvercurrentA | board::kDriverOvercurrentB | board::kDriverOvercurrentHighSide;

int32_t wrapping_difference(int32_t a, int32_t b) {
  return static_cast<int32_t>(static_cast<uint32_t>(a) - static_cast<uint32_t>(b));
}

uint32_t magnitude(int32_t v) { return v < 0 ? 0u - static_cast<uint32_t>(v) : static_cast<uint32_t>(v); }

uint32_t saturate_u32(double v) {
  if (v <= 0.0) return 0;
  if (v >= 4294967295.0) return UINT32_MAX;
  return static_cast<uint32_t>(std::lround(v));
}

}  // namespace

void Tmcm3216Stepper::reset() {
  const uint32_t angle = electrical_angle_;  // the field stays: a reset must not make the rotor jump
  const StepperObjects kept = objects;
  *this = Tmcm3216Stepper{};
  objects = kept;
  electrical_angle_ = angle;
  active_microstep_code_ = objects.microstep_code <= 8 ? objects.microstep_code : 8;
}

void Tmcm3216Stepper::set_actual_position(int32_t position_usteps) {
  demand_started_ = true;
  last_demand_position_ = position_usteps;
}

bool Tmcm3216Stepper::take_position_initialization(int32_t& position_usteps) {
  if (!position_init_pending_) return false;
  position_init_pending_ = false;
  position_usteps = position_init_value_;
  return true;
}

double Tmcm3216Stepper::velocity_object_pps(uint32_t value) const {
  return objects.velocity_in_chip_units ? value * kPpsPerChipVelocityUnit : static_cast<double>(value);
}

int32_t Tmcm3216Stepper::velocity_object_value(int32_t velocity_pps) const {
  double v = velocity_pps;
  if (objects.velocity_in_chip_units) v /= kPpsPerChipVelocityUnit;
  const auto rounded = static_cast<int64_t>(std::llround(v));
  if (rounded > kMeasuredVelocityMax) return kMeasuredVelocityMax;
  if (rounded < -kMeasuredVelocityMax) return -kMeasuredVelocityMax;
  return static_cast<int32_t>(rounded);
}

// The driver's current for a 5-bit scale: (CS + 1) / 32 of the range's peak (20A3), times the
// global scaler (20A2: 0 = 256/256).
int32_t Tmcm3216Stepper::current_of_scale(uint8_t scale) const {
  const int64_t range_ma = kCurrentRangePeakMa[objects.current_range & 3u];
  const int64_t global = objects.global_current_scaler == 0 ? 256 : objects.global_current_scaler;
  const int64_t numerator = range_ma * global * (scale + 1);
  constexpr int64_t kDenominator = 256 * 32;
  return static_cast<int32_t>((numerator + kDenominator / 2) / kDenominator);
}

void Tmcm3216Stepper::tick(board::StepperPowerStage& stage, const StepperDemand& demand, uint32_t dt_us) {
  const board::StepperFeedback& feedback = stage.feedback;
  switch_on_disabled_ = demand.switch_on_disabled;
  // A new resolution (2000) takes effect while the power stage is off (docs "Decisions"), or
  // when the demand allows it.
  if (!power_on_ || demand.resolution_change_allowed) {
    active_microstep_code_ = objects.microstep_code <= 8 ? objects.microstep_code : 8;
  }

  read_switches(feedback.switches);
  // The sensors saw the rotor where the previous demand put the field.
  read_encoder(feedback, last_demand_position_);

  // The sequencer follows the demand's motion (not its value: assigning a position moves nothing).
  if (!demand_started_) {
    demand_started_ = true;
    last_demand_position_ = demand.position_usteps;
  }
  const int32_t delta = wrapping_difference(demand.position_usteps, last_demand_position_);
  last_demand_position_ = demand.position_usteps;
  const int64_t per_microstep = int64_t{board::kElectricalAnglePerFullStep} >> active_microstep_code_;
  electrical_angle_ += static_cast<uint32_t>(static_cast<uint64_t>(static_cast<int64_t>(delta) * per_microstep));
  moving_ = delta != 0 || demand.velocity_pps != 0;
  if (moving_) {
    standstill_us_ = 0;
  } else if (standstill_us_ < UINT64_MAX - dt_us) {
    standstill_us_ += dt_us;  // this tick included
  }

  run_power_sequence(demand, dt_us);
  stealthchop_ = motion::stealth_chop_active(saturate_u32(velocity_object_pps(objects.pwm_threshold_velocity)),
                                             objects.pwm_gradient, demand.velocity_pps);
  run_stallguard(feedback, demand);
  run_current_control(demand);

  uint8_t flags = feedback.driver_status;
  if (feedback.supply_millivolt < kUndervoltageMillivolt) flags |= board::kDriverUndervoltage;
  if (objects.short_protection_disabled != 0) flags = static_cast<uint8_t>(flags & ~kShortFlags);
  driver_error_flags_ = flags;

  measured_velocity_ = power_on_ ? velocity_object_value(demand.velocity_pps) : 0;
  if (power_on_ && stealthchop_) {
    // PWM_AMPL + PWM_GRAD x 256 / TSTEP, TSTEP = fCLK / (steps/s at 256 microsteps).
    const double steps_256 = static_cast<double>(magnitude(demand.velocity_pps)) * (1u << (8 - active_microstep_code_));
    const double scale = objects.pwm_amplitude + objects.pwm_gradient * 256.0 * steps_256 / kDriverClockHz;
    pwm_scale_ = scale >= 255.0 ? 255 : static_cast<uint8_t>(scale);
  } else {
    pwm_scale_ = 0;
  }
  brake_duty_ = !brake_control() ? 0 : (brake_released_ ? objects.brake_release_current : objects.brake_apply_current);
  write_drive(stage.drive);
}

// 2005: bit 0 right, 1 left, 2 home in the electrical levels; a level set = switch active unless
// inverted; a disabled switch reads inactive.
void Tmcm3216Stepper::read_switches(uint8_t levels) {
  const cia402::Switches active = cia402::active_switches(
      objects.switch_config, cia402::Switches{(levels & 2u) != 0, (levels & 1u) != 0, (levels & 4u) != 0});
  switches_.raw = static_cast<uint8_t>(levels & 7u);
  switches_.right = active.right;
  switches_.left = active.left;
  switches_.home = active.home;
}

void Tmcm3216Stepper::read_encoder(const board::StepperFeedback& feedback, int32_t demand_position) {
  if (!encoder_started_) {
    encoder_started_ = true;
    encoder_last_raw_ = feedback.encoder_count;
    raw_index_events_ = feedback.encoder_index_events;
  }
  int32_t counts = wrapping_difference(feedback.encoder_count, encoder_last_raw_);
  encoder_last_raw_ = feedback.encoder_count;
  if (objects.encoder_reversed != 0) counts = static_cast<int32_t>(0u - static_cast<uint32_t>(counts));
  encoder_count_ = static_cast<int32_t>(static_cast<uint32_t>(encoder_count_) + static_cast<uint32_t>(counts));
  // 608F: increments per motor revolution -> microsteps of the active resolution.
  const int64_t per_revolution = static_cast<int64_t>(objects.full_steps_per_revolution) << active_microstep_code_;
  const int64_t increments = objects.encoder_increments;
  const int64_t position = increments == 0 ? 0 : static_cast<int64_t>(encoder_count_) * per_revolution / increments;
  encoder_position_usteps_ = static_cast<int32_t>(static_cast<uint32_t>(static_cast<uint64_t>(position)));

  // N pulses (the interface sees them only with the polarity of 200B sub 1, drive.encoder_index_active_low):
  // the motor position at the last one is where the rotor was sensed, within one tick's motion.
  const uint32_t new_events = feedback.encoder_index_events - raw_index_events_;
  raw_index_events_ = feedback.encoder_index_events;
  if (new_events != 0) {
    index_events_ += new_events;
    index_position_usteps_ = demand_position;
  }
}

// Switching on: power stage on, after 200A the brake opens, after 2002 sub 2 the axis is ready.
// Switching off: the brake closes at once, after 2002 sub 1 the power stage goes off.
void Tmcm3216Stepper::run_power_sequence(const StepperDemand& demand, uint32_t dt_us) {
  const bool want_on = demand.power_enabled || demand.brake_released_request;
  const bool want_release = demand.brake_released_request;
  if (!power_on_ && want_on) {
    power_on_ = true;
    brake_released_ = false;
    ready_ = false;
    phase_us_ = 0;
    apply_us_ = 0;
    if (objects.encoder_initialize_position != 0 && objects.encoder_used) {
      position_init_pending_ = true;
      position_init_value_ = encoder_position_usteps_;
    }
  }
  if (!power_on_) return;
  if (want_release) {
    apply_us_ = 0;
    if (!brake_released_) {
      if (phase_us_ >= uint64_t{objects.enable_drive_delay_ms} * 1000) {
        brake_released_ = true;
        phase_us_ = 0;
      } else {
        phase_us_ += dt_us;
      }
    }
    if (brake_released_ && !ready_) {
      if (phase_us_ >= uint64_t{objects.brake_release_delay_ms} * 1000) {
        ready_ = true;
      } else {
        phase_us_ += dt_us;
      }
    }
    return;
  }
  ready_ = false;
  if (brake_released_) {
    brake_released_ = false;
    apply_us_ = 0;
  }
  phase_us_ = 0;
  if (want_on) {
    apply_us_ = 0;
    return;
  }
  if (apply_us_ >= uint64_t{objects.brake_apply_delay_ms} * 1000) {
    power_on_ = false;
    apply_us_ = 0;
  } else {
    apply_us_ += dt_us;
  }
}

void Tmcm3216Stepper::run_stallguard(const board::StepperFeedback& feedback, const StepperDemand& demand) {
  bool new_measurement = false;
  if (!measurements_started_) {
    measurements_started_ = true;
  } else {
    new_measurement = feedback.stallguard_measurements != last_measurements_;
  }
  last_measurements_ = feedback.stallguard_measurements;
  new_measurement_ = false;
  // The driver's registers hold their last result (at standstill, in the other chopper mode).
  load_value_ = feedback.stallguard2_result;
  stallguard4_result_ = feedback.stallguard4_result;
  if (!power_on_) return;
  motion::StallDetectorConfig config;
  config.stop_velocity_pps = saturate_u32(velocity_object_pps(objects.stop_on_stall_velocity));
  stall_reaction_of(objects.stop_on_stall_option, config.reaction);
  config.stallguard4_threshold = objects.stallguard4_threshold;
  motion::StallDetectorInputs inputs;
  inputs.velocity_pps = demand.velocity_pps;
  inputs.stallguard2_result = feedback.stallguard2_result;
  inputs.stallguard4_result = feedback.stallguard4_result;
  inputs.new_measurement = new_measurement;
  inputs.stealth_chop = stealthchop_;
  stall_detector_.step(config, inputs);
  stall_ = stall_detector_.stalled();
  new_measurement_ = new_measurement;
}

// Run current (with CoolStep) while moving; after 2089 at standstill the power-down ramp (20B9)
// lowers the scale one step per 20B9 x 2^18 clocks to the standby current.
void Tmcm3216Stepper::run_current_control(const StepperDemand& demand) {
  const uint8_t run_scale = motion::CoolStep::current_scale_of(objects.run_current);
  const uint8_t hold_scale = motion::CoolStep::current_scale_of(objects.standby_current);
  if (!power_on_) {
    coolstep_.reset();
    coolstep_active_ = false;
    standby_current_reached_ = false;
    current_scale_ = 0;
    current_ma_ = 0;
    return;
  }
  motion::CoolStepConfig config;
  config.run_current_scale = run_scale;
  config.minimum_current = objects.coolstep_current_minimum;
  config.down_step = objects.coolstep_down_step;
  config.hysteresis = objects.coolstep_hysteresis;
  config.up_step = objects.coolstep_up_step;
  config.hysteresis_start = objects.coolstep_hysteresis_start;
  config.threshold_velocity_pps = saturate_u32(velocity_object_pps(objects.coolstep_threshold_velocity));
  motion::CoolStepInputs inputs;
  inputs.velocity_pps = demand.velocity_pps;
  inputs.stallguard2_result = load_value_;
  inputs.new_measurement = new_measurement_;
  inputs.stealth_chop = stealthchop_;
  uint8_t scale = coolstep_.step(config, inputs);
  coolstep_active_ = coolstep_.active();

  standby_current_reached_ = false;
  if (!moving_ && standby_scale(standstill_us_, run_scale, hold_scale, scale)) {
    standby_current_reached_ = scale == hold_scale;
  }
  current_scale_ = scale;
  current_ma_ = current_of_scale(scale);
}

bool Tmcm3216Stepper::standby_scale(uint64_t standstill_us, uint8_t run_scale, uint8_t hold_scale,
                                    uint8_t& scale) const {
  const uint64_t delay_us = uint64_t{objects.standby_delay_10ms} * 10000;
  if (standstill_us < delay_us) return false;
  const uint64_t into_ramp_us = standstill_us - delay_us;
  if (hold_scale >= run_scale || objects.power_down_ramp == 0) {
    scale = hold_scale;
  } else {
    const double step_us = objects.power_down_ramp * kPowerDownStepUsPerUnit;
    const auto steps = static_cast<uint64_t>(static_cast<double>(into_ramp_us) / step_us);
    scale = steps >= static_cast<uint64_t>(run_scale - hold_scale) ? hold_scale : static_cast<uint8_t>(run_scale - steps);
  }
  return true;
}

bool Tmcm3216Stepper::standstill_time_read_alike(uint32_t dt_us) const {
  if (!power_on_) return true;
  if (moving_) return false;  // a moving tick sets it to 0
  // The last tick read standstill_us_ (it counts itself), the next one reads it + dt_us.
  const uint64_t next_us = standstill_us_ < UINT64_MAX - dt_us ? standstill_us_ + dt_us : standstill_us_;
  const uint8_t run_scale = motion::CoolStep::current_scale_of(objects.run_current);
  const uint8_t hold_scale = motion::CoolStep::current_scale_of(objects.standby_current);
  uint8_t scale = 0;
  if (!standby_scale(next_us, run_scale, hold_scale, scale)) return true;  // both before 2089
  return standby_scale(standstill_us_, run_scale, hold_scale, scale) && scale == hold_scale;
}

void Tmcm3216Stepper::write_drive(board::StepperDrive& drive) {
  // 2097 = 0 switches all bridge transistors off: the motor freewheels.
  drive.enabled = power_on_ && objects.chopper_off_time != 0;
  // The field moves only by steps of the active resolution. A new resolution (2000) steps on from
  // where the old one left the field, off its grid: snapping to the new grid would move the rotor.
  drive.electrical_angle = electrical_angle_;
  const motion::CoilCurrents currents = motion::coil_currents(drive.electrical_angle, drive.enabled ? current_ma_ : 0);
  drive.coil_a_ma = currents.coil_a_ma;
  drive.coil_b_ma = currents.coil_b_ma;
  drive.stealth_chop = stealthchop_;
  drive.stallguard2_threshold = objects.stallguard2_threshold;
  drive.stallguard2_filter = objects.stallguard2_filter != 0;
  drive.stallguard4_filter = objects.stallguard4_filter != 0;
  drive.stallguard4_angle_offset = objects.stallguard4_angle_offset != 0;
  drive.encoder_index_active_low = objects.encoder_index_inverted != 0;
}

}  // namespace motwin::modules::tmcm3216
