// One axis of the TMCM-3216's TMCL firmware (docs/tmcm-3216-tmcl.md): the TMCL motion commands on
// the same stepper below (Tmcm3216Stepper: sequencer, currents, CoolStep, StallGuard, switches,
// encoder, brake) and the same EightPoint ramp (motion::EightPointRamp, shaped by the same
// Tmcm3216DriveObjects::shape_profile) as the CANopen firmware's axes, with no CiA-402 drive in
// between: MVP and SAP 0 start a position move, ROR/ROL/SAP 2 a velocity move, MST stops with the
// ramp; a stop switch, unless disabled (AP 12/13), stops motion towards it, as the TMC5160's
// ramp generator does (hard stop: docs "Decisions").
//
// Units: positions in microsteps, velocities in microsteps/s (pps), accelerations in pps/s, as the
// CANopen firmware's objects at their default dimension (208C/208E); the stepper's own settings
// keep the CANopen objects' units (currents 0..255, microstep code 0..8).
#pragma once

#include <cstdint>

#include "board/stepper_drive.h"
#include "core/modules/tmcm3216/tmcm3216_drive.h"
#include "core/modules/tmcm3216/tmcm3216_stepper.h"
#include "core/cia402/homing.h"
#include "core/motion/eight_point_ramp.h"
#include "core/motion/reference_search.h"
#include "core/tmcl/status.h"

