// The TMCM-1636 parameter tables: every row of manual table 11 (axis parameters) and
// table 13 (global parameters, bank 0), bound to the module's config and state fields.
// Ranges whose separators the manual lost ("060000") are read as "0...60000".
#include <cmath>
#include <iterator>

#include "core/modules/tmcm1636/tmcm1636.h"
#include "core/modules/tmcm1636/tmcm1636_hardware.h"

namespace motwin::modules::tmcm1636 {
namespace {

using params::access;
using params::Binding;
using params::Unit;

// The regulators' gains (AP 70..74) and their live errors and error sums (AP 75..81) are the
// fields of their motion::PiConfig and motion::PiState (core/motion/pi_regulator.h).
motion::PiConfig& current_pi_config(Tmcm1636& m) { return m.axis().config.current_pi; }
motion::PiConfig& velocity_pi_config(Tmcm1636& m) { return m.axis().config.velocity_pi; }
motion::PiConfig& position_pi_config(Tmcm1636& m) { return m.axis().config.position_pi; }
motion::PiState& torque_pi_state(Tmcm1636& m) { return m.axis().state.torque_pi; }
motion::PiState& flux_pi_state(Tmcm1636& m) { return m.axis().state.flux_pi; }
motion::PiState& velocity_pi_state(Tmcm1636& m) { return m.axis().state.velocity_pi; }
motion::PiState& position_pi_state(Tmcm1636& m) { return m.axis().state.position_pi; }

template <auto Part, int32_t motion::PiConfig::*Field>
constexpr Binding<Tmcm1636> pi_gain() {
  return params::field_binding<Tmcm1636, Part, Field>();
}

template <auto Part, int32_t motion::PiState::*Field>
constexpr Binding<Tmcm1636> pi_value() {
  return params::field_binding<Tmcm1636, Part, Field, false>();
}

constexpr Binding<Tmcm1636> kSupplyVoltage{
    [](Tmcm1636& m, uint8_t) {
      return supply_decivolt_from_adc(m.io().analog_input(board::Tmcm1636Io::kAnalogSupplyChannel));
    },
    nullptr};
constexpr Binding<Tmcm1636> kDriverTemperature{
    [](Tmcm1636& m, uint8_t) {
      return temperature_celsius_from_adc(m.io().analog_input(board::Tmcm1636Io::kAnalogTemperatureChannel));
    },
    nullptr};

// Firmware 1.13's motor direction (AP 13): with AP 13 = 1 the host's frame is the motor's
// inverted, so a binding of a signed motion value (target and actual torque, velocity, position)
// changes the sign on its way in and out. Negation wraps at 32 bits like the position counter.
int32_t directed(const Tmcm1636& m, int32_t value) {
  return m.axis().config.motor_direction != 0 ? static_cast<int32_t>(0u - static_cast<uint32_t>(value)) : value;
}

// kWritable says whether kMotorFrame has a setter (a function pointer is no constant expression
// under the sanitizers, so the row tells).
template <const Binding<Tmcm1636>& kMotorFrame, bool kWritable>
constexpr Binding<Tmcm1636> host_frame() {
  Binding<Tmcm1636> binding;
  binding.get = [](Tmcm1636& m, uint8_t axis) { return directed(m, kMotorFrame.get(m, axis)); };
  if constexpr (kWritable) {
    binding.set = [](Tmcm1636& m, uint8_t axis, int32_t value) { return kMotorFrame.set(m, axis, directed(m, value)); };
  }
  return binding;
}

// Firmware 1.13's positions (AP 50, 51, 52): the host's frame is also scaled to AP 56 counts per
// revolution (Tmcm1636Axis::host_position).
template <const Binding<Tmcm1636>& kMotorFrame, bool kWritable>
constexpr Binding<Tmcm1636> host_position_frame() {
  Binding<Tmcm1636> binding;
  binding.get = [](Tmcm1636& m, uint8_t axis) { return directed(m, m.axis().host_position(kMotorFrame.get(m, axis))); };
  if constexpr (kWritable) {
    binding.set = [](Tmcm1636& m, uint8_t axis, int32_t value) {
      return kMotorFrame.set(m, axis, m.axis().axis_position(directed(m, value)));
    };
  }
  return binding;
}

}  // namespace

// Manual table 11. The bindings (config_field, state_value, axis_command ...) are those of
// tmcl::ModuleRows (core/tmcl/module_rows.h).
const Tmcm1636::Table& Tmcm1636::axis_parameters(Firmware firmware) {
  // The motion values AP 13 of firmware 1.13 inverts (host_frame above).
  static constexpr Binding kTargetTorque = axis_command<&AxisState::target_torque_ma, &Tmcm1636Axis::set_target_torque>();
  static constexpr Binding kActualTorque = state_value<&AxisState::actual_torque_ma>();
  static constexpr Binding kTargetVelocity = axis_command<&AxisState::target_velocity_rpm, &Tmcm1636Axis::set_target_velocity>();
  static constexpr Binding kRampVelocity = state_value<&AxisState::ramp_velocity_rpm>();
  static constexpr Binding kActualVelocity = state_value<&AxisState::actual_velocity_rpm>();
  static constexpr Binding kTargetPosition = axis_command<&Tmcm1636Axis::target_position, &Tmcm1636Axis::set_target_position>();
  static constexpr Binding kRampPosition = axis_value<&Tmcm1636Axis::ramp_position>();
  static constexpr Binding kActualPosition = axis_command<&AxisState::actual_position, &Tmcm1636Axis::set_actual_position>();
  // clang-format off
  static constexpr Row kRows[] = {
    {{0, "adc_I0_raw", 0, 65535, 32767, access("R"), Unit::kAdcCount, "Raw ADC measurement of the phase A shunt"}, state_value<&AxisState::adc_phase_a_raw>()},
    {{1, "adc_I1_raw", 0, 65535, 32767, access("R"), Unit::kAdcCount, "Raw ADC measurement of the phase B shunt"}, state_value<&AxisState::adc_phase_b_raw>()},
    {{2, "adc_I0", -32768, 32767, 0, access("R"), Unit::kMilliampere, "Phase A current: (AP 0 - AP 5) * AP 7 / 256"}, state_value<&AxisState::adc_phase_a>()},
    {{3, "adc_I1", -32768, 32767, 0, access("R"), Unit::kMilliampere, "Phase B current: (AP 1 - AP 6) * AP 7 / 256"}, state_value<&AxisState::adc_phase_b>()},
    {{4, "adc_I2", -32768, 32767, 0, access("R"), Unit::kMilliampere, "Phase C current: -(AP 2 + AP 3)"}, state_value<&AxisState::adc_phase_c>()},
    {{5, "adc_I0_offset", 0, 65535, 32767, access("RWEX"), Unit::kAdcCount, "Dual-shunt phase A offset"}, config_field<&AxisConfig::adc_phase_a_offset>()},
    {{6, "adc_I1_offset", 0, 65535, 32767, access("RWEX"), Unit::kAdcCount, "Dual-shunt phase B offset"}, config_field<&AxisConfig::adc_phase_b_offset>()},
    {{7, "dual shunt factor", 1, 65535, 256, access("RWEX"), Unit::kNone, "Dual-shunt current measurement factor"}, config_field<&AxisConfig::dual_shunt_factor>()},
    {{10, "motor pole pairs", 1, 255, 4, access("RWEX"), Unit::kNone, "Number of motor pole pairs"}, config_field<&AxisConfig::motor_pole_pairs>()},
    {{11, "max current", 0, 60000, 2000, access("RWEX"), Unit::kMilliampere, "Maximum absolute motor current"}, config_field<&AxisConfig::max_current_ma>()},
    {{12, "open loop current", 0, 60000, 2000, access("RWEX"), Unit::kMilliampere, "Motor current in open-loop commutation (mode 1)"}, config_field<&AxisConfig::open_loop_current_ma>()},
    {{14, "motor type", 0, 3, 0, access("RWEX"), Unit::kNone, "0 no motor, 1 single phase DC, 3 three phase BLDC"}, config_field<&AxisConfig::motor_type>()},
    // Selecting ABN or absolute encoder commutation starts the encoder initialisation.
    {{15, "commutation mode", 0, 4, 0, access("RWEX"), Unit::kNone, "0 disabled, 1 open loop, 2 digital hall, 3 ABN encoder, 4 absolute encoder; 3 and 4 start the encoder initialisation"}, axis_command<&AxisConfig::commutation_mode, &Tmcm1636Axis::set_commutation_mode>()},
    {{16, "open loop commutation angle", -32768, 32767, 0, access("R"), Unit::kNone, "Actual open-loop angle"}, state_value<&AxisState::open_loop_angle>()},
    {{17, "encoder commutation angle", -32768, 32767, 0, access("R"), Unit::kNone, "Actual ABN encoder angle"}, state_value<&AxisState::encoder_angle>()},
    {{18, "digital hall commutation angle", -32768, 32767, 0, access("R"), Unit::kNone, "Actual digital hall angle"}, state_value<&AxisState::hall_angle>()},
    {{19, "absolute encoder commutation angle", -32768, 32767, 0, access("R"), Unit::kNone, "Actual absolute encoder angle"}, state_value<&AxisState::absolute_encoder_angle>()},
    {{25, "commutation mode position", 0, 2, 0, access("RWEX"), Unit::kNone, "Position source: 0 same as FOC, 1 ABN encoder, 2 absolute encoder"}, config_field<&AxisConfig::position_commutation_mode>()},
    {{30, "target torque", -60000, 60000, 0, access("RW"), Unit::kMilliampere, "Target current; writing it selects current regulation"}, kTargetTorque},
    {{31, "actual torque", kMin32, kMax32, 0, access("R"), Unit::kMilliampere, "Actual motor current"}, kActualTorque},
    {{32, "target flux", -60000, 60000, 0, access("RW"), Unit::kMilliampere, "Target flux; writing it selects current regulation"}, axis_command<&AxisState::target_flux_ma, &Tmcm1636Axis::set_target_flux>()},
    {{33, "actual flux", kMin32, kMax32, 0, access("R"), Unit::kMilliampere, "Actual motor flux"}, state_value<&AxisState::actual_flux_ma>()},
    {{40, "target velocity", -200000, 200000, 0, access("RW"), Unit::kRpm, "Target velocity; writing it selects velocity mode"}, kTargetVelocity},
    {{41, "ramp velocity", kMin32, kMax32, 0, access("R"), Unit::kRpm, "Velocity of the ramp generator"}, kRampVelocity},
    {{42, "actual velocity", kMin32, kMax32, 0, access("R"), Unit::kRpm, "Actual motor velocity"}, kActualVelocity},
    {{43, "max velocity", 0, 200000, 4000, access("RWEX"), Unit::kRpm, "Maximum velocity in velocity and position mode"}, config_field<&AxisConfig::max_velocity_rpm>()},
    {{44, "acceleration", 0, 100000, 2000, access("RWEX"), Unit::kRpmPerSecond, "Acceleration of the velocity ramp (ROR, ROL, MVP)"}, config_field<&AxisConfig::acceleration_rpm_per_s>()},
    {{45, "enable velocity ramp", 0, 1, 1, access("RWEX"), Unit::kNone, "1 ramp generator on, 0 off"}, config_field<&AxisConfig::velocity_ramp_enabled>()},
    {{50, "target position", kMin32, kMax32, 0, access("RW"), Unit::kPositionCount, "Target position; writing it selects position mode"}, kTargetPosition},
    {{51, "ramp position", kMin32, kMax32, 0, access("R"), Unit::kPositionCount, "Position of the ramp generator"}, kRampPosition},
    {{52, "actual position", kMin32, kMax32, 0, access("RW"), Unit::kPositionCount, "Actual position counter"}, kActualPosition},
    {{53, "position reached distance", 0, 100000, 5, access("RWEX"), Unit::kPositionCount, "Largest distance at which the position reached flag is set"}, config_field<&AxisConfig::position_reached_distance>()},
    {{54, "position reached velocity", 0, 200000, 500, access("RWEX"), Unit::kRpm, "Largest velocity at which the position reached flag is set"}, config_field<&AxisConfig::position_reached_velocity_rpm>()},
    {{55, "position reached flag", 0, 1, 0, access("R"), Unit::kNone, "1 when actual position and velocity are within the target window"}, state_value<&AxisState::position_reached>()},
    {{70, "torque P", 0, 32767, 0, access("RWEX"), Unit::kNone, "P of the torque and flux regulators: mV = P * error[mA] / 256"}, pi_gain<current_pi_config, &motion::PiConfig::p>()},
    {{71, "torque I", 0, 32767, 0, access("RWEX"), Unit::kNone, "I of the torque and flux regulators: mV = I * error sum[mA*ticks] / 65536"}, pi_gain<current_pi_config, &motion::PiConfig::i>()},
    {{72, "velocity P", 0, 32767, 0, access("RWEX"), Unit::kNone, "P of the velocity regulator: mA = P * error[rpm] / 256"}, pi_gain<velocity_pi_config, &motion::PiConfig::p>()},
    {{73, "velocity I", 0, 32767, 0, access("RWEX"), Unit::kNone, "I of the velocity regulator: mA = I * error sum[rpm*ticks] / 262144"}, pi_gain<velocity_pi_config, &motion::PiConfig::i>()},
    {{74, "position P", 0, 32767, 0, access("RWEX"), Unit::kNone, "P of the position regulator: rpm = P * error[1/65536 revolution] / 1024"}, pi_gain<position_pi_config, &motion::PiConfig::p>()},
    {{75, "torque PI error sum", kMin32, kMax32, 0, access("R"), Unit::kNone, "Error sum of the torque (q current) regulator, mA*ticks"}, pi_value<torque_pi_state, &motion::PiState::error_sum>()},
    {{76, "flux PI error sum", kMin32, kMax32, 0, access("R"), Unit::kNone, "Error sum of the flux (d current) regulator, mA*ticks"}, pi_value<flux_pi_state, &motion::PiState::error_sum>()},
    {{77, "velocity PI error sum", kMin32, kMax32, 0, access("R"), Unit::kNone, "Error sum of the velocity regulator, rpm*ticks"}, pi_value<velocity_pi_state, &motion::PiState::error_sum>()},
    {{78, "torque PI error", kMin32, kMax32, 0, access("R"), Unit::kNone, "Error of the torque regulator, mA"}, pi_value<torque_pi_state, &motion::PiState::error>()},
    {{79, "flux PI error", kMin32, kMax32, 0, access("R"), Unit::kNone, "Error of the flux regulator, mA"}, pi_value<flux_pi_state, &motion::PiState::error>()},
    {{80, "velocity PI error", kMin32, kMax32, 0, access("R"), Unit::kNone, "Error of the velocity regulator, rpm"}, pi_value<velocity_pi_state, &motion::PiState::error>()},
    {{81, "position PI error", kMin32, kMax32, 0, access("R"), Unit::kNone, "Error of the position regulator, 1/65536 revolution"}, pi_value<position_pi_state, &motion::PiState::error>()},
    {{90, "hall polarity", 0, 1, 0, access("RWEX"), Unit::kNone, "0 standard, 1 inverted"}, config_field<&AxisConfig::hall_polarity>()},
    {{91, "hall direction", 0, 1, 0, access("RWEX"), Unit::kNone, "0 standard, 1 inverted"}, config_field<&AxisConfig::hall_direction>()},
    {{92, "hall interpolation", 0, 1, 0, access("RWEX"), Unit::kNone, "0 off, 1 on"}, config_field<&AxisConfig::hall_interpolation>()},
    {{93, "hall phi_e offset", -32768, 32767, 0, access("RWEX"), Unit::kNone, "Offset of the hall electrical angle"}, config_field<&AxisConfig::hall_phi_e_offset>()},
    {{100, "encoder steps", 0, 16777215, 8192, access("RWEX"), Unit::kEncoderSteps, "Encoder steps per motor revolution"}, config_field<&AxisConfig::encoder_steps>()},
    {{101, "encoder direction", 0, 1, 0, access("RWEX"), Unit::kNone, "0 standard, 1 inverted"}, config_field<&AxisConfig::encoder_direction>()},
    {{102, "encoder init mode", 0, 2, 1, access("RWEX"), Unit::kNone, "0 estimate offset, 1 N channel, 2 use hall"}, config_field<&AxisConfig::encoder_init_mode>()},
    {{103, "encoder init state", 0, 3, 0, access("R"), Unit::kNone, "0 idle, 1 start, 2 wait init time, 3 estimate offset"}, state_value<&AxisState::encoder_init_state>()},
    {{104, "encoder init delay", 0, 10000, 1000, access("RWEX"), Unit::kMillisecond, "Duration of the encoder initialisation"}, config_field<&AxisConfig::encoder_init_delay_ms>()},
    {{105, "encoder init velocity", -200000, 200000, 100, access("RWEX"), Unit::kRpm, "Velocity of the N-channel encoder initialisation"}, config_field<&AxisConfig::encoder_init_velocity_rpm>()},
    {{106, "encoder offset", 0, 65535, 0, access("RWE"), Unit::kNone, "ABN counter value (mod AP 100) at electrical angle 0"}, config_field<&AxisConfig::encoder_offset>()},
    // A write re-arms the clear at the next N pulse (AP 108 = 1 clears only once).
    {{107, "clear on null", 0, 1, 0, access("RWEX"), Unit::kNone, "1 clears the position counter at the next N channel event"}, axis_command<&AxisConfig::clear_on_null, &Tmcm1636Axis::set_clear_on_null>()},
    {{108, "clear once", 0, 1, 0, access("RWEX"), Unit::kNone, "1 clears only once, 0 at every N channel event"}, config_field<&AxisConfig::clear_once>()},
    {{110, "motor PWM frequency", 25000, 100000, 25000, access("RWEX"), Unit::kHertz, "Frequency of the motor PWM"}, config_field<&AxisConfig::pwm_frequency_hz>()},
    {{120, "release brake", 0, 1, 0, access("RW"), Unit::kNone, "1 brake PWM active (brake released)"}, state_field<&AxisState::release_brake>()},
    {{121, "brake releasing duty cycle", 0, 100, 75, access("RWEX"), Unit::kPercent, "Duty cycle of the releasing phase"}, config_field<&AxisConfig::brake_release_duty_percent>()},
    {{122, "brake holding duty cycle", 0, 100, 11, access("RWEX"), Unit::kPercent, "Duty cycle of the holding phase"}, config_field<&AxisConfig::brake_hold_duty_percent>()},
    {{123, "brake releasing duration", 0, 65535, 80, access("RWEX"), Unit::kMillisecond, "Duration of the releasing phase"}, config_field<&AxisConfig::brake_release_duration_ms>()},
    {{124, "enable brake output", 0, 1, 0, access("RWEX"), Unit::kNone, "Brake output function (manual: 0 enabled, 1 disabled)"}, config_field<&AxisConfig::brake_output>()},
    {{125, "invert brake output", 0, 1, 0, access("RWEX"), Unit::kNone, "Brake output polarity (manual: 0 inverted, 1 normal)"}, config_field<&AxisConfig::brake_output_polarity>()},
    {{140, "enable brake chopper", 0, 1, 0, access("RWE"), Unit::kNone, "1 brake chopper active above its voltage limit"}, config_field<&AxisConfig::brake_chopper_enabled>()},
    {{141, "brake chopper voltage limit", 50, 600, 260, access("RWE"), Unit::kDecivolt, "Supply voltage above which the chopper switches on"}, config_field<&AxisConfig::brake_chopper_limit_decivolt>()},
    {{142, "brake chopper hysteresis", 0, 50, 5, access("RWE"), Unit::kDecivolt, "Chopper switches off below limit minus hysteresis"}, config_field<&AxisConfig::brake_chopper_hysteresis_decivolt>()},
    {{144, "brake chopper active", 0, 600, 255, access("R"), Unit::kNone, "Non-zero while the brake chopper is on"}, state_value<&AxisState::brake_chopper_active>()},
    {{156, "status flags", 0, status_flag::kAll, 0, access("R"), Unit::kNone, "Status flag bits (docs/tmcm-1636-servo.md)"}, state_value<&AxisState::status_flags>()},
    {{160, "absolute encoder type", 0, 2, 0, access("RWEX"), Unit::kNone, "0 disabled, 1 AMT20, 2 AMT23"}, config_field<&AxisConfig::absolute_encoder_type>()},
    {{161, "absolute encoder init", 0, 1, 0, access("RWEX"), Unit::kNone, "0 estimate offset, 1 use offset"}, config_field<&AxisConfig::absolute_encoder_init>()},
    {{162, "absolute encoder direction", 0, 1, 0, access("RWEX"), Unit::kNone, "0 standard, 1 inverted"}, config_field<&AxisConfig::absolute_encoder_direction>()},
    {{163, "absolute encoder offset", 0, 65535, 0, access("RWE"), Unit::kNone, "Absolute angle at electrical angle 0, 65536 per revolution"}, config_field<&AxisConfig::absolute_encoder_offset>()},
    {{209, "reference switch enable", 0, 3, 0, access("RWX"), Unit::kNone, "Bit 0 right, bit 1 left: 1 = switch stops motion towards it"}, config_field<&AxisConfig::reference_switch_enable>()},
    {{210, "reference switch polarity", 0, 7, 0, access("RWX"), Unit::kNone, "Bit 0 right, 1 left, 2 home: 1 = high active"}, config_field<&AxisConfig::reference_switch_polarity>()},
    {{211, "right reference switch active", 0, 1, 0, access("R"), Unit::kNone, "1 while the right reference switch is active"}, state_value<&AxisState::right_switch_active>()},
    {{212, "left reference switch active", 0, 1, 0, access("R"), Unit::kNone, "1 while the left reference switch is active"}, state_value<&AxisState::left_switch_active>()},
    {{213, "home reference switch active", 0, 1, 0, access("R"), Unit::kNone, "1 while the home switch is active"}, state_value<&AxisState::home_switch_active>()},
    {{220, "supply voltage", 0, 1000, 480, access("R"), Unit::kDecivolt, "Actual supply voltage"}, kSupplyVoltage},
    {{221, "driver temperature", -20, 150, 0, access("R"), Unit::kDegreeCelsius, "Actual temperature of the motor driver"}, kDriverTemperature},
    {{230, "main loops", 0, kMaxU32, 0, access("R"), Unit::kPerSecond, "Main loops per second"}, state_value<&AxisState::main_loops_per_s>()},
    {{231, "torque loops", 0, kMaxU32, 0, access("R"), Unit::kPerSecond, "Torque loops per second"}, state_value<&AxisState::torque_loops_per_s>()},
    {{232, "velocity loops", 0, kMaxU32, 0, access("R"), Unit::kPerSecond, "Velocity loops per second"}, state_value<&AxisState::velocity_loops_per_s>()},
    {{240, "debug value 0", kMin32, kMax32, 0, access("RW"), Unit::kNone, "Free debugging value"}, element_field<&AxisState::debug_values, 0>()},
    {{241, "debug value 1", kMin32, kMax32, 0, access("RW"), Unit::kNone, "Free debugging value"}, element_field<&AxisState::debug_values, 1>()},
    {{242, "debug value 2", kMin32, kMax32, 0, access("RW"), Unit::kNone, "Free debugging value"}, element_field<&AxisState::debug_values, 2>()},
    {{243, "debug value 3", kMin32, kMax32, 0, access("RW"), Unit::kNone, "Free debugging value"}, element_field<&AxisState::debug_values, 3>()},
    {{244, "debug value 4", kMin32, kMax32, 0, access("RW"), Unit::kNone, "Free debugging value"}, element_field<&AxisState::debug_values, 4>()},
    {{245, "debug value 5", kMin32, kMax32, 0, access("RW"), Unit::kNone, "Free debugging value"}, element_field<&AxisState::debug_values, 5>()},
    {{246, "debug value 6", kMin32, kMax32, 0, access("RW"), Unit::kNone, "Free debugging value"}, element_field<&AxisState::debug_values, 6>()},
    {{247, "debug value 7", kMin32, kMax32, 0, access("RW"), Unit::kNone, "Free debugging value"}, element_field<&AxisState::debug_values, 7>()},
    {{248, "debug value 8", kMin32, kMax32, 0, access("RW"), Unit::kNone, "Free debugging value"}, element_field<&AxisState::debug_values, 8>()},
    {{249, "debug value 9", kMin32, kMax32, 0, access("RW"), Unit::kNone, "Free debugging value"}, element_field<&AxisState::debug_values, 9>()},
    // Manual default column says 0, its description "enabled by default": we follow the text.
    {{255, "enable driver", 0, 1, 1, access("RW"), Unit::kNone, "0 driver disabled, 1 driver enabled"}, axis_command<&AxisState::driver_enabled, &Tmcm1636Axis::set_driver_enabled>()},
  };
  // Firmware 1.13 (docs/tmcm-1636.md "Firmware generations"): numbers and names from
  // PyTrinamic's TMCM1636 class, the default of AP 56 from the CANopen EDS Fw1.12; the other
  // ranges and defaults are Motwin's choice ("inferred" in the doc), as is the meaning of AP 13.
  static constexpr uint16_t kRemovedIn113[] = {7};  // dual shunt factor
  static constexpr params::ReboundRow<Tmcm1636> kReboundIn113[] = {
    {30, host_frame<kTargetTorque, true>()}, {31, host_frame<kActualTorque, false>()},
    {40, host_frame<kTargetVelocity, true>()}, {41, host_frame<kRampVelocity, false>()},
    {42, host_frame<kActualVelocity, false>()}, {50, host_position_frame<kTargetPosition, true>()},
    {51, host_position_frame<kRampPosition, false>()}, {52, host_position_frame<kActualPosition, true>()},
  };
  static constexpr Row kAddedIn113[] = {
    {{13, "motor direction", 0, 1, 0, access("RWEX"), Unit::kNone, "0 standard, 1 inverted: the motor turns the other way; AP 30, 31, 40..42, 50..52 change sign between host and motor"}, config_field<&AxisConfig::motor_direction>()},
    {{26, "velocity sensor selection", 0, 2, 0, access("RWEX"), Unit::kNone, "Velocity source: 0 same as commutation, 1 ABN encoder, 2 absolute encoder (stored only: the velocity comes from the position source, AP 25)"}, config_field<&AxisConfig::velocity_sensor_selection>()},
    {{56, "position scaler", 1, 16777215, 65536, access("RWEX"), Unit::kNone, "Position counts per revolution of AP 50..53 and MVP, whatever the sensor"}, config_field<&AxisConfig::position_scaler>()},
    {{94, "hall sensor inputs", 0, 7, 0, access("R"), Unit::kNone, "Hall input levels: bit 0 H1, bit 1 H2, bit 2 H3"}, axis_value<&Tmcm1636Axis::hall_inputs>()},
    {{109, "encoder inputs", 0, 7, 0, access("R"), Unit::kNone, "ABN encoder input levels: bit 0 A, bit 1 B, bit 2 N (N reads 0)"}, axis_value<&Tmcm1636Axis::encoder_inputs>()},
    {{165, "absolute encoder data length", 1, 32, 16, access("RWEX"), Unit::kNone, "Bits per absolute encoder transfer (stored only)"}, config_field<&AxisConfig::absolute_encoder_data_length>()},
    {{166, "absolute encoder position start", 0, 31, 0, access("RWEX"), Unit::kNone, "First position bit in the transfer (stored only)"}, config_field<&AxisConfig::absolute_encoder_position_start>()},
    {{167, "absolute encoder position length", 1, 32, 16, access("RWEX"), Unit::kNone, "Number of position bits in the transfer (stored only)"}, config_field<&AxisConfig::absolute_encoder_position_length>()},
  };
  // clang-format on
  static constexpr size_t kRowsIn113 = std::size(kRows) - std::size(kRemovedIn113) + std::size(kAddedIn113);
  static constexpr auto kRows113 =
      params::revised_rows<Tmcm1636, kRowsIn113>(kRows, kRemovedIn113, kReboundIn113, kAddedIn113);
  static constexpr Table kTable = params::sorted_table<Tmcm1636>(kRows);
  static constexpr Table kTable113 = params::sorted_table<Tmcm1636>(kRows113);
  return firmware == Firmware::kV113 ? kTable113 : kTable;
}

// Bank 0 (table 13). Section 4.1: "parameters between 64 and 128 are automatically stored",
// so every writable one below 128 carries A. GP 66/76 defaults:
// docs/decisions.md "Errata in the manuals". GP 128..132 come from the TMCL module base.
const Tmcm1636::Table& Tmcm1636::global_parameters() {
  // clang-format off
  static constexpr Row kSettingRows[] = {
    {{65, "serial baud rate", 0, 7, 7, access("RWA"), Unit::kBaudRateCode, "0 9600, 1 14400, 2 19200, 3 28800, 4 38400, 5 57600, 6 76800, 7 115200 bit/s; no effect on a pseudo-terminal"}, global_field<&GlobalConfig::serial_baud_rate_code>()},
    {{66, "serial address", 1, 255, 1, access("RWAX"), Unit::kAddress, "Module (target) address on RS485, RS232, USB and TCP"}, global_field<&GlobalConfig::serial_address>()},
    // Motwin extension: the TMCM-1636 manual has no ASCII interface; Motwin gives it the one of
    // the TMCM-142 (command 139, GP 67 as in its manual 6.6.4) so that terminal users can drive
    // it (docs/ascii-mode.md). Bits other than 0, 4 and 5 are kept but have no effect.
    {{67, "ASCII mode", 0, 255, 0, access("RWA"), Unit::kNone, "bit 0 start in ASCII mode; bits 4-5 echo: 00 each character, bit 4 whole line after CR, bit 5 none"}, global_field<&GlobalConfig::ascii_mode>()},
    {{69, "CAN bit rate", 2, 8, 8, access("RWA"), Unit::kBitRateCode, "2 20, 3 50, 4 100, 5 125, 6 250, 7 500, 8 1000 kbit/s"}, global_field<&GlobalConfig::can_bit_rate_code>()},
    {{70, "CAN send ID", 0, 255, 2, access("RWAX"), Unit::kAddress, "CAN identifier of the module's replies"}, global_field<&GlobalConfig::can_send_id>()},
    {{71, "CAN receive ID", 0, 255, 1, access("RWAX"), Unit::kAddress, "CAN identifier the module listens to"}, global_field<&GlobalConfig::can_receive_id>()},
    {{75, "telegram pause time", 0, 255, 0, access("RWAX"), Unit::kMillisecond, "Pause before a serial reply is sent"}, global_field<&GlobalConfig::telegram_pause_ms>()},
    {{76, "serial host address", 1, 255, 2, access("RWAX"), Unit::kAddress, "Host address used in serial replies"}, global_field<&GlobalConfig::serial_host_address>()},
    {{77, "auto start mode", 0, 1, 1, access("RWAX"), Unit::kNone, "1 starts the TMCL program after power-up"}, global_field<&GlobalConfig::auto_start_mode>()},
    // Not in table 13, but manual 6.4 describes it.
    {{85, "do not restore user variables", 0, 1, 0, access("RWA"), Unit::kNone, "0 user variables 0..55 restored at power-up, 1 they start at 0"}, global_field<&GlobalConfig::skip_user_variable_restore>()},
  };
  // clang-format on
  static constexpr auto kRows = params::join_rows<Tmcm1636>(kSettingRows, program_status_rows());
  static constexpr Table kTable = params::sorted_table<Tmcm1636>(kRows);
  return kTable;
}

}  // namespace motwin::modules::tmcm1636
