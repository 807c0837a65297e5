// The TMCM-3216's TMCL firmware core (core/modules/tmcm3216/tmcm3216_tmcl.h) on the simulated
// board: three motors addressed by the motor byte, the EightPoint ramp of the CANopen firmware
// behind MVP/ROR/MST, AP 8 as PyTrinamic's eight-point demo polls it, the stop switches as its
// stop-switch demo needs them, the stepper's settings (AP 6, 7, 140), the I/O banks and what the
// Zephyr driver sends at start-up.
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <cstdint>
#include <memory>
#include <vector>

#include "support/tmcm3216_tmcl_rig.h"

namespace motwin::testing {
namespace {

TEST(Tmcm3216Tmcl, has_three_motors_and_refuses_a_fourth) {
  Tmcm3216TmclRig rig;
  EXPECT_EQ(rig.module->motor_count(), 3);
  EXPECT_EQ(rig.command(kGap, 1, 3, 0).status, 4);
  EXPECT_EQ(rig.command(kMvp, 0, 3, 100).status, 4);
  EXPECT_EQ(rig.command(136, 1, 0, 0).value, (3216 << 16) | (1 << 8) | 0);
}

TEST(Tmcm3216Tmcl, mvp_moves_only_its_motor_on_the_trapezoid_of_ap4_and_ap5) {
  Tmcm3216TmclRig rig;
  ASSERT_EQ(rig.sap(4, 1, 20000), 100);
  ASSERT_EQ(rig.sap(5, 1, 40000), 100);
  ASSERT_EQ(rig.sap(17, 1, 40000), 100);
  ASSERT_EQ(rig.command(kMvp, 0, 1, 51200).status, 100);
  EXPECT_EQ(rig.gap(8, 1), 0) << "AP 8 reads 0 right after the MVP";
  rig.run_ms(250);  // accelerating: 0.5 s to 20000 pps
  EXPECT_NEAR(rig.gap(3, 1), 10000, 50);
  EXPECT_EQ(rig.gap(1, 0), 0);
  EXPECT_EQ(rig.gap(1, 2), 0);
  // 51200 µsteps: 0.5 s up (5000 µsteps), 2.06 s at VMAX, 0.5 s down: about 3.06 s in all.
  const double ms = rig.ms_until_reached(1, 5000);
  EXPECT_NEAR(ms, 3060 - 250, 20);
  EXPECT_EQ(rig.gap(1, 1), 51200);
  EXPECT_EQ(rig.gap(3, 1), 0);
  // 51200 µsteps at 256 microsteps per full step of a 200-step motor: one revolution.
  EXPECT_NEAR(rig.board.rotor_revolutions(1), 1.0, 0.01);
  EXPECT_NEAR(rig.board.rotor_revolutions(0), 0.0, 1e-9);
}

TEST(Tmcm3216Tmcl, mvp_rel_adds_to_the_position_and_ror_rol_mst_drive_velocity) {
  Tmcm3216TmclRig rig;
  EXPECT_EQ(rig.gap(8, 2), 1) << "at power-up the ramp stands on its target, as the driver chip's";
  ASSERT_EQ(rig.sap(1, 2, 1000), 100);  // sets the counter (and the target), moves nothing
  EXPECT_EQ(rig.gap(8, 2), 1);
  ASSERT_EQ(rig.command(kMvp, 1, 2, 500).status, 100);
  EXPECT_EQ(rig.gap(0, 2), 1500);
  EXPECT_GE(rig.ms_until_reached(2, 2000), 0);
  EXPECT_EQ(rig.gap(1, 2), 1500);

  ASSERT_EQ(rig.command(kRol, 0, 0, 10000).status, 100);
  EXPECT_EQ(rig.gap(2, 0), -10000);
  rig.run_ms(400);
  EXPECT_EQ(rig.gap(3, 0), -10000);
  EXPECT_EQ(rig.gap(8, 0), 0);
  ASSERT_EQ(rig.command(kMst, 0, 0, 0).status, 100);
  rig.run_ms(300);
  EXPECT_EQ(rig.gap(3, 0), 0);
  EXPECT_LT(rig.gap(1, 0), -1000);
  ASSERT_EQ(rig.command(kRor, 0, 0, 20000000).status, 4) << "beyond AP 2's range";
  EXPECT_EQ(rig.gap(2, 0), 0);
}

// PyTrinamic's eight_point_ramp_demo.py: its SAPs (A1 and V1 twice, no A2/V2), SAP 1 = 0,
// MVP 100000, AP 1 and 3 sampled while AP 8 is 0; then back to 0.
TEST(Tmcm3216Tmcl, the_eight_point_demo_sees_its_segments_and_reaches_both_targets) {
  Tmcm3216TmclRig rig;
  const std::vector<std::pair<uint8_t, int32_t>> saps = {{4, 40000}, {5, 30000}, {15, 5000},  {16, 10000},
                                                         {15, 15000}, {16, 20000}, {17, 20000}, {36, 10000},
                                                         {18, 5000}, {19, 5000}, {20, 5000},  {21, 31250}};
  for (const auto& [number, value] : saps) ASSERT_EQ(rig.sap(number, 0, value), 100) << "AP " << int{number};
  ASSERT_EQ(rig.sap(1, 0, 0), 100);
  for (int32_t target : {100000, 0}) {
    ASSERT_EQ(rig.command(kMvp, 0, 0, target).status, 100);
    std::vector<int32_t> velocities;
    int polls = 0;
    while (rig.gap(8, 0) == 0 && polls < 20000) {
      velocities.push_back(rig.gap(3, 0));
      rig.run_ms(1);
      ++polls;
    }
    ASSERT_FALSE(velocities.empty()) << "the demo's samples[0]";
    EXPECT_EQ(rig.gap(1, 0), target);
    // VSTART 5000 at once (after the ramp wait time of the first move, 31250 x 32 µs = 1 s, on
    // the way back), then A1 15000 up to V1 20000 and AMAX 30000 towards VMAX 40000; the long D1
    // segment (5000 from V1 down to VSTOP) leaves no room to cruise: it turns just below VMAX.
    const int32_t peak = target > 0 ? *std::max_element(velocities.begin(), velocities.end())
                                    : -*std::min_element(velocities.begin(), velocities.end());
    EXPECT_LE(peak, 40000);
    EXPECT_GT(peak, 39500);
    const auto first_motion = std::find_if(velocities.begin(), velocities.end(), [](int32_t v) { return v != 0; });
    ASSERT_NE(first_motion, velocities.end());
    EXPECT_GE(std::abs(*first_motion), 5000) << "VSTART";
    EXPECT_LT(std::abs(*first_motion), 5100);
    const double waited_ms = static_cast<double>(first_motion - velocities.begin());
    if (target == 0) {
      EXPECT_NEAR(waited_ms, 1000, 30) << "TZEROWAIT before the second move";
    }
  }
}

// PyTrinamic's stop_switch_demo.py: ROR 50000 until AP 10 reads 1, MST, ROR -50000, MST.
TEST(Tmcm3216Tmcl, a_right_switch_stops_motion_towards_it_and_lets_the_axis_leave) {
  Tmcm3216TmclRig rig;
  rig.board.set_input("AXIS0_REF_R_AT", 2.0);  // high beyond two revolutions
  ASSERT_EQ(rig.command(kRor, 0, 0, 50000).status, 100);
  double ms = 0;
  while (rig.gap(10, 0) == 0 && ms < 5000) {
    rig.run_ms(1);
    ms += 1;
  }
  ASSERT_EQ(rig.gap(10, 0), 1);
  rig.run_ms(5);
  EXPECT_EQ(rig.gap(3, 0), 0) << "stopped by the switch";
  const int32_t stopped_at = rig.gap(1, 0);
  EXPECT_NEAR(stopped_at / 51200.0, 2.0, 0.02);
  ASSERT_EQ(rig.command(kRor, 0, 0, 50000).status, 100);  // towards the switch again
  rig.run_ms(50);
  EXPECT_EQ(rig.gap(1, 0), stopped_at);
  ASSERT_EQ(rig.command(kMst, 0, 0, 0).status, 100);
  ASSERT_EQ(rig.command(kRor, 0, 0, -50000).status, 100);  // away from it
  rig.run_ms(500);
  EXPECT_LT(rig.gap(1, 0), stopped_at - 5000);
  EXPECT_EQ(rig.gap(10, 0), 0);
  ASSERT_EQ(rig.command(kMst, 0, 0, 0).status, 100);

  // AP 12 = 1: the switch is read but no longer stops the axis.
  ASSERT_EQ(rig.sap(12, 0, 1), 100);
  ASSERT_EQ(rig.command(kRor, 0, 0, 50000).status, 100);
  rig.run_ms(3000);
  EXPECT_EQ(rig.gap(10, 0), 1);
  EXPECT_EQ(rig.gap(3, 0), 50000);
}

TEST(Tmcm3216Tmcl, an_eight_point_ramp_the_generator_refuses_answers_status_4) {
  Tmcm3216TmclRig rig;
  ASSERT_EQ(rig.sap(5, 0, 0), 100);  // AMAX 0: the axis could never leave VSTART
  EXPECT_EQ(rig.command(kMvp, 0, 0, 1000).status, 4);
  EXPECT_EQ(rig.command(kRor, 0, 0, 1000).status, 4);
  EXPECT_EQ(rig.gap(0, 0), 0);
  ASSERT_EQ(rig.sap(5, 0, 1000), 100);
  ASSERT_EQ(rig.sap(16, 0, 30000), 100);  // V1 above V2 with V2 in use
  ASSERT_EQ(rig.sap(35, 0, 20000), 100);
  ASSERT_EQ(rig.sap(15, 0, 1000), 100);
  ASSERT_EQ(rig.sap(34, 0, 1000), 100);
  EXPECT_EQ(rig.command(kMvp, 0, 0, 1000).status, 4);
}

// What Zephyr's driver sends at start-up (tmcm3216_stepper_driver.c, _ctrl.c) and when it
// enables and disables a motor.
TEST(Tmcm3216Tmcl, the_stepper_settings_of_the_zephyr_driver_reach_the_stepper) {
  Tmcm3216TmclRig rig;
  EXPECT_EQ(rig.gap(140, 2), 8);
  ASSERT_EQ(rig.sap(140, 2, 4), 100);  // 16 microsteps
  ASSERT_EQ(rig.sap(4, 2, 2000), 100);
  ASSERT_EQ(rig.sap(5, 2, 500), 100);
  ASSERT_EQ(rig.sap(6, 2, 100), 100);
  EXPECT_EQ(rig.module->axis(2).stepper.objects.microstep_code, 4);
  EXPECT_EQ(rig.module->axis(2).stepper.objects.run_current, 100);
  EXPECT_EQ(rig.gap(6, 2), 100);
  EXPECT_EQ(rig.sap(140, 2, 9), 4) << "beyond 256 microsteps";
  // 3200 µsteps at 16 per full step: 200 full steps, one revolution.
  ASSERT_EQ(rig.command(kMvp, 1, 2, 3200).status, 100);
  EXPECT_GE(rig.ms_until_reached(2, 10000), 0);
  EXPECT_NEAR(rig.board.rotor_revolutions(2), 1.0, 0.01);
  ASSERT_EQ(rig.sap(6, 2, 0), 100);
  ASSERT_EQ(rig.sap(7, 2, 0), 100);
  rig.run_ms(10);
  // Current scale 0 is still 1/32 of the range (3 A), as on the driver chip.
  EXPECT_NEAR(rig.module->axis(2).stepper.current_ma(), 3000 / 32.0, 1);
}

TEST(Tmcm3216Tmcl, stap_keeps_a_setting_of_one_motor_over_a_power_cycle) {
  Tmcm3216TmclRig rig;
  ASSERT_EQ(rig.sap(4, 1, 12345), 100);
  ASSERT_EQ(rig.command(kStap, 4, 1, 0).status, 100);
  ASSERT_EQ(rig.sap(4, 2, 777), 100);  // not stored
  rig.power_up();
  EXPECT_EQ(rig.gap(4, 1), 12345);
  EXPECT_EQ(rig.gap(4, 2), 51200);
  EXPECT_EQ(rig.gap(4, 0), 51200);
}

TEST(Tmcm3216Tmcl, the_io_banks_map_pytrinamics_ports) {
  Tmcm3216TmclRig rig;
  ASSERT_EQ(rig.command(kSio, 2, 2, 1).status, 100);  // OUT2
  rig.tick();
  EXPECT_EQ(rig.command(kGio, 2, 2, 0).value, 1);
  EXPECT_TRUE(rig.board.board().io.output_mode[2]);
  EXPECT_TRUE(rig.board.board().io.output_levels[2]);
  EXPECT_EQ(rig.command(kSio, 4, 2, 1).status, 3) << "OUT0..OUT3 only";
  rig.board.set_input("AIN1", 3000);  // raw counts
  rig.board.set_input("DIO1", 1);
  rig.tick();
  EXPECT_EQ(rig.command(kGio, 1, 1, 0).value, 3000);
  EXPECT_EQ(rig.command(kGio, 1, 0, 0).value, 1) << "AIN1 above half scale reads high";
  EXPECT_EQ(rig.command(kGio, 0, 0, 0).value, 0);
  EXPECT_EQ(rig.command(kGio, 3, 0, 0).value, 1) << "IN1 (port 3) is DIO1";
  EXPECT_EQ(rig.command(kGio, 6, 0, 0).status, 3) << "IN0..IN3 are ports 2..5";
}

// PyTrinamic's rotate_demo.py: ROR 50000 for 5 s, MST, 5 s, MVP REL by the position read with
// VMAX 50000. At AP 127's default the relative move adds to the last target (0: the demo moved
// nothing before), so it ends where the axis stands and AP 8 reads 1 at once; with AP 127 = 1 (as
// PyTrinamic's TMCM-1260/1290 examples set it before a move_by) the distance doubles, exactly.
TEST(Tmcm3216Tmcl, the_rotate_demo_reaches_its_relative_target_at_either_ap127) {
  // The host's requests fall anywhere within the ticks: every phase of the MST and the MVP.
  for (uint64_t phase = 0; phase < 40; ++phase) {
    const int32_t origin_option = phase % 2 == 0 ? 1 : 0;
    Tmcm3216TmclRig rig;
    ASSERT_EQ(rig.sap(127, 0, origin_option), 100);
    ASSERT_EQ(rig.command(kRor, 0, 0, 50000).status, 100);
    rig.tick(5000 * 20 + phase);
    ASSERT_EQ(rig.command(kMst, 0, 0, 0).status, 100);
    rig.tick(5000 * 20 + 3 * phase);
    const int32_t position = rig.gap(1, 0);
    const int32_t target = origin_option == 1 ? 2 * position : position;
    ASSERT_EQ(rig.sap(4, 0, 50000), 100);
    ASSERT_EQ(rig.command(kMvp, 1, 0, position).status, 100);
    EXPECT_EQ(rig.gap(0, 0), target);
    EXPECT_GE(rig.ms_until_reached(0, 20000), 0)
        << "phase " << phase << ": AP 1 " << rig.gap(1, 0) << ", target " << target;
    EXPECT_EQ(rig.gap(1, 0), target);
  }
}

}  // namespace
}  // namespace motwin::testing
