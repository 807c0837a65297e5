#include "core/modules/tmcm3216/tmcm3216_tmcl_axis.h"

#include <cmath>

namespace motwin::modules::tmcm3216 {

motion::EightPointConfig Tmcm3216TmclAxis::ramp_config() const {
  motion::EightPointConfig profile;
  // A reference search runs at its own speeds (AP 194, 195) instead of AP 4.
  profile.vmax_pps = search_ != SearchKind::kNone ? search_velocity_limit_pps_ : config.max_velocity_pps;
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
  last_ramp_position_ = 0;
  motor_position_ = 0;
  search_ = SearchKind::kNone;
  switch_search_ = motion::ReferenceSearch{};
  home_search_ = cia402::Homing{};
  search_final_move_ = false;
  deviation_exceeded_ = false;
  start_pending_ = false;
  compare_started_ = false;
  compare_pulse_remaining_us_ = 0;
  stepper.reset();
}

int32_t Tmcm3216TmclAxis::actual_velocity_pps() const { return static_cast<int32_t>(std::lround(ramp_.velocity())); }

tmcl::Status Tmcm3216TmclAxis::set_target_position(int32_t position) {
  const motion::EightPointConfig profile = ramp_config();
  if (motion::EightPointRamp::validate(profile) != motion::EightPointConfigError::kNone || profile.vmax_pps <= 0.0) {
    return tmcl::Status::kInvalidValue;
  }
  start_motion();
  state.target_position = position;
  ramp_.set_position_target(position);
  return tmcl::Status::kOk;
}

tmcl::Status Tmcm3216TmclAxis::set_target_velocity(int32_t velocity_pps) {
  if (velocity_pps != 0 && motion::EightPointRamp::validate(ramp_config(), motion::EightPointRamp::Mode::kVelocity) !=
                               motion::EightPointConfigError::kNone) {
    return tmcl::Status::kInvalidValue;
  }
  if (velocity_pps != 0) {
    start_motion();
  } else {
    start_pending_ = false;  // MST: nothing left to start
  }
  state.target_velocity = velocity_pps;
  ramp_.set_velocity_target(velocity_pps);
  return tmcl::Status::kOk;
}

void Tmcm3216TmclAxis::start_motion() {
  stepper.clear_stall();
  if (search_ != SearchKind::kNone) end_search(false, 0);
  start_pending_ = config.motion_start_input_mask != 0;
}

namespace {
// The compare interval of `position`: which repeat the point lies in, rounded towards the
// direction of motion so that a point counts when reached moving up and when left moving down.
int64_t compare_interval(int64_t position, int64_t first, int64_t repeat, bool rising) {
  const int64_t offset = position - first;
  if (rising) return offset >= 0 ? offset / repeat : -((-offset + repeat - 1) / repeat);
  return offset >= 0 ? (offset + repeat - 1) / repeat : -(-offset / repeat);
}
}  // namespace

void Tmcm3216TmclAxis::run_position_compare(uint32_t dt_us) {
  compare_pulse_remaining_us_ = compare_pulse_remaining_us_ > dt_us ? compare_pulse_remaining_us_ - dt_us : 0;
  const int32_t position = ramp_.position();
  if (!compare_started_) {
    compare_started_ = true;
    last_compare_position_ = position;
    return;
  }
  const int64_t last = last_compare_position_;
  const int64_t now = position;
  last_compare_position_ = position;
  if (now == last || config.compare_output_mask == 0) return;
  const int64_t first = config.compare_position;
  bool passed = false;
  if (config.compare_repeat <= 0) {
    passed = (last < first && now >= first) || (last > first && now <= first);
  } else {
    const bool rising = now > last;
    passed = compare_interval(last, first, config.compare_repeat, rising) !=
             compare_interval(now, first, config.compare_repeat, rising);
  }
  if (passed) {
    const uint32_t length_us = static_cast<uint32_t>(config.compare_pulse_length_ms) * 1000u;
    compare_pulse_remaining_us_ = length_us > dt_us ? length_us : dt_us;
  }
}

int32_t Tmcm3216TmclAxis::relative_move_origin() const {
  switch (config.relative_positioning_option) {
    case 1: return ramp_.position();
    case 2: return encoder_position();
    default: return state.target_position;  // Trinamic's firmwares' default (docs "Decisions")
  }
}

tmcl::Status Tmcm3216TmclAxis::start_reference_search() {
  if (config.reference_search_speed_pps <= 0 || config.reference_switch_speed_pps <= 0) {
    return tmcl::Status::kInvalidValue;
  }
  start_motion();
  const int32_t mode = config.reference_search_mode;
  const int32_t base = mode & ~(reference_mode::kRightSwitchOption | reference_mode::kInvertHomeOption);
  const double fast = config.reference_search_speed_pps;
  const double slow = config.reference_switch_speed_pps;
  search_velocity_limit_pps_ = fast > slow ? fast : slow;
  search_final_move_ = false;
  state.target_velocity = 0;
  if (base <= reference_mode::kLeftBothSides) {
    search_ = SearchKind::kSwitches;
    search_mirrored_ = (mode & reference_mode::kRightSwitchOption) != 0;
    const motion::ReferenceSearch::Command first = switch_search_.start(base, fast, slow);
    ramp_.set_velocity_target(search_mirrored_ ? -first.velocity : first.velocity);
    return tmcl::Status::kOk;
  }
  // The CiA-402 method of the same search: the direction in which the switch is left last is
  // the opposite of the search direction (homing.h); the null channel is searched at the slow speed.
  int8_t method = 0;
  switch (base) {
    case reference_mode::kHomeNegativeReversing:
    case reference_mode::kHomeNegativeIgnoringStops: method = 21; break;
    case reference_mode::kHomePositiveReversing:
    case reference_mode::kHomePositiveIgnoringStops: method = 19; break;
    case reference_mode::kIndexPositive: method = 34; break;
    default: method = 33; break;
  }
  cia402::HomingConfig homing;
  homing.fast_speed_pps = config.reference_search_speed_pps;
  homing.slow_speed_pps = config.reference_switch_speed_pps;
  homing.acceleration_pps2 = config.max_acceleration_pps2;
  homing.home_offset_usteps = 0;
  // Give up on a null channel that does not come within two motor revolutions.
  homing.index_search_limit_usteps = 2u * stepper.objects.full_steps_per_revolution * stepper.microsteps_per_full_step();
  search_ = SearchKind::kHome;
  home_search_.start(method, homing);
  return tmcl::Status::kOk;
}

void Tmcm3216TmclAxis::stop_reference_search() {
  if (search_ == SearchKind::kNone) return;
  end_search(false, 0);
  ramp_.stop();
}

void Tmcm3216TmclAxis::end_search(bool set_zero, int32_t position_before) {
  if (search_ == SearchKind::kHome && home_search_.active()) (void)home_search_.stop();
  switch_search_.stop();
  search_ = SearchKind::kNone;
  search_final_move_ = false;
  if (set_zero) state.last_reference_position = position_before;
}

void Tmcm3216TmclAxis::run_reference_search() {
  if (search_ == SearchKind::kSwitches) run_switch_search();
  if (search_ == SearchKind::kHome) run_home_search();
}

void Tmcm3216TmclAxis::run_switch_search() {
  const bool left = (search_mirrored_ ? state.right_switch_active : state.left_switch_active) != 0;
  const bool right = (search_mirrored_ ? state.left_switch_active : state.right_switch_active) != 0;
  const motion::ReferenceSearch::Command command =
      switch_search_.step({left, right, search_position(), position_reached()});
  const double sign = search_mirrored_ ? -1.0 : 1.0;
  const int32_t position_before = ramp_.position();
  using Action = motion::ReferenceSearch::Action;
  switch (command.action) {
    case Action::kNone:
      break;
    case Action::kStopAndVelocity:
      ramp_.halt();
      [[fallthrough]];
    case Action::kVelocity:
      ramp_.set_velocity_target(sign * command.velocity);
      break;
    case Action::kSetPositionAndStop:
      ramp_.halt();
      set_actual_position(search_mirrored_ ? -command.position : command.position);
      ramp_.set_position_target(ramp_.position());
      state.target_position = ramp_.position();
      state.reference_switch_distance = switch_search_.measured_travel();
      end_search(true, position_before);
      break;
    case Action::kSetPositionAndMove:
      ramp_.halt();
      set_actual_position(search_mirrored_ ? -command.position : command.position);
      state.last_reference_position = position_before;
      state.reference_switch_distance = switch_search_.measured_travel();
      search_velocity_limit_pps_ = config.reference_switch_speed_pps;
      search_final_move_ = true;
      state.target_position = 0;
      ramp_.set_position_target(0);
      break;
    case Action::kDone:
      search_ = SearchKind::kNone;
      search_final_move_ = false;
      break;
  }
}

void Tmcm3216TmclAxis::run_home_search() {
  const int32_t base = config.reference_search_mode & ~reference_mode::kInvertHomeOption;
  const bool ignore_stops = base == reference_mode::kHomePositiveIgnoringStops ||
                            base == reference_mode::kHomeNegativeIgnoringStops;
  const bool home_inverted = (config.reference_search_mode & reference_mode::kInvertHomeOption) != 0;
  cia402::HomingInputs in;
  in.position_usteps = ramp_.position();
  in.left_limit = !ignore_stops && state.left_switch_active != 0;
  in.right_limit = !ignore_stops && state.right_switch_active != 0;
  in.home_switch = (state.home_switch_active != 0) != home_inverted;
  in.index_events = stepper.index_events();
  in.index_position_usteps = stepper.index_position();
  in.index_available = true;  // a search without a null channel ends at the index search limit
  in.target_reached = ramp_.mode() == motion::EightPointRamp::Mode::kPosition && ramp_.position_reached();
  const cia402::HomingCommand command = home_search_.step(in, 0);
  using Kind = cia402::HomingCommand::Kind;
  switch (command.kind) {
    case Kind::kVelocity:
      search_velocity_limit_pps_ = command.velocity_pps < 0 ? -command.velocity_pps : command.velocity_pps;
      ramp_.set_velocity_target(command.velocity_pps);
      break;
    case Kind::kPosition:
      search_velocity_limit_pps_ = command.velocity_pps < 0 ? -command.velocity_pps : command.velocity_pps;
      state.target_position = command.target_position_usteps;
      ramp_.set_position_target(command.target_position_usteps);
      break;
    case Kind::kStop:
      break;
    case Kind::kDone: {
      const int32_t position_before = ramp_.position();
      if (command.set_position) set_actual_position(command.new_position);
      state.target_position = ramp_.position();
      end_search(command.set_position, position_before);
      break;
    }
    case Kind::kError:
      ramp_.stop();
      end_search(false, 0);
      break;
  }
}

void Tmcm3216TmclAxis::set_actual_position(int32_t position) {
  ramp_.set_position(position);
  last_ramp_position_ = position;  // the motor does not move
  last_compare_position_ = position;  // nor is a compare point passed
  if (ramp_.mode() == motion::EightPointRamp::Mode::kPosition) state.target_position = position;
}

int32_t Tmcm3216TmclAxis::encoder_position() const {
  return static_cast<int32_t>(static_cast<uint32_t>(stepper.encoder_position()) +
                              static_cast<uint32_t>(state.encoder_offset));
}

void Tmcm3216TmclAxis::set_encoder_position(int32_t position) {
  state.encoder_offset =
      static_cast<int32_t>(static_cast<uint32_t>(position) - static_cast<uint32_t>(stepper.encoder_position()));
}

int32_t Tmcm3216TmclAxis::take_error_flags() {
  const int32_t flags = state.error_flags;
  state.error_flags = 0;
  return flags;
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

bool Tmcm3216TmclAxis::stop_ahead(int direction) {
  const int32_t stop_position = config.virtual_stop_encoder_mode != 0 ? encoder_position() : ramp_.position();
  const bool left_virtual = (config.virtual_stop_enable & 1) != 0 && stop_position <= config.virtual_stop_left;
  const bool right_virtual = (config.virtual_stop_enable & 2) != 0 && stop_position >= config.virtual_stop_right;
  state.virtual_stop_flags = (left_virtual ? 1 : 0) | (right_virtual ? 2 : 0);
  if (direction > 0) return right_virtual || (state.right_switch_active != 0 && config.right_limit_disabled == 0);
  if (direction < 0) return left_virtual || (state.left_switch_active != 0 && config.left_limit_disabled == 0);
  return false;
}

bool Tmcm3216TmclAxis::stop_on_fault(int direction) {
  // A stall only counts while the axis moves above AP 181 (the stepper's detector checks it).
  if (stepper.stall_detected() && direction != 0) {
    state.error_flags |= kStallStopFlag;
    return true;
  }
  bool exceeded = false;
  if (config.max_encoder_deviation > 0) {
    const int64_t deviation = static_cast<int32_t>(static_cast<uint32_t>(ramp_.position()) -
                                                   static_cast<uint32_t>(encoder_position()));
    exceeded = deviation > config.max_encoder_deviation || -deviation > config.max_encoder_deviation;
  }
  // AP 207 reports the deviation starting, as the TMCM-142's: set on every tick of a lasting one
  // it would undo the clear-on-read between two host reads. The axis is held while it lasts: the
  // host re-bases AP 1 or AP 209 to go on.
  if (exceeded && !deviation_exceeded_) state.error_flags |= kDeviationStopFlag;
  deviation_exceeded_ = exceeded;
  return exceeded && direction != 0;
}

void Tmcm3216TmclAxis::tick(board::StepperPowerStage& stage, uint32_t dt_us, uint8_t input_levels) {
  read_switches();  // the levels the stepper read in the last tick
  if (start_pending_ && (input_levels & config.motion_start_input_mask) != 0) start_pending_ = false;
  run_reference_search();
  const int direction = direction_of_motion();
  if (stop_on_fault(direction)) {
    ramp_.halt();
    state.target_velocity = 0;
    if (search_ != SearchKind::kNone) end_search(false, 0);
  } else if (search_ == SearchKind::kNone && stop_ahead(direction)) {
    state.target_velocity = 0;
    if (config.soft_stop != 0) {
      ramp_.stop();  // with the ramp's deceleration segments
      ramp_.step(ramp_config(), static_cast<double>(dt_us) * 1e-6);
    } else {
      ramp_.halt();  // hard stop, as the driver chip's stop switch input does
    }
  } else if (!start_pending_) {
    ramp_.step(ramp_config(), static_cast<double>(dt_us) * 1e-6);
  }
  run_position_compare(dt_us);

  // The motor follows the ramp's change, reversed by AP 251.
  const uint32_t change = static_cast<uint32_t>(ramp_.position()) - static_cast<uint32_t>(last_ramp_position_);
  last_ramp_position_ = ramp_.position();
  motor_position_ = static_cast<int32_t>(static_cast<uint32_t>(motor_position_) +
                                         (config.reverse_shaft != 0 ? 0u - change : change));

  stepper.objects.switch_config = 0;  // read_switches() applies the TMCL polarity and swap
  stepper.objects.stop_on_stall_option = 1;  // TMCL stops the axis; there is no FAULT state
  StepperDemand demand;
  demand.position_usteps = motor_position_;
  demand.velocity_pps = config.reverse_shaft != 0 ? -actual_velocity_pps() : actual_velocity_pps();
  // The TMCL firmware drives its motors from power-up on (run and standby current, AP 6/7).
  demand.power_enabled = true;
  demand.brake_released_request = true;
  demand.switch_on_disabled = true;  // every stepper setting is writable at any time
  demand.resolution_change_allowed = ramp_.standstill();  // AP 140 takes effect at standstill
  stepper.tick(stage, demand, dt_us);
}

}  // namespace motwin::modules::tmcm3216
