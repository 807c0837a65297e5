// The TMCM-1636 servo cascade on the power-stage seam (manual chapter 5, table 11 numbers per
// docs/decisions.md "Errata in the manuals"): measurements from ADC counts and sensor counts,
// commutation angle, encoder initialisation, position P -> velocity PI -> FOC flux/torque PI ->
// space-vector PWM, brake output, brake chopper and protections. No plant knowledge: everything
// here would run on the module's microcontroller. Structure and units: docs/tmcm-1636-servo.md.
#include <cmath>

#include "core/modules/tmcm1636/tmcm1636_axis.h"
#include "core/modules/tmcm1636/tmcm1636_hardware.h"
#include "core/motion/foc.h"

namespace motwin::modules::tmcm1636 {
namespace {

constexpr uint32_t kTicksPerSecond = 1'000'000 / kControlTickUs;
// Bandwidths of the position/velocity estimator (rad/s): encoders resolve a revolution finely,
// hall sensors give 6 steps per electrical turn.
constexpr double kEncoderEstimatorBandwidth = 1500.0;
constexpr double kHallEstimatorBandwidth = 150.0;
constexpr double kTwoPow32 = 4294967296.0;
// The PWM computed in a tick is applied during the next PWM period: the commutation angle is
// advanced by 1.5 ticks at the electrical speed so that the voltage vector lands where the rotor
// will be in the middle of that period.
constexpr double kPwmDelayTicks = 1.5;

// Half away from zero, as lround, without the library call (this runs several times a tick).
int32_t round_to_int32(double v) {
  if (v >= 2147483647.0) return INT32_MAX;
  if (v <= -2147483648.0) return INT32_MIN;
  // copysign keeps it branch-free: errors near zero change sign every tick.
  return static_cast<int32_t>(v + std::copysign(0.5, v));
}

int64_t round_to_int64(double v) { return static_cast<int64_t>(v + std::copysign(0.5, v)); }

int32_t clamp_i32(int32_t v, int32_t limit) { return v > limit ? limit : (v < -limit ? -limit : v); }

// Floor division for a positive divisor, with the remainder kept by the caller.
int64_t floor_div(int64_t a, int64_t b) {
  int64_t q = a / b;
  if ((a % b != 0) && (a < 0)) --q;
  return q;
}

int64_t positive_mod(int64_t a, int64_t b) {
  const int64_t r = a % b;
  return r < 0 ? r + b : r;
}

// Scales a delta in native units to AP 100 counts, carrying the fraction.
int64_t scale_delta(int64_t delta, int64_t counts_per_rev, int64_t native_per_rev, int64_t& remainder) {
  if (native_per_rev <= 0) return 0;
  const int64_t total = delta * counts_per_rev + remainder;
  const int64_t counts = floor_div(total, native_per_rev);
  remainder = total - counts * native_per_rev;
  return counts;
}

// ADC_VM in volts, in single precision for the current regulators.
float supply_volts_from_adc(uint16_t raw) {
  return static_cast<float>(raw) * (static_cast<float>(kSupplyFullScaleDecivolt) * 0.1f / kAdc12Max);
}

enum class PositionSource : uint8_t { kAbn, kHall, kAbsolute, kOpenLoop };

// The source of AP 52: AP 25, or with AP 25 = 0 the commutation sensor; a DC motor has only the
// ABN and the absolute encoder (docs/tmcm-1636-servo.md).
PositionSource position_source(const AxisConfig& config) {
  if (config.motor_type == MotorType::kDc) {
    return config.commutation_mode == CommutationMode::kAbsoluteEncoder ||
                   config.position_commutation_mode == PositionCommutationMode::kAbsoluteEncoder
               ? PositionSource::kAbsolute
               : PositionSource::kAbn;
  }
  if (config.position_commutation_mode == PositionCommutationMode::kAbnEncoder) return PositionSource::kAbn;
  if (config.position_commutation_mode == PositionCommutationMode::kAbsoluteEncoder) return PositionSource::kAbsolute;
  switch (config.commutation_mode) {
    case CommutationMode::kOpenLoop: return PositionSource::kOpenLoop;
    case CommutationMode::kDigitalHall: return PositionSource::kHall;
    case CommutationMode::kAbsoluteEncoder: return PositionSource::kAbsolute;
    default: return PositionSource::kAbn;
  }
}

}  // namespace

void Tmcm1636Axis::start_encoder_init(bool absolute) {
  servo_.init_for_absolute = absolute;
  servo_.init_ticks = 0;
  state.encoder_init_state = EncoderInitState::kStartInit;
  if (absolute) {
    servo_.absolute_estimated = false;
  } else {
    servo_.abn_initialised = false;
  }
}

void Tmcm1636Axis::reset_regulators() {
  motion::pi_reset(state.torque_pi);
  motion::pi_reset(state.flux_pi);
  motion::pi_reset(state.velocity_pi);
}

// Electrical angle of the commutation counter: (count - offset) * pole pairs / AP 100 turns.
// Only the fraction of a turn matters, so a double product replaces two 64-bit divisions.
uint16_t Tmcm1636Axis::abn_angle() const {
  if (config.encoder_steps <= 0) return 0;
  const double angle = static_cast<double>(servo_.abn_count - servo_.abn_reference - config.encoder_offset) *
                       (static_cast<double>(config.motor_pole_pairs) * 65536.0) * servo_.inverse_encoder_steps;
  return static_cast<uint16_t>(static_cast<int64_t>(angle >= 0.0 ? angle : angle - 1.0));
}

uint16_t Tmcm1636Axis::absolute_angle(uint16_t mechanical) const {
  const auto relative = static_cast<uint32_t>(mechanical) - static_cast<uint32_t>(config.absolute_encoder_offset);
  return static_cast<uint16_t>(relative * static_cast<uint32_t>(config.motor_pole_pairs));
}

// Reads the sensors of one tick: the commutation counter, N pulses, hall sectors and the
// absolute angle; moves AP 52 by the selected position source and estimates the velocity.
void Tmcm1636Axis::read_sensors(const board::Tmcm1636Feedback& feedback, double dt_s) {
  const uint16_t absolute = absolute_reading(feedback.absolute_angle);
  if (!servo_.started) start_sensors(feedback, absolute);
  const SensorDeltas deltas = sensor_deltas(feedback, absolute);
  update_position(deltas, dt_s);
  // Commutation angles (AP 16..19).
  state.open_loop_angle = static_cast<int16_t>(static_cast<uint16_t>(servo_.open_loop_phase >> 16));
  state.encoder_angle = static_cast<int16_t>(abn_angle());
  state.hall_angle = static_cast<int16_t>(servo_.hall.angle());
  state.absolute_encoder_angle = static_cast<int16_t>(absolute_angle(servo_.absolute_last));
  find_encoder_offset(deltas);
}

motion::HallConfig Tmcm1636Axis::hall_config() const {
  return motion::HallConfig{config.hall_polarity != 0, config.hall_direction != 0, config.hall_interpolation != 0,
                            config.hall_phi_e_offset};
}

// The absolute encoder's angle at its resolution (AP 160) and in its direction (AP 162).
uint16_t Tmcm1636Axis::absolute_reading(uint16_t raw) const {
  uint16_t absolute = raw;
  if (config.absolute_encoder_type == AbsoluteEncoderType::kAmt20) absolute &= 0xFFF0;  // 12 bits
  if (config.absolute_encoder_type == AbsoluteEncoderType::kAmt23) absolute &= 0xFFFC;  // 14 bits
  if (config.absolute_encoder_direction != 0) absolute = static_cast<uint16_t>(-absolute);
  return absolute;
}

// The first tick since power-up: the sensors' readings become the references of their deltas.
void Tmcm1636Axis::start_sensors(const board::Tmcm1636Feedback& feedback, uint16_t absolute) {
  Servo& s = servo_;
  s.started = true;
  s.abn_last_raw = feedback.abn_count;
  s.abn_index_events = feedback.abn_index_events;
  s.absolute_last = absolute;
  s.hall.update(feedback.hall, hall_config());
  s.hall_last_steps = s.hall.steps();
  s.open_loop_last = s.open_loop_phase;
  s.pll.reset(0);
}

// How far each sensor moved since the last tick; the commutation counter follows the ABN
// encoder (AP 101 applied) and an N pulse is noted with the counts since it.
Tmcm1636Axis::SensorDeltas Tmcm1636Axis::sensor_deltas(const board::Tmcm1636Feedback& feedback, uint16_t absolute) {
  Servo& s = servo_;
  SensorDeltas deltas;
  // ABN: the counter is free running; only its deltas count.
  const bool reversed = config.encoder_direction != 0;
  const auto raw_delta =
      static_cast<int32_t>(static_cast<uint32_t>(feedback.abn_count) - static_cast<uint32_t>(s.abn_last_raw));
  s.abn_last_raw = feedback.abn_count;
  deltas.abn = reversed ? -static_cast<int64_t>(raw_delta) : raw_delta;
  s.abn_count += deltas.abn;
  if (feedback.abn_index_events != s.abn_index_events) {
    s.abn_index_events = feedback.abn_index_events;
    deltas.index = true;
    const auto since = static_cast<int32_t>(static_cast<uint32_t>(feedback.abn_count) -
                                            static_cast<uint32_t>(feedback.abn_index_count));
    deltas.counts_since_index = reversed ? -static_cast<int64_t>(since) : since;
  }

  s.hall.update(feedback.hall, hall_config());
  deltas.hall = s.hall.steps() - s.hall_last_steps;
  s.hall_last_steps = s.hall.steps();

  if (config.absolute_encoder_type != AbsoluteEncoderType::kNone && feedback.absolute_valid) {
    deltas.absolute = static_cast<int16_t>(static_cast<uint16_t>(absolute - s.absolute_last));
    s.absolute_last = absolute;
  }
  deltas.open_loop = static_cast<int32_t>(s.open_loop_phase - s.open_loop_last);
  s.open_loop_last = s.open_loop_phase;
  return deltas;
}

// AP 52 moves by the position source's delta in AP 100 counts (AP 107/108 may clear it at the
// N pulse); the estimator follows the source and gives the velocity (AP 42).
void Tmcm1636Axis::update_position(const SensorDeltas& deltas, double dt_s) {
  Servo& s = servo_;
  const int64_t steps = config.encoder_steps;
  const int64_t pole_pairs = config.motor_pole_pairs;
  int64_t delta = 0;
  double bandwidth = kEncoderEstimatorBandwidth;
  switch (position_source(config)) {
    case PositionSource::kAbn:
      delta = deltas.abn;
      break;
    case PositionSource::kHall:
      delta = scale_delta(deltas.hall, steps, 6 * pole_pairs, s.hall_remainder);
      bandwidth = kHallEstimatorBandwidth;
      break;
    case PositionSource::kAbsolute:
      delta = scale_delta(deltas.absolute, steps, 65536, s.absolute_remainder);
      break;
    case PositionSource::kOpenLoop:
      delta = scale_delta(deltas.open_loop, steps, pole_pairs << 32, s.open_loop_remainder);
      break;
  }
  s.sensor_position += delta;
  state.actual_position = static_cast<int32_t>(static_cast<uint32_t>(state.actual_position) + static_cast<uint32_t>(delta));
  // AP 107/108: the N pulse clears the position counter (once, or at every pulse).
  if (deltas.index && s.clear_armed && config.clear_on_null != 0) {
    state.actual_position = static_cast<int32_t>(deltas.counts_since_index);
    if (config.clear_once != 0) s.clear_armed = false;
  }
  s.pll.update(s.sensor_position, dt_s, bandwidth);
  s.velocity_counts_per_s = s.pll.velocity();
  state.actual_velocity_rpm = round_to_int32(to_rpm(s.velocity_counts_per_s));
}

// An ABN encoder initialisation waiting for its event (AP 102) takes the commutation offset
// (AP 106) from it.
void Tmcm1636Axis::find_encoder_offset(const SensorDeltas& deltas) {
  Servo& s = servo_;
  const int64_t steps = config.encoder_steps;
  const int64_t pole_pairs = config.motor_pole_pairs;
  if (state.encoder_init_state != EncoderInitState::kWaitInitTime || s.init_for_absolute || steps <= 0 ||
      pole_pairs <= 0) {
    return;
  }
  // N channel: the offset relative to the pulse, from the field angle the rotor follows in open
  // loop (the rotor lags it by its small load angle).
  if (deltas.index && config.encoder_init_mode == EncoderInitMode::kNChannel) {
    s.abn_reference = s.abn_count - deltas.counts_since_index;
    const int64_t field = (s.open_loop_phase >> 16) * steps / (pole_pairs * 65536);
    config.encoder_offset = static_cast<int32_t>(positive_mod(deltas.counts_since_index - field, steps));
    state.encoder_init_state = EncoderInitState::kEstimateOffset;
    return;
  }
  // "Use hall": the first hall edge is an exact electrical angle.
  if (s.hall.edge() && config.encoder_init_mode == EncoderInitMode::kUseHall) {
    const int64_t edge = static_cast<int64_t>(s.hall.edge_angle()) * steps / (pole_pairs * 65536);
    config.encoder_offset = static_cast<int32_t>(positive_mod(s.abn_count - s.abn_reference - edge, steps));
    state.encoder_init_state = EncoderInitState::kEstimateOffset;
  }
}

// Runs the initialisation states that own the current loop (estimate offset, N channel).
// Returns true when it sets the angle and the flux current of this tick itself.
bool Tmcm1636Axis::run_encoder_init(const board::Tmcm1636Feedback& /*feedback*/, uint16_t& angle, float& id_ref,
                                    double dt_s) {
  Servo& s = servo_;
  const bool estimate = s.init_for_absolute || config.encoder_init_mode == EncoderInitMode::kEstimateOffset;
  const bool index_search = !s.init_for_absolute && config.encoder_init_mode == EncoderInitMode::kNChannel;
  switch (state.encoder_init_state) {
    case EncoderInitState::kIdle:
      return false;
    case EncoderInitState::kStartInit:
      reset_regulators();
      s.init_ticks = 0;
      state.encoder_init_state = EncoderInitState::kWaitInitTime;
      break;
    case EncoderInitState::kWaitInitTime: {
      if (estimate) {
        // Force the rotor to electrical 90°, then to 0°; two steps, so that a rotor standing
        // exactly opposite the first field still gets pulled round by the second.
        const uint32_t ticks = static_cast<uint32_t>(config.encoder_init_delay_ms) * (kTicksPerSecond / 1000);
        angle = s.init_ticks < ticks / 2 ? 16384 : 0;
        id_ref = static_cast<float>(config.open_loop_current_ma);
        if (++s.init_ticks >= ticks) state.encoder_init_state = EncoderInitState::kEstimateOffset;
        return true;
      }
      if (index_search) {
        const double turns_per_tick = config.encoder_init_velocity_rpm / 60.0 * config.motor_pole_pairs * dt_s;
        s.open_loop_phase += static_cast<uint32_t>(static_cast<int64_t>(round_to_int64(turns_per_tick * kTwoPow32)));
        angle = static_cast<uint16_t>(s.open_loop_phase >> 16);
        id_ref = static_cast<float>(config.open_loop_current_ma);
        return true;
      }
      return false;  // "use hall": normal regulation on the hall angle until an edge
    }
    case EncoderInitState::kEstimateOffset: {
      if (estimate) {
        if (s.init_for_absolute) {
          config.absolute_encoder_offset = s.absolute_last;
          s.absolute_estimated = true;
        } else if (config.encoder_steps > 0) {
          s.abn_reference = 0;
          config.encoder_offset =
              static_cast<int32_t>(positive_mod(s.abn_count - s.abn_reference, config.encoder_steps));
        }
      }
      if (!s.init_for_absolute) s.abn_initialised = true;
      state.encoder_init_state = EncoderInitState::kIdle;
      reset_regulators();
      seed_ramp();
      if (state.mode == MotionMode::kPosition) ramp_.set_position_target(ramp_.target_position());
      break;
    }
  }
  angle = 0;
  id_ref = 0.0f;
  return estimate || index_search;
}

void Tmcm1636Axis::update_protection(const board::Tmcm1636Feedback& feedback, int32_t supply_decivolt) {
  Servo& s = servo_;
  if (supply_decivolt < kUndervoltageTripDecivolt) s.undervoltage = true;
  if (supply_decivolt > kUndervoltageClearDecivolt) s.undervoltage = false;
  if (supply_decivolt >= kOvervoltageTripDecivolt) s.overvoltage = true;
  if (supply_decivolt < kOvervoltageClearDecivolt) s.overvoltage = false;
  const int32_t celsius = temperature_celsius_from_adc(feedback.adc_temperature);
  if (celsius >= kOvertemperatureTripCelsius) s.overtemperature = true;
  if (celsius < kOvertemperatureClearCelsius) s.overtemperature = false;
  // Brake chopper (AP 140..144): on above the limit, off below limit - hysteresis.
  if (config.brake_chopper_enabled == 0) {
    s.chopper_on = false;
  } else if (supply_decivolt >= config.brake_chopper_limit_decivolt) {
    s.chopper_on = true;
  } else if (supply_decivolt < config.brake_chopper_limit_decivolt - config.brake_chopper_hysteresis_decivolt) {
    s.chopper_on = false;
  }
  state.brake_chopper_active = s.chopper_on ? 1 : 0;
}

// Brake output (AP 120..125): releasing duty for the releasing time, then holding duty.
void Tmcm1636Axis::update_brake(board::Tmcm1636Drive& drive, double dt_s) {
  Servo& s = servo_;
  const int32_t release = state.release_brake;
  if (release != 0 && s.brake_previous_release == 0) s.brake_release_ticks = 0;
  s.brake_previous_release = release;
  int32_t duty = 0;
  if (release != 0) {
    const double elapsed_ms = static_cast<double>(s.brake_release_ticks) * dt_s * 1000.0;
    duty = elapsed_ms < config.brake_release_duration_ms ? config.brake_release_duty_percent
                                                         : config.brake_hold_duty_percent;
    if (s.brake_release_ticks < 0xFFFFFFFFu) ++s.brake_release_ticks;
  }
  // AP 124: 0 enables the function (manual). AP 125 = 0, the manual's "inverted" and its
  // default, drives the connector as computed; 1 complements it (docs/tmcm-1636-servo.md).
  if (config.brake_output == BrakeOutput::kDisabled) {
    drive.brake_duty_percent = 0;
    return;
  }
  drive.brake_duty_percent =
      static_cast<uint8_t>(config.brake_output_polarity == BrakeOutputPolarity::kAsComputed ? duty : 100 - duty);
}

// The velocity demand of velocity and position modes (rpm): ramp generator (AP 44/45),
// position P (AP 74) with the ramp velocity as feed-forward, limit AP 43, reference switches.
float Tmcm1636Axis::velocity_reference_rpm(double dt_s) {
  const motion::TrapezoidRampConfig ramp_config{
      to_counts_per_s(config.max_velocity_rpm),
      to_counts_per_s(config.acceleration_rpm_per_s),
      config.velocity_ramp_enabled != 0,
  };
  const bool open_loop = config.motor_type == MotorType::kBldc && config.commutation_mode == CommutationMode::kOpenLoop;
  double velocity_rpm = 0.0;
  if (external_reference_) {
    // follow_position / follow_velocity set the reference; it moves on with its velocity until the
    // next one (the drive gives one a millisecond).
    advance_reference(dt_s);
    velocity_rpm = to_rpm(ramp_.velocity());
  } else if (state.mode == MotionMode::kVelocity) {
    ramp_.set_velocity_target(to_counts_per_s(state.target_velocity_rpm));
    ramp_.step(ramp_config, dt_s);
    velocity_rpm = to_rpm(ramp_.velocity());
  } else if (config.velocity_ramp_enabled != 0 || open_loop) {
    ramp_.step(ramp_config, dt_s);
    velocity_rpm = to_rpm(ramp_.velocity());
  } else {
    // No ramp: the reference jumps to the target and position P alone sets the velocity,
    // limited by AP 43 (manual 5.5.2.1).
    ramp_.set_state(ramp_.target_position(), 0.0);
  }
  if (state.mode == MotionMode::kPosition && !open_loop) {
    const auto error_counts =
        static_cast<int32_t>(static_cast<uint32_t>(ramp_.position()) - static_cast<uint32_t>(state.actual_position));
    // The regulator's unit: 1/65536 revolution (saturates far beyond where AP 43 clips the output).
    const int32_t error = round_to_int32(static_cast<double>(error_counts) * kPositionErrorUnitsPerRevolution *
                                         servo_.inverse_encoder_steps);
    velocity_rpm += motion::pi_apply(config.position_pi, kPositionPiScale, state.position_pi, error, 1e9f);
  }
  const double limit = config.max_velocity_rpm;
  if (velocity_rpm > limit || velocity_rpm < -limit) {
    velocity_rpm = velocity_rpm > 0.0 ? limit : -limit;
    servo_.flags |= status_flag::kVelocityLimit;
  }
  if (switch_blocks(velocity_rpm)) {
    stop_at_switch();
    velocity_rpm = 0.0;
  }
  return static_cast<float>(velocity_rpm);
}

// One tick of the cascade: scales, switches and measurements in, protections, brake and
// chopper, then either the regulators drive the bridge or the motor coasts; AP 55, the loop
// counters and the status flags last.
void Tmcm1636Axis::servo_tick(board::Tmcm1636PowerStage& stage, double dt_s) {
  const board::Tmcm1636Feedback& feedback = stage.feedback;
  board::Tmcm1636Drive& drive = stage.drive;
  servo_.flags = 0;
  refresh_velocity_scales();
  update_switches(feedback.reference_switches);
  const PhaseCurrents currents = measure_phase_currents(feedback);
  read_sensors(feedback, dt_s);
  update_protection(feedback, supply_decivolt_from_adc(feedback.adc_supply));
  drive.brake_chopper_on = servo_.chopper_on;
  drive.pwm_frequency_hz = static_cast<uint32_t>(config.pwm_frequency_hz);
  update_brake(drive, dt_s);

  // Only a BLDC motor has a commutation offset to find.
  if (config.motor_type != MotorType::kBldc) state.encoder_init_state = EncoderInitState::kIdle;
  const bool bridge = bridge_switches();
  if (bridge) {
    regulate_currents(feedback, currents, supply_volts_from_adc(feedback.adc_supply), drive, dt_s);
  } else {
    coast(currents, drive);
  }

  update_position_reached_servo();
  count_loops();
  state.status_flags = servo_status_flags(bridge);
}

// rpm <-> counts/s factors and 1 / AP 100 for this tick (AP 100 may have changed).
void Tmcm1636Axis::refresh_velocity_scales() {
  counts_per_s_per_rpm_ = static_cast<double>(config.encoder_steps) * (1.0 / 60.0);
  servo_.inverse_encoder_steps = config.encoder_steps > 0 ? 1.0 / static_cast<double>(config.encoder_steps) : 0.0;
  rpm_per_count_per_s_ = 60.0 * servo_.inverse_encoder_steps;
}

// AP 0..4: the shunt readings and the phase currents in mA (phase C from the other two).
Tmcm1636Axis::PhaseCurrents Tmcm1636Axis::measure_phase_currents(const board::Tmcm1636Feedback& feedback) {
  state.adc_phase_a_raw = feedback.adc_phase_a;
  state.adc_phase_b_raw = feedback.adc_phase_b;
  state.adc_phase_a = static_cast<int32_t>(
      (static_cast<int64_t>(feedback.adc_phase_a) - config.adc_phase_a_offset) * config.dual_shunt_factor / 256);
  state.adc_phase_b = static_cast<int32_t>(
      (static_cast<int64_t>(feedback.adc_phase_b) - config.adc_phase_b_offset) * config.dual_shunt_factor / 256);
  state.adc_phase_c = -state.adc_phase_a - state.adc_phase_b;
  return PhaseCurrents{static_cast<float>(state.adc_phase_a), static_cast<float>(state.adc_phase_b)};
}

// The bridge switches when the driver is enabled (AP 255), a motor type and a commutation mode
// are set and no protection has tripped.
bool Tmcm1636Axis::bridge_switches() const {
  const bool motor = config.motor_type == MotorType::kBldc || config.motor_type == MotorType::kDc;
  const bool fault = servo_.undervoltage || servo_.overvoltage || servo_.overtemperature;
  return state.driver_enabled != 0 && motor && config.commutation_mode != CommutationMode::kDisabled && !fault;
}

// Bridge off: the regulators rest and the reference follows the coasting motor, so that
// switching on again is bumpless; the currents are still measured (at angle 0).
void Tmcm1636Axis::coast(const PhaseCurrents& currents, board::Tmcm1636Drive& drive) {
  reset_regulators();
  drive.bridge_enabled = false;
  drive.duty[0] = drive.duty[1] = drive.duty[2] = 0.5f;
  if (state.mode != MotionMode::kTorque) ramp_.set_state(state.actual_position, servo_.velocity_counts_per_s);
  state.ramp_velocity_rpm = state.mode == MotionMode::kTorque ? 0 : round_to_int32(to_rpm(ramp_.velocity()));
  const motion::Dq measured = motion::park(motion::clarke(currents.a, currents.b), motion::sin_cos(0));
  state.actual_torque_ma = round_to_int32(measured.q);
  state.actual_flux_ma = round_to_int32(measured.d);
}

// Bridge on: the current demand of this tick, then the current regulators of the motor type.
void Tmcm1636Axis::regulate_currents(const board::Tmcm1636Feedback& feedback, const PhaseCurrents& currents,
                                     float supply_volts, board::Tmcm1636Drive& drive, double dt_s) {
  const CurrentDemand demand = current_demand(feedback, dt_s);
  ++servo_.torque_loops;
  drive.bridge_enabled = true;
  if (config.motor_type == MotorType::kDc) {
    regulate_dc_current(demand, currents, supply_volts, drive);
  } else {
    regulate_foc_currents(demand, currents, supply_volts, drive, dt_s);
  }
}

// The field angle and the current references: from a running encoder initialisation that
// drives the field itself, else from the motion mode and the commutation mode.
Tmcm1636Axis::CurrentDemand Tmcm1636Axis::current_demand(const board::Tmcm1636Feedback& feedback, double dt_s) {
  CurrentDemand demand;
  demand.electrical_turns_per_s =
      servo_.velocity_counts_per_s * servo_.inverse_encoder_steps * config.motor_pole_pairs;
  const bool bldc = config.motor_type == MotorType::kBldc;
  if (bldc && state.encoder_init_state != EncoderInitState::kIdle &&
      run_encoder_init(feedback, demand.angle, demand.id_ref, dt_s)) {
    demand.electrical_turns_per_s = 0.0;
    return demand;
  }
  const bool open_loop = bldc && config.commutation_mode == CommutationMode::kOpenLoop;
  if (state.mode == MotionMode::kTorque) {
    torque_mode_demand(open_loop, demand);
  } else {
    velocity_mode_demand(open_loop, demand, dt_s);
  }
  demand.angle = commutation_angle(demand.angle);
  return demand;
}

// Torque mode: AP 30/32 limited by AP 11; an enabled reference switch stops the torque towards
// it. In open loop the field stands with the open-loop current (AP 12).
void Tmcm1636Axis::torque_mode_demand(bool open_loop, CurrentDemand& demand) {
  demand.iq_ref = static_cast<float>(clamp_i32(state.target_torque_ma, config.max_current_ma));
  demand.id_ref = static_cast<float>(clamp_i32(state.target_flux_ma, config.max_current_ma));
  if (std::abs(state.target_torque_ma) > config.max_current_ma) servo_.flags |= status_flag::kCurrentLimit;
  if (switch_blocks(demand.iq_ref)) {
    stop_at_switch();
    demand.iq_ref = 0.0f;
  }
  state.ramp_velocity_rpm = 0;
  if (open_loop) demand.id_ref = static_cast<float>(config.open_loop_current_ma);
  demand.electrical_turns_per_s = open_loop ? 0.0 : demand.electrical_turns_per_s;
}

// Velocity and position modes: the velocity demand, then either the field turns at it in open
// loop with the open-loop current (AP 12) or the velocity PI sets the torque current.
void Tmcm1636Axis::velocity_mode_demand(bool open_loop, CurrentDemand& demand, double dt_s) {
  const float velocity_ref = velocity_reference_rpm(dt_s);
  state.ramp_velocity_rpm = round_to_int32(to_rpm(ramp_.velocity()));
  if (open_loop) {
    demand.electrical_turns_per_s = velocity_ref / 60.0 * config.motor_pole_pairs;
    servo_.open_loop_phase += static_cast<uint32_t>(
        static_cast<int64_t>(round_to_int64(demand.electrical_turns_per_s * dt_s * kTwoPow32)));
    demand.id_ref = static_cast<float>(config.open_loop_current_ma);
  } else {
    const int32_t error = round_to_int32(velocity_ref - to_rpm(servo_.velocity_counts_per_s));
    demand.iq_ref =
        motion::pi_apply(config.velocity_pi, kVelocityPiScale, state.velocity_pi, error, static_cast<float>(config.max_current_ma));
    if (state.velocity_pi.limited) servo_.flags |= status_flag::kCurrentLimit;
    ++servo_.velocity_loops;
  }
}

// The electrical angle of the commutation mode (AP 15); `otherwise` without one.
uint16_t Tmcm1636Axis::commutation_angle(uint16_t otherwise) const {
  const Servo& s = servo_;
  switch (config.commutation_mode) {
    case CommutationMode::kOpenLoop: return static_cast<uint16_t>(s.open_loop_phase >> 16);
    case CommutationMode::kDigitalHall: return s.hall.angle();
    case CommutationMode::kAbnEncoder:
      // "Use hall" initialisation: hall commutation until the first edge.
      return state.encoder_init_state != EncoderInitState::kIdle && config.encoder_init_mode == EncoderInitMode::kUseHall
                 ? s.hall.angle()
                 : abn_angle();
    case CommutationMode::kAbsoluteEncoder: return absolute_angle(s.absolute_last);
    default: return otherwise;
  }
}

// DC motor between U and V: one current, one voltage (torque regulator only).
void Tmcm1636Axis::regulate_dc_current(const CurrentDemand& demand, const PhaseCurrents& currents, float supply_volts,
                                       board::Tmcm1636Drive& drive) {
  state.actual_torque_ma = state.adc_phase_a;
  state.actual_flux_ma = 0;
  const float volts_mv = motion::pi_apply(config.current_pi, kCurrentPiScale, state.torque_pi,
                                          round_to_int32(demand.iq_ref - currents.a), supply_volts * 1000.0f);
  motion::pi_reset(state.flux_pi);
  if (state.torque_pi.limited) servo_.flags |= status_flag::kVoltageLimit;
  const float half = supply_volts > 0.0f ? 0.5f * volts_mv * 0.001f / supply_volts : 0.0f;
  drive.duty[0] = 0.5f + half;
  drive.duty[1] = 0.5f - half;
  drive.duty[2] = 0.5f;
}

// BLDC motor: Clarke and Park at the field angle, the flux and torque PI within the voltage
// space-vector modulation can give, inverse Park at the angle advanced by the PWM delay, SVM.
void Tmcm1636Axis::regulate_foc_currents(const CurrentDemand& demand, const PhaseCurrents& currents,
                                         float supply_volts, board::Tmcm1636Drive& drive, double dt_s) {
  const motion::SinCos angle_sin_cos = motion::sin_cos(demand.angle);
  const motion::Dq measured = motion::park(motion::clarke(currents.a, currents.b), angle_sin_cos);
  state.actual_torque_ma = round_to_int32(measured.q);
  state.actual_flux_ma = round_to_int32(measured.d);
  const float limit_mv = motion::svm_voltage_limit(supply_volts) * 1000.0f;
  motion::pi_apply_vector(config.current_pi, kCurrentPiScale, state.flux_pi, state.torque_pi, round_to_int32(demand.id_ref - measured.d),
                          round_to_int32(demand.iq_ref - measured.q), limit_mv);
  if (state.torque_pi.limited) servo_.flags |= status_flag::kVoltageLimit;
  // The advance is a few degrees: rotate the measurement angle's sin/cos by it.
  const auto advance = static_cast<float>(demand.electrical_turns_per_s * kPwmDelayTicks * dt_s * motion::kTwoPi);
  const motion::AlphaBeta volts =
      motion::inverse_park(motion::Dq{state.flux_pi.output * 0.001f, state.torque_pi.output * 0.001f},
                           motion::rotate(angle_sin_cos, advance));
  const motion::Duties duties = motion::svm(volts, supply_volts);
  drive.duty[0] = duties.a;
  drive.duty[1] = duties.b;
  drive.duty[2] = duties.c;
}

// Loops per second (AP 230..232), counted over each simulated second.
void Tmcm1636Axis::count_loops() {
  Servo& s = servo_;
  if (++s.window_ticks >= kTicksPerSecond) {
    state.main_loops_per_s = s.window_ticks;
    state.torque_loops_per_s = s.torque_loops;
    state.velocity_loops_per_s = s.velocity_loops;
    s.window_ticks = 0;
    s.torque_loops = 0;
    s.velocity_loops = 0;
  }
}

// AP 156: the limits met during the tick and the conditions at its end.
uint32_t Tmcm1636Axis::servo_status_flags(bool bridge) const {
  const Servo& s = servo_;
  const CommutationMode commutation = config.commutation_mode;
  uint32_t flags = s.flags;
  if (state.driver_enabled != 0) flags |= status_flag::kDriverEnabled;
  if (bridge) flags |= status_flag::kPowerStageOn;
  flags |= state.mode == MotionMode::kTorque     ? status_flag::kTorqueMode
           : state.mode == MotionMode::kPosition ? status_flag::kPositionMode
                                                 : status_flag::kVelocityMode;
  if (state.position_reached != 0) flags |= status_flag::kPositionReached;
  if (s.abn_initialised) flags |= status_flag::kEncoderInitialised;
  if (state.encoder_init_state != EncoderInitState::kIdle) flags |= status_flag::kEncoderInitRunning;
  if (config.absolute_encoder_type != AbsoluteEncoderType::kNone &&
      (config.absolute_encoder_init == AbsoluteEncoderInit::kUseOffset || s.absolute_estimated)) {
    flags |= status_flag::kAbsoluteEncoderReady;
  }
  const bool hall_used = commutation == CommutationMode::kDigitalHall ||
                         (commutation == CommutationMode::kAbnEncoder && config.encoder_init_mode == EncoderInitMode::kUseHall);
  if (hall_used && !s.hall.valid()) flags |= status_flag::kHallError;
  if (state.release_brake != 0 && config.brake_output == BrakeOutput::kEnabled) flags |= status_flag::kBrakeReleased;
  if (s.chopper_on) flags |= status_flag::kBrakeChopperActive;
  if (s.undervoltage) flags |= status_flag::kUndervoltage;
  if (s.overvoltage) flags |= status_flag::kOvervoltage;
  if (s.overtemperature) flags |= status_flag::kOvertemperature;
  if (switch_blocks(1.0)) flags |= status_flag::kRightSwitchStop;
  if (switch_blocks(-1.0)) flags |= status_flag::kLeftSwitchStop;
  return flags;
}

}  // namespace motwin::modules::tmcm1636
