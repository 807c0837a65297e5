#include "core/modules/tmcm142/tmcm142_axis.h"

#include <cmath>

#include "core/motion/microstep_table.h"

namespace motwin::modules::tmcm142 {
namespace {

constexpr double kQ32 = 4294967296.0;

double bow_pps3(int32_t bow) {
  // The maximum bow is an unlimited jerk: a trapezoid corner (SRampConfig: 0).
  return bow >= kMaxBow ? 0.0 : bow * kPps3PerBowUnit;
}

}  // namespace

void Tmcm142Axis::reset_state() {
  state = AxisState{};
  ramp_ = motion::SRamp{};
  search_ = motion::ReferenceSearch{};
  pid_ = motion::EasyPidState{};
  search_final_move_ = false;
  switch_stopping_ = false;
  deviation_event_ = false;
  encoder_ = EncoderCounter{};
  // The field stays where it was: a power-up must not make the rotor jump.
  last_ramp_q32_ = ramp_.position_q32();
  standstill_ticks_ = 0;
}

RampMode Tmcm142Axis::ramp_mode() const {
  switch (ramp_.mode()) {
    case motion::SRamp::Mode::kPosition: return RampMode::kPosition;
    case motion::SRamp::Mode::kVelocity: return RampMode::kVelocity;
    case motion::SRamp::Mode::kHold: return RampMode::kHold;
  }
  return RampMode::kPosition;
}

// A motion command ends a reference search in progress (the search drives the ramp directly).
void Tmcm142Axis::set_target_position(int32_t position) {
  search_.stop();
  search_final_move_ = false;
  switch_stopping_ = false;
  ramp_.set_position_target(clipped_to_position_limits(position));
}

// AP 50..53: a target beyond an enabled position limit ends on the limit (Motwin decision).
int32_t Tmcm142Axis::clipped_to_position_limits(int32_t target) const {
  if (config.right_position_limit_enable != 0 && target > config.right_position_limit) return config.right_position_limit;
  if (config.left_position_limit_enable != 0 && target < config.left_position_limit) return config.left_position_limit;
  return target;
}

void Tmcm142Axis::set_actual_position(int32_t position) {
  ramp_.set_position(position);
  last_ramp_q32_ = ramp_.position_q32();  // a new count, not a motion
}

void Tmcm142Axis::set_target_velocity(double velocity_pps) {
  search_.stop();
  search_final_move_ = false;
  switch_stopping_ = false;
  state.target_velocity_pps = velocity_pps;
  ramp_.set_velocity_target(velocity_pps);
}

int32_t Tmcm142Axis::set_ramp_mode(int32_t mode) {
  switch (static_cast<RampMode>(mode)) {
    case RampMode::kPosition: ramp_.set_position_target(ramp_.target_position()); return 0;
    case RampMode::kVelocity: ramp_.set_velocity_target(state.target_velocity_pps); return 0;
    case RampMode::kHold: ramp_.hold(); return 0;
  }
  return 4;
}

void Tmcm142Axis::stop() { set_target_velocity(0.0); }

void Tmcm142Axis::set_encoder_position(int32_t position) {
  encoder_.position_q16 = static_cast<int64_t>(position) * 65536;
  state.encoder_position = position;
}

tmcl::Status Tmcm142Axis::start_reference_search() {
  if (config.reference_fast_pps <= 0.0 || config.reference_slow_pps <= 0.0) return tmcl::Status::kInvalidValue;
  switch_stopping_ = false;
  search_final_move_ = false;
  const auto command = search_.start(static_cast<int32_t>(config.reference_mode), config.reference_fast_pps, config.reference_slow_pps);
  ramp_.set_velocity_target(command.velocity);
  return tmcl::Status::kOk;
}

void Tmcm142Axis::stop_reference_search() {
  if (search_.running()) set_target_velocity(0.0);
}

int32_t Tmcm142Axis::status_flags() const {
  int32_t flags = 0;
  if (position_reached()) flags |= status_flag::kPositionReached;
  if (velocity_reached()) flags |= status_flag::kVelocityReached;
  if (ramp_.standstill()) flags |= status_flag::kStandstill;
  if (state.deviation_exceeded || encoder_warning()) flags |= status_flag::kEncoderWarning;
  return flags;
}

int32_t Tmcm142Axis::encoder_deviation() const {
  return static_cast<int32_t>(static_cast<uint32_t>(state.encoder_position) - static_cast<uint32_t>(ramp_.position()));
}

// AP 47: |AP 41 - AP 1| beyond the warn distance (0 = off) sets AP 129 bit 3 (V1.06 manual).
bool Tmcm142Axis::encoder_warning() const {
  if (config.encoder_warn_distance <= 0) return false;
  const int64_t difference = encoder_deviation();
  return (difference < 0 ? -difference : difference) > config.encoder_warn_distance;
}

int32_t Tmcm142Axis::switch_status() const {
  return state.right_switch_active | (state.left_switch_active << 1) | (state.home_switch_active << 2);
}

int32_t Tmcm142Axis::driver_status() const {
  int32_t status = 0;
  if (state.standby) status |= driver_status::kStandby;
  if (state.supply_millivolt < kMinimumSupplyMillivolt) status |= driver_status::kUndervoltage;
  if (state.compare_output) status |= driver_status::kCompareOutput;
  return status;
}

// The sequencer's entry in the driver's sine table: 1024 per full step, 4096 per electrical
// period (the whole table), whatever AP 27 selects.
int32_t Tmcm142Axis::microstep_table_position() const {
  return static_cast<int32_t>(last_drive_angle_ / (board::kElectricalAnglePerFullStep / 1024u));
}

int32_t Tmcm142Axis::take_encoder_status() {
  const int32_t status = state.encoder_status;
  state.encoder_status &= ~encoder_status::kLatched;
  return status;
}

int32_t Tmcm142Axis::take_error_flags() {
  const int32_t flags = state.error_flags;
  state.error_flags = 0;
  return flags;
}

bool Tmcm142Axis::take_deviation_event() {
  const bool event = deviation_event_;
  deviation_event_ = false;
  return event;
}

int64_t Tmcm142Axis::pid_velocity_internal() const {
  const double v = std::round(ramp_.velocity() / kPpsPerVelocityUnit);
  const int64_t with_correction = static_cast<int64_t>(v) + (config.pid_mode == PidMode::kEasyPid ? pid_.correction : 0);
  if (with_correction > INT32_MAX) return INT32_MAX;
  if (with_correction < INT32_MIN) return INT32_MIN;
  return with_correction;
}

void Tmcm142Axis::read_feedback(const board::StepperFeedback& feedback) {
  bool right = (feedback.switches & 1) != 0;
  bool left = (feedback.switches & 2) != 0;
  // Level set = switch closed; AP 14 inverts each input and may swap them.
  if ((config.switch_mode & switch_mode::kInvertLeft) != 0) left = !left;
  if ((config.switch_mode & switch_mode::kInvertRight) != 0) right = !right;
  if ((config.switch_mode & switch_mode::kSwap) != 0) {
    const bool swapped = left;
    left = right;
    right = swapped;
  }
  state.right_switch_active = right ? 1 : 0;
  state.left_switch_active = left ? 1 : 0;
  state.home_switch_active = (feedback.switches & 4) != 0 ? 1 : 0;

  if (!encoder_.started) {
    encoder_.started = true;
    encoder_.last_count = feedback.encoder_count;
    encoder_.index_events = feedback.encoder_index_events;  // pulses before power-up latch nothing
  }
  int64_t counts = static_cast<int32_t>(static_cast<uint32_t>(feedback.encoder_count) - static_cast<uint32_t>(encoder_.last_count));
  encoder_.last_count = feedback.encoder_count;
  if (counts_reversed()) counts = -counts;
  encoder_.position_q16 += counts * config.encoder_constant;
  // Nearest microstep; the 32-bit register wraps.
  state.encoder_position = static_cast<int32_t>(static_cast<uint32_t>(static_cast<uint64_t>((encoder_.position_q16 + 32768) >> 16)));
  latch_on_null_channel(feedback);
  state.supply_millivolt = feedback.supply_millivolt;
}

// AP 43 bit 0 and AP 19 each reverse the count: a mirrored shaft turns the encoder with it.
bool Tmcm142Axis::counts_reversed() const {
  return ((config.encoder_mode & encoder_mode::kReverse) != 0) != (config.shaft != 0);
}

// AP 43 bits 1, 2: at an N pulse the encoder position (at the count the pulse latched) goes to
// AP 45 and the actual position to AP 46, AP 44 bit 0 is set; with bit 2 the encoder counter
// then restarts from 0 at that count.
void Tmcm142Axis::latch_on_null_channel(const board::StepperFeedback& feedback) {
  const bool pulse = feedback.encoder_index_events != encoder_.index_events;
  encoder_.index_events = feedback.encoder_index_events;
  if (!pulse || (config.encoder_mode & encoder_mode::kLatchOnNull) == 0) return;
  int64_t since_pulse = static_cast<int32_t>(static_cast<uint32_t>(feedback.encoder_count) -
                                             static_cast<uint32_t>(feedback.encoder_index_count));
  if (counts_reversed()) since_pulse = -since_pulse;
  const int64_t at_pulse_q16 = encoder_.position_q16 - since_pulse * config.encoder_constant;
  state.encoder_latch = static_cast<int32_t>(static_cast<uint32_t>(static_cast<uint64_t>((at_pulse_q16 + 32768) >> 16)));
  state.position_latch = ramp_.position();
  state.encoder_status |= encoder_status::kLatched;
  if ((config.encoder_mode & encoder_mode::kClearOnNull) != 0) {
    encoder_.position_q16 = since_pulse * config.encoder_constant;
    state.encoder_position = static_cast<int32_t>(static_cast<uint32_t>(static_cast<uint64_t>((encoder_.position_q16 + 32768) >> 16)));
  }
}

void Tmcm142Axis::run_reference_search() {
  if (!search_.running()) return;
  const auto command = search_.step(motion::ReferenceSearch::Inputs{
      state.left_switch_active != 0, state.right_switch_active != 0, ramp_.position(), position_reached()});
  using Action = motion::ReferenceSearch::Action;
  switch (command.action) {
    case Action::kNone:
      break;
    case Action::kStopAndVelocity:
      ramp_.stop_now();
      [[fallthrough]];
    case Action::kVelocity:
      ramp_.set_velocity_target(command.velocity);
      break;
    case Action::kSetPositionAndStop:
      ramp_.stop_now();
      set_actual_position(command.position);
      ramp_.set_position_target(command.position);
      state.travel = search_.measured_travel();
      break;
    case Action::kSetPositionAndMove:
      ramp_.stop_now();
      set_actual_position(command.position);
      ramp_.set_position_target(0);
      search_final_move_ = true;
      state.travel = search_.measured_travel();
      break;
    case Action::kDone:
      search_final_move_ = false;
      break;
  }
}

// A closed, enabled limit switch stops motion towards it: with AP 15 (AP 14 bit 5), else at once.
// An enabled position limit (AP 50..53) reached or passed stops motion beyond it the same way.
void Tmcm142Axis::apply_switch_stops() {
  const double v = ramp_.velocity();
  const int32_t position = ramp_.position();
  const bool right_limit = config.right_position_limit_enable != 0 && position >= config.right_position_limit;
  const bool left_limit = config.left_position_limit_enable != 0 && position <= config.left_position_limit;
  const bool right_blocks =
      v > 0.0 && ((state.right_switch_active != 0 && config.right_switch_disable == 0) || right_limit);
  const bool left_blocks = v < 0.0 && ((state.left_switch_active != 0 && config.left_switch_disable == 0) || left_limit);
  if (!right_blocks && !left_blocks) return;
  if ((config.switch_mode & switch_mode::kSoftStop) != 0) {
    if (!switch_stopping_) {
      state.target_velocity_pps = 0.0;
      ramp_.set_velocity_target(0.0);
      switch_stopping_ = true;
    }
  } else {
    ramp_.stop_now();
    if (ramp_.mode() != motion::SRamp::Mode::kPosition) {
      state.target_velocity_pps = 0.0;
      ramp_.set_velocity_target(0.0);
    }
  }
}

// AP 212: encoder and actual position further apart than allowed stop the motor at once.
void Tmcm142Axis::check_deviation() {
  const int32_t difference = encoder_deviation();
  const int64_t magnitude = difference < 0 ? -static_cast<int64_t>(difference) : difference;
  const bool exceeded = config.max_encoder_deviation > 0 && magnitude > config.max_encoder_deviation;
  if (exceeded) {
    // AP 207 and EDV report the event (the deviation starting), not the condition: AP 129 bit 3
    // shows the condition. Setting AP 207 on every tick of a lasting deviation would undo the
    // clear-on-read between two host reads.
    if (!state.deviation_exceeded) {
      deviation_event_ = true;
      state.error_flags |= error_flag::kDeviationStop;
    }
    if (!ramp_.standstill()) ramp_.stop_now();
    if (ramp_.mode() == motion::SRamp::Mode::kVelocity) {
      state.target_velocity_pps = 0.0;
      ramp_.set_velocity_target(0.0);
    }
    if (search_.running()) search_.stop();
  }
  state.deviation_exceeded = exceeded;
}

motion::SRampConfig Tmcm142Axis::ramp_config() const {
  motion::SRampConfig c;
  c.max_velocity = config.max_velocity_pps;
  if (search_.running()) {
    const double fastest = config.reference_fast_pps > config.reference_slow_pps ? config.reference_fast_pps
                                                                                 : config.reference_slow_pps;
    c.max_velocity = search_final_move_ ? config.reference_slow_pps : fastest;
  }
  c.acceleration = config.acceleration_pps2;
  c.deceleration = switch_stopping_ ? config.stop_deceleration_pps2 : config.deceleration_pps2;
  // AP 18, the one bow of the module, limits all four changes of acceleration (Motwin decision).
  for (double& bow : c.bow) bow = bow_pps3(config.max_bow);
  return c;
}

void Tmcm142Axis::tick(board::StepperPowerStage& stage) {
  read_feedback(stage.feedback);
  run_reference_search();
  if (!search_.running()) apply_switch_stops();
  ramp_.step(ramp_config(), kControlTickS);
  if (switch_stopping_ && ramp_.standstill()) switch_stopping_ = false;
  check_deviation();

  const uint64_t ramp_q32 = ramp_.position_q32();
  const auto ramp_delta_q32 = static_cast<int64_t>(ramp_q32 - last_ramp_q32_);
  last_ramp_q32_ = ramp_q32;

  if (config.pid_mode == PidMode::kEasyPid) {
    int64_t error = encoder_deviation();
    // AP 28: within the tolerance the loop sees no error (Motwin decision).
    if ((error < 0 ? -error : error) <= config.pid_tolerance) error = 0;
    const auto d_ticks = static_cast<uint32_t>(std::lround(
        (config.pid.d_clock_divider == 0 ? 256 : config.pid.d_clock_divider) * kPidDClockS / kControlTickS));
    motion::EasyPid::step(config.pid, pid_, error, static_cast<int32_t>(kPidSamplesPerTick), d_ticks);
  } else {
    pid_ = motion::EasyPidState{};
  }

  if (ramp_.standstill() && !search_.running()) {
    if (standstill_ticks_ < UINT32_MAX) ++standstill_ticks_;
  } else {
    standstill_ticks_ = 0;
  }
  const uint64_t delay_ticks = static_cast<uint64_t>(config.standby_delay_10ms) * 10 * kTicksPerMillisecond;
  state.standby = standstill_ticks_ > delay_ticks;
  state.compare_output = ramp_.position() >= config.compare_position;

  write_drive(stage.drive, ramp_delta_q32);
}

void Tmcm142Axis::write_drive(board::StepperDrive& drive, int64_t ramp_delta_q32) {
  const uint32_t microsteps = microsteps_per_full_step();
  // µsteps in Q32 -> electrical angle in Q16: x 2^30 / microsteps / 2^32 x 2^16.
  int64_t delta_q32 = ramp_delta_q32;
  if (config.pid_mode == PidMode::kEasyPid) {
    delta_q32 += static_cast<int64_t>(std::llround(pid_.correction * kPpsPerVelocityUnit * kControlTickS * kQ32));
  }
  // AP 19: the field turns the other way for the same positions.
  if (config.shaft != 0) delta_q32 = -delta_q32;
  angle_q16_ += static_cast<uint64_t>(delta_q32 * 16384 / static_cast<int64_t>(microsteps));
  // The driver's table moves in whole microsteps of the selected resolution.
  const uint32_t per_microstep = board::kElectricalAnglePerFullStep / microsteps;
  const uint64_t exact = (angle_q16_ + 32768) >> 16;
  const auto angle = static_cast<uint32_t>((exact + per_microstep / 2) / per_microstep * per_microstep);
  const motion::CoilCurrents currents = motion::coil_currents(angle, coil_current_ma());
  last_drive_angle_ = angle;
  drive.enabled = true;
  drive.electrical_angle = angle;
  drive.coil_a_ma = currents.coil_a_ma;
  drive.coil_b_ma = currents.coil_b_ma;
}

}  // namespace motwin::modules::tmcm142
