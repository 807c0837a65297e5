// The TMCM-142 parameter tables, numbered and named as the real module's list
// (tests/data/tmcm142_real_parameters.csv, docs/tmcm-142.md "Sources"), and the global parameters
// of bank 0, bound to the module's config and state. What no public source says (a range, a
// default, a bit) is tagged params::kMotwinDecisionTag. Speeds and accelerations read and write
// in the units AP 255 selects.
#include <algorithm>
#include <cmath>

#include "core/modules/tmcm142/tmcm142.h"

namespace motwin::modules::tmcm142 {
namespace {

using params::access;
using params::Binding;
using params::Unit;
using tmcl::Status;

motion::EasyPidConfig& pid_config(Tmcm142& m) { return m.axis().config.pid; }

template <int32_t motion::EasyPidConfig::*Field>
constexpr Binding<Tmcm142> pid_field() {
  return params::field_binding<Tmcm142, pid_config, Field>();
}

int32_t clamp_to_int32(double v) {
  if (v >= 2147483647.0) return INT32_MAX;
  if (v <= -2147483648.0) return INT32_MIN;
  return static_cast<int32_t>(std::lround(v));
}

bool pps_mode(const Tmcm142& m) { return m.axis().config.unit_mode == UnitMode::kMicrostepsPerSecond; }

// Speeds: TMC457 units (v * fCLK / 2^32 µsteps/s) or µsteps/s up to 31999999.
int32_t speed_to_wire(const Tmcm142& m, double pps) {
  return clamp_to_int32(pps_mode(m) ? pps : pps / kPpsPerVelocityUnit);
}
bool speed_from_wire(const Tmcm142& m, int32_t wire, double& pps) {
  const int64_t magnitude = wire < 0 ? -static_cast<int64_t>(wire) : wire;
  if (pps_mode(m)) {
    if (magnitude > kMaxVelocityPps) return false;
    pps = wire;
  } else {
    pps = wire * kPpsPerVelocityUnit;
  }
  return true;
}

// Accelerations: TMC457 units (a * fCLK² / 2^48 µsteps/s²) or µsteps/s², the same 1..16777215.
int32_t acceleration_to_wire(const Tmcm142& m, double pps2) {
  return clamp_to_int32(pps_mode(m) ? pps2 : pps2 / kPps2PerAccelerationUnit);
}
double acceleration_from_wire(const Tmcm142& m, int32_t wire) {
  return pps_mode(m) ? static_cast<double>(wire) : wire * kPps2PerAccelerationUnit;
}

template <double AxisConfig::*Field>
constexpr Binding<Tmcm142> speed_field() {
  return {[](Tmcm142& m, uint8_t) { return speed_to_wire(m, m.axis().config.*Field); },
          [](Tmcm142& m, uint8_t, int32_t value) {
            double pps = 0.0;
            if (!speed_from_wire(m, value, pps)) return Status::kInvalidValue;
            m.axis().config.*Field = pps;
            return Status::kOk;
          }};
}

template <double AxisConfig::*Field>
constexpr Binding<Tmcm142> acceleration_field() {
  return {[](Tmcm142& m, uint8_t) { return acceleration_to_wire(m, m.axis().config.*Field); },
          [](Tmcm142& m, uint8_t, int32_t value) {
            m.axis().config.*Field = acceleration_from_wire(m, value);
            return Status::kOk;
          }};
}

// AP 255. TMC457 units reach 14.6 times further than the µsteps/s² of unit mode 1 (both
// 1..16777215 on the wire): a switch to mode 1 lowers each acceleration above 16777215 µsteps/s²
// to it, so that AP 5, 15, 16 and 17 still read inside their range (fuzz finding of 2026-11-27).
constexpr Binding<Tmcm142> kUnitMode{
    [](Tmcm142& m, uint8_t) { return static_cast<int32_t>(m.axis().config.unit_mode); },
    [](Tmcm142& m, uint8_t, int32_t value) {
      AxisConfig& config = m.axis().config;
      config.unit_mode = static_cast<UnitMode>(value);
      if (pps_mode(m)) {
        for (double* pps2 : {&config.acceleration_pps2, &config.stop_deceleration_pps2, &config.deceleration_pps2}) {
          *pps2 = std::min(*pps2, static_cast<double>(kMaxAccelerationInternal));
        }
      }
      return Status::kOk;
    }};
constexpr Binding<Tmcm142> kTargetSpeed{
    [](Tmcm142& m, uint8_t) { return speed_to_wire(m, m.axis().state.target_velocity_pps); },
    [](Tmcm142& m, uint8_t, int32_t value) {
      double pps = 0.0;
      if (!speed_from_wire(m, value, pps)) return Status::kInvalidValue;
      m.axis().set_target_velocity(pps);
      return Status::kOk;
    }};
constexpr Binding<Tmcm142> kActualSpeed{
    [](Tmcm142& m, uint8_t) { return speed_to_wire(m, m.axis().actual_velocity_pps()); }, nullptr};
constexpr Binding<Tmcm142> kPidErrorSum{
    [](Tmcm142& m, uint8_t) { return clamp_to_int32(static_cast<double>(m.axis().pid_state().error_sum)); },
    [](Tmcm142& m, uint8_t, int32_t) {
      m.axis().clear_pid_sum();  // any write clears it (V1.06 manual)
      return Status::kOk;
    }};
constexpr Binding<Tmcm142> kPidError{[](Tmcm142& m, uint8_t) { return m.axis().pid_state().error; }, nullptr};
constexpr Binding<Tmcm142> kRampMode{
    [](Tmcm142& m, uint8_t) { return static_cast<int32_t>(m.axis().ramp_mode()); },
    [](Tmcm142& m, uint8_t, int32_t value) {
      return m.axis().set_ramp_mode(value) == 0 ? Status::kOk : Status::kInvalidValue;
    }};

}  // namespace

// The bindings (config_field, state_value, axis_command ...) are those of tmcl::ModuleRows
// (core/tmcl/module_rows.h).
const Tmcm142::Table& Tmcm142::axis_parameters() {
  // clang-format off
  static constexpr Row kRows[] = {
    {{0, "target position", kMin32, kMax32, 0, access("RW"), Unit::kMicrosteps, "Target position; writing it starts a move in position mode (as MVP ABS); clipped to enabled position limits (AP 50..53)"}, axis_command<&Tmcm142Axis::target_position, &Tmcm142Axis::set_target_position>()},
    {{1, "actual position", kMin32, kMax32, 0, access("RW"), Unit::kMicrosteps, "Position counter of the ramp generator; writing it sets the counter without moving"}, axis_command<&Tmcm142Axis::actual_position, &Tmcm142Axis::set_actual_position>()},
    {{2, "target velocity", -kMax32, kMax32, 0, access("RW"), Unit::kSpeed, "Target velocity of velocity mode (ROR/ROL); unit mode 1 limits it to +-31999999"}, kTargetSpeed},
    {{3, "actual velocity", -kMax32, kMax32, 0, access("R"), Unit::kSpeed, "Velocity of the ramp generator"}, kActualSpeed},
    {{4, "max velocity", 0, kMax32, kDefaultMaxVelocity, access("RWE"), Unit::kSpeed, "VMAX of positioning; unit mode 1: 0..31999999 µsteps/s"}, speed_field<&AxisConfig::max_velocity_pps>()},
    {{5, "max acceleration", 1, kMaxAccelerationInternal, kDefaultAcceleration, access("RWE"), Unit::kAcceleration, "AMAX; also the deceleration while AP 17 is 0. The same setting as AP 16"}, acceleration_field<&AxisConfig::acceleration_pps2>()},
    {{6, "max current", 0, 15, 5, access("RWE"), Unit::kNone, "Run current: (value + 1) * 7000 / 16 mA peak"}, config_field<&AxisConfig::run_current_code>()},
    {{7, "standby current", 0, 15, 1, access("RWE"), Unit::kNone, "Current at rest after the standby delay (AP 20): (value + 1) * 7000 / 16 mA peak"}, config_field<&AxisConfig::standby_current_code>()},
    {{8, "position reached flag", 0, 1, 0, access("R"), Unit::kNone, "1 in position mode at rest exactly on the target"}, axis_value<&Tmcm142Axis::position_reached>()},
    {{9, "switch status", 0, 7, 0, access("R"), Unit::kNone, "[Motwin decision] bit 0 right limit switch (AP 10), bit 1 left (AP 11), bit 2 home switch"}, axis_value<&Tmcm142Axis::switch_status>()},
    {{10, "right endstop", 0, 1, 0, access("R"), Unit::kNone, "1 while the right limit switch is active (after AP 14 polarity and swap)"}, state_value<&AxisState::right_switch_active>()},
    {{11, "left endstop", 0, 1, 0, access("R"), Unit::kNone, "1 while the left limit switch is active"}, state_value<&AxisState::left_switch_active>()},
    {{12, "right limit switch disable", 0, 1, 0, access("RWE"), Unit::kNone, "1: the right switch does not stop the motor"}, config_field<&AxisConfig::right_switch_disable>()},
    {{13, "left limit switch disable", 0, 1, 0, access("RWE"), Unit::kNone, "1: the left switch does not stop the motor"}, config_field<&AxisConfig::left_switch_disable>()},
    {{14, "switch mode", 0, 63, 0, access("RWE"), Unit::kNone, "[Motwin decision] bit 2 invert left, bit 3 invert right, bit 4 swap left/right, bits 0, 1 unused; bit 5 (public) soft stop with AP 15, else hard stop"}, config_field<&AxisConfig::switch_mode>()},
    {{15, "stop event decel.", 1, kMaxAccelerationInternal, kDefaultAcceleration, access("RWE"), Unit::kAcceleration, "Deceleration of a soft stop at a limit switch or position limit"}, acceleration_field<&AxisConfig::stop_deceleration_pps2>()},
    {{16, "max. acceleration", 1, kMaxAccelerationInternal, kDefaultAcceleration, access("RW"), Unit::kAcceleration, "[Motwin decision] AP 5 under its TMC457 name: the same setting, stored with STAP 5"}, acceleration_field<&AxisConfig::acceleration_pps2>()},
    {{17, "max deceleration", 0, kMaxAccelerationInternal, 0, access("RWE"), Unit::kAcceleration, "[Motwin decision] DMAX of positioning and of velocity changes towards 0; 0 = the acceleration (AP 5)"}, acceleration_field<&AxisConfig::deceleration_pps2>()},
    {{18, "max. bow", 1, kMaxBow, kDefaultBow, access("RWE"), Unit::kNone, "[Motwin decision] jerk of all four changes of acceleration, b * fCLK^3 / 2^64 µsteps/s^3; 16777215 = unlimited (trapezoid)"}, config_field<&AxisConfig::max_bow>()},
    {{19, "shaft", 0, 1, 0, access("RWE"), Unit::kNone, "1 turns the motor the other way for the same positions (the encoder count follows, AP 43)"}, config_field<&AxisConfig::shaft>()},
    {{20, "standby delay", 0, 65535, 200, access("RWE"), Unit::kTenMilliseconds, "[Motwin decision] unit, range and default; time at rest before the standby current (AP 7)"}, config_field<&AxisConfig::standby_delay_10ms>()},
    {{21, "mixed decay run", 0, 1, 0, access("RWE"), Unit::kNone, "[Motwin decision] mixed decay while running; stored, the simulated chopper regulates the current exactly"}, config_field<&AxisConfig::mixed_decay_run>()},
    {{22, "mixed decay standby", 0, 1, 0, access("RWE"), Unit::kNone, "[Motwin decision] mixed decay at standby current; stored, no effect in the simulation"}, config_field<&AxisConfig::mixed_decay_standby>()},
    {{23, "chopper clock divider", 0, 255, 0, access("RWE"), Unit::kNone, "[Motwin decision] chopper frequency divider; stored, no effect in the simulation"}, config_field<&AxisConfig::chopper_clock_divider>()},
    {{26, "driver status", 0, 7, 0, access("R"), Unit::kNone, "[Motwin decision] bit 0 standby current applied, bit 1 supply below 15 V, bit 2 compare output (AP 48) high"}, axis_value<&Tmcm142Axis::driver_status>()},
    {{27, "microstep resolution", kFinestResolutionCode, kCoarsestResolutionCode, kFinestResolutionCode, access("RWE"), Unit::kNone, "2^(11 - value) microsteps per full step: 1 = 1024 ... 11 = full steps; 0 (2048) refused"}, config_field<&AxisConfig::microstep_code>()},
    {{28, "PID tolerance", 0, 1 << 23, 0, access("RWE"), Unit::kMicrosteps, "[Motwin decision] |encoder - actual position| up to this counts as 0 for the easyPID (AP 38 then reads 0)"}, config_field<&AxisConfig::pid_tolerance>()},
    {{29, "sine wave offset", 0, 255, 0, access("RWE"), Unit::kNone, "[Motwin decision] offset of the driver's sine table; stored, no effect in the simulation"}, config_field<&AxisConfig::sine_wave_offset>()},
    {{30, "PID p factor", 0, 16777215, 65536, access("RWE"), Unit::kNone, "[Motwin decision] range and default; easyPID P: -pid_e * P / 256"}, pid_field<&motion::EasyPidConfig::p>()},
    {{31, "PID i factor", 0, 16777215, 0, access("RWE"), Unit::kNone, "[Motwin decision] range; easyPID I: -pid_isum * I / 65536"}, pid_field<&motion::EasyPidConfig::i>()},
    {{32, "PID d factor", 0, 16777215, 0, access("RWE"), Unit::kNone, "easyPID D: (last pid_e - pid_e, clipped to +-127) * D"}, pid_field<&motion::EasyPidConfig::d>()},
    {{33, "PID i clipping", 0, 32640, 0, access("RWE"), Unit::kNone, "pid_isum clipped to +-value * 2^16"}, pid_field<&motion::EasyPidConfig::i_clip>()},
    {{34, "PID i sum", kMin32, kMax32, 0, access("RW"), Unit::kNone, "Integrator sum (fCLK/128 samples); any write clears it"}, kPidErrorSum},
    {{35, "PID d clock divider", 0, 255, 0, access("RWE"), Unit::kNone, "D sampled every value * 128 clocks (0 = 256)"}, pid_field<&motion::EasyPidConfig::d_clock_divider>()},
    {{37, "pid_dv_clip", 0, kMax32, 67108864, access("RWE"), Unit::kTmc457Velocity, "Limit of the velocity correction"}, pid_field<&motion::EasyPidConfig::velocity_clip>()},
    {{38, "pid_e", -(1 << 23), 1 << 23, 0, access("R"), Unit::kMicrosteps, "PID error: encoder position - actual position, clipped to +-2^23"}, kPidError},
    {{39, "pid_vactual", kMin32, kMax32, 0, access("R"), Unit::kTmc457Velocity, "Ramp velocity plus the easyPID correction"}, axis_value<&Tmcm142Axis::pid_velocity_internal>()},
    {{40, "PID mode", 0, 1, 0, access("RWE"), Unit::kNone, "0 open loop, 1 easyPID on the encoder"}, config_field<&AxisConfig::pid_mode>()},
    {{41, "encoder position", kMin32, kMax32, 0, access("RW"), Unit::kMicrosteps, "Encoder counter scaled by AP 42; writing sets it"}, axis_command<&AxisState::encoder_position, &Tmcm142Axis::set_encoder_position>()},
    {{42, "encoder constant", 0, kMax32, 3355443, access("RWE"), Unit::kNone, "Microsteps per encoder count * 65536 (default 51.2: 4000 counts/rev at 1024 microsteps)"}, config_field<&AxisConfig::encoder_constant>()},
    {{43, "encoder mode", 0, encoder_mode::kAll, 0, access("RWE"), Unit::kNone, "[Motwin decision] bit 0 count the other way, bit 1 latch AP 45/46 at each N (null channel) pulse, bit 2 also restart the encoder count from 0 there"}, config_field<&AxisConfig::encoder_mode>()},
    {{44, "encoder status", 0, 1, 0, access("R"), Unit::kNone, "[Motwin decision] bit 0 an N pulse latched AP 45/46 since the last read; cleared by reading"}, axis_value<&Tmcm142Axis::take_encoder_status>()},
    {{45, "encoder latch", kMin32, kMax32, 0, access("R"), Unit::kMicrosteps, "Encoder position at the last latching N pulse (AP 43 bit 1)"}, state_value<&AxisState::encoder_latch>()},
    {{46, "position latch", kMin32, kMax32, 0, access("R"), Unit::kMicrosteps, "Actual position at the last latching N pulse (AP 43 bit 1)"}, state_value<&AxisState::position_latch>()},
    {{47, "encoder warn distance", 0, kMax32, 0, access("RWE"), Unit::kMicrosteps, "[Motwin decision] range and default (0 = off); |encoder - actual position| above it sets AP 129 bit 3"}, config_field<&AxisConfig::encoder_warn_distance>()},
    {{48, "compare position", kMin32, kMax32, 0, access("RWE"), Unit::kMicrosteps, "[Motwin decision] the compare output (AP 26 bit 2) is high while the actual position is at or above it"}, config_field<&AxisConfig::compare_position>()},
    {{50, "right position limit", kMin32, kMax32, 0, access("RWE"), Unit::kMicrosteps, "With AP 52: targets above it end on it, motion beyond it stops as at the right switch"}, config_field<&AxisConfig::right_position_limit>()},
    {{51, "left position limit", kMin32, kMax32, 0, access("RWE"), Unit::kMicrosteps, "With AP 53: targets below it end on it, motion beyond it stops as at the left switch"}, config_field<&AxisConfig::left_position_limit>()},
    {{52, "right position limit enable", 0, 1, 0, access("RWE"), Unit::kNone, "1 enables AP 50"}, config_field<&AxisConfig::right_position_limit_enable>()},
    {{53, "left position limit enable", 0, 1, 0, access("RWE"), Unit::kNone, "1 enables AP 51"}, config_field<&AxisConfig::left_position_limit_enable>()},
    {{63, "microstep table position", 0, 4095, 0, access("R"), Unit::kNone, "[Motwin decision] entry of the driver's sine table: 1024 per full step, 4096 per electrical period"}, axis_value<&Tmcm142Axis::microstep_table_position>()},
    {{64, "step pulse length", 0, 255, 0, access("RWE"), Unit::kNone, "[Motwin decision] stored; the module drives its own power stage, no step output is simulated"}, config_field<&AxisConfig::step_pulse_length>()},
    {{128, "ramp mode", 0, 3, 0, access("RW"), Unit::kNone, "0 position, 2 velocity, 3 hold (1 refused)"}, kRampMode},
    {{129, "status flags", 0, 15, 0, access("R"), Unit::kNone, "Bit 0 position reached, 1 velocity reached, 2 velocity zero, 3 encoder warn distance (AP 47) or max. deviation (AP 212) exceeded"}, axis_value<&Tmcm142Axis::status_flags>()},
    {{130, "velocity reached", 0, 1, 0, access("R"), Unit::kNone, "1 when the actual speed equals the target speed"}, axis_value<&Tmcm142Axis::velocity_reached>()},
    {{193, "reference search mode", 1, 3, 1, access("RWE"), Unit::kNone, "1 left switch, 2 right then left switch, 3 as 2 with the reference at the centre of the left switch"}, config_field<&AxisConfig::reference_mode>()},
    {{194, "reference search speed", 0, kMax32, kDefaultMaxVelocity, access("RWE"), Unit::kSpeed, "Fast approach of the switches"}, speed_field<&AxisConfig::reference_fast_pps>()},
    {{195, "ref switch speed", 0, kMax32, kDefaultReferenceSlow, access("RWE"), Unit::kSpeed, "Slow search of the switching points (default a quarter of AP 4)"}, speed_field<&AxisConfig::reference_slow_pps>()},
    {{196, "reference switch distance", kMin32, kMax32, 0, access("R"), Unit::kMicrosteps, "End switch distance: right minus left switching point, measured by modes 2 and 3"}, state_value<&AxisState::travel>()},
    {{207, "extended error flags", 0, 3, 0, access("R"), Unit::kNone, "Bit 1 stopped by encoder deviation (bit 0 is never set by Motwin); cleared by reading"}, axis_value<&Tmcm142Axis::take_error_flags>()},
    {{212, "max. encoder deviation", 0, kMax32, 0, access("RWE"), Unit::kMicrosteps, "|encoder - actual position| above it stops the motor and sets EDV; 0 off"}, config_field<&AxisConfig::max_encoder_deviation>()},
    {{255, "unit mode", 0, 1, 0, access("RWE"), Unit::kNone, "Speeds and accelerations: 0 TMC457 units, 1 µsteps/s and µsteps/s² (accelerations above 16777215 µsteps/s² are lowered to it)"}, kUnitMode},
  };
  // clang-format on
  static constexpr Table kTable = params::sorted_table<Tmcm142>(kRows);
  return kTable;
}

// Bank 0: docs/tmcm-142.md "Global parameters (bank 0)"; every writable one below 128 is
// automatically stored (A), as on the TMCM-1636 (docs/decisions.md). GP 73 stores itself.
// GP 128..132 come from the TMCL module base.
const Tmcm142::Table& Tmcm142::global_parameters() {
  // clang-format off
  static constexpr Row kSettingRows[] = {
    {{64, "EEPROM magic", 0, 255, kEepromMagic, access("RWA"), Unit::kNone, "[Motwin decision] from the TMCM-351 (not in the real list): any value other than 228 re-initialises all parameters at the next power-up"}, global_field<&GlobalConfig::eeprom_magic>()},
    {{65, "serial baud rate", 0, 11, 0, access("RWA"), Unit::kBaudRateCode, "0 9600, 1 14400, 2 19200, 3 28800, 4 38400, 5 57600, 6 76800, 7 115200, 8 230400, 9 250000, 10 500000, 11 1000000 bit/s; no effect on a pseudo-terminal"}, global_field<&GlobalConfig::serial_baud_rate_code>()},
    {{66, "serial address", 1, 255, 1, access("RWA"), Unit::kAddress, "Module (target) address"}, global_field<&GlobalConfig::serial_address>()},
    {{67, "ASCII mode", 0, 255, 0, access("RWA"), Unit::kNone, "Bit 0 start in ASCII mode; bits 4-5 echo: 00 each character, bit 4 whole line after CR, bit 5 none"}, global_field<&GlobalConfig::ascii_mode>()},
    {{68, "serial heartbeat", 0, 65535, 0, access("RWA"), Unit::kMillisecond, "[Motwin decision] range and default; stored; Motwin does not watch the serial link (0 = off)"}, global_field<&GlobalConfig::serial_heartbeat_ms>()},
    {{69, "CAN bitrate", 2, 8, 8, access("RWA"), Unit::kBitRateCode, "2 20, 3 50, 4 100, 5 125, 6 250, 7 500, 8 1000 kbit/s"}, global_field<&GlobalConfig::can_bit_rate_code>()},
    {{70, "CAN reply ID", 0, 2047, 2, access("RWA"), Unit::kAddress, "CAN identifier of the module's replies"}, global_field<&GlobalConfig::can_reply_id>()},
    {{71, "CAN ID", 0, 2047, 1, access("RWA"), Unit::kAddress, "CAN identifier the module listens to"}, global_field<&GlobalConfig::can_id>()},
    {{73, "EEPROM lock", 0, kUnlockCode, 0, access("RW"), Unit::kNone, "[Motwin decision] from the TMCM-351 (not in the real list): write 1234 to lock, 4321 to unlock (kept over power-up); reads 1 while locked. Locked: STAP, STGP, stored SGP and stored coordinates answer status 5"},
     {[](Tmcm142& m, uint8_t) { return int32_t{m.eeprom_locked() ? 1 : 0}; },
      [](Tmcm142& m, uint8_t, int32_t value) { return m.set_eeprom_lock(value); }}},
    {{75, "telegram pause time", 0, 255, 0, access("RWA"), Unit::kMillisecond, "Pause before a serial reply is sent"}, global_field<&GlobalConfig::telegram_pause_ms>()},
    {{76, "serial host address", 1, 255, 2, access("RWA"), Unit::kAddress, "Host address used in replies"}, global_field<&GlobalConfig::serial_host_address>()},
    {{77, "auto start mode", 0, 1, 1, access("RWA"), Unit::kNone, "1 starts the TMCL program after power-up"}, global_field<&GlobalConfig::auto_start_mode>()},
    {{81, "protection mode", 0, 3, 0, access("RWA"), Unit::kNone, "[Motwin decision] range and default; TMCL code protection; stored, Motwin does not protect the program"}, global_field<&GlobalConfig::code_protection>()},
    {{82, "CAN heartbeat", 0, 65535, 0, access("RWA"), Unit::kMillisecond, "[Motwin decision] range and default; stored; Motwin does not watch the CAN link (0 = off)"}, global_field<&GlobalConfig::can_heartbeat_ms>()},
    {{83, "CAN secondary address", 0, 2047, 0, access("RWA"), Unit::kAddress, "[Motwin decision] range and default; stored; Motwin listens on GP 71 only (0 = off)"}, global_field<&GlobalConfig::can_secondary_id>()},
    {{84, "eeprom coordinate store", 0, 1, 0, access("RWA"), Unit::kNone, "0 coordinates in RAM (SCO/GCO n, 255 copy them), 1 coordinates 1..20 stored at once and restored at power-up"}, global_field<&GlobalConfig::coordinate_storage>()},
    {{85, "zero user variables", 0, 1, 0, access("RWA"), Unit::kNone, "0 user variables 0..55 restored at power-up, 1 they start at 0"}, global_field<&GlobalConfig::skip_user_variable_restore>()},
    {{87, "serial secondary address", 0, 255, 0, access("RWA"), Unit::kAddress, "[Motwin decision] range and default; stored; Motwin answers on GP 66 only (0 = off)"}, global_field<&GlobalConfig::serial_secondary_address>()},
  };
  // GP 131 and 133 besides the base's GP 128..132.
  static constexpr Row kRandomNumberRows[] = {
    {{131, "last TMCL error", 0, 255, 0, access("R"), Unit::kNone, "[Motwin decision] status code (2..6) of the last command that failed, from a host or the program; 0 none since power-up"},
     {[](Tmcm142& m, uint8_t) { return static_cast<int32_t>(m.runtime().last_error); }, nullptr}},
    {{133, "random number", 0, kMax32, 0, access("R"), Unit::kNone, "A new pseudo-random number 0..2^31-1 on every read (xorshift, reproducible)"},
     {[](Tmcm142& m, uint8_t) { return m.next_random(); }, nullptr}},
  };
  // clang-format on
  // GP 131 goes between the base's 130 and 132.
  static constexpr auto kRows = [] {
    auto rows = params::join_rows<Tmcm142>(kSettingRows, program_status_rows(), kRandomNumberRows);
    std::sort(rows.begin(), rows.end(), [](const Row& a, const Row& b) { return a.info.number < b.info.number; });
    return rows;
  }();
  static constexpr Table kTable = params::sorted_table<Tmcm142>(kRows);
  return kTable;
}

}  // namespace motwin::modules::tmcm142
