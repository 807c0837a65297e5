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
#include "core/motion/eight_point_ramp.h"
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
};

struct TmclAxisState {
  int32_t target_position = 0;  // AP 0
  int32_t target_velocity = 0;  // AP 2 (ROR/ROL, MST = 0)
  // The switches' active levels after AP 14, 24, 25, whether or not they stop the axis (AP 10,
  // 11; the home switch: AP 9); read by the TMCL module base for WAIT and the stop interrupts.
  int32_t right_switch_active = 0;
  int32_t left_switch_active = 0;
  int32_t home_switch_active = 0;
};

class Tmcm3216TmclAxis {
 public:
  TmclAxisConfig config;
  TmclAxisState state;
  Tmcm3216Stepper stepper;

  // One tick on the axis' power stage.
  void tick(board::StepperPowerStage& stage, uint32_t dt_us);

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

  // The ramp of AP 4, 5, 15..21, 34..37.
  motion::EightPointConfig ramp_config() const;

 private:
  void read_switches();
  // The direction the ramp is about to move in: its velocity's, else its target's.
  int direction_of_motion() const;

  motion::EightPointRamp ramp_;
};

}  // namespace motwin::modules::tmcm3216