namespace motwin::modules::tmcm3216 {

// The ramp and switch settings of an axis (stored with STAP), defaults as the CANopen firmware's
// objects of the same meaning (manual V1.04) where one exists.
struct TmclAxisConfig {
  int32_t max_velocity_pps = 51200;           // AP 4: VMAX (6081)
  int32_t max_acceleration_pps2 = 51200;      // AP 5: AMAX (6083)
  int32_t max_deceleration_pps2 = 51200;      // AP 17: DMAX (6084)
  int32_t stop_velocity_pps = 0;              // AP 20: VSTOP (6082)
  // AP 15 A1, 16 V1, 18 D1, 19 VSTART, 21 ramp wait time (32 µs units), 34 A2, 35 V2, 36 D2:
  // 2010..2018 of the CANopen firmware, in pps (velocity_dimension stays 181).
  Tmcm3216DriveObjects shape{};
  int32_t cruise_minimum_time_us = 0;         // AP 37: TVMAX, the shortest cruise at VMAX
  int32_t right_limit_disabled = 0;           // AP 12: 1 = the right switch does not stop the axis
  int32_t left_limit_disabled = 0;            // AP 13
  int32_t limit_switches_swapped = 0;         // AP 14: 1 = the left input is the right switch
  int32_t right_switch_inverted = 0;          // AP 24: 1 = active while its level is low
  int32_t left_switch_inverted = 0;           // AP 25
  int32_t soft_stop = 0;                      // AP 26: 1 = stop switches and virtual stops brake with the ramp
  int32_t virtual_stop_left = 0;              // AP 38: µsteps
  int32_t virtual_stop_right = 0;             // AP 39: µsteps
  int32_t virtual_stop_enable = 0;            // AP 41: bit 0 the left, bit 1 the right virtual stop
  int32_t virtual_stop_encoder_mode = 0;      // AP 42: 1 = the stops compare the encoder position (AP 209)
  int32_t max_encoder_deviation = 0;          // AP 212: µsteps between AP 1 and AP 209 that stop the axis (0: off)
  int32_t reverse_shaft = 0;                  // AP 251: 1 = the motor turns the other way for the same moves
  int32_t compare_position = 0;               // AP 43: µsteps, the first compare point
  int32_t compare_repeat = 0;                 // AP 44: µsteps between compare points (0: one point)
  int32_t compare_output_mask = 0;            // AP 45: OUT0..OUT3 pulsed at each compare point (0: off)
  int32_t compare_pulse_length_ms = 1;        // AP 46: 0 = one control tick
  int32_t target_reached_output_mask = 0;     // AP 47: OUT0..OUT3 high while AP 8 reads 1
  int32_t motion_start_input_mask = 0;        // AP 48: IN0..IN3; a new move waits for one of them high
  int32_t relative_positioning_option = 0;    // AP 127: MVP REL from 0 the last target, 1 AP 1, 2 AP 209
  int32_t reference_search_mode = 1;          // AP 193: 1..10, +64 (1..4: the right switch), +128 (5..8)
  int32_t reference_search_speed_pps = 0;     // AP 194: the fast search for the switch (6099 sub 1)
  int32_t reference_switch_speed_pps = 0;     // AP 195: the slow approach of the switching point (6099 sub 2)
  // Stored and reported only (no effect on the simulated driver; docs "Decisions").
  int32_t step_interpolation = 0;             // AP 160
  int32_t passive_fast_decay_time = 0;        // AP 185
  int32_t pwm_mode = 0;                       // AP 190
  int32_t pwm_frequency = 0;                  // AP 191
  int32_t pwm_autoscale = 1;                  // AP 192
  int32_t encoder_mode = 0;                   // AP 201
  int32_t freewheeling_mode = 0;              // AP 204
};

// AP 193: the reference search modes (Zephyr's tmcm3216_reg.h lists 1..10; Trinamic's TMCL
// manuals of this generation 1..8 with the +64 and +128 options).
namespace reference_mode {
inline constexpr int32_t kLeftSwitch = 1;                 // the left stop switch only
inline constexpr int32_t kRightThenLeft = 2;              // right, then left; AP 196 the travel
inline constexpr int32_t kRightThenLeftBothSides = 3;     // as 2, the left switch's centre
inline constexpr int32_t kLeftBothSides = 4;              // the left switch's centre
inline constexpr int32_t kHomeNegativeReversing = 5;      // home switch, negative, reversing at the left stop
inline constexpr int32_t kHomePositiveReversing = 6;      // home switch, positive, reversing at the right stop
inline constexpr int32_t kHomePositiveIgnoringStops = 7;  // home switch, positive, the stop switches ignored
inline constexpr int32_t kHomeNegativeIgnoringStops = 8;  // home switch, negative, the stop switches ignored
inline constexpr int32_t kIndexPositive = 9;              // the encoder's null channel, positive direction
inline constexpr int32_t kIndexNegative = 10;             // ... negative direction
inline constexpr int32_t kRightSwitchOption = 64;         // modes 1..4 with the right switch for the left
inline constexpr int32_t kInvertHomeOption = 128;         // modes 5..8 with the home switch active low
constexpr bool valid(int32_t mode) {
  const int32_t base = mode & ~(kRightSwitchOption | kInvertHomeOption);
  if (base < kLeftSwitch || base > kIndexNegative) return false;
  if ((mode & kRightSwitchOption) != 0 && (base > kLeftBothSides || (mode & kInvertHomeOption) != 0)) return false;
  if ((mode & kInvertHomeOption) != 0 && (base < kHomeNegativeReversing || base > kHomeNegativeIgnoringStops)) return false;
  return true;
}
}  // namespace reference_mode

struct TmclAxisState {
  int32_t target_position = 0;  // AP 0
  int32_t target_velocity = 0;  // AP 2 (ROR/ROL, MST = 0)
  // The switches' active levels after AP 14, 24, 25, whether or not they stop the axis (AP 10,
  // 11; the home switch: AP 9); read by the TMCL module base for WAIT and the stop interrupts.
  int32_t right_switch_active = 0;
  int32_t left_switch_active = 0;
  int32_t home_switch_active = 0;
  int32_t virtual_stop_flags = 0;  // AP 40: bit 0 the left, bit 1 the right virtual stop is reached
  int32_t error_flags = 0;         // AP 207: kStallStopFlag, kDeviationStopFlag; cleared when read
  int32_t encoder_offset = 0;      // AP 209 = the stepper's encoder position + this (a write sets it)
  int32_t reference_switch_distance = 0;  // AP 196: modes 2, 3: right switching point - left one
  int32_t last_reference_position = 0;    // AP 197: AP 1 just before the search set it to 0
};

// AP 207 bits: why the axis stopped by itself (as the TMCM-142's AP 207).
inline constexpr int32_t kStallStopFlag = 1 << 0;
inline constexpr int32_t kDeviationStopFlag = 1 << 1;

class Tmcm3216TmclAxis {
 public:
  TmclAxisConfig config;
  TmclAxisState state;
  Tmcm3216Stepper stepper;

