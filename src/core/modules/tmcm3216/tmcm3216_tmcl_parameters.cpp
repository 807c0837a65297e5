// The TMCM-3216 TMCL firmware's parameter tables (docs/tmcm-3216-tmcl.md "Axis parameters",
// "Global parameters"): numbers and names of PyTrinamic's TMCM3216 class (pytrinamic/modules/
// TMCM3216.py, 84382a8), which Zephyr's tmcm3216_reg.h confirms for AP 0..8, 10, 11 and 140. No
// public source gives a range or a default: each is the CANopen firmware's for the object of the
// same meaning (manual V1.04, named in the description), or tagged params::kMotwinDecisionTag.
#include <type_traits>

#include "core/modules/tmcm3216/tmcm3216_tmcl.h"

namespace motwin::modules::tmcm3216 {
namespace {

using params::access;
using params::Binding;
using params::Unit;
using tmcl::Status;
using Module = Tmcm3216Tmcl;

// A field of the EightPoint shape (2010..2018 of the CANopen firmware) of the motor's axis.
template <auto Field>
constexpr Binding<Module> shape_field() {
  using Value = std::remove_cvref_t<decltype(std::declval<Tmcm3216DriveObjects&>().*Field)>;
  return {[](Module& m, uint8_t motor) { return static_cast<int32_t>(m.axis(motor).config.shape.*Field); },
          [](Module& m, uint8_t motor, int32_t value) {
            m.axis(motor).config.shape.*Field = static_cast<Value>(value);
            return Status::kOk;
          }};
}

// A setting of the motor's stepper (the CANopen firmware's per-axis object of the same meaning).
template <auto Field>
constexpr Binding<Module> stepper_field() {
  using Value = std::remove_cvref_t<decltype(std::declval<StepperObjects&>().*Field)>;
  return {[](Module& m, uint8_t motor) { return static_cast<int32_t>(m.axis(motor).stepper.objects.*Field); },
          [](Module& m, uint8_t motor, int32_t value) {
            m.axis(motor).stepper.objects.*Field = static_cast<Value>(value);
            return Status::kOk;
          }};
}

// A reading of the motor's stepper.
template <auto Get>
constexpr Binding<Module> stepper_value() {
  return {[](Module& m, uint8_t motor) { return static_cast<int32_t>((m.axis(motor).stepper.*Get)()); }, nullptr};
}

// 2010's range (VSTART), and that of the other velocity and acceleration objects 2011..2018.
constexpr int64_t kStartVelocityMax = 268435455;
constexpr int64_t kRampValueMax = 16777215;

}  // namespace

const Tmcm3216Tmcl::Table& Tmcm3216Tmcl::axis_parameters() {
  // clang-format off
  static constexpr Row kRows[] = {
    {{0, "target position", kMin32, kMax32, 0, access("RW"), Unit::kMicrosteps, "Target of a position move; a write starts the move (as MVP ABS)"}, axis_command<&TmclAxisState::target_position, &Tmcm3216TmclAxis::set_target_position>()},
    {{1, "actual position", kMin32, kMax32, 0, access("RW"), Unit::kMicrosteps, "Position counter; a write sets it without moving"}, axis_command<&Tmcm3216TmclAxis::actual_position, &Tmcm3216TmclAxis::set_actual_position>()},
    {{2, "target velocity", -kRampValueMax, kRampValueMax, 0, access("RW"), Unit::kMicrostepsPerSecond, "[Motwin decision] range of 60FF; a write starts a velocity move (as ROR/ROL), bounded by AP 4"}, axis_command<&TmclAxisState::target_velocity, &Tmcm3216TmclAxis::set_target_velocity>()},
    {{3, "actual velocity", -kRampValueMax, kRampValueMax, 0, access("R"), Unit::kMicrostepsPerSecond, "Velocity of the ramp generator"}, axis_value<&Tmcm3216TmclAxis::actual_velocity_pps>()},
    {{4, "max velocity", 0, kRampValueMax, 51200, access("RWE"), Unit::kMicrostepsPerSecond, "[Motwin decision] range and default of 6081: VMAX of position moves, the bound of velocity moves"}, config_field<&TmclAxisConfig::max_velocity_pps>()},
    {{5, "max acceleration", 0, kRampValueMax, 51200, access("RWE"), Unit::kMicrostepsPerSecondSquared, "[Motwin decision] range and default of 6083: AMAX, V2..VMAX (both ways in velocity moves)"}, config_field<&TmclAxisConfig::max_acceleration_pps2>()},
    {{6, "max current", 0, 255, 128, access("RWE"), Unit::kNone, "[Motwin decision] range and default of 2003: run current, 0..255 = 0..100 % of the current range"}, stepper_field<&StepperObjects::run_current>()},
    {{7, "standby current", 0, 255, 8, access("RWE"), Unit::kNone, "[Motwin decision] range and default of 2004: current at standstill after the standby delay"}, stepper_field<&StepperObjects::standby_current>()},
    {{8, "position reached", 0, 1, 0, access("R"), Unit::kNone, "1: a position move is at its target; 0 while moving, in velocity mode and right after a new target"}, axis_value<&Tmcm3216TmclAxis::position_reached>()},
    {{9, "home switch", 0, 1, 0, access("R"), Unit::kNone, "Level of the home switch input"}, state_value<&TmclAxisState::home_switch_active>()},
    {{10, "right endstop", 0, 1, 0, access("R"), Unit::kNone, "1: the right switch is active (after AP 14, 24), whether or not it stops the axis"}, state_value<&TmclAxisState::right_switch_active>()},
    {{11, "left endstop", 0, 1, 0, access("R"), Unit::kNone, "1: the left switch is active (after AP 14, 25)"}, state_value<&TmclAxisState::left_switch_active>()},
    {{12, "right limit switch disable", 0, 1, 0, access("RWE"), Unit::kNone, "[Motwin decision] default of 2005 bit 1: 1 = the right switch does not stop the axis"}, config_field<&TmclAxisConfig::right_limit_disabled>()},
    {{13, "left limit switch disable", 0, 1, 0, access("RWE"), Unit::kNone, "[Motwin decision] default of 2005 bit 0: 1 = the left switch does not stop the axis"}, config_field<&TmclAxisConfig::left_limit_disabled>()},
    {{14, "swap limit switches", 0, 1, 0, access("RWE"), Unit::kNone, "[Motwin decision] 1 = the left input is the right switch and the reverse"}, config_field<&TmclAxisConfig::limit_switches_swapped>()},
    {{15, "A1", 0, kRampValueMax, 0, access("RWE"), Unit::kMicrostepsPerSecondSquared, "[Motwin decision] range and default of 2011: acceleration VSTART..V1"}, shape_field<&Tmcm3216DriveObjects::a1>()},
    {{16, "V1", 0, kRampValueMax, 0, access("RWE"), Unit::kMicrostepsPerSecond, "[Motwin decision] range and default of 2012: 0 = no A1/D1 segment"}, shape_field<&Tmcm3216DriveObjects::v1>()},
    {{17, "max deceleration", 0, kRampValueMax, 51200, access("RWE"), Unit::kMicrostepsPerSecondSquared, "[Motwin decision] range and default of 6084: DMAX, VMAX..V2"}, config_field<&TmclAxisConfig::max_deceleration_pps2>()},
    {{18, "D1", 0, kRampValueMax, 0, access("RWE"), Unit::kMicrostepsPerSecondSquared, "[Motwin decision] range and default of 2013: deceleration V1..VSTOP; 0 with V1 = 0: DMAX"}, shape_field<&Tmcm3216DriveObjects::d1>()},
    {{19, "start velocity", 0, kStartVelocityMax, 0, access("RWE"), Unit::kMicrostepsPerSecond, "[Motwin decision] range and default of 2010: VSTART"}, shape_field<&Tmcm3216DriveObjects::start_velocity>()},
    {{20, "stop velocity", 0, kRampValueMax, 0, access("RWE"), Unit::kMicrostepsPerSecond, "[Motwin decision] range of 2012, default of 6082: VSTOP, at least VSTART for a position move"}, config_field<&TmclAxisConfig::stop_velocity_pps>()},
    {{21, "ramp wait time", 0, 65535, 0, access("RWE"), Unit::kThirtyTwoMicroseconds, "[Motwin decision] range and default of 2015: rest at 0 before the next move or a reversal"}, shape_field<&Tmcm3216DriveObjects::ramp_wait_time>()},
    {{24, "right limit switch polarity", 0, 1, 0, access("RWE"), Unit::kNone, "[Motwin decision] default of 2005 bit 3: 1 = active while the input is low"}, config_field<&TmclAxisConfig::right_switch_inverted>()},
    {{25, "left limit switch polarity", 0, 1, 0, access("RWE"), Unit::kNone, "[Motwin decision] default of 2005 bit 2: 1 = active while the input is low"}, config_field<&TmclAxisConfig::left_switch_inverted>()},
    {{34, "A2", 0, kRampValueMax, 0, access("RWE"), Unit::kMicrostepsPerSecondSquared, "[Motwin decision] range and default of 2016: acceleration V1..V2"}, shape_field<&Tmcm3216DriveObjects::a2>()},
    {{35, "V2", 0, kRampValueMax, 0, access("RWE"), Unit::kMicrostepsPerSecond, "[Motwin decision] range and default of 2017: 0 = no A2/D2 segment"}, shape_field<&Tmcm3216DriveObjects::v2>()},
    {{36, "D2", 0, kRampValueMax, 0, access("RWE"), Unit::kMicrostepsPerSecondSquared, "[Motwin decision] range and default of 2018: deceleration V2..V1; 0 with V2 = 0: DMAX"}, shape_field<&Tmcm3216DriveObjects::d2>()},
    {{37, "VMAX minimum time", 0, 65535, 0, access("RWE"), Unit::kMicrosecond, "[Motwin decision] range, default and unit (no CANopen object): the shortest cruise at VMAX"}, config_field<&TmclAxisConfig::cruise_minimum_time_us>()},
    {{140, "microstep resolution", 0, 8, 8, access("RWE"), Unit::kNone, "[Motwin decision] default of 2000: 0 full step, 1 half, 2..8: 4..256 microsteps; takes effect at standstill"}, stepper_field<&StepperObjects::microstep_code>()},
    {{206, "load value", 0, 1023, 0, access("R"), Unit::kNone, "StallGuard2 load value (2101)"}, stepper_value<&Tmcm3216Stepper::load_value>()},
  };
  // clang-format on
  static constexpr Table kTable = params::sorted_table<Module>(kRows);
  return kTable;
}

const Tmcm3216Tmcl::Table& Tmcm3216Tmcl::global_parameters() {
  // clang-format off
  static constexpr Row kSettingRows[] = {
    {{65, "RS485 baud rate", 0, 11, 0, access("RWA"), Unit::kBaudRateCode, "[Motwin decision] the TMCM-142's codes: 0 9600 .. 11 1000000 bit/s; no effect on a pseudo-terminal"}, global_field<&TmclGlobalConfig::serial_baud_rate_code>()},
    {{66, "serial address", 1, 255, 1, access("RWA"), Unit::kAddress, "Module (target) address"}, global_field<&TmclGlobalConfig::serial_address>()},
    {{68, "serial heartbeat", 0, 65535, 0, access("RWA"), Unit::kMillisecond, "[Motwin decision] range and default; stored; Motwin does not watch the serial link (0 = off)"}, global_field<&TmclGlobalConfig::serial_heartbeat_ms>()},
    {{69, "CAN bit rate", 2, 8, 8, access("RWA"), Unit::kBitRateCode, "[Motwin decision] the TMCM-142's codes: 2 20, 3 50, 4 100, 5 125, 6 250, 7 500, 8 1000 kbit/s"}, global_field<&TmclGlobalConfig::can_bit_rate_code>()},
    {{70, "CAN send ID", 0, 2047, 2, access("RWA"), Unit::kAddress, "CAN identifier of the module's replies"}, global_field<&TmclGlobalConfig::can_reply_id>()},
    {{71, "CAN receive ID", 0, 2047, 1, access("RWA"), Unit::kAddress, "CAN identifier the module listens to"}, global_field<&TmclGlobalConfig::can_id>()},
    {{75, "telegram pause time", 0, 255, 0, access("RWA"), Unit::kMillisecond, "Pause before a serial reply is sent"}, global_field<&TmclGlobalConfig::telegram_pause_ms>()},
    {{76, "serial host address", 1, 255, 2, access("RWA"), Unit::kAddress, "Host address used in replies"}, global_field<&TmclGlobalConfig::serial_host_address>()},
    {{77, "auto start mode", 0, 1, 0, access("RWA"), Unit::kNone, "[Motwin decision] default 0: 1 starts the TMCL program after power-up"}, global_field<&TmclGlobalConfig::auto_start_mode>()},
    {{81, "protection mode", 0, 3, 0, access("RWA"), Unit::kNone, "[Motwin decision] range and default; TMCL code protection; stored, Motwin does not protect the program"}, global_field<&TmclGlobalConfig::code_protection>()},
    {{82, "CAN heartbeat", 0, 65535, 0, access("RWA"), Unit::kMillisecond, "[Motwin decision] range and default; stored; Motwin does not watch the CAN link (0 = off)"}, global_field<&TmclGlobalConfig::can_heartbeat_ms>()},
    {{83, "CAN secondary address", 0, 2047, 0, access("RWA"), Unit::kAddress, "[Motwin decision] range and default; stored; Motwin listens on GP 71 only (0 = off)"}, global_field<&TmclGlobalConfig::can_secondary_id>()},
    {{84, "EEPROM coordinate store", 0, 1, 0, access("RWA"), Unit::kNone, "[Motwin decision] range and default; stored; this firmware has no coordinates in Motwin"}, global_field<&TmclGlobalConfig::coordinate_storage>()},
    {{85, "zero user variables", 0, 1, 0, access("RWA"), Unit::kNone, "0 user variables 0..55 restored at power-up, 1 they start at 0"}, global_field<&TmclGlobalConfig::skip_user_variable_restore>()},
    {{86, "serial secondary address", 0, 255, 0, access("RWA"), Unit::kAddress, "[Motwin decision] range and default; stored; Motwin answers on GP 66 only (0 = off)"}, global_field<&TmclGlobalConfig::serial_secondary_address>()},
  };
  // clang-format on
  static constexpr auto kRows = params::join_rows<Module>(kSettingRows, program_status_rows());
  static constexpr Table kTable = params::sorted_table<Module>(kRows);
  return kTable;
}

}  // namespace motwin::modules::tmcm3216
