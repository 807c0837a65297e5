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

// The parts of a motor's axis that rows bind fields of: the EightPoint shape (2010..2018 of the
// CANopen firmware), the stepper's settings (its per-axis objects), the TMCL settings.
constexpr Tmcm3216DriveObjects& shape_of(Tmcm3216TmclAxis& axis) { return axis.config.shape; }
constexpr StepperObjects& stepper_of(Tmcm3216TmclAxis& axis) { return axis.stepper.objects; }
constexpr TmclAxisConfig& config_of(Tmcm3216TmclAxis& axis) { return axis.config; }

// A field of any integer width of one part of the motor's axis; with `Valid`, values inside the
// row's range that the firmware refuses answer status 4 (the holes of 2097 and 20A2, AP 193's
// option combinations).
template <auto Part, auto Field, auto Valid = nullptr>
constexpr Binding<Module> part_field() {
  using Value = std::remove_cvref_t<decltype(Part(std::declval<Tmcm3216TmclAxis&>()).*Field)>;
  return {[](Module& m, uint8_t motor) { return static_cast<int32_t>(Part(m.axis(motor)).*Field); },
          [](Module& m, uint8_t motor, int32_t value) {
            if constexpr (!std::is_same_v<decltype(Valid), std::nullptr_t>) {
              if (!Valid(value)) return Status::kInvalidValue;
            }
            Part(m.axis(motor)).*Field = static_cast<Value>(value);
            return Status::kOk;
          }};
}
template <auto Field>
constexpr Binding<Module> shape_field() { return part_field<&shape_of, Field>(); }
template <auto Field>
constexpr Binding<Module> stepper_field() { return part_field<&stepper_of, Field>(); }
template <auto Field, auto Valid>
constexpr Binding<Module> checked_stepper_field() { return part_field<&stepper_of, Field, Valid>(); }
template <auto Field, auto Valid>
constexpr Binding<Module> checked_config_field() { return part_field<&config_of, Field, Valid>(); }

// A reading of the motor's stepper.
template <auto Get>
constexpr Binding<Module> stepper_value() {
  return {[](Module& m, uint8_t motor) { return static_cast<int32_t>((m.axis(motor).stepper.*Get)()); }, nullptr};
}