  // One tick on the axis' power stage; `input_levels`: IN0..IN3 (bits 0..3) for AP 48.
  void tick(board::StepperPowerStage& stage, uint32_t dt_us, uint8_t input_levels = 0);
  // The outputs the axis drives (AP 45, 47: bits 0..3 = OUT0..OUT3) and their levels now.
  uint8_t driven_outputs() const {
    return static_cast<uint8_t>((config.compare_output_mask | config.target_reached_output_mask) & 0x0F);
  }
  uint8_t output_levels() const {
    uint8_t levels = 0;
    if (compare_pulse_remaining_us_ > 0) levels |= static_cast<uint8_t>(config.compare_output_mask);
    if (position_reached()) levels |= static_cast<uint8_t>(config.target_reached_output_mask);
    return static_cast<uint8_t>(levels & 0x0F);
  }
  // AP 48: a move accepted but held until a masked input is high.
  bool motion_start_pending() const { return start_pending_; }

  // TMCL module base: power-up clears the live state (settings are restored after).
  void reset_state();
  // AP 8: in position mode, exactly on the target and at rest. 0 in velocity mode and while a
  // move has just been started (the host's poll right after MVP reads 0).
  bool position_reached() const { return ramp_.mode() == motion::EightPointRamp::Mode::kPosition && ramp_.position_reached(); }
  int32_t actual_position() const { return ramp_.position(); }
  int32_t actual_velocity_pps() const;  // AP 3

  // AP 0 and MVP: a position move; AP 2 and ROR/ROL: a velocity move; AP 1: the counter
  // without moving. A ramp the EightPoint generator refuses (AMAX 0, V1 above V2, ...:
  // motion::EightPointRamp::validate) starts no move: status 4 (docs "Decisions").
  tmcl::Status set_target_position(int32_t position);
  tmcl::Status set_target_velocity(int32_t velocity_pps);
  void set_actual_position(int32_t position);
  // AP 209: the encoder position in µsteps (the stepper's, scaled by AP 210), and its assignment.
  int32_t encoder_position() const;
  void set_encoder_position(int32_t position);
  // AP 207: read once, then cleared.
  int32_t take_error_flags();
  // MVP REL's origin (AP 127).
  int32_t relative_move_origin() const;

  // RFS START, STOP and STATUS. start: status 4 for a search at speed 0 (it would never end).
  tmcl::Status start_reference_search();
  void stop_reference_search();
  bool reference_search_running() const { return search_ != SearchKind::kNone; }

  // The ramp of AP 4, 5, 15..21, 34..37.
  motion::EightPointConfig ramp_config() const;

 private:
  void read_switches();
  // The direction the ramp is about to move in: its velocity's, else its target's.
  int direction_of_motion() const;
  // A switch or virtual stop ahead of `direction` that stops the axis now (AP 12, 13, 38..42).
  bool stop_ahead(int direction);
  // A stall (AP 181) or an encoder deviation (AP 212) that stops the axis, moving in `direction`
  // (0: at rest), at once.
  bool stop_on_fault(int direction);
  // A new move clears what stopped the last one (a stall) and ends a reference search; with AP 48
  // set it waits for its input.
  void start_motion();
  // AP 43..46: a pulse when the position passes a compare point this tick.
  void run_position_compare(uint32_t dt_us);
  // One tick of the reference search: the state machine's command carried out on the ramp.
  void run_reference_search();
  void run_switch_search();
  void run_home_search();
  void end_search(bool set_zero, int32_t position_before);
  // AP 1 seen from the switch search (modes 1..4; + 64 mirrors the axis).
  int32_t search_position() const { return search_mirrored_ ? -ramp_.position() : ramp_.position(); }

  motion::EightPointRamp ramp_;
  // The reference search: modes 1..4 find the stop switches as the TMCM-142's search does, 5..10
  // the home switch and the null channel as the CiA-402 homing of the CANopen firmware does.
  enum class SearchKind : uint8_t { kNone, kSwitches, kHome };
  SearchKind search_ = SearchKind::kNone;
  motion::ReferenceSearch switch_search_;
  cia402::Homing home_search_;
  bool search_mirrored_ = false;    // + 64: the right switch plays the left one
  bool search_final_move_ = false;  // to the reference point at the slow speed
  double search_velocity_limit_pps_ = 0.0;
  bool deviation_exceeded_ = false;  // AP 207 bit 1 is set when the deviation starts
  bool start_pending_ = false;       // AP 48
  bool compare_started_ = false;
  int32_t last_compare_position_ = 0;
  uint32_t compare_pulse_remaining_us_ = 0;
  // The motor's side of AP 251: the ramp's position changes, reversed or not, summed; the stepper
  // follows this, so that turning AP 251 over moves nothing.
  int32_t last_ramp_position_ = 0;
  int32_t motor_position_ = 0;
};

}  // namespace motwin::modules::tmcm3216
