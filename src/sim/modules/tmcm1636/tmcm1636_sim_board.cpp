#include "sim/modules/tmcm1636/tmcm1636_sim_board.h"

#include <cmath>

namespace motwin::sim {
namespace {

using board::ReferenceSwitch;

constexpr SignalInfo kMotorSignals[] = {
    {"LOAD_TORQUE", -1000, 1000, false, "load torque in N m against forward rotation (physical motor)", "N m"},
    {"LOAD_INERTIA", 0, 100, false, "inertia coupled to the rotor in kg m^2 (physical motor)", "kg m²"},
    {"BLOCKED", 0, 1, true, "1 blocks the rotor: an obstacle (physical motor)"},
    {"REF_R_AT", -1e6, 1e6, false, "right switch active at rotor positions >= this, revolutions (physical motor)", "rev"},
    {"REF_L_AT", -1e6, 1e6, false, "left switch active at rotor positions <= this, revolutions (physical motor)", "rev"},
    {"REF_H_AT", -1e6, 1e6, false, "home switch active at rotor positions >= this, revolutions (physical motor)", "rev"},
    {"REF_AT_LEVEL", 0, 1, true, "input level of a REF_*_AT switch while the rotor is past it, the other elsewhere (default 1)"},
    {"ENCODER_FAULT", 0, 1, true, "1 freezes the ABN encoder: lost A/B/N signals (physical motor)"},
    {"HALL_FAULT", 0, 1, true, "1 makes the hall inputs read 000: lost hall supply (physical motor)"},
};

enum MotorSignal : size_t {
  kLoadTorque,
  kLoadInertia,
  kBlocked,
  kRefRightAt,
  kRefLeftAt,
  kRefHomeAt,
  kRefAtLevel,
  kEncoderFault,
  kHallFault
};

}  // namespace

std::span<const SignalInfo> Tmcm1636SimBoard::signal_table() {
  static const std::vector<SignalInfo> table = concat_signals(Tmcm1636SimIo::signal_table(), kMotorSignals);
  return table;
}

Tmcm1636SimBoard::Tmcm1636SimBoard(Tmcm1636SimIo& io) : SimBoardOverIo(io) {}

Tmcm1636SimBoard::Tmcm1636SimBoard(Tmcm1636SimIo& io, const MotorDescription& motor, uint64_t noise_seed,
                                   int sub_steps)
    : SimBoardOverIo(io), plant_(std::make_unique<Tmcm1636Plant>(motor, noise_seed, Tmcm1636BoardModel{}, sub_steps)) {
  io_.set_supply_millivolt(static_cast<int32_t>(std::lround(motor.supply.voltage_v * 1000.0)));
  sense();
}

void Tmcm1636SimBoard::set_input(std::string_view name, double value) {
  const SignalInfo* motor_signal = find_signal(kMotorSignals, name);
  if (motor_signal == nullptr) {
    io_.set_input(name, value);
    // A level set by name takes the switch back from the rotor position.
    if (same_signal_name(name, "REF_R")) switch_at_revolutions_[0].reset();
    if (same_signal_name(name, "REF_L")) switch_at_revolutions_[1].reset();
    if (same_signal_name(name, "REF_H")) switch_at_revolutions_[2].reset();
    return;
  }
  switch (static_cast<MotorSignal>(motor_signal - kMotorSignals)) {
    case kLoadTorque: load_torque_ = value; break;
    case kLoadInertia: load_inertia_ = value; break;
    case kBlocked: blocked_ = value != 0; break;
    case kRefRightAt: switch_at_revolutions_[0] = value; break;
    case kRefLeftAt: switch_at_revolutions_[1] = value; break;
    case kRefHomeAt: switch_at_revolutions_[2] = value; break;
    case kRefAtLevel: switch_at_pressed_level_ = value != 0; break;
    case kEncoderFault: encoder_fault_ = value != 0; break;
    case kHallFault: hall_fault_ = value != 0; break;
  }
  if (plant_) {
    plant_->set_load_torque(load_torque_);
    plant_->set_load_inertia(load_inertia_);
    plant_->set_blocked(blocked_);
    plant_->set_encoder_fault(encoder_fault_);
    plant_->set_hall_fault(hall_fault_);
  }
}

std::optional<double> Tmcm1636SimBoard::read_signal(std::string_view name) const {
  if (const SignalInfo* motor_signal = find_signal(kMotorSignals, name)) {
    switch (static_cast<MotorSignal>(motor_signal - kMotorSignals)) {
      case kLoadTorque: return load_torque_;
      case kLoadInertia: return load_inertia_;
      case kBlocked: return blocked_ ? 1.0 : 0.0;
      case kRefRightAt: return switch_at_revolutions_[0];
      case kRefLeftAt: return switch_at_revolutions_[1];
      case kRefHomeAt: return switch_at_revolutions_[2];
      case kRefAtLevel: return switch_at_pressed_level_ ? 1.0 : 0.0;
      case kEncoderFault: return encoder_fault_ ? 1.0 : 0.0;
      case kHallFault: return hall_fault_ ? 1.0 : 0.0;
    }
  }
  if (plant_) {
    const Tmcm1636Plant& p = *plant_;
    if (same_signal_name(name, "SPEED_RPM")) return p.speed_rpm();
    if (same_signal_name(name, "POSITION_REV")) return p.position_revolutions();
    if (same_signal_name(name, "VBUS")) return p.bus_voltage();
    if (same_signal_name(name, "TORQUE_NM")) return p.electromagnetic_torque_nm();
    if (same_signal_name(name, "IQ_A")) return p.iq_amps();
    if (same_signal_name(name, "ID_A")) return p.id_amps();
    if (same_signal_name(name, "CHOPPER")) return p.chopper_on() ? 1.0 : 0.0;
    if (same_signal_name(name, "BRAKE_ENGAGED")) return p.brake_engaged() ? 1.0 : 0.0;
    if (same_signal_name(name, "DRIVER_TEMP")) return p.driver_celsius();
  }
  return io_.read_signal(name);
}

void Tmcm1636SimBoard::sense() {
  Tmcm1636Plant& p = *plant_;
  p.set_source_voltage(io_.supply_millivolt() / 1000.0);
  p.set_ambient_celsius(io_.temperature_celsius());
  const double position = p.position_revolutions();
  const auto place = [&](ReferenceSwitch which, bool pressed) {
    io_.set_reference_switch_level(which, pressed == switch_at_pressed_level_);
  };
  if (switch_at_revolutions_[0]) place(ReferenceSwitch::kRight, position >= *switch_at_revolutions_[0]);
  if (switch_at_revolutions_[1]) place(ReferenceSwitch::kLeft, position <= *switch_at_revolutions_[1]);
  if (switch_at_revolutions_[2]) place(ReferenceSwitch::kHome, position >= *switch_at_revolutions_[2]);
  p.sense(stage_.feedback);
  uint8_t levels = 0;
  if (io_.reference_switch_level(ReferenceSwitch::kRight)) levels |= 1;
  if (io_.reference_switch_level(ReferenceSwitch::kLeft)) levels |= 2;
  if (io_.reference_switch_level(ReferenceSwitch::kHome)) levels |= 4;
  stage_.feedback.reference_switches = levels;
  io_.set_measured_supply_raw(stage_.feedback.adc_supply);
  if (p.ticks() % 20 == 0) io_.set_measured_temperature_celsius(p.driver_celsius());
}

}  // namespace motwin::sim