// AP 207: read and cleared.
constexpr Binding<Module> error_flags_value() {
  return {[](Module& m, uint8_t motor) { return m.axis(motor).take_error_flags(); }, nullptr};
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
    {{22, "high speed threshold", 0, kRampValueMax, 0, access("RWE"), Unit::kMicrostepsPerSecond, "[Motwin decision] range and default of 20B6 (THIGH): above it the high-speed chopper/fullstep modes (AP 27, 28) apply; stored and reported only"}, stepper_field<&StepperObjects::fullstep_threshold_velocity>()},
    {{23, "min DcStep speed", 0, kRampValueMax, 0, access("RWE"), Unit::kMicrostepsPerSecond, "[Motwin decision] range and default of 20B3; stored and reported only"}, stepper_field<&StepperObjects::dcstep_minimum_velocity>()},
    {{24, "right limit switch polarity", 0, 1, 0, access("RWE"), Unit::kNone, "[Motwin decision] default of 2005 bit 3: 1 = active while the input is low"}, config_field<&TmclAxisConfig::right_switch_inverted>()},
    {{25, "left limit switch polarity", 0, 1, 0, access("RWE"), Unit::kNone, "[Motwin decision] default of 2005 bit 2: 1 = active while the input is low"}, config_field<&TmclAxisConfig::left_switch_inverted>()},
    {{26, "soft stop", 0, 1, 0, access("RWE"), Unit::kNone, "[Motwin decision] default 0: a stop switch or virtual stop stops the axis at once; 1: with the ramp's deceleration (DMAX, D2, D1)"}, config_field<&TmclAxisConfig::soft_stop>()},
    {{27, "high speed chopper mode", 0, 1, 0, access("RWE"), Unit::kNone, "[Motwin decision] range and default of 20B7; stored and reported only"}, stepper_field<&StepperObjects::high_speed_chopper>()},
    {{28, "high speed fullstep mode", 0, 1, 0, access("RWE"), Unit::kNone, "[Motwin decision] range and default of 20B8; stored and reported only"}, stepper_field<&StepperObjects::high_speed_fullstep>()},
    {{29, "measured speed", -kRampValueMax, kRampValueMax, 0, access("R"), Unit::kMicrostepsPerSecond, "Velocity measured from the motor's steps (2122)"}, stepper_value<&Tmcm3216Stepper::measured_velocity>()},
    {{31, "power down ramp", 0, 15, 7, access("RWE"), Unit::kNone, "[Motwin decision] range and default of 20B9 (IHOLDDELAY): 2^18 clocks per current step down to the standby current"}, stepper_field<&StepperObjects::power_down_ramp>()},
    {{32, "DcStep time", 0, 1023, 0, access("RWE"), Unit::kNone, "[Motwin decision] range and default of 20B4; stored and reported only"}, stepper_field<&StepperObjects::dcstep_time>()},
    {{33, "DcStep StallGuard", 0, 255, 0, access("RWE"), Unit::kNone, "[Motwin decision] range and default of 20B5; stored and reported only"}, stepper_field<&StepperObjects::dcstep_stallguard>()},
    {{34, "A2", 0, kRampValueMax, 0, access("RWE"), Unit::kMicrostepsPerSecondSquared, "[Motwin decision] range and default of 2016: acceleration V1..V2"}, shape_field<&Tmcm3216DriveObjects::a2>()},
    {{35, "V2", 0, kRampValueMax, 0, access("RWE"), Unit::kMicrostepsPerSecond, "[Motwin decision] range and default of 2017: 0 = no A2/D2 segment"}, shape_field<&Tmcm3216DriveObjects::v2>()},
    {{36, "D2", 0, kRampValueMax, 0, access("RWE"), Unit::kMicrostepsPerSecondSquared, "[Motwin decision] range and default of 2018: deceleration V2..V1; 0 with V2 = 0: DMAX"}, shape_field<&Tmcm3216DriveObjects::d2>()},
    {{37, "VMAX minimum time", 0, 65535, 0, access("RWE"), Unit::kMicrosecond, "[Motwin decision] range, default and unit (no CANopen object): the shortest cruise at VMAX"}, config_field<&TmclAxisConfig::cruise_minimum_time_us>()},
    {{38, "virtual stop left", kMin32, kMax32, 0, access("RWE"), Unit::kMicrosteps, "[Motwin decision] default 0: the axis does not move left of it while AP 41 bit 0 is set"}, config_field<&TmclAxisConfig::virtual_stop_left>()},
    {{39, "virtual stop right", kMin32, kMax32, 0, access("RWE"), Unit::kMicrosteps, "[Motwin decision] default 0: the axis does not move right of it while AP 41 bit 1 is set"}, config_field<&TmclAxisConfig::virtual_stop_right>()},
    {{40, "virtual stop flags", 0, 3, 0, access("R"), Unit::kNone, "Bit 0: at or left of the left virtual stop, bit 1: at or right of the right one (enabled stops only)"}, state_value<&TmclAxisState::virtual_stop_flags>()},
    {{41, "virtual stop enable", 0, 3, 0, access("RWE"), Unit::kNone, "[Motwin decision] default 0: bit 0 enables the left, bit 1 the right virtual stop"}, config_field<&TmclAxisConfig::virtual_stop_enable>()},
    {{42, "virtual stop encoder mode", 0, 1, 0, access("RWE"), Unit::kNone, "[Motwin decision] default 0: the stops compare AP 1; 1: the encoder position AP 209"}, config_field<&TmclAxisConfig::virtual_stop_encoder_mode>()},
    {{43, "position compare start", kMin32, kMax32, 0, access("RWE"), Unit::kMicrosteps, "[Motwin decision] default 0: the first compare point"}, config_field<&TmclAxisConfig::compare_position>()},
    {{44, "position compare repeat", 0, kMax32, 0, access("RWE"), Unit::kMicrosteps, "[Motwin decision] default 0: compare points every this many µsteps from AP 43 (0: AP 43 alone)"}, config_field<&TmclAxisConfig::compare_repeat>()},
    {{45, "position compare output mask", 0, 15, 0, access("RWE"), Unit::kNone, "[Motwin decision] default 0 (off): bits 0..3 = OUT0..OUT3 pulse when AP 1 reaches a compare point moving up or leaves it moving down"}, config_field<&TmclAxisConfig::compare_output_mask>()},
    {{46, "position compare pulse length", 0, 65535, 1, access("RWE"), Unit::kMillisecond, "[Motwin decision] default 1: the pulse's length; 0 = one control tick (50 µs)"}, config_field<&TmclAxisConfig::compare_pulse_length_ms>()},
    {{47, "target reached output mask", 0, 15, 0, access("RWE"), Unit::kNone, "[Motwin decision] default 0 (off): bits 0..3 = OUT0..OUT3 high while AP 8 reads 1, low otherwise"}, config_field<&TmclAxisConfig::target_reached_output_mask>()},
    {{48, "motion start input mask", 0, 15, 0, access("RWE"), Unit::kNone, "[Motwin decision] default 0 (off): bits 0..3 = IN0..IN3; a new move (MVP, ROR, ROL, SAP 0/2, RFS) is accepted and waits until one of them is high"}, config_field<&TmclAxisConfig::motion_start_input_mask>()},
    {{127, "relative positioning option", 0, 2, 0, access("RWE"), Unit::kNone, "[Motwin decision] default 0 as Trinamic's TMCL firmwares: MVP REL adds to 0 the last target (AP 0), 1 the actual position (AP 1), 2 the encoder position (AP 209)"}, config_field<&TmclAxisConfig::relative_positioning_option>()},
    {{140, "microstep resolution", 0, 8, 8, access("RWE"), Unit::kNone, "[Motwin decision] default of 2000: 0 full step, 1 half, 2..8: 4..256 microsteps; takes effect at standstill"}, stepper_field<&StepperObjects::microstep_code>()},
    {{160, "step interpolation enable", 0, 1, 0, access("RWE"), Unit::kNone, "[Motwin decision] range and default; stored and reported only (MicroPlyer of the driver chip)"}, config_field<&TmclAxisConfig::step_interpolation>()},
    {{162, "chopper blank time", 0, 3, 2, access("RWE"), Unit::kNone, "[Motwin decision] range and default of 2092; stored and reported only"}, stepper_field<&StepperObjects::chopper_blank_time>()},
    {{163, "constant TOff mode", 0, 1, 0, access("RWE"), Unit::kNone, "[Motwin decision] range and default of 2093; stored and reported only"}, stepper_field<&StepperObjects::chopper_mode>()},
    {{164, "disable fast decay comparator", 0, 1, 0, access("RWE"), Unit::kNone, "[Motwin decision] range and default of 2094; stored and reported only"}, stepper_field<&StepperObjects::chopper_fast_decay_comparator_off>()},
    {{165, "chopper hysteresis end", -3, 12, 0, access("RWE"), Unit::kNone, "[Motwin decision] range and default of 2095; stored and reported only"}, stepper_field<&StepperObjects::chopper_hysteresis_end>()},
    {{166, "chopper hysteresis start", 0, 8, 3, access("RWE"), Unit::kNone, "[Motwin decision] range and default of 2096; stored and reported only"}, stepper_field<&StepperObjects::chopper_hysteresis_start>()},
    {{167, "TOff", 0, 15, 5, access("RWE"), Unit::kNone, "[Motwin decision] range and default of 2097: 0 switches the bridges off (the motor freewheels), 1 is refused"}, checked_stepper_field<&StepperObjects::chopper_off_time, &valid_chopper_off_time>()},
    {{168, "smartEnergy current minimum", 0, 1, 0, access("RWE"), Unit::kNone, "[Motwin decision] range and default of 2098 (SEIMIN): 0 half, 1 a quarter of the run current"}, stepper_field<&StepperObjects::coolstep_current_minimum>()},
    {{169, "smartEnergy current down step", 0, 3, 0, access("RWE"), Unit::kNone, "[Motwin decision] range and default of 2099 (SEDN)"}, stepper_field<&StepperObjects::coolstep_down_step>()},
    {{170, "smartEnergy hysteresis", 0, 15, 0, access("RWE"), Unit::kNone, "[Motwin decision] range and default of 209A (SEMAX)"}, stepper_field<&StepperObjects::coolstep_hysteresis>()},
    {{171, "smartEnergy current up step", 0, 3, 0, access("RWE"), Unit::kNone, "[Motwin decision] range and default of 209B (SEUP)"}, stepper_field<&StepperObjects::coolstep_up_step>()},
    {{172, "smartEnergy hysteresis start", 0, 15, 0, access("RWE"), Unit::kNone, "[Motwin decision] range and default of 209C (SEMIN): 0 = CoolStep off"}, stepper_field<&StepperObjects::coolstep_hysteresis_start>()},
    {{173, "StallGuard2 filter enable", 0, 1, 0, access("RWE"), Unit::kNone, "[Motwin decision] range and default of 209D (SFILT)"}, stepper_field<&StepperObjects::stallguard2_filter>()},
    {{174, "StallGuard2 threshold", -63, 63, 0, access("RWE"), Unit::kNone, "[Motwin decision] range and default of 209E (SGT)"}, stepper_field<&StepperObjects::stallguard2_threshold>()},
    {{178, "global current scaler", 0, 255, 0, access("RWE"), Unit::kNone, "[Motwin decision] range and default of 20A2: 0 = 256/256, 32..255 = x/256, 1..31 refused"}, checked_stepper_field<&StepperObjects::global_current_scaler, &valid_global_current_scaler>()},
    {{179, "full scale current range", 0, 3, 3, access("RWE"), Unit::kNone, "[Motwin decision] range and default of 20A3: 0 1 A, 1 2 A, 2 and 3 3 A peak"}, stepper_field<&StepperObjects::current_range>()},
    {{180, "smartEnergy actual current", 0, 31, 0, access("R"), Unit::kNone, "Current scale CS the driver applies now (CoolStep, standby)"}, stepper_value<&Tmcm3216Stepper::current_scale>()},
    {{181, "stop on stall", 0, kMax32, 0, access("RWE"), Unit::kMicrostepsPerSecond, "[Motwin decision] range and default of 20A4: above this velocity a StallGuard stall stops the axis (AP 207 bit 0); 0 = off"}, stepper_field<&StepperObjects::stop_on_stall_velocity>()},
    {{182, "smartEnergy threshold speed", 0, kMax32, 0, access("RWE"), Unit::kMicrostepsPerSecond, "[Motwin decision] range and default of 20A5: CoolStep above this velocity"}, stepper_field<&StepperObjects::coolstep_threshold_velocity>()},
    {{185, "passive fast decay time", 0, 15, 0, access("RWE"), Unit::kNone, "[Motwin decision] range and default; stored and reported only"}, config_field<&TmclAxisConfig::passive_fast_decay_time>()},
    {{186, "PWM threshold speed", 0, kRampValueMax, 0, access("RWE"), Unit::kMicrostepsPerSecond, "[Motwin decision] range and default of 20B0: StealthChop below this velocity (0: off)"}, stepper_field<&StepperObjects::pwm_threshold_velocity>()},
    {{187, "PWM gradient", 0, 255, 0, access("RWE"), Unit::kNone, "[Motwin decision] range and default of 20B1: 0 = StealthChop off"}, stepper_field<&StepperObjects::pwm_gradient>()},
    {{188, "PWM amplitude", 0, 255, 0, access("RWE"), Unit::kNone, "[Motwin decision] range and default of 20B2"}, stepper_field<&StepperObjects::pwm_amplitude>()},
    {{189, "PWM scale", 0, 255, 0, access("R"), Unit::kNone, "StealthChop PWM scale (2121)"}, stepper_value<&Tmcm3216Stepper::pwm_scale>()},
    {{190, "PWM mode", 0, 1, 0, access("RWE"), Unit::kNone, "[Motwin decision] range and default; stored and reported only (StealthChop follows AP 186, 187)"}, config_field<&TmclAxisConfig::pwm_mode>()},
    {{191, "PWM frequency", 0, 3, 0, access("RWE"), Unit::kNone, "[Motwin decision] range and default of the TMC5160's PWM_FREQ; stored and reported only"}, config_field<&TmclAxisConfig::pwm_frequency>()},
    {{192, "PWM autoscale", 0, 1, 1, access("RWE"), Unit::kNone, "[Motwin decision] range and default of the TMC5160's PWM_AUTOSCALE; stored and reported only"}, config_field<&TmclAxisConfig::pwm_autoscale>()},
    {{193, "reference search mode", 1, 136, 1, access("RWE"), Unit::kNone, "[Motwin decision] default 1: 1 left switch, 2 right then left (AP 196), 3 as 2 and the left switch's centre, 4 the left switch's centre, 5/6 home switch negative/positive reversing at the stop switch, 7/8 home switch positive/negative ignoring the stop switches, 9/10 the encoder's null channel positive/negative; +64 the right switch for the left (1..4), +128 the home switch active low (5..8)"}, checked_config_field<&TmclAxisConfig::reference_search_mode, &reference_mode::valid>()},
    {{194, "reference search speed", 0, kRampValueMax, 0, access("RWE"), Unit::kMicrostepsPerSecond, "[Motwin decision] range and default of 6099 sub 1: the fast search for the switch; 0 refuses RFS START"}, config_field<&TmclAxisConfig::reference_search_speed_pps>()},
    {{195, "reference switch speed", 0, kRampValueMax, 0, access("RWE"), Unit::kMicrostepsPerSecond, "[Motwin decision] range and default of 6099 sub 2: the slow approach of the switching point and the null channel"}, config_field<&TmclAxisConfig::reference_switch_speed_pps>()},
    {{196, "reference switch distance", kMin32, kMax32, 0, access("R"), Unit::kMicrosteps, "Modes 2 and 3: from the left to the right switching point"}, state_value<&TmclAxisState::reference_switch_distance>()},
    {{197, "last reference position", kMin32, kMax32, 0, access("R"), Unit::kMicrosteps, "AP 1 just before the reference search set it to 0"}, state_value<&TmclAxisState::last_reference_position>()},
    {{201, "encoder mode", 0, 1023, 0, access("RWE"), Unit::kNone, "[Motwin decision] range and default; stored and reported only (the encoder counts A/B, AP 210 scales it)"}, config_field<&TmclAxisConfig::encoder_mode>()},
    {{202, "fullstep resolution", 0, 65535, 200, access("RWE"), Unit::kNone, "[Motwin decision] range and default of 2001: full steps per motor revolution"}, stepper_field<&StepperObjects::full_steps_per_revolution>()},
    {{204, "freewheeling mode", 0, 3, 0, access("RWE"), Unit::kNone, "[Motwin decision] range and default; stored and reported only (0 normal, 1 freewheeling, 2/3 coils shorted at standby current 0)"}, config_field<&TmclAxisConfig::freewheeling_mode>()},
    {{206, "load value", 0, 1023, 0, access("R"), Unit::kNone, "StallGuard2 load value (2101)"}, stepper_value<&Tmcm3216Stepper::load_value>()},
    {{207, "error flags", 0, 3, 0, access("R"), Unit::kNone, "Bit 0: stopped by a stall (AP 181), bit 1: stopped by an encoder deviation (AP 212); cleared when read"}, error_flags_value()},
    {{208, "driver error flags", 0, 255, 0, access("R"), Unit::kNone, "The driver's error flags (2102's bits: overcurrent, open load, temperature, undervoltage)"}, stepper_value<&Tmcm3216Stepper::driver_error_flags>()},
    {{209, "encoder position", kMin32, kMax32, 0, access("RW"), Unit::kMicrosteps, "Encoder position in microsteps (scaled by AP 210); a write sets it"}, axis_command<&Tmcm3216TmclAxis::encoder_position, &Tmcm3216TmclAxis::set_encoder_position>()},
    {{210, "encoder resolution", 0, kMax32, 1, access("RWE"), Unit::kNone, "[Motwin decision] range and default of 608F sub 1: encoder counts per motor revolution"}, stepper_field<&StepperObjects::encoder_increments>()},
    {{212, "max encoder deviation", 0, kMax32, 0, access("RWE"), Unit::kMicrosteps, "[Motwin decision] default 0 (off): AP 1 and AP 209 further apart stop the axis (AP 207 bit 1)"}, config_field<&TmclAxisConfig::max_encoder_deviation>()},
    {{214, "power down delay", 0, 400, 200, access("RWE"), Unit::kTenMilliseconds, "[Motwin decision] range and default of 2089: standstill time before the standby current"}, stepper_field<&StepperObjects::standby_delay_10ms>()},
    {{220, "StallGuard4 result", 0, 511, 0, access("R"), Unit::kNone, "StallGuard4 result in StealthChop (210A)"}, stepper_value<&Tmcm3216Stepper::stallguard4_result>()},
    {{221, "StallGuard4 threshold", 0, 511, 0, access("RWE"), Unit::kNone, "[Motwin decision] range and default of 20A8: a stall when the result falls below it"}, stepper_field<&StepperObjects::stallguard4_threshold>()},
    {{222, "StallGuard4 filter enable", 0, 1, 0, access("RWE"), Unit::kNone, "[Motwin decision] range and default of 20A9"}, stepper_field<&StepperObjects::stallguard4_filter>()},
    {{223, "StallGuard4 angle offset", 0, 1, 0, access("RWE"), Unit::kNone, "[Motwin decision] range and default of 20AA; stored and reported only"}, stepper_field<&StepperObjects::stallguard4_angle_offset>()},
    {{251, "reverse shaft", 0, 1, 0, access("RWE"), Unit::kNone, "[Motwin decision] default 0: 1 turns the motor the other way for the same positions"}, config_field<&TmclAxisConfig::reverse_shaft>()},
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
