#include "sim/modules/tmcm142/tmcm142_sim_board.h"

namespace motwin::sim {
namespace {

constexpr SignalInfo kMotorSignals[] = {
    {"LOAD_TORQUE", -100, 100, false, "load torque in N m against forward rotation (physical motor)", "N m"},
    {"LOAD_INERTIA", 0, 10, false, "inertia coupled to the rotor in kg m^2 (physical motor)", "kg m²"},
    {"BLOCKED", 0, 1, true, "1 blocks the rotor: an obstacle, every step is lost (physical motor)"},
    {"REF_R", 0, 1, true, "right limit switch level, 1 = closed (releases REF_R_AT/FROM/TO)"},
    {"REF_L", 0, 1, true, "left limit switch level, 1 = closed"},
    {"REF_H", 0, 1, true, "home switch level, 1 = closed"},
    {"REF_R_AT", -1e6, 1e6, false, "right switch closed at rotor positions >= this, revolutions", "rev"},
    {"REF_L_AT", -1e6, 1e6, false, "left switch closed at rotor positions <= this, revolutions", "rev"},
    {"REF_H_AT", -1e6, 1e6, false, "home switch closed at rotor positions >= this, revolutions", "rev"},
    {"REF_R_FROM", -1e6, 1e6, false, "right switch window: closed from this rotor position on, revolutions", "rev"},
    {"REF_R_TO", -1e6, 1e6, false, "right switch window: closed up to this rotor position, revolutions", "rev"},
    {"REF_L_FROM", -1e6, 1e6, false, "left switch window (a cam): closed from this position on, revolutions", "rev"},
    {"REF_L_TO", -1e6, 1e6, false, "left switch window: closed up to this position, revolutions", "rev"},
    {"REF_H_FROM", -1e6, 1e6, false, "home switch window: closed from this position on, revolutions", "rev"},
    {"REF_H_TO", -1e6, 1e6, false, "home switch window: closed up to this position, revolutions", "rev"},
    {"ENCODER_CPR", 0, 1e6, true, "encoder quadrature counts per revolution, 0 = no encoder (default 4000)",
     "counts/rev"},
    {"ENCODER_REVERSED", 0, 1, true, "1: the encoder counts down for forward rotation"},
    {"ENCODER_INDEX_AT", 0, 0.999999, false, "rotor angle of the N pulse within a revolution, revolutions", "rev"},
    {"ENCODER_FAULT", 0, 1, true, "1 freezes the encoder counter: lost A/B/N signals"},
};

enum MotorSignal : size_t {
  kLoadTorque,
  kLoadInertia,
  kBlocked,
  kRefRight,  // REF_R ... REF_H_TO in the order of StepperSwitchSources::SwitchSignal
  kEncoderCpr = kRefRight + StepperSwitchSources::kSignalCount,
  kEncoderReversed,
  kEncoderIndexAt,
  kEncoderFault,
};
static_assert(kEncoderFault + 1 == std::size(kMotorSignals));

}  // namespace

std::span<const SignalInfo> Tmcm142SimBoard::signal_table() {
  static const std::vector<SignalInfo> table = concat_signals(Tmcm142SimIo::signal_table(), kMotorSignals);
  return table;
}

Tmcm142SimBoard::Tmcm142SimBoard(Tmcm142SimIo& io) : SimBoardOverIo(io) {
  apply_sensor_config();
  before_tick();
}

Tmcm142SimBoard::Tmcm142SimBoard(Tmcm142SimIo& io, const StepperMotorDescription& motor, int sub_steps)
    : SimBoardOverIo(io), plant_(std::make_unique<StepperPlant>(motor, sub_steps)) {
  ideal_.full_steps_per_revolution = motor.full_steps_per_revolution;
  apply_sensor_config();
  before_tick();
}

double Tmcm142SimBoard::rotor_revolutions() const {
  return plant_ ? plant_->position_revolutions() : ideal_.position_revolutions();
}

void Tmcm142SimBoard::set_rotor_revolutions(double position) {
  if (plant_) {
    plant_->set_position_revolutions(position);
  } else {
    ideal_.set_position_revolutions(position);
  }
  before_tick();
}

void Tmcm142SimBoard::before_tick() {
  board::StepperFeedback& feedback = stage_.feedback;
  sensors_.sense(rotor_revolutions(), feedback);
  // N pulses counted before the index angle last changed (see set_input) carry on.
  const uint32_t events_since_restart = feedback.encoder_index_events;
  feedback.encoder_index_events += index_events_carry_;
  if (events_since_restart == 0) feedback.encoder_index_count = index_count_carry_;
  encoder_freeze_.apply(feedback);
  switches_.add_levels(feedback.switches);
  feedback.supply_millivolt = io_.supply_millivolt();
}

void Tmcm142SimBoard::set_input(std::string_view name, double value) {
  const SignalInfo* motor_signal = find_signal(kMotorSignals, name);
  if (motor_signal == nullptr) {
    io_.set_input(name, value);
    return;
  }
  const auto index = static_cast<size_t>(motor_signal - kMotorSignals);
  if (index >= kRefRight && index < kEncoderCpr) {
    switches_.set(index - kRefRight, value);
  } else {
    switch (static_cast<MotorSignal>(index)) {
      case kLoadTorque: load_torque_ = value; break;
      case kLoadInertia: load_inertia_ = value; break;
      case kBlocked: blocked_ = value != 0; break;
      case kEncoderCpr: encoder_.counts_per_revolution = static_cast<int32_t>(value); break;
      case kEncoderReversed: encoder_.reversed = value != 0; break;
      case kEncoderIndexAt:
        // A new index angle is a different encoder mounting, not a crossing: the sensors start
        // afresh at the present rotor position, and the N pulse counter carries on.
        encoder_.index_revolutions = value;
        index_events_carry_ = stage_.feedback.encoder_index_events;
        index_count_carry_ = stage_.feedback.encoder_index_count;
        sensors_ = StepperSensors{};
        break;
      case kEncoderFault: encoder_freeze_.set_fault(value != 0); break;
      default: break;
    }
    apply_motor_settings();
  }
  apply_sensor_config();
}

void Tmcm142SimBoard::apply_motor_settings() {
  if (!plant_) return;
  plant_->set_load_torque_nm(load_torque_);
  plant_->set_load_inertia_kg_m2(load_inertia_);
  plant_->set_blocked(blocked_);
}

void Tmcm142SimBoard::apply_sensor_config() {
  StepperSensorConfig config;
  config.encoder = encoder_;
  switches_.configure(config);
  sensors_.set_config(config);
}

std::optional<double> Tmcm142SimBoard::read_signal(std::string_view name) const {
  if (const SignalInfo* motor_signal = find_signal(kMotorSignals, name)) {
    const auto index = static_cast<size_t>(motor_signal - kMotorSignals);
    if (index >= kRefRight && index < kEncoderCpr) return switches_.read(index - kRefRight, stage_.feedback.switches);
    switch (static_cast<MotorSignal>(index)) {
      case kLoadTorque: return load_torque_;
      case kLoadInertia: return load_inertia_;
      case kBlocked: return blocked_ ? 1.0 : 0.0;
      case kEncoderCpr: return encoder_.counts_per_revolution;
      case kEncoderReversed: return encoder_.reversed ? 1.0 : 0.0;
      case kEncoderIndexAt: return encoder_.index_revolutions;
      case kEncoderFault: return encoder_freeze_.fault() ? 1.0 : 0.0;
      default: return std::nullopt;
    }
  }
  if (same_signal_name(name, "POSITION_REV")) return rotor_revolutions();
  if (same_signal_name(name, "SPEED_RPM")) return 60.0 * (plant_ ? plant_->velocity_rps() : ideal_.velocity_rps());
  if (same_signal_name(name, "ENCODER_COUNT")) return stage_.feedback.encoder_count;
  if (plant_) {
    if (same_signal_name(name, "COIL_A_A")) return plant_->coil_a_current_a();
    if (same_signal_name(name, "COIL_B_A")) return plant_->coil_b_current_a();
    if (same_signal_name(name, "TORQUE_NM")) return plant_->motor_torque_nm();
  }
  return io_.read_signal(name);
}

}  // namespace motwin::sim
