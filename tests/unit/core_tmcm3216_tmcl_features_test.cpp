// The TMCM-3216 TMCL firmware's axis parameters beyond motion (docs/tmcm-3216-tmcl.md): the
// stepper settings the CANopen firmware has as objects (chopper, CoolStep, StallGuard2/4), the
// stop on stall, virtual stops, soft stop, the encoder with its deviation stop, reverse shaft.
#include <gtest/gtest.h>

#include <cstdint>
#include <cstdlib>

#include "sim/stepper_plant.h"
#include "support/tmcl_command.h"
#include "support/tmcm3216_tmcl_rig.h"

namespace motwin::testing {
namespace {

constexpr int32_t kMicrostepsPerRev = 51200;  // 200 full steps x 256

TEST(Tmcm3216TmclFeatures, stepper_settings_reach_the_stepper_with_the_objects_ranges) {
  Tmcm3216TmclRig rig;
  const auto& objects = rig.module->axis(1).stepper.objects;
  ASSERT_EQ(rig.sap(174, 1, -10), 100);
  EXPECT_EQ(objects.stallguard2_threshold, -10);
  EXPECT_EQ(rig.gap(174, 1), -10);
  EXPECT_EQ(rig.sap(174, 1, 64), 4);
  ASSERT_EQ(rig.sap(172, 1, 5), 100);
  ASSERT_EQ(rig.sap(170, 1, 2), 100);
  EXPECT_EQ(objects.coolstep_hysteresis_start, 5);
  EXPECT_EQ(objects.coolstep_hysteresis, 2);
  // The holes in the ranges the driver refuses, as the CANopen objects 2097 and 20A2 do.
  EXPECT_EQ(rig.sap(167, 1, 1), 4);
  EXPECT_EQ(objects.chopper_off_time, 5);
  ASSERT_EQ(rig.sap(167, 1, 0), 100);
  EXPECT_EQ(objects.chopper_off_time, 0);
  EXPECT_EQ(rig.sap(178, 1, 20), 4);
  ASSERT_EQ(rig.sap(178, 1, 128), 100);
  EXPECT_EQ(objects.global_current_scaler, 128);
  ASSERT_EQ(rig.sap(214, 1, 50), 100);
  EXPECT_EQ(objects.standby_delay_10ms, 50);
  EXPECT_EQ(rig.sap(214, 1, 401), 4);
  // Other motors keep their defaults.
  EXPECT_EQ(rig.gap(167, 0), 5);
  EXPECT_EQ(rig.gap(174, 2), 0);
}

TEST(Tmcm3216TmclFeatures, chopper_off_time_zero_lets_the_motor_freewheel) {
  Tmcm3216TmclRig rig;
  rig.run_ms(5);
  EXPECT_TRUE(rig.board.board().axes[0].drive.enabled);
  ASSERT_EQ(rig.sap(167, 0, 0), 100);
  rig.run_ms(5);
  EXPECT_FALSE(rig.board.board().axes[0].drive.enabled);
}

TEST(Tmcm3216TmclFeatures, a_stall_above_ap181_stops_the_axis_and_sets_ap207_once) {
  Tmcm3216TmclRig rig(sim::StepperMotorDescription::nema17());
  ASSERT_EQ(rig.sap(6, 0, 255), 100);
  ASSERT_EQ(rig.sap(179, 0, 1), 100);  // 2 A peak: a NEMA17 rated 1.5 A
  ASSERT_EQ(rig.sap(181, 0, 30000), 100);  // StallGuard2 is valid well above it
  ASSERT_EQ(rig.sap(4, 0, 2 * kMicrostepsPerRev), 100);
  ASSERT_EQ(rig.sap(5, 0, 400000), 100);
  ASSERT_EQ(rig.command(kRor, 0, 0, 2 * kMicrostepsPerRev).status, 100);
  rig.run_ms(400);
  EXPECT_EQ(rig.gap(3, 0), 2 * kMicrostepsPerRev) << "free running: no stall";
  EXPECT_EQ(rig.gap(207, 0), 0);
  rig.board.set_input("AXIS0_BLOCKED", 1);
  rig.run_ms(200);
  EXPECT_EQ(rig.gap(3, 0), 0) << "stopped by the stall";
  EXPECT_EQ(rig.gap(2, 0), 0);
  EXPECT_EQ(rig.gap(207, 0), 1) << "bit 0: stopped by a stall";
  EXPECT_EQ(rig.gap(207, 0), 0) << "cleared when read";
  // The obstacle gone, a new command moves again.
  rig.board.set_input("AXIS0_BLOCKED", 0);
  ASSERT_EQ(rig.command(kRor, 0, 0, 2 * kMicrostepsPerRev).status, 100);
  rig.run_ms(300);
  EXPECT_EQ(rig.gap(3, 0), 2 * kMicrostepsPerRev);
  // AP 181 = 0: a blocked rotor is not detected, the field runs on.
  ASSERT_EQ(rig.sap(181, 0, 0), 100);
  rig.board.set_input("AXIS0_BLOCKED", 1);
  rig.run_ms(200);
  EXPECT_EQ(rig.gap(3, 0), 2 * kMicrostepsPerRev);
  EXPECT_EQ(rig.gap(207, 0), 0);
}

TEST(Tmcm3216TmclFeatures, virtual_stops_stop_motion_towards_them_only_while_enabled) {
  Tmcm3216TmclRig rig;
  ASSERT_EQ(rig.sap(38, 0, -1000), 100);
  ASSERT_EQ(rig.sap(39, 0, 20000), 100);
  ASSERT_EQ(rig.command(kMvp, 0, 0, 30000).status, 100);
  EXPECT_GE(rig.ms_until_reached(0, 3000), 0) << "not enabled: the stops do nothing";
  EXPECT_EQ(rig.gap(40, 0), 0);
  ASSERT_EQ(rig.command(kMvp, 0, 0, 0).status, 100);
  EXPECT_GE(rig.ms_until_reached(0, 3000), 0);

  ASSERT_EQ(rig.sap(41, 0, 3), 100);
  ASSERT_EQ(rig.command(kMvp, 0, 0, 30000).status, 100);
  rig.run_ms(2000);
  EXPECT_EQ(rig.gap(8, 0), 0) << "the target lies beyond the right stop";
  EXPECT_EQ(rig.gap(3, 0), 0);
  const int32_t stopped_at = rig.gap(1, 0);
  EXPECT_GE(stopped_at, 20000) << "hard stop in the first tick at or past the stop";
  EXPECT_LT(stopped_at, 20000 + 10);
  EXPECT_EQ(rig.gap(40, 0), 2);
  // Away from it works; towards the left stop it stops again.
  ASSERT_EQ(rig.command(kRol, 0, 0, 51200).status, 100);
  rig.run_ms(2000);
  EXPECT_EQ(rig.gap(3, 0), 0);
  EXPECT_LE(rig.gap(1, 0), -1000);
  EXPECT_GT(rig.gap(1, 0), -1000 - 10);
  EXPECT_EQ(rig.gap(40, 0), 1);
}

TEST(Tmcm3216TmclFeatures, soft_stop_brakes_with_the_ramp_at_a_switch) {
  for (int32_t soft : {0, 1}) {
    Tmcm3216TmclRig rig;
    rig.board.set_input("AXIS0_REF_R_AT", 1.0);
    ASSERT_EQ(rig.sap(26, 0, soft), 100);
    ASSERT_EQ(rig.sap(17, 0, 102400), 100);  // DMAX: 0.5 s from 51200 pps, 12800 µsteps
    ASSERT_EQ(rig.command(kRor, 0, 0, 51200).status, 100);
    while (rig.gap(10, 0) == 0) rig.run_ms(1);
    const int32_t switch_at = rig.gap(1, 0);
    rig.run_ms(1000);
    EXPECT_EQ(rig.gap(3, 0), 0);
    const int32_t overrun = rig.gap(1, 0) - switch_at;
    if (soft != 0) {
      EXPECT_NEAR(overrun, 12800, 300) << "braked with DMAX";
    } else {
      EXPECT_LT(overrun, 10) << "stopped at once";
    }
  }
}

TEST(Tmcm3216TmclFeatures, reverse_shaft_turns_the_motor_the_other_way_without_a_jump) {
  Tmcm3216TmclRig rig;
  ASSERT_EQ(rig.command(kMvp, 0, 0, kMicrostepsPerRev).status, 100);
  ASSERT_GE(rig.ms_until_reached(0, 5000), 0);
  EXPECT_NEAR(rig.board.rotor_revolutions(0), 1.0, 0.01);
  ASSERT_EQ(rig.sap(251, 0, 1), 100);
  rig.run_ms(10);
  EXPECT_NEAR(rig.board.rotor_revolutions(0), 1.0, 0.01) << "turning AP 251 over moves nothing";
  ASSERT_EQ(rig.command(kMvp, 0, 0, 2 * kMicrostepsPerRev).status, 100);
  ASSERT_GE(rig.ms_until_reached(0, 5000), 0);
  EXPECT_EQ(rig.gap(1, 0), 2 * kMicrostepsPerRev);
  EXPECT_NEAR(rig.board.rotor_revolutions(0), 0.0, 0.01) << "the next revolution went backwards";
}

TEST(Tmcm3216TmclFeatures, the_encoder_position_follows_the_rotor_and_a_deviation_stops_the_axis) {
  Tmcm3216TmclRig rig(sim::StepperMotorDescription::nema17());
  ASSERT_EQ(rig.sap(6, 1, 255), 100);
  ASSERT_EQ(rig.sap(179, 1, 1), 100);
  ASSERT_EQ(rig.sap(210, 1, 4000), 100);  // the simulated encoder's counts per revolution
  ASSERT_EQ(rig.sap(209, 1, 0), 100);
  ASSERT_EQ(rig.command(kMvp, 0, 1, kMicrostepsPerRev).status, 100);
  ASSERT_GE(rig.ms_until_reached(1, 5000), 0);
  EXPECT_NEAR(rig.gap(209, 1), kMicrostepsPerRev, 2 * 256);
  ASSERT_EQ(rig.sap(209, 1, 1000), 100);
  EXPECT_NEAR(rig.gap(209, 1), 1000, 13) << "a write sets the encoder position";
  ASSERT_EQ(rig.sap(209, 1, rig.gap(1, 1)), 100);

  // An obstacle: the field runs on, the encoder stands; beyond AP 212 the axis stops.
  ASSERT_EQ(rig.sap(212, 1, 2000), 100);
  rig.board.set_input("AXIS1_BLOCKED", 1);
  ASSERT_EQ(rig.command(kRor, 0, 1, kMicrostepsPerRev).status, 100);
  rig.run_ms(1000);
  EXPECT_EQ(rig.gap(3, 1), 0);
  const int32_t deviation = rig.gap(1, 1) - rig.gap(209, 1);
  EXPECT_GT(deviation, 2000);
  EXPECT_LT(deviation, 2000 + 2 * 256) << "stopped within a few ticks of the limit";
  EXPECT_EQ(rig.gap(207, 1), 2) << "bit 1: stopped by the encoder deviation";
}

// AP 127 at its default: MVP REL adds to the last target, as Trinamic's TMCL firmwares do
// (the TMC5072 module's Commands.c: RelativePositioningOptionCode = RMO_TARGET; MST leaves
// XTARGET alone), so a relative move after ROR/MST starts from the old target.
TEST(Tmcm3216TmclFeatures, mvp_rel_adds_to_the_origin_ap127_names) {
  Tmcm3216TmclRig rig;
  ASSERT_EQ(rig.command(kMvp, 0, 0, 1000).status, 100);
  ASSERT_GE(rig.ms_until_reached(0, 1000), 0);
  ASSERT_EQ(rig.command(kRor, 0, 0, 20000).status, 100);
  rig.run_ms(300);
  ASSERT_EQ(rig.command(kMst, 0, 0, 0).status, 100);
  rig.run_ms(1000);
  const int32_t stood_at = rig.gap(1, 0);
  ASSERT_GT(stood_at, 3000);
  ASSERT_EQ(rig.command(kMvp, 1, 0, 500).status, 100);
  EXPECT_EQ(rig.gap(0, 0), 1500) << "AP 127 = 0: the last target + 500";
  ASSERT_EQ(rig.sap(127, 0, 1), 100);
  ASSERT_EQ(rig.command(kMvp, 1, 0, 500).status, 100);
  EXPECT_EQ(rig.gap(0, 0), stood_at + 500) << "AP 127 = 1: the actual position + 500";
  ASSERT_EQ(rig.sap(209, 0, 40), 100);
  ASSERT_EQ(rig.sap(127, 0, 2), 100);
  ASSERT_EQ(rig.command(kMvp, 1, 0, 500).status, 100);
  EXPECT_EQ(rig.gap(0, 0), 540) << "AP 127 = 2: the encoder position + 500";
  EXPECT_EQ(rig.sap(127, 0, 3), 4);
}

// RFS modes 1..4 (+64): the stop switches as the TMCM-142's search finds them.
struct SwitchRig : Tmcm3216TmclRig {
  SwitchRig() {
    board.set_input("AXIS0_REF_L_AT", -1.0);  // left switch high at and below -1 rev
    board.set_input("AXIS0_REF_R_AT", 1.5);   // right switch high at and above +1.5 rev
    EXPECT_EQ(sap(194, 0, 51200), 100);
    EXPECT_EQ(sap(195, 0, 2560), 100);
  }
  // Starts the search and ticks until RFS STATUS reads 0; false if it did not within the time.
  bool search(int32_t mode, double limit_ms = 20000) {
    if (sap(193, 0, mode) != 100 || command(kRfs, 0, 0, 0).status != 100) return false;
    for (double ms = 0; ms < limit_ms; ms += 1.0) {
      if (command(kRfs, 2, 0, 0).value == 0) return true;
      run_ms(1.0);
    }
    return false;
  }
  static constexpr uint8_t kRfs = 13;
};

TEST(Tmcm3216TmclFeatures, rfs_mode_1_references_the_left_switching_point) {
  SwitchRig rig;
  ASSERT_EQ(rig.sap(1, 0, 12345), 100);
  ASSERT_TRUE(rig.search(1));
  EXPECT_EQ(rig.gap(1, 0), 0);
  EXPECT_EQ(rig.gap(3, 0), 0);
  // The slow approach finds the point to within a tick's travel at AP 195 (2560 pps x 50 µs).
  EXPECT_NEAR(rig.board.rotor_revolutions(0), -1.0, 2.0 / kMicrostepsPerRev);
  EXPECT_NEAR(rig.gap(197, 0), 12345 - kMicrostepsPerRev, 2);
}

TEST(Tmcm3216TmclFeatures, rfs_mode_2_measures_the_travel_and_65_uses_the_right_switch) {
  SwitchRig rig;
  ASSERT_TRUE(rig.search(2));
  EXPECT_EQ(rig.gap(1, 0), 0);
  EXPECT_NEAR(rig.board.rotor_revolutions(0), -1.0, 2.0 / kMicrostepsPerRev);
  EXPECT_NEAR(rig.gap(196, 0), 2.5 * kMicrostepsPerRev, 4);
  ASSERT_TRUE(rig.search(1 + 64));
  EXPECT_EQ(rig.gap(1, 0), 0);
  EXPECT_NEAR(rig.board.rotor_revolutions(0), 1.5, 2.0 / kMicrostepsPerRev);
}

TEST(Tmcm3216TmclFeatures, rfs_mode_4_references_the_centre_of_the_left_switch) {
  SwitchRig rig;
  rig.board.set_input("AXIS0_REF_L_AT", -1e6);  // a cam instead of a stop switch
  rig.board.set_input("AXIS0_REF_L_FROM", -1.25);
  rig.board.set_input("AXIS0_REF_L_TO", -0.75);
  ASSERT_TRUE(rig.search(4));
  EXPECT_EQ(rig.gap(1, 0), 0);
  EXPECT_EQ(rig.gap(8, 0), 1);
  EXPECT_NEAR(rig.board.rotor_revolutions(0), -1.0, 4.0 / kMicrostepsPerRev);
}

TEST(Tmcm3216TmclFeatures, rfs_modes_5_and_6_find_the_home_switch_reversing_at_a_stop_switch) {
  // The home cam between 0.5 and 0.6 rev; mode 5 searches left first, meets the left switch at
  // -1 rev and comes back; it leaves the cam last going right: its right edge. Mode 6 finds it
  // going right and leaves it going left: the left edge.
  for (int32_t mode : {5, 6}) {
    SwitchRig rig;
    rig.board.set_input("AXIS0_REF_H_FROM", 0.5);
    rig.board.set_input("AXIS0_REF_H_TO", 0.6);
    ASSERT_TRUE(rig.search(mode)) << "mode " << mode;
    EXPECT_EQ(rig.gap(1, 0), 0);
    EXPECT_NEAR(rig.board.rotor_revolutions(0), mode == 5 ? 0.6 : 0.5, 4.0 / kMicrostepsPerRev) << "mode " << mode;
  }
}

TEST(Tmcm3216TmclFeatures, rfs_mode_8_ignores_the_stop_switches_and_136_inverts_the_home_switch) {
  SwitchRig rig;
  rig.board.set_input("AXIS0_REF_H_FROM", -1.6);  // beyond the left switch
  rig.board.set_input("AXIS0_REF_H_TO", -1.4);
  ASSERT_TRUE(rig.search(8));
  EXPECT_EQ(rig.gap(1, 0), 0);
  EXPECT_NEAR(rig.board.rotor_revolutions(0), -1.4, 4.0 / kMicrostepsPerRev);
  // Home switch active low: the first low level going right from -1.4 rev (home switch high
  // only inside the cam) is at once; the search leaves the low region at the cam's left edge.
  SwitchRig inverted;
  inverted.board.set_input("AXIS0_REF_H_FROM", -10.0);
  inverted.board.set_input("AXIS0_REF_H_TO", 0.25);  // high up to 0.25 rev: low beyond it
  inverted.run_ms(1);  // the switches read before the search starts
  ASSERT_TRUE(inverted.search(7 + 128));
  EXPECT_NEAR(inverted.board.rotor_revolutions(0), 0.25, 4.0 / kMicrostepsPerRev);
}

TEST(Tmcm3216TmclFeatures, rfs_modes_9_and_10_reference_the_null_channel) {
  for (int32_t mode : {9, 10}) {
    SwitchRig rig;
    rig.board.set_input("AXIS0_ENCODER_INDEX_AT", 0.25);
    ASSERT_TRUE(rig.search(mode)) << "mode " << mode;
    EXPECT_EQ(rig.gap(1, 0), 0);
    EXPECT_NEAR(rig.board.rotor_revolutions(0), mode == 9 ? 0.25 : -0.75, 4.0 / kMicrostepsPerRev) << "mode " << mode;
  }
}

TEST(Tmcm3216TmclFeatures, rfs_refuses_what_it_cannot_run_and_stops_on_request) {
  SwitchRig rig;
  EXPECT_EQ(rig.sap(193, 0, 11), 4);
  EXPECT_EQ(rig.sap(193, 0, 5 + 64), 4) << "+64 only with modes 1..4";
  EXPECT_EQ(rig.sap(193, 0, 1 + 128), 4) << "+128 only with modes 5..8";
  EXPECT_EQ(rig.gap(193, 0), 1);
  ASSERT_EQ(rig.sap(194, 0, 0), 100);
  EXPECT_EQ(rig.command(SwitchRig::kRfs, 0, 0, 0).status, 4) << "a search at speed 0 would never end";
  EXPECT_EQ(rig.command(SwitchRig::kRfs, 0, 3, 0).status, 4) << "motor 3";
  ASSERT_EQ(rig.sap(194, 0, 51200), 100);
  ASSERT_EQ(rig.command(SwitchRig::kRfs, 0, 0, 0).status, 100);
  rig.run_ms(200);
  EXPECT_NE(rig.command(SwitchRig::kRfs, 2, 0, 0).value, 0);
  EXPECT_LT(rig.gap(3, 0), 0);
  ASSERT_EQ(rig.command(SwitchRig::kRfs, 1, 0, 0).status, 100);
  EXPECT_EQ(rig.command(SwitchRig::kRfs, 2, 0, 0).value, 0);
  rig.run_ms(1500);
  EXPECT_EQ(rig.gap(3, 0), 0) << "stopped with the ramp";
  EXPECT_NE(rig.gap(1, 0), 0) << "no reference set";
}

// Bank 3 and the vectors of PyTrinamic's GP3 list for three axes: the stop switches of axis 1
// (29 left, 30 right), Input_0 (39: IN0, GIO port 2), and position reached per motor (3 + m).
TEST(Tmcm3216TmclFeatures, interrupts_of_each_axis_and_input_run_their_routines) {
  Tmcm3216TmclRig rig;
  namespace cmd = tmcl::command;
  constexpr uint8_t kBank3 = 3, kVars = 2;
  download_program(rig, {
      {cmd::kSgp, 29, kBank3, 1},   // 0: axis 1 left stop switch: rising edge
      {cmd::kSgp, 39, kBank3, 3},   // 1: Input_0: both edges
      {cmd::kVect, 29, 0, 10},      // 2
      {cmd::kVect, 39, 0, 14},      // 3
      {cmd::kVect, 5, 0, 18},       // 4: position reached, motor 2
      {cmd::kEi, 29, 0, 0},         // 5
      {cmd::kEi, 39, 0, 0},         // 6
      {cmd::kEi, 5, 0, 0},          // 7
      {cmd::kEi, 255, 0, 0},        // 8
      {cmd::kJa, 0, 0, 9},          // 9: idle
      {cmd::kGgp, 0, kVars, 0},     // 10: var 0 counts axis 1's left switch
      {cmd::kCalc, 0, 0, 1},        // 11
      {cmd::kAgp, 0, kVars, 0},     // 12
      {cmd::kReti, 0, 0, 0},        // 13
      {cmd::kGgp, 1, kVars, 0},     // 14: var 1 counts IN0's edges
      {cmd::kCalc, 0, 0, 1},        // 15
      {cmd::kAgp, 1, kVars, 0},     // 16
      {cmd::kReti, 0, 0, 0},        // 17
      {cmd::kGap, 1, 2, 0},         // 18: var 2 = motor 2's position on arrival
      {cmd::kAgp, 2, kVars, 0},     // 19
      {cmd::kReti, 0, 0, 0},        // 20
  });
  EXPECT_EQ(rig.command(cmd::kGgp, 31, kBank3, 0).status, 100) << "axis 2's left switch";
  EXPECT_EQ(rig.command(cmd::kGgp, 33, kBank3, 0).status, 3) << "no fourth axis";
  ASSERT_EQ(rig.command(cmd::kRunApplication, 1, 0, 0).status, 100);
  rig.run_ms(20);
  rig.board.set_input("AXIS0_REF_L", 1);  // another axis' switch: no interrupt
  rig.run_ms(20);
  EXPECT_EQ(rig.command(cmd::kGgp, 0, kVars, 0).value, 0);
  rig.board.set_input("AXIS1_REF_L", 1);
  rig.run_ms(20);
  EXPECT_EQ(rig.command(cmd::kGgp, 0, kVars, 0).value, 1);
  rig.board.set_input("AXIS1_REF_L", 0);
  rig.run_ms(20);
  EXPECT_EQ(rig.command(cmd::kGgp, 0, kVars, 0).value, 1) << "rising edge only";
  rig.board.set_input("DIO0", 1);
  rig.run_ms(20);
  rig.board.set_input("DIO0", 0);
  rig.run_ms(20);
  EXPECT_EQ(rig.command(cmd::kGgp, 1, kVars, 0).value, 2) << "IN0 (DIO0): both edges";
  ASSERT_EQ(rig.command(kMvp, 0, 2, 3000).status, 100);
  rig.run_ms(1000);
  EXPECT_EQ(rig.command(cmd::kGgp, 2, kVars, 0).value, 3000) << "motor 2 arrived";
}

// AP 140 on a running module: the new resolution applies once the axis stands still (the
// TMCL firmware has no power-off state in which the CANopen firmware applies 2000).
TEST(Tmcm3216TmclFeatures, a_new_microstep_resolution_applies_at_standstill) {
  Tmcm3216TmclRig rig;
  rig.run_ms(10);  // the power stage is on
  ASSERT_EQ(rig.command(kRor, 0, 1, 12800).status, 100);
  rig.run_ms(500);
  ASSERT_EQ(rig.sap(140, 1, 4), 100);  // 16 microsteps, while moving
  rig.run_ms(10);
  EXPECT_EQ(rig.module->axis(1).stepper.active_microstep_code(), 8) << "not while moving";
  ASSERT_EQ(rig.command(kMst, 0, 1, 0).status, 100);
  rig.run_ms(1000);
  EXPECT_EQ(rig.module->axis(1).stepper.active_microstep_code(), 4);
  const double before = rig.board.rotor_revolutions(1);
  ASSERT_EQ(rig.command(kMvp, 1, 1, 3200).status, 100);  // AP 127 = 0: from the last target
  ASSERT_EQ(rig.sap(127, 1, 1), 100);
  ASSERT_EQ(rig.command(kMvp, 1, 1, 3200).status, 100);  // from the actual position
  ASSERT_GE(rig.ms_until_reached(1, 5000), 0);
  EXPECT_NEAR(rig.board.rotor_revolutions(1) - before, 1.0, 0.01) << "3200 steps of 1/16: one revolution";
}

// AP 43..46: OUT1 pulses for AP 46 ms at every compare point AP 1 passes (AP 43 + k x AP 44),
// both ways; AP 47: OUT3 high while AP 8 reads 1.
TEST(Tmcm3216TmclFeatures, position_compare_pulses_an_output_at_each_point_and_47_shows_target_reached) {
  Tmcm3216TmclRig rig;
  ASSERT_EQ(rig.sap(43, 0, 1000), 100);
  ASSERT_EQ(rig.sap(44, 0, 2000), 100);
  ASSERT_EQ(rig.sap(45, 0, 2), 100);  // OUT1
  ASSERT_EQ(rig.sap(46, 0, 2), 100);  // 2 ms
  ASSERT_EQ(rig.sap(47, 0, 8), 100);  // OUT3
  ASSERT_EQ(rig.sap(4, 0, 10000), 100);
  ASSERT_EQ(rig.sap(5, 0, 1000000), 100);
  ASSERT_EQ(rig.sap(17, 0, 1000000), 100);
  rig.tick();
  const auto& io = rig.board.board().io;
  EXPECT_TRUE(io.output_levels[3]) << "at rest on its target at power-up";
  // Points at 1000, 3000, 5000, 7000 on the way to 8000: four pulses, rising edges counted.
  ASSERT_EQ(rig.command(kMvp, 0, 0, 8000).status, 100);
  int pulses = 0;
  int longest_ticks = 0;
  int ticks_high = 0;
  bool previous = false;
  bool reached_output_seen_low = false;
  for (int t = 0; t < 20000 && rig.gap(8, 0) == 0; ++t) {
    rig.tick();
    const bool level = io.output_levels[1];
    if (level && !previous) ++pulses;
    ticks_high = level ? ticks_high + 1 : 0;
    if (ticks_high > longest_ticks) longest_ticks = ticks_high;
    previous = level;
    if (!io.output_levels[3]) reached_output_seen_low = true;
  }
  EXPECT_EQ(rig.gap(1, 0), 8000);
  EXPECT_EQ(pulses, 4);
  EXPECT_EQ(longest_ticks, 40) << "2 ms of 50 µs ticks";
  EXPECT_TRUE(reached_output_seen_low);
  rig.tick();
  EXPECT_TRUE(io.output_levels[3]) << "on the target again";
  // Back to 0: the points again, moving down.
  ASSERT_EQ(rig.command(kMvp, 0, 0, 0).status, 100);
  pulses = 0;
  previous = false;
  for (int t = 0; t < 20000 && rig.gap(8, 0) == 0; ++t) {
    rig.tick();
    const bool level = io.output_levels[1];
    if (level && !previous) ++pulses;
    previous = level;
  }
  EXPECT_EQ(pulses, 4);
  // AP 1 re-based by a write passes no point.
  rig.run_ms(5);
  ASSERT_EQ(rig.sap(1, 0, 6000), 100);
  rig.run_ms(1);
  EXPECT_FALSE(io.output_levels[1]);
}

// AP 48: a move waits for a masked input (IN1 = DIO1) and starts when it goes high.
TEST(Tmcm3216TmclFeatures, a_move_waits_for_the_motion_start_input) {
  Tmcm3216TmclRig rig;
  ASSERT_EQ(rig.sap(48, 2, 2), 100);  // IN1
  ASSERT_EQ(rig.command(kMvp, 0, 2, 5000).status, 100);
  rig.run_ms(200);
  EXPECT_EQ(rig.gap(1, 2), 0) << "held";
  EXPECT_EQ(rig.gap(8, 2), 0);
  EXPECT_TRUE(rig.module->axis(2).motion_start_pending());
  rig.board.set_input("DIO1", 1);
  EXPECT_GE(rig.ms_until_reached(2, 2000), 0);
  EXPECT_EQ(rig.gap(1, 2), 5000);
  // MST drops a held start.
  rig.board.set_input("DIO1", 0);
  rig.run_ms(1);
  ASSERT_EQ(rig.command(kRor, 0, 2, 10000).status, 100);
  ASSERT_EQ(rig.command(kMst, 0, 2, 0).status, 100);
  EXPECT_FALSE(rig.module->axis(2).motion_start_pending());
  rig.board.set_input("DIO1", 1);
  rig.run_ms(100);
  EXPECT_EQ(rig.gap(3, 2), 0);
  EXPECT_EQ(rig.gap(1, 2), 5000);
}

// The datalogger (command 142) samples any motor's parameters: AP 1 and AP 3 of motor 2 turning
// at 20000 pps, 2 kHz rows: AP 1 advances exactly 10 µsteps a row.
TEST(Tmcm3216TmclFeatures, the_datalogger_samples_a_parameter_of_any_motor) {
  Tmcm3216TmclRig rig;
  constexpr uint8_t kRamDebug = 142;
  namespace op = tmcl::ram_debug::op;
  const auto ok = [&](uint8_t type, uint8_t motor, int32_t value) {
    const tmcl::Reply reply = rig.command(kRamDebug, type, motor, value);
    EXPECT_EQ(reply.status, 100) << "142 type " << int{type};
    return reply.value;
  };
  EXPECT_EQ(ok(op::kGetInfo, 0, 2), 2000) << "base rate";
  EXPECT_EQ(ok(op::kGetInfo, 0, 0), 4) << "channels";
  ASSERT_EQ(rig.command(kRor, 0, 2, 20000).status, 100);
  rig.run_ms(600);
  ASSERT_EQ(rig.gap(3, 2), 20000);
  ok(op::kInit, 0, 0);
  ok(op::kSetSampleCount, 0, 20);
  ok(op::kSetPrescaler, 0, 0);
  ok(op::kSetChannel, tmcl::ram_debug::channel_type::kAxisParameter, (2 << 24) | 1);
  ok(op::kSetChannel, tmcl::ram_debug::channel_type::kAxisParameter, (2 << 24) | 3);
  EXPECT_EQ(rig.command(kRamDebug, op::kSetChannel, tmcl::ram_debug::channel_type::kAxisParameter, (3 << 24) | 1).status, 4)
      << "no motor 3";
  ok(op::kEnableTrigger, 0, 0);
  for (int t = 0; t < 1000 && ok(op::kGetState, 0, 0) != static_cast<int32_t>(tmcl::ram_debug::State::kComplete); ++t) {
    rig.tick();
  }
  ASSERT_EQ(ok(op::kGetState, 0, 0), static_cast<int32_t>(tmcl::ram_debug::State::kComplete));
  for (int32_t row = 0; row < 10; ++row) {
    EXPECT_EQ(ok(op::kGetSample, 0, 2 * row + 1), 20000) << "AP 3, row " << row;
    if (row > 0) {
      EXPECT_EQ(ok(op::kGetSample, 0, 2 * row) - ok(op::kGetSample, 0, 2 * row - 2), 10) << "row " << row;
    }
  }
}

}  // namespace
}  // namespace motwin::testing
