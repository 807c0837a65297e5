#include "sim/modules/tmcm3216/tmcm3216_sim_board.h"

#include <cmath>
#include <iterator>
#include <string>

namespace motwin::sim {
namespace {

constexpr SignalInfo kDeviceSignals[] = {
    {"DIO0", 0, 1, true, "level driven onto DIO0 from outside (read while the pin is an input, 2711)"},
    {"DIO1", 0, 1, true, "level driven onto DIO1 from outside"},
    {"DIO2", 0, 1, true, "level driven onto DIO2 from outside"},
    {"DIO3", 0, 1, true, "level driven onto DIO3 from outside"},
    {"AIN0", 0, Tmcm3216SimBoard::kAdcMax, true, "raw 12-bit ADC count of analog input 0 (270E sub 1)", "counts"},
    {"AIN1", 0, Tmcm3216SimBoard::kAdcMax, true, "raw 12-bit ADC count of analog input 1 (270E sub 2)", "counts"},
    {"VSUPPLY", 0, 60, false, "motor supply voltage in volts (below 8 V the drivers flag undervoltage)", "V"},
    {"ENABLE", 0, 1, true,
     "enable signal of the shutdown switch, default 1; 0: all drivers off, EMCY 5441, every axis to FAULT"},
};
enum DeviceSignal : size_t { kDio0, kAin0 = kDio0 + 4, kAin1, kVsupply, kEnable };
static_assert(kEnable + 1 == std::size(kDeviceSignals));

// Per axis, named AXIS<n>_<suffix>.
struct AxisSignalInfo {
  std::string_view suffix;
  double min;
  double max;
  bool whole;
  std::string_view description;
  std::string_view unit = {};
};
constexpr AxisSignalInfo kAxisSignals[] = {
    {"LOAD_TORQUE", -100, 100, false, "load torque in N m against forward rotation (physical motor)", "N m"},
    {"LOAD_INERTIA", 0, 10, false, "inertia coupled to the rotor in kg m^2 (physical motor)", "kg m²"},
    {"BLOCKED", 0, 1, true, "1 blocks the rotor: an obstacle, steps are lost (physical motor)"},
    {"REF_R", 0, 1, true, "right limit switch level, 1 = high (releases REF_R_AT/FROM/TO)"},
    {"REF_L", 0, 1, true, "left limit switch level, 1 = high"},
    {"REF_H", 0, 1, true, "home switch level, 1 = high"},
    {"REF_R_AT", -1e6, 1e6, false, "right switch high at rotor positions >= this, revolutions", "rev"},
    {"REF_L_AT", -1e6, 1e6, false, "left switch high at rotor positions <= this, revolutions", "rev"},
    {"REF_H_AT", -1e6, 1e6, false, "home switch high at rotor positions >= this, revolutions", "rev"},
    {"REF_R_FROM", -1e6, 1e6, false, "right switch window: high from this rotor position on, revolutions", "rev"},
    {"REF_R_TO", -1e6, 1e6, false, "right switch window: high up to this rotor position, revolutions", "rev"},
    {"REF_L_FROM", -1e6, 1e6, false, "left switch window: high from this rotor position on, revolutions", "rev"},
    {"REF_L_TO", -1e6, 1e6, false, "left switch window: high up to this rotor position, revolutions", "rev"},
    {"REF_H_FROM", -1e6, 1e6, false, "home switch window (a cam): high from this position on, revolutions", "rev"},
    {"REF_H_TO", -1e6, 1e6, false, "home switch window: high up to this position, revolutions", "rev"},
    {"ENCODER_CPR", 0, 1e6, true, "encoder quadrature counts per revolution, 0 = no encoder (default 4000)",
     "counts/rev"},
    {"ENCODER_REVERSED", 0, 1, true, "1: the encoder counts down for forward rotation"},
    {"ENCODER_INDEX_AT", 0, 0.999999, false, "rotor angle of the N pulse within a revolution, revolutions", "rev"},
    {"ENCODER_INDEX_ACTIVE_LOW", 0, 1, true, "1: the N channel is active low (200B sub 1 must match)"},
    {"ENCODER_FAULT", 0, 1, true, "1 freezes the encoder counter: lost A/B/N signals"},
    {"OPEN_COIL_A", 0, 1, true, "1: coil A is open (no current; the driver flags open load A)"},
    {"OPEN_COIL_B", 0, 1, true, "1: coil B is open"},
    {"SHORT", 0, 1, true, "1: a motor lead is shorted (the driver switches its bridges off, flags overcurrent)"},
    {"DRIVER_TEMP", -40, 200, false, "driver chip temperature in degrees C (120: pre-warning, 150: shutdown)", "°C"},
    {"BRAKE", 0, 1, true, "1: a holding brake is fitted; it holds the rotor unless its output carries current"},
};
enum AxisSignal : size_t {
  kLoadTorque,
  kLoadInertia,
  kBlocked,
  kRefRight,  // REF_R ... REF_H_TO in the order of StepperSwitchSources::SwitchSignal
  kEncoderCpr = kRefRight + StepperSwitchSources::kSignalCount,
  kEncoderReversed,
  kEncoderIndexAt,
  kEncoderIndexActiveLow,
  kEncoderFault,
  kOpenCoilA,
  kOpenCoilB,
  kShort,
  kDriverTemp,
  kBrake,
};
constexpr size_t kAxisSignalCount = std::size(kAxisSignals);
static_assert(kBrake + 1 == kAxisSignalCount);

constexpr std::string_view kDioNames[] = {"DIO0", "DIO1", "DIO2", "DIO3"};
constexpr std::string_view kBrakeNames[] = {"BRAKE0", "BRAKE1", "BRAKE2"};

// Names live as long as the program: the table refers to them.
const std::vector<std::string>& axis_signal_names() {
  static const std::vector<std::string> names = [] {
    std::vector<std::string> all;
    for (uint8_t axis = 0; axis < Tmcm3216SimBoard::kAxisCount; ++axis) {
      for (const AxisSignalInfo& info : kAxisSignals) all.push_back("AXIS" + std::to_string(axis) + "_" + std::string(info.suffix));
    }
    return all;
  }();
  return names;
}

// "AXIS<n>_<rest>": the axis and the rest; false for other names.
bool split_axis_name(std::string_view name, uint8_t& axis, std::string_view& rest) {
  if (name.size() < 7 || !same_signal_name(name.substr(0, 4), "AXIS") || name[5] != '_') return false;
  if (name[4] < '0' || name[4] >= static_cast<char>('0' + Tmcm3216SimBoard::kAxisCount)) return false;
  axis = static_cast<uint8_t>(name[4] - '0');
  rest = name.substr(6);
  return true;
}

std::optional<size_t> axis_signal_index(std::string_view rest) {
  for (size_t i = 0; i < kAxisSignalCount; ++i) {
    if (same_signal_name(kAxisSignals[i].suffix, rest)) return i;
  }
  return std::nullopt;
}

}  // namespace

std::span<const SignalInfo> Tmcm3216SimBoard::signal_table() {
  static const std::vector<SignalInfo> table = [] {
    std::vector<SignalInfo> all(std::begin(kDeviceSignals), std::end(kDeviceSignals));
    const std::vector<std::string>& names = axis_signal_names();
    for (uint8_t axis = 0; axis < kAxisCount; ++axis) {
      for (size_t i = 0; i < kAxisSignalCount; ++i) {
        const AxisSignalInfo& info = kAxisSignals[i];
        all.push_back(
            SignalInfo{names[axis * kAxisSignalCount + i], info.min, info.max, info.whole, info.description, info.unit});
      }
    }
    return all;
  }();
  return table;
}

Tmcm3216SimBoard::Tmcm3216SimBoard() {
  for (uint8_t axis = 0; axis < kAxisCount; ++axis) apply_sensor_config(axis);
  before_tick();
}

Tmcm3216SimBoard::Tmcm3216SimBoard(const StepperMotorDescription& motor, int sub_steps)
    : Tmcm3216SimBoard(std::array<std::optional<StepperMotorDescription>, kAxisCount>{motor, motor, motor}, sub_steps) {}

Tmcm3216SimBoard::Tmcm3216SimBoard(std::span<const std::optional<StepperMotorDescription>> motors, int sub_steps) {
  for (uint8_t axis = 0; axis < kAxisCount; ++axis) {
    if (axis < motors.size() && motors[axis]) {
      axes_[axis].plant = std::make_unique<StepperPlant>(*motors[axis], sub_steps);
      axes_[axis].ideal.full_steps_per_revolution = motors[axis]->full_steps_per_revolution;
    }
    apply_sensor_config(axis);
  }
  before_tick();
}

double Tmcm3216SimBoard::rotor_revolutions(uint8_t axis) const {
  const Axis& a = axes_[axis];
  return a.plant ? a.plant->position_revolutions() : a.ideal.position_revolutions();
}

void Tmcm3216SimBoard::set_rotor_revolutions(uint8_t axis, double position) {
  Axis& a = axes_[axis];
  if (a.plant) {
    a.plant->set_position_revolutions(position);
  } else {
    a.ideal.set_position_revolutions(position);
  }
  touched_ = true;
  sense_axis(axis);
}

uint8_t Tmcm3216SimBoard::brake_duty_seen(uint8_t axis) const {
  const board::Tmcm3216Io& io = board_.io;
  if (io.brake_control[axis]) return io.brake_duty[axis];
  // Without the automatic control a fitted brake hangs on DIO n like any load.
  return axes_[axis].brake_fitted && axis < board::Tmcm3216Io::kDioCount && io.output_mode[axis] && io.output_levels[axis]
             ? 255
             : 0;
}

// A fail-safe brake: it holds while its coil carries no current.
bool Tmcm3216SimBoard::brake_engaged(uint8_t axis) const { return axes_[axis].brake_fitted && brake_duty_seen(axis) == 0; }

bool Tmcm3216SimBoard::pin_level(uint8_t dio) const {
  const board::Tmcm3216Io& io = board_.io;
  if (!io.output_mode[dio]) return dio_external_[dio];
  if (io.output_levels[dio]) return true;
  // Push-pull drives low; a high-side switch that is off lets the outside decide.
  return io.push_pull[dio] ? false : dio_external_[dio];
}

void Tmcm3216SimBoard::before_tick() {
  board::Tmcm3216Io& io = board_.io;
  for (uint8_t n = 0; n < board::Tmcm3216Io::kDioCount; ++n) io.dio_levels[n] = pin_level(n);
  io.analog_inputs = analog_raw_;
  io.supply_millivolt = supply_millivolt_;
  io.enable_input = enable_input_;
  for (uint8_t axis = 0; axis < kAxisCount; ++axis) {
    const board::StepperPowerStage& stage = board_.axes[axis];
    // A resting axis senses what it sensed before: its rotor, inputs and drive are unchanged.
    skipped_sensing_[axis] = !touched_ && resting_[axis] && stage.drive == resting_drive_[axis] &&
                             stage.feedback == resting_feedback_[axis];
    if (skipped_sensing_[axis]) continue;
    feedback_before_[axis] = stage.feedback;
    drive_before_[axis] = stage.drive;
    sense_axis(axis);
  }
}

void Tmcm3216SimBoard::sense_axis(uint8_t axis) {
  Axis& a = axes_[axis];
  board::StepperPowerStage& stage = board_.axes[axis];
  board::StepperFeedback& feedback = stage.feedback;
  a.sensors.sense(rotor_revolutions(axis), feedback);
  a.encoder_freeze.apply(feedback);
  // The encoder interface latches an N pulse only with the polarity it was told (200B sub 1).
  const uint32_t new_events = feedback.encoder_index_events - a.sensor_index_events;
  a.sensor_index_events = feedback.encoder_index_events;
  if (new_events != 0 && a.index_active_low == stage.drive.encoder_index_active_low) {
    a.reported_index_events += new_events;
    a.reported_index_count = feedback.encoder_index_count;
  }
  feedback.encoder_index_events = a.reported_index_events;
  feedback.encoder_index_count = a.reported_index_count;
  a.switches.add_levels(feedback.switches);
  feedback.supply_millivolt = supply_millivolt_;
  feedback.stallguard2_result = a.stallguard.stallguard2_result();
  feedback.stallguard4_result = a.stallguard.stallguard4_result();
  feedback.stallguard_measurements = a.stallguard.measurements();
  uint8_t status = 0;
  if (stage.drive.enabled && a.open_coil_a) status |= board::kDriverOpenLoadA;
  if (stage.drive.enabled && a.open_coil_b) status |= board::kDriverOpenLoadB;
  if (a.short_circuit) status |= board::kDriverOvercurrentA | board::kDriverOvercurrentB;
  if (a.driver_celsius >= kTemperatureWarningCelsius) status |= board::kDriverTemperatureWarning;
  if (a.driver_celsius >= kOvertemperatureCelsius) status |= board::kDriverOvertemperature;
  if (supply_millivolt_ < 8000) status |= board::kDriverUndervoltage;
  feedback.driver_status = status;
}

void Tmcm3216SimBoard::after_tick(double dt_s) {
  const double supply_volt = supply_millivolt_ * 1e-3;
  for (uint8_t axis = 0; axis < kAxisCount; ++axis) {
    Axis& a = axes_[axis];
    board::StepperDrive drive = board_.axes[axis].drive;
    // The chip's protections switch the bridges off, and so does the shutdown switch (its enable
    // signal gates every driver in hardware, whatever the firmware asks); an open coil carries no
    // current.
    if (a.short_circuit || a.driver_celsius >= kOvertemperatureCelsius || supply_millivolt_ < 8000 || !enable_input_) {
      drive.enabled = false;
    }
    if (a.open_coil_a) drive.coil_a_ma = 0;
    if (a.open_coil_b) drive.coil_b_ma = 0;
    const StallGuardSettings settings{drive.stealth_chop, drive.stallguard2_threshold, drive.stallguard2_filter,
                                      drive.stallguard4_filter, drive.stallguard4_angle_offset};
    if (a.plant) {
      a.plant->set_blocked(a.blocked || brake_engaged(axis));
      a.plant->advance(drive, supply_volt, dt_s);
      a.stallguard.update(*a.plant, drive, settings, dt_s);
      continue;
    }
    const board::StepperPowerStage& stage = board_.axes[axis];
    if (skipped_sensing_[axis] && stage.drive == resting_drive_[axis]) continue;  // the motor rests too
    const bool sensed = !skipped_sensing_[axis];
    a.ideal.advance(drive, dt_s);
    a.stallguard.update_ideal(drive, settings, dt_s);
    // Rests from here: the drive seen before this tick (applied by the previous after_tick) and
    // now is the same, with the bridges off, or on with the standstill settled in the StallGuard
    // model. Then the motor holds its position at velocity 0 (a powered one: this tick moved it
    // by the same field angle as the last, by nothing) and the StallGuard model stays reset
    // (count kept) whatever it was, or holds its results while the standstill lengthens
    // (StallGuardModel::standstill_settled), and sensing the same rotor with the same inputs
    // again gives the same feedback (the N-pulse and filter bookkeeping caught up in this tick's
    // sensing), so the next ticks change nothing. Without a signal set or a rotor moved in
    // between, and with this tick's feedback the same as the last one.
    resting_[axis] = sensed && resting_enabled_ && !touched_ && (!drive.enabled || a.stallguard.standstill_settled()) &&
                     stage.drive == drive_before_[axis] && stage.feedback == feedback_before_[axis];
    resting_drive_[axis] = stage.drive;
    resting_feedback_[axis] = stage.feedback;
  }
  touched_ = false;
  for (uint8_t n = 0; n < board::Tmcm3216Io::kDioCount; ++n) {
    const int32_t level = board_.io.output_mode[n] && pin_level(n) ? 1 : 0;
    if (level != logged_dio_[n]) {
      logged_dio_[n] = level;
      output_changes_.record(kDioNames[n], level);
    }
  }
  for (uint8_t axis = 0; axis < kAxisCount; ++axis) {
    const int32_t duty = brake_duty_seen(axis);
    if (duty != logged_brake_[axis]) {
      logged_brake_[axis] = duty;
      output_changes_.record(kBrakeNames[axis], duty);
    }
  }
}

void Tmcm3216SimBoard::set_input(std::string_view name, double value) {
  touched_ = true;
  if (const SignalInfo* device = find_signal(kDeviceSignals, name)) {
    const auto index = static_cast<size_t>(device - kDeviceSignals);
    if (index < kAin0) {
      dio_external_[index - kDio0] = value != 0;
    } else if (index == kAin0 || index == kAin1) {
      analog_raw_[index - kAin0] = static_cast<uint16_t>(std::lround(value));
    } else if (index == kVsupply) {
      supply_millivolt_ = static_cast<int32_t>(std::lround(value * 1000.0));
    } else {
      enable_input_ = value != 0;
    }
    return;
  }
  uint8_t axis = 0;
  std::string_view rest;
  if (!split_axis_name(name, axis, rest)) return;
  const std::optional<size_t> found = axis_signal_index(rest);
  if (!found) return;
  const size_t index = *found;
  Axis& a = axes_[axis];
  if (index >= kRefRight && index < kEncoderCpr) {
    a.switches.set(index - kRefRight, value);
  } else {
    switch (static_cast<AxisSignal>(index)) {
      case kLoadTorque: a.load_torque = value; break;
      case kLoadInertia: a.load_inertia = value; break;
      case kBlocked: a.blocked = value != 0; break;
      case kEncoderCpr: a.encoder.counts_per_revolution = static_cast<int32_t>(value); break;
      case kEncoderReversed: a.encoder.reversed = value != 0; break;
      case kEncoderIndexAt: a.encoder.index_revolutions = value; break;
      case kEncoderIndexActiveLow: a.index_active_low = value != 0; break;
      case kEncoderFault: a.encoder_freeze.set_fault(value != 0); break;
      case kOpenCoilA: a.open_coil_a = value != 0; break;
      case kOpenCoilB: a.open_coil_b = value != 0; break;
      case kShort: a.short_circuit = value != 0; break;
      case kDriverTemp: a.driver_celsius = value; break;
      case kBrake: a.brake_fitted = value != 0; break;
      default: break;
    }
    apply_motor_settings(axis);
  }
  apply_sensor_config(axis);
}

void Tmcm3216SimBoard::apply_motor_settings(uint8_t axis) {
  Axis& a = axes_[axis];
  if (!a.plant) return;
  a.plant->set_load_torque_nm(a.load_torque);
  a.plant->set_load_inertia_kg_m2(a.load_inertia);
  a.plant->set_blocked(a.blocked || brake_engaged(axis));
}

void Tmcm3216SimBoard::apply_sensor_config(uint8_t axis) {
  Axis& a = axes_[axis];
  StepperSensorConfig config;
  config.encoder = a.encoder;
  a.switches.configure(config);
  a.sensors.set_config(config);
}

std::optional<double> Tmcm3216SimBoard::read_axis_signal(uint8_t axis, size_t index) const {
  const Axis& a = axes_[axis];
  if (index >= kRefRight && index < kEncoderCpr) {
    return a.switches.read(index - kRefRight, board_.axes[axis].feedback.switches);
  }
  switch (static_cast<AxisSignal>(index)) {
    case kLoadTorque: return a.load_torque;
    case kLoadInertia: return a.load_inertia;
    case kBlocked: return a.blocked ? 1.0 : 0.0;
    case kEncoderCpr: return a.encoder.counts_per_revolution;
    case kEncoderReversed: return a.encoder.reversed ? 1.0 : 0.0;
    case kEncoderIndexAt: return a.encoder.index_revolutions;
    case kEncoderIndexActiveLow: return a.index_active_low ? 1.0 : 0.0;
    case kEncoderFault: return a.encoder_freeze.fault() ? 1.0 : 0.0;
    case kOpenCoilA: return a.open_coil_a ? 1.0 : 0.0;
    case kOpenCoilB: return a.open_coil_b ? 1.0 : 0.0;
    case kShort: return a.short_circuit ? 1.0 : 0.0;
    case kDriverTemp: return a.driver_celsius;
    case kBrake: return a.brake_fitted ? 1.0 : 0.0;
    default: return std::nullopt;
  }
}

std::optional<double> Tmcm3216SimBoard::read_signal(std::string_view name) const {
  if (const SignalInfo* device = find_signal(kDeviceSignals, name)) {
    const auto index = static_cast<size_t>(device - kDeviceSignals);
    if (index < kAin0) return pin_level(static_cast<uint8_t>(index - kDio0)) ? 1.0 : 0.0;
    if (index == kAin0 || index == kAin1) return analog_raw_[index - kAin0];
    if (index == kEnable) return enable_input_ ? 1.0 : 0.0;
    return supply_millivolt_ * 1e-3;
  }
  for (uint8_t axis = 0; axis < kAxisCount; ++axis) {
    if (same_signal_name(name, kBrakeNames[axis])) return brake_duty_seen(axis);
  }
  uint8_t axis = 0;
  std::string_view rest;
  if (!split_axis_name(name, axis, rest)) return std::nullopt;
  if (const std::optional<size_t> index = axis_signal_index(rest)) return read_axis_signal(axis, *index);
  const Axis& a = axes_[axis];
  if (same_signal_name(rest, "POSITION_REV")) return rotor_revolutions(axis);
  if (same_signal_name(rest, "SPEED_RPM")) return 60.0 * (a.plant ? a.plant->velocity_rps() : a.ideal.velocity_rps());
  if (same_signal_name(rest, "ENCODER_COUNT")) return board_.axes[axis].feedback.encoder_count;
  if (same_signal_name(rest, "SG2")) return a.stallguard.stallguard2_result();
  if (same_signal_name(rest, "SG4")) return a.stallguard.stallguard4_result();
  if (same_signal_name(rest, "BRAKE_ENGAGED")) return brake_engaged(axis) ? 1.0 : 0.0;
  if (a.plant) {
    if (same_signal_name(rest, "COIL_A_A")) return a.plant->coil_a_current_a();
    if (same_signal_name(rest, "COIL_B_A")) return a.plant->coil_b_current_a();
    if (same_signal_name(rest, "TORQUE_NM")) return a.plant->motor_torque_nm();
  }
  return std::nullopt;
}

}  // namespace motwin::sim
