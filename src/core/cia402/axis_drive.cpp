// cia402::AxisDriveCore (axis_drive.h): the CiA-402 drive of every module, compiled once.
#include <algorithm>
#include <cmath>
#include <cstdlib>
#include <limits>

#include "core/cia402/axis_drive.h"

namespace motwin::cia402 {

namespace drive_detail {

inline constexpr int32_t kMin32 = std::numeric_limits<int32_t>::min();
inline constexpr int32_t kMax32 = std::numeric_limits<int32_t>::max();

inline int32_t wrap(int64_t value) { return static_cast<int32_t>(static_cast<uint32_t>(static_cast<uint64_t>(value))); }
inline int32_t difference(int32_t a, int32_t b) { return wrap(static_cast<int64_t>(a) - b); }

}  // namespace drive_detail

AxisDriveCore::AxisDriveCore(bool servo) : servo_(servo) {}

void AxisDriveCore::reset(int32_t position) {
  pds_.reset();
  ramp_ = motion::EightPointRamp{};
  ramp_.set_position(position);
  ramp_.halt();
  homing_ = Homing{};
  demand_ = AxisDemand{};
  demand_.position_usteps = position;
  active_mode_ = objects.mode;
  controlword_ = 0;
  target_ = position;
  moving_to_target_ = false;
  set_point_ack_ = false;
  pending_ = false;
  set_point_refused_ = false;
  set_point_taken_in_tick_ = false;
  set_point_buffered_ = false;
  set_point_base_ = 0;
  in_window_us_ = 0;
  target_reached_ = true;
  halted_ = false;
  stopping_on_limit_ = false;
  us_since_sync_ = kSyncAbsentUs;
  cyclic_latched_ = false;
  cyclic_torque_ = 0;
  control_ = DriveControl::kPosition;
  actual_velocity_pps_ = 0.0;
  following_error_ = false;
  limit_active_ = false;
  for (bool& reported : limit_reported_) reported = false;
  stall_latched_ = false;
  stall_stop_ = false;
  clear_stall_request_ = false;
  actual_position_ = position;
  last_encoder_usteps_ = 0;
  encoder_offset_ = 0;
  negative_direction_ = false;
  position_assigned_ = false;
  emcy_head_ = 0;
  emcy_count_ = 0;
}

PdsOptions AxisDriveCore::options() const {
  PdsOptions o;
  o.quick_stop = objects.quick_stop_option;
  o.shutdown = objects.shutdown_option;
  o.disable_operation = objects.disable_operation_option;
  o.halt = objects.halt_option;
  o.fault_reaction = objects.fault_reaction_option;
  return o;
}

void AxisDriveCore::emergency(DriveEvent event) {
  if (emcy_count_ == emcy_.size()) return;  // the oldest are kept: they name the first cause
  emcy_[(emcy_head_ + emcy_count_) % emcy_.size()] = event;
  ++emcy_count_;
}

bool AxisDriveCore::take_event(DriveEvent& out) {
  if (emcy_count_ == 0) return false;
  out = emcy_[emcy_head_];
  emcy_head_ = (emcy_head_ + 1) % emcy_.size();
  --emcy_count_;
  return true;
}

bool AxisDriveCore::take_position_assignment(int32_t& position) {
  if (!position_assigned_) return false;
  position = assigned_position_;
  position_assigned_ = false;
  return true;
}

void AxisDriveCore::assign_position(int32_t position) {
  // A stepper's encoder keeps its own count: it is re-based. A servo's module sets the axis'
  // counter itself (take_position_assignment), so the next reading is the new position.
  if (!servo_) encoder_offset_ = drive_detail::difference(position, last_encoder_usteps_);
  ramp_.set_position(position);
  ramp_.halt();
  target_ = position;
  moving_to_target_ = false;
  demand_.position_usteps = position;
  actual_position_ = position;
  cyclic_from_ = cyclic_to_ = position;
}

// --- Units and profiles -----------------------------------------------------------------------

motion::EightPointConfig AxisDriveCore::trapezoid_config(const UnitScale& u) const {
  // The profile objects make a plain trapezoid: the segments below V1 and V2 brake with DMAX.
  motion::EightPointConfig c;
  c.vmax_pps = u.velocity_pps(objects.profile_velocity);
  c.amax_pps2 = u.acceleration_pps2(objects.profile_acceleration);
  c.dmax_pps2 = u.acceleration_pps2(objects.profile_deceleration);
  c.d1_pps2 = c.dmax_pps2;
  c.d2_pps2 = c.dmax_pps2;
  c.vstop_pps = u.velocity_pps(objects.end_velocity);
  // 607F bounds the profile velocity (0: no bound).
  if (objects.max_profile_velocity != 0) c.vmax_pps = std::min(c.vmax_pps, u.velocity_pps(objects.max_profile_velocity));
  return c;
}

bool AxisDriveCore::min_limit(int64_t& limit) const {
  if (objects.software_limit_min == drive_detail::kMin32) return false;
  limit = static_cast<int64_t>(objects.software_limit_min) - objects.home_offset;
  return true;
}

bool AxisDriveCore::max_limit(int64_t& limit) const {
  if (objects.software_limit_max == drive_detail::kMax32) return false;
  limit = static_cast<int64_t>(objects.software_limit_max) - objects.home_offset;
  return true;
}

double AxisDriveCore::slow_down_pps2() const {
  // "The slow down ramp is the deceleration value of the used mode of operation" (5.1.1).
  const UnitScale& u = units_;
  double value = 0;
  switch (static_cast<Mode>(active_mode_)) {
    case Mode::kProfileVelocity: value = objects.profile_acceleration; break;
    case Mode::kHoming:
      value = objects.homing_acceleration != 0 ? objects.homing_acceleration : objects.profile_acceleration;
      break;
    default: value = objects.profile_deceleration; break;
  }
  return u.acceleration_pps2(value);
}

double AxisDriveCore::interpolation_period_s() const {
  double period = objects.interpolation_period;
  for (int i = 0; i < std::abs(objects.interpolation_index); ++i) {
    period = objects.interpolation_index < 0 ? period / 10.0 : period * 10.0;
  }
  return period;
}

void AxisDriveCore::stop_ramp(double deceleration_pps2) {
  if (deceleration_pps2 <= 0.0) {
    ramp_.halt();  // no ramp configured: stop at once
    return;
  }
  ramp_.stop(deceleration_pps2);  // every tick: a later, steeper stop (quick stop after halt) takes over
}

// --- Controlword and set-points --------------------------------------------------------------

void AxisDriveCore::write_controlword(uint16_t controlword) {
  // A mode written just before (an RPDO 2 of 6040 + 6060, or SDO writes with no tick between)
  // applies before the controlword acts in it, as it would have a tick later.
  take_mode_change();
  const uint16_t previous = controlword_;
  controlword_ = controlword;
  const PdsState before = pds_.state();
  pds_.on_controlword(controlword, options());
  if (pds_.take_fault_reset_event()) {
    following_error_ = false;
    stall_latched_ = false;
    clear_stall_request_ = true;  // the stepper's stall flag is cleared in the next tick
    emergency(DriveEvent::kFaultReset);
  }
  if (before != PdsState::kOperationEnabled && pds_.state() == PdsState::kOperationEnabled) {
    // Operation enabled anew: pp stands on its position until a new set-point comes.
    target_ = ramp_.position();
    moving_to_target_ = false;
    pending_ = false;
  }
  const bool bit4_rose = (controlword & kCwNewSetPoint) != 0 && (previous & kCwNewSetPoint) == 0;
  const bool bit4_fell = (controlword & kCwNewSetPoint) == 0 && (previous & kCwNewSetPoint) != 0;
  const bool running = pds_.state() == PdsState::kOperationEnabled && pds_.motion() == PdsMotion::kRun;
  switch (static_cast<Mode>(objects.mode)) {
    case Mode::kProfilePosition:
      if (bit4_rose && running) accept_set_point(controlword);
      if (bit4_fell && !pending_) set_point_ack_ = false;
      break;
    case Mode::kHoming:
      if (bit4_rose) {
        // Method 35 needs no motion and works in any state where the drive is switched on.
        const bool method35 = objects.homing_method == 35 && (pds_.state() == PdsState::kSwitchedOn || running);
        if (running || method35) start_homing();
      }
      if (bit4_fell && homing_.active()) {
        // "0: stop homing": ramp down with the homing acceleration, bit 10 set, not attained.
        const HomingCommand command = homing_.stop();
        stop_ramp(command.acceleration_pps2 > 0 ? static_cast<double>(command.acceleration_pps2) : slow_down_pps2());
      }
      break;
    default: break;
  }
}

void AxisDriveCore::accept_set_point(uint16_t controlword) {
  if (pending_) return;  // the buffer is full: bit 12 stays set, the edge is not taken
  const motion::EightPointConfig config = profile_;
  if (motion::EightPointRamp::validate(config) != motion::EightPointConfigError::kNone || config.vmax_pps <= 0.0) {
    set_point_refused_ = true;  // statusword bit 7 (warning) until a set-point is accepted
    return;
  }
  set_point_refused_ = false;
  stall_stop_ = false;
  set_point_base_ = 0;
  if ((controlword & kCwRelative) != 0) {
    // 60F2 bits 0..1: relative to the previous target, to the demand (6062), or to the actual (6064).
    switch (objects.positioning_option & 0x3) {
      case 1: set_point_base_ = ramp_.position(); break;
      case 2: set_point_base_ = position_actual(); break;
      default: set_point_base_ = target_; break;
    }
  }
  const int32_t t = set_point_target();
  set_point_taken_in_tick_ = true;
  set_point_ack_ = true;
  target_reached_ = false;
  in_window_us_ = 0;
  const bool immediately = (controlword & kCwChangeImmediately) != 0;
  // Single set-point (bit 5) or nothing under way: start now; else buffer it for later.
  const bool under_way = moving_to_target_ && !(ramp_.mode() == motion::EightPointRamp::Mode::kPosition &&
                                               ramp_.position_reached());
  set_point_buffered_ = !(immediately || !under_way);
  if (!set_point_buffered_) {
    target_ = t;
    moving_to_target_ = true;
    ramp_.set_position_target(t);
  } else {
    pending_ = true;
    pending_target_ = t;
  }
}

int32_t AxisDriveCore::set_point_target() {
  int64_t target = drive_detail::wrap(static_cast<int64_t>(objects.target_position) + set_point_base_);
  int64_t limit = 0;
  if (min_limit(limit) && target < limit) target = limit;
  if (max_limit(limit) && target > limit) target = limit;
  return static_cast<int32_t>(target);
}

void AxisDriveCore::start_homing() {
  const UnitScale& u = units_;
  HomingConfig config;
  config.fast_speed_pps = saturate_to_int32(u.velocity_pps(objects.homing_speed_fast));
  config.slow_speed_pps = saturate_to_int32(u.velocity_pps(objects.homing_speed_slow));
  const uint32_t acceleration =
      objects.homing_acceleration != 0 ? objects.homing_acceleration : objects.profile_acceleration;
  config.acceleration_pps2 = saturate_to_int32(u.acceleration_pps2(acceleration));
  config.home_offset_usteps = objects.home_offset;
  // An index method finds its pulse within one revolution; two allow for the edge's position.
  config.index_search_limit_usteps = 2 * usteps_per_revolution_;
  homing_.start(objects.homing_method, config);
  if (!Homing::moves(objects.homing_method)) {
    // 0 and 35 complete at once (35 also outside operation enabled).
    HomingInputs inputs;
    inputs.position_usteps = ramp_.position();
    inputs.target_reached = true;
    const HomingCommand command = homing_.step(inputs, 0);
    if (command.kind == HomingCommand::Kind::kDone && command.set_position) {
      assign_position(command.new_position);
      position_assigned_ = true;
      assigned_position_ = command.new_position;
    }
  }
}

void AxisDriveCore::target_position_written() {
  if (objects.mode == static_cast<int8_t>(Mode::kProfilePosition) && set_point_taken_in_tick_ &&
      (controlword_ & kCwNewSetPoint) != 0) {
    // An RPDO that maps 6040 before 607A (RPDO 3, ros2_canopen's pp PDO) writes the controlword
    // first: the set-point its bit 4 edge took is the 607A of the same frame, written in the same
    // instant (no tick in between), not the previous one.
    const int32_t t = set_point_target();
    if (set_point_buffered_) {
      pending_target_ = t;
    } else {
      target_ = t;
      ramp_.set_position_target(t);
    }
  }
  if (objects.mode == static_cast<int8_t>(Mode::kCyclicSyncPosition) && us_since_sync_ >= kSyncAbsentUs) {
    take_mode_change();  // a mode written in the same instant applies first (it would clear the latch)
    latch_cyclic_set_point();
  }
}

void AxisDriveCore::target_velocity_written() {
  if (objects.mode == static_cast<int8_t>(Mode::kProfileVelocity)) {
    stall_stop_ = false;
    // Bit 10 drops with the write, not a tick later: a poll right after it sees the change.
    if (units_.velocity_pps(objects.target_velocity) != ramp_.velocity()) target_reached_ = false;
  }
  if (objects.mode == static_cast<int8_t>(Mode::kCyclicSyncVelocity) && us_since_sync_ >= kSyncAbsentUs) {
    take_mode_change();
    latch_cyclic_set_point();
  }
}

void AxisDriveCore::target_torque_written() {
  if (objects.mode == static_cast<int8_t>(Mode::kCyclicSyncTorque) && us_since_sync_ >= kSyncAbsentUs) {
    take_mode_change();
    latch_cyclic_set_point();
  }
}

void AxisDriveCore::on_sync() {
  us_since_sync_ = 0;
  take_mode_change();
  latch_cyclic_set_point();
}

void AxisDriveCore::latch_cyclic_set_point() {
  const bool running = pds_.state() == PdsState::kOperationEnabled && pds_.motion() == PdsMotion::kRun;
  if (!running) return;
  if (objects.mode == static_cast<int8_t>(Mode::kCyclicSyncPosition)) {
    int64_t target = static_cast<int64_t>(objects.target_position) + objects.position_offset;
    target = drive_detail::wrap(target);
    int64_t limit = 0;
    if (min_limit(limit) && target < limit) target = limit;
    if (max_limit(limit) && target > limit) target = limit;
    cyclic_from_ = ramp_.position();
    cyclic_to_ = static_cast<int32_t>(target);
  } else if (objects.mode == static_cast<int8_t>(Mode::kCyclicSyncVelocity)) {
    cyclic_velocity_from_ = ramp_.velocity();
    cyclic_velocity_to_ =
        units_.velocity_pps(static_cast<double>(objects.target_velocity) + static_cast<double>(objects.velocity_offset));
  } else if (objects.mode == static_cast<int8_t>(Mode::kCyclicSyncTorque)) {
    cyclic_torque_ = limited_torque(int32_t{objects.target_torque} + objects.torque_offset);
  } else {
    return;
  }
  cyclic_latched_ = true;
  cyclic_elapsed_s_ = 0;
}

// --- The tick ---------------------------------------------------------------------------------

void AxisDriveCore::follow_actual_motion() {
  ramp_.set_state(actual_position_, actual_velocity_pps_);
}

int32_t AxisDriveCore::limited_torque(int32_t torque) const {
  const int32_t limit = objects.max_torque;
  if (limit == 0) return torque;
  return torque > limit ? limit : torque < -limit ? -limit : torque;
}

void AxisDriveCore::take_mode_change() {
  if (objects.mode == active_mode_) return;
  const int8_t from = active_mode_;
  active_mode_ = objects.mode;
  on_mode_change(from, active_mode_);
}

void AxisDriveCore::on_mode_change(int8_t from, int8_t to) {
  if (from == static_cast<int8_t>(Mode::kHoming) && homing_.active()) homing_.stop();
  // A servo's new mode starts from where the motor is and how fast it turns (bumpless).
  if (servo_) follow_actual_motion();
  cyclic_latched_ = false;
  cyclic_torque_ = 0;
  halted_ = false;
  stall_stop_ = false;
  switch (static_cast<Mode>(to)) {
    case Mode::kProfilePosition:
      target_ = ramp_.position();
      moving_to_target_ = false;
      pending_ = false;
      set_point_ack_ = false;
      if (!ramp_.standstill()) stop_ramp(slow_down_pps2());
      break;
    case Mode::kCyclicSyncPosition:
      cyclic_from_ = cyclic_to_ = ramp_.position();
      break;
    case Mode::kCyclicSyncVelocity: cyclic_velocity_from_ = cyclic_velocity_to_ = ramp_.velocity(); break;
    default: break;
  }
}

void AxisDriveCore::step(const AxisInputs& inputs, uint32_t dt_us) {
  const double dt_s = static_cast<double>(dt_us) * 1e-6;
  // A stall flag the drive asked to clear is still set in this tick's readings: not a new stall.
  AxisInputs in = inputs;
  set_point_taken_in_tick_ = false;
  demand_.clear_stall = clear_stall_request_;
  if (clear_stall_request_) in.stall = false;
  clear_stall_request_ = false;
  if (us_since_sync_ < kSyncAbsentUs) us_since_sync_ += dt_us;
  take_mode_change();
  actual_velocity_pps_ = inputs.actual_velocity_pps;
  last_encoder_usteps_ = inputs.encoder_position_usteps;
  in.encoder_position_usteps = drive_detail::wrap(static_cast<int64_t>(inputs.encoder_position_usteps) + encoder_offset_);
  actual_position_ = objects.sensor_selection == 0 ? in.encoder_position_usteps : ramp_.position();
  check_faults(in);
  run_pds_motion(in, dt_s);
  if (ramp_.velocity() != 0.0) negative_direction_ = ramp_.velocity() < 0.0;
  if (objects.sensor_selection != 0) actual_position_ = ramp_.position();
  update_target_reached(inputs, dt_us);

  demand_.control = control_;
  demand_.torque = control_ == DriveControl::kTorque ? cyclic_torque_ : 0;
  demand_.position_usteps = ramp_.position();
  demand_.velocity_exact_pps = ramp_.velocity();
  // A stepper takes whole steps per second; a servo the exact value.
  if (!servo_) demand_.velocity_pps = static_cast<int32_t>(std::lround(ramp_.velocity()));
  demand_.power_enabled = pds_.power_enabled();
  const PdsState state = pds_.state();
  demand_.brake_released_request = pds_.power_enabled() &&
                                   (state == PdsState::kOperationEnabled || state == PdsState::kQuickStopActive ||
                                    state == PdsState::kFaultReactionActive);
  demand_.switch_on_disabled = state == PdsState::kSwitchOnDisabled || state == PdsState::kNotReadyToSwitchOn;
}

void AxisDriveCore::check_faults(const AxisInputs& inputs) {
  const bool powered = pds_.power_enabled();
  // Following error (6065 with 606A = 0): demand against the encoder.
  if (powered && objects.sensor_selection == 0 && objects.following_error_window != 0 && !following_error_) {
    const int64_t deviation = std::llabs(static_cast<int64_t>(drive_detail::difference(ramp_.position(), inputs.encoder_position_usteps)));
    if (deviation > static_cast<int64_t>(objects.following_error_window)) {
      following_error_ = true;
      emergency(DriveEvent::kFollowingError);
      pds_.fault();
    }
  }
  // Stall: an emergency, then FAULT or a quick stop, as the module's stall reaction says.
  if (inputs.stall && !stall_latched_) {
    stall_latched_ = true;
    emergency(DriveEvent::kStall);
    if (inputs.stall_enters_fault) {
      pds_.fault();
    } else {
      // Stop only: the axis stops and stays until the master commands a new motion.
      stall_stop_ = true;
      moving_to_target_ = false;
      pending_ = false;
      if (homing_.active()) homing_.stop();
      stop_ramp(units_.acceleration_pps2(objects.quick_stop_deceleration));
    }
  }
  // A power-stage fault keeps the motor from running: FAULT while the power stage is on.
  if (inputs.power_stage_fault && powered) pds_.fault();
}

void AxisDriveCore::run_pds_motion(const AxisInputs& inputs, double dt_s) {
  // The velocity modes hand the axis a velocity (also while they stop); the others a position.
  // cst hands it a torque while it runs (run_cyclic_torque) and a velocity while it stops.
  const Mode mode = static_cast<Mode>(active_mode_);
  control_ = mode == Mode::kProfileVelocity || mode == Mode::kCyclicSyncVelocity || mode == Mode::kCyclicSyncTorque
                 ? DriveControl::kVelocity
                 : DriveControl::kPosition;
  switch (pds_.motion()) {
    case PdsMotion::kOff:
    case PdsMotion::kHold:
      ramp_.halt();
      // A servo's motor is not held by the demand meanwhile: the demand stays where it is.
      if (servo_) ramp_.set_position(actual_position_);
      if (homing_.active()) homing_.stop();
      moving_to_target_ = false;
      pending_ = false;
      cyclic_latched_ = false;
      stall_stop_ = false;
      target_ = ramp_.position();
      if ((controlword_ & kCwNewSetPoint) == 0) set_point_ack_ = false;
      break;
    case PdsMotion::kQuickStop:
      if (homing_.active()) homing_.stop();
      stop_ramp(units_.acceleration_pps2(objects.quick_stop_deceleration));
      ramp_.step(ramp_config_, dt_s);
      break;
    case PdsMotion::kSlowDownStop:
      if (homing_.active()) homing_.stop();
      stop_ramp(slow_down_pps2());
      ramp_.step(ramp_config_, dt_s);
      break;
    case PdsMotion::kRun:
      // Operation enabled, but the power stage or the brake is not ready yet: nothing moves.
      if (!inputs.ready && ramp_.standstill()) break;
      run_mode(inputs, dt_s);
      break;
  }
  if ((pds_.motion() == PdsMotion::kQuickStop || pds_.motion() == PdsMotion::kSlowDownStop) && ramp_.standstill()) {
    moving_to_target_ = false;
    pending_ = false;
    target_ = ramp_.position();
    pds_.motion_stopped(options());
  }
  if (stall_latched_ && ramp_.standstill() && pds_.state() != PdsState::kFault &&
      pds_.state() != PdsState::kFaultReactionActive) {
    // A stall that only stopped the axis is over once it stands: the next one is detected again.
    stall_latched_ = false;
    clear_stall_request_ = true;
  }
}

void AxisDriveCore::run_mode(const AxisInputs& inputs, double dt_s) {
  const bool halt = (controlword_ & kCwHalt) != 0;
  const Mode mode = static_cast<Mode>(active_mode_);
  halted_ = halt && mode != Mode::kHoming && mode != Mode::kNone;
  if (halted_) {
    // 605D = 1: slow-down ramp, stay in operation enabled; the mode resumes when bit 8 clears.
    stop_ramp(slow_down_pps2());
    ramp_.step(ramp_config_, dt_s);
    if (mode == Mode::kCyclicSyncPosition) cyclic_from_ = cyclic_to_ = ramp_.position();
    return;
  }
  if (stall_stop_) {
    stop_ramp(units_.acceleration_pps2(objects.quick_stop_deceleration));
    ramp_.step(ramp_config_, dt_s);
    cyclic_latched_ = false;
    return;
  }
  switch (mode) {
    case Mode::kProfilePosition: run_profile_position(inputs, dt_s); break;
    case Mode::kProfileVelocity: run_profile_velocity(inputs, dt_s); break;
    case Mode::kHoming: run_homing(inputs, static_cast<uint32_t>(std::lround(dt_s * 1e6)), dt_s); break;
    case Mode::kCyclicSyncPosition: run_cyclic_position(dt_s); break;
    case Mode::kCyclicSyncVelocity: run_cyclic_velocity(inputs, dt_s); break;
    case Mode::kCyclicSyncTorque: run_cyclic_torque(); break;
    case Mode::kNone:
      // "The motor does not run when the operating mode is set to 0" (5.1.6).
      stop_ramp(slow_down_pps2());
      ramp_.step(ramp_config_, dt_s);
      break;
  }
}

void AxisDriveCore::update_limits(const AxisInputs& inputs) {
  const int32_t position = ramp_.position();
  int64_t limit = 0;
  const bool above = max_limit(limit) && position >= limit;
  const bool below = min_limit(limit) && position <= limit;
  limit_positive_ = inputs.right_limit || above;
  limit_negative_ = inputs.left_limit || below;
  limit_active_ = limit_positive_ || limit_negative_;
  const double v = ramp_.velocity();
  // An emergency once per excursion, when the axis runs into the limit.
  auto report = [&](bool active, int index, DriveEvent event, bool moving_into) {
    if (!active) {
      limit_reported_[index] = false;
    } else if (moving_into && !limit_reported_[index]) {
      limit_reported_[index] = true;
      emergency(event);
    }
  };
  report(above, 0, DriveEvent::kSoftwareLimitPositive, v > 0);
  report(below, 1, DriveEvent::kSoftwareLimitNegative, v < 0);
  report(inputs.right_limit, 2, DriveEvent::kLimitSwitchPositive, v > 0);
  report(inputs.left_limit, 3, DriveEvent::kLimitSwitchNegative, v < 0);
}

bool AxisDriveCore::brake_onto_software_limit(double target_pps, double velocity_ramp_pps2, double dt_s) {
  const double v = ramp_.velocity();
  // Towards where the axis moves, or (standing) where the target would take it.
  const double heading = v != 0.0 ? v : target_pps;
  const double direction = heading > 0.0 ? 1.0 : heading < 0.0 ? -1.0 : 0.0;
  const double quick_stop_pps2 = units_.acceleration_pps2(objects.quick_stop_deceleration);
  int64_t limit = 0;
  const bool limited = direction > 0.0 ? max_limit(limit) : direction < 0.0 && min_limit(limit);
  if (!limited || quick_stop_pps2 <= 0.0) return false;
  // The exact position (the counter floors a fraction: -34999.9 reads -35000, still short of a
  // negative limit at -35000).
  const double position = static_cast<double>(static_cast<int64_t>(ramp_.position_q32())) / 4294967296.0;
  const double remaining = direction * (static_cast<double>(limit) - position);
  if (remaining <= 0.0) return false;  // on or past the limit: update_limits() stops the axis
  // The velocity after the next tick (still accelerating towards the target) and the distance
  // from there to standstill on 6085: braking starts no later than needed.
  const double speed = std::fabs(v);
  const bool target_ahead = direction * target_pps > 0.0;
  const double next_pps =
      target_ahead ? std::max(speed, std::min(std::fabs(target_pps), speed + velocity_ramp_pps2 * dt_s)) : speed;
  const double stop_distance = next_pps * dt_s + next_pps * next_pps / (2.0 * quick_stop_pps2);
  // A target away from the limit (or 0) stops on the velocity ramp, unless that passes the limit.
  const double ramp_stop_distance =
      velocity_ramp_pps2 > 0.0 ? speed * dt_s + speed * speed / (2.0 * velocity_ramp_pps2) : stop_distance;
  if (stop_distance < remaining || (!target_ahead && ramp_stop_distance < remaining)) return false;
  // Position mode onto the limit: the ramp's braking point lands exactly on it.
  motion::EightPointConfig config;
  config.vmax_pps = target_ahead ? std::fabs(target_pps) : speed;
  if (config.vmax_pps <= 0.0) config.vmax_pps = speed;
  config.amax_pps2 = velocity_ramp_pps2 > 0.0 ? velocity_ramp_pps2 : quick_stop_pps2;
  config.dmax_pps2 = config.d1_pps2 = config.d2_pps2 = quick_stop_pps2;
  ramp_.set_position_target(static_cast<int32_t>(limit));
  ramp_.step(config, dt_s);
  ramp_config_ = config;
  return true;
}

void AxisDriveCore::run_profile_position(const AxisInputs& inputs, double dt_s) {
  ramp_config_ = profile_;
  update_limits(inputs);
  if ((limit_positive_ && ramp_.velocity() > 0) || (limit_negative_ && ramp_.velocity() < 0)) {
    // A limit switch or software limit ahead: the move ends here.
    moving_to_target_ = false;
    pending_ = false;
    stopping_on_limit_ = true;
  }
  if (stopping_on_limit_) {
    stop_ramp(units_.acceleration_pps2(objects.quick_stop_deceleration));
    ramp_.step(ramp_config_, dt_s);
    if (ramp_.standstill()) {
      stopping_on_limit_ = false;
      target_ = ramp_.position();
      ramp_.set_position_target(target_);
    }
    return;
  }
  if (moving_to_target_ && ramp_.mode() != motion::EightPointRamp::Mode::kPosition) ramp_.set_position_target(target_);
  if (!moving_to_target_ && ramp_.mode() != motion::EightPointRamp::Mode::kPosition) {
    // Stand (or finish a stop) where the axis is.
    if (ramp_.standstill()) {
      ramp_.set_position_target(ramp_.position());
    } else {
      stop_ramp(ramp_config_.dmax_pps2);
    }
  }
  ramp_.step(ramp_config_, dt_s);
  if (moving_to_target_ && ramp_.position_reached()) {
    if (pending_) {
      pending_ = false;
      target_ = pending_target_;
      ramp_.set_position_target(target_);
      target_reached_ = false;
      in_window_us_ = 0;
      if ((controlword_ & kCwNewSetPoint) == 0) set_point_ack_ = false;
    }
  }
}

void AxisDriveCore::run_profile_velocity(const AxisInputs& inputs, double dt_s) {
  ramp_config_ = profile_;
  // pv: AMAX both ways (6083), no D segments; VMAX bounds nothing but the target itself.
  const double target = units_.velocity_pps(objects.target_velocity);
  ramp_config_.vmax_pps = std::fabs(target);
  update_limits(inputs);
  // A limit ahead stops the axis on the quick-stop ramp; a target away from it runs again.
  const double v = ramp_.velocity();
  const bool switch_ahead =
      (inputs.right_limit && (target > 0 || v > 0)) || (inputs.left_limit && (target < 0 || v < 0));
  if (!switch_ahead && brake_onto_software_limit(target, ramp_config_.amax_pps2, dt_s)) {
    return;  // braking onto a software limit ahead: the axis stops on it, not past it
  }
  if ((limit_positive_ && (target > 0 || v > 0)) || (limit_negative_ && (target < 0 || v < 0))) {
    stop_ramp(units_.acceleration_pps2(objects.quick_stop_deceleration));
  } else {
    ramp_.set_velocity_target(target);
  }
  ramp_.step(ramp_config_, dt_s);
}

void AxisDriveCore::run_homing(const AxisInputs& inputs, uint32_t dt_us, double dt_s) {
  limit_active_ = inputs.left_limit || inputs.right_limit;
  if (!homing_.active()) {
    if (!ramp_.standstill()) {
      ramp_.step(ramp_config_, dt_s);  // finishing the stop of an interrupted or failed homing
    } else {
      ramp_.halt();
    }
    return;
  }
  HomingInputs in;
  in.position_usteps = ramp_.position();
  in.left_limit = inputs.left_limit;
  in.right_limit = inputs.right_limit;
  in.home_switch = inputs.home_switch;
  in.index_events = inputs.index_events;
  in.index_position_usteps = inputs.index_position_usteps;
  in.index_available = inputs.index_available;
  in.target_reached = ramp_.mode() == motion::EightPointRamp::Mode::kPosition && ramp_.position_reached();
  const HomingCommand command = homing_.step(in, dt_us);
  const double acceleration = command.acceleration_pps2 > 0 ? command.acceleration_pps2 : slow_down_pps2();
  motion::EightPointConfig config;
  config.amax_pps2 = config.dmax_pps2 = config.d1_pps2 = config.d2_pps2 = acceleration;
  config.vmax_pps = std::fabs(static_cast<double>(command.velocity_pps));
  switch (command.kind) {
    case HomingCommand::Kind::kVelocity: ramp_.set_velocity_target(command.velocity_pps); break;
    case HomingCommand::Kind::kPosition: ramp_.set_position_target(command.target_position_usteps); break;
    case HomingCommand::Kind::kStop:
    case HomingCommand::Kind::kError: stop_ramp(acceleration); break;
    case HomingCommand::Kind::kDone:
      ramp_.halt();
      if (command.set_position) {
        assign_position(command.new_position);
        position_assigned_ = true;
        assigned_position_ = command.new_position;
      }
      break;
  }
  ramp_config_ = config;
  if (command.kind != HomingCommand::Kind::kDone) ramp_.step(config, dt_s);
}

void AxisDriveCore::run_cyclic_position(double dt_s) {
  // csp: linear interpolation from the position at the last SYNC to the new set-point over one
  // interpolation period (60C2); without a new SYNC the axis holds the last set-point.
  const int32_t previous = ramp_.position();
  const double period = interpolation_period_s();
  int32_t position = previous;
  if (cyclic_latched_) {
    cyclic_elapsed_s_ += dt_s;
    const double fraction = period <= 0.0 ? 1.0 : std::min(1.0, cyclic_elapsed_s_ / period);
    const int32_t delta = drive_detail::difference(cyclic_to_, cyclic_from_);
    position = drive_detail::wrap(static_cast<int64_t>(cyclic_from_) + std::llround(static_cast<double>(delta) * fraction));
  }
  const double velocity = dt_s > 0.0 ? static_cast<double>(drive_detail::difference(position, previous)) / dt_s : 0.0;
  ramp_.set_state(position, velocity);
  ramp_config_ = profile_;
}

void AxisDriveCore::run_cyclic_velocity(const AxisInputs& inputs, double dt_s) {
  // csv: the velocity ramps linearly to the new set-point within one interpolation period.
  const double period = interpolation_period_s();
  motion::EightPointConfig config;
  const double change = std::fabs(cyclic_velocity_to_ - cyclic_velocity_from_);
  const double acceleration = period > 0.0 ? change / period : 0.0;
  config.amax_pps2 = acceleration > 0.0 ? acceleration : 1e12;
  config.dmax_pps2 = config.d1_pps2 = config.d2_pps2 = config.amax_pps2;
  config.vmax_pps = std::fabs(cyclic_velocity_to_);
  const double target = cyclic_latched_ ? cyclic_velocity_to_ : ramp_.velocity();
  // Limits as in pv: a reached limit stops motion towards it on 6085, a software limit ahead is
  // braked onto.
  update_limits(inputs);
  const double quick_stop_pps2 = units_.acceleration_pps2(objects.quick_stop_deceleration);
  const double v = ramp_.velocity();
  const bool switch_ahead =
      (inputs.right_limit && (target > 0 || v > 0)) || (inputs.left_limit && (target < 0 || v < 0));
  if (!switch_ahead && brake_onto_software_limit(target, config.amax_pps2, dt_s)) return;
  if ((limit_positive_ && (target > 0 || v > 0)) || (limit_negative_ && (target < 0 || v < 0))) {
    stop_ramp(quick_stop_pps2);
  } else {
    ramp_.set_velocity_target(target);
  }
  ramp_.step(config, dt_s);
  ramp_config_ = config;
  ramp_config_.amax_pps2 = ramp_config_.dmax_pps2 = quick_stop_pps2;
}

void AxisDriveCore::run_cyclic_torque() {
  // cst: the torque set-point goes to the axis as it is (6071 + 60B2, bounded by 6072); the
  // profile generator follows the measured motion, so that a stop or another mode goes on from it.
  follow_actual_motion();
  control_ = DriveControl::kTorque;
  if (!cyclic_latched_) cyclic_torque_ = 0;
  ramp_config_ = profile_;
}

void AxisDriveCore::update_target_reached(const AxisInputs& /*inputs*/, uint32_t dt_us) {
  const Mode mode = static_cast<Mode>(active_mode_);
  if (halted_) {
    target_reached_ = ramp_.standstill();
    return;
  }
  switch (mode) {
    case Mode::kProfilePosition: {
      if (!moving_to_target_ && !pending_) {
        target_reached_ = ramp_.standstill();
        break;
      }
      const bool demand_there = ramp_.position_reached() && !pending_;
      const uint32_t window = objects.position_window;
      if (window == 0 || window == 0xFFFF'FFFFu) {
        target_reached_ = demand_there;
        break;
      }
      const int64_t error = std::llabs(static_cast<int64_t>(drive_detail::difference(position_actual(), target_)));
      if (demand_there && error <= static_cast<int64_t>(window)) {
        in_window_us_ += dt_us;
      } else {
        in_window_us_ = 0;
      }
      target_reached_ = in_window_us_ > 0 && in_window_us_ >= static_cast<uint32_t>(objects.position_window_time_ms) * 1000u;
      break;
    }
    case Mode::kProfileVelocity: target_reached_ = ramp_.velocity_reached(); break;
    default: target_reached_ = ramp_.standstill(); break;
  }
}

int32_t AxisDriveCore::position_actual() const { return actual_position_; }

uint16_t AxisDriveCore::statusword() const {
  uint16_t sw = pds_.statusword_state_bits() | kSwRemote;
  if (set_point_refused_) sw |= kSwWarning;
  if (limit_active_) sw |= kSwInternalLimit;
  const bool enabled = pds_.state() == PdsState::kOperationEnabled;
  if (following_error_) sw |= kSwOms13;  // pp and csp define it; kept in FAULT as the cause
  // The other mode-specific bits mean something only while the drive function runs.
  if (!enabled && pds_.state() != PdsState::kQuickStopActive) return sw;
  switch (static_cast<Mode>(objects.mode)) {
    case Mode::kProfilePosition:
      if (target_reached_) sw |= kSwTargetReached;
      if (set_point_ack_) sw |= kSwOms12;
      break;
    case Mode::kProfileVelocity:
      if (target_reached_) sw |= kSwTargetReached;
      break;
    case Mode::kHoming:
      // Bit 10 while idle, cleared while homing, set with bit 12 when done (docs/tmcm-3216-drive.md).
      if (!homing_.active()) sw |= kSwTargetReached;
      if (homing_.attained()) sw |= kSwOms12;
      if (homing_.error()) sw |= kSwOms13;
      break;
    case Mode::kCyclicSyncPosition:
    case Mode::kCyclicSyncVelocity:
    case Mode::kCyclicSyncTorque:
      if (enabled && pds_.motion() == PdsMotion::kRun && !halted_) sw |= kSwOms12;
      break;
    case Mode::kNone: break;
  }
  return sw;
}

}  // namespace motwin::cia402
