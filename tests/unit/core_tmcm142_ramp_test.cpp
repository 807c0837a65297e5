// The TMCM-142's ramp through its parameters (not motion::SRamp alone): AP 16..19 = 16777215
// gives the trapezoid's time d/V + V/A, finite bows give the S-curve's d/V + V/A + A/J and a
// jerk of exactly the converted bow in each of the four phases; AP 128 hold mode keeps the
// velocity; AP 130 velocity reached in velocity, hold and position mode.
#include <algorithm>
#include <cmath>

#include <gtest/gtest.h>

#include "core/modules/tmcm142/tmcm142_hardware.h"
#include "support/tmcm142_rig.h"

namespace motwin::testing {
namespace {

namespace hw = modules::tmcm142;
constexpr uint8_t kOk = 100;

void use_pps(Tmcm142Rig& rig, int32_t vmax, int32_t acceleration) {
  ASSERT_EQ(rig.sap(255, 1), kOk);
  ASSERT_EQ(rig.sap(4, vmax), kOk);
  ASSERT_EQ(rig.sap(5, acceleration), kOk);
}

// AP 18, the module's one bow, for all four changes of acceleration.
void set_max_bow(Tmcm142Rig& rig, int32_t bow) { ASSERT_EQ(rig.sap(18, bow), kOk); }

TEST(Tmcm142Ramp, maximum_bows_give_the_trapezoid_time) {
  Tmcm142Rig rig;
  use_pps(rig, 100000, 1000000);
  set_max_bow(rig, 16777215);
  ASSERT_EQ(rig.command(4, 0, 0, 200000).status, kOk);
  rig.run_ms(1);
  // A trapezoid corner: the full acceleration from the first tick.
  EXPECT_DOUBLE_EQ(rig.module.axis().ramp().acceleration(), 1000000.0);
  // d/V + V/A = 200000 / 100000 + 100000 / 1e6 = 2.1 s.
  const uint32_t ms = rig.run_until([&] { return rig.gap(8) == 1; }, 5000) + 1;
  EXPECT_NEAR(ms, 2100, 2);
  EXPECT_EQ(rig.gap(1), 200000);
}

TEST(Tmcm142Ramp, default_bows_add_a_over_j_to_the_move_time) {
  Tmcm142Rig rig;
  use_pps(rig, 100000, 1000000);
  // Factory bow 1000: J = 1000 * 64e6^3 / 2^64 = 14210855 µsteps/s³ in all four phases.
  EXPECT_EQ(rig.gap(18), 1000);
  const double jerk = 1000 * hw::kPps3PerBowUnit;
  EXPECT_NEAR(jerk, 14210855.0, 1.0);
  ASSERT_EQ(rig.command(4, 0, 0, 200000).status, kOk);
  // d/V + V/A + A/J = 2 + 0.1 + 0.0704 = 2.1704 s.
  const uint32_t ms = rig.run_until([&] { return rig.gap(8) == 1; }, 5000);
  EXPECT_NEAR(ms, 2000 + 100 + 1e6 / jerk * 1000, 3);
  EXPECT_EQ(rig.gap(1), 200000);
}

// AP 18 limits the jerk of each of the four phases of the S-curve, AP 17 the deceleration; the
// acceleration stays within AMAX (AP 5) and the velocity within VMAX.
TEST(Tmcm142Ramp, max_bow_limits_the_jerk_of_every_phase_and_ap_17_the_deceleration) {
  Tmcm142Rig rig;
  use_pps(rig, 200000, 1000000);
  set_max_bow(rig, 500);
  ASSERT_EQ(rig.sap(17, 500000), kOk);
  EXPECT_EQ(rig.gap(16), 1000000) << "AP 16 is AP 5";
  const double bow_pps3 = 500 * hw::kPps3PerBowUnit;
  ASSERT_EQ(rig.command(4, 0, 0, 600000).status, kOk);
  double peak_jerk[4] = {0, 0, 0, 0};
  double peak_acceleration = 0.0;
  double peak_deceleration = 0.0;
  double peak_velocity = 0.0;
  double last_acceleration = 0.0;
  bool braking = false;
  for (int tick = 0; tick < 8 * 20000 && rig.gap(8) == 0; ++tick) {
    rig.tick();
    const auto& ramp = rig.module.axis().ramp();
    const double a = ramp.acceleration();
    const double jerk = (a - last_acceleration) / hw::kControlTickS;
    last_acceleration = a;
    peak_acceleration = std::max(peak_acceleration, a);
    peak_deceleration = std::max(peak_deceleration, -a);
    peak_velocity = std::max(peak_velocity, ramp.velocity());
    // Phases: build-up of acceleration, its reduction, build-up of deceleration, its reduction.
    if (a < 0.0) braking = true;
    int phase = -1;
    if (jerk > 1.0) phase = braking ? 3 : 0;
    if (jerk < -1.0) phase = braking ? 2 : 1;
    if (phase >= 0) peak_jerk[phase] = std::max(peak_jerk[phase], std::fabs(jerk));
  }
  EXPECT_EQ(rig.gap(8), 1);
  EXPECT_EQ(rig.gap(1), 600000);
  EXPECT_LE(peak_acceleration, 1000000.0 * (1 + 1e-9));
  EXPECT_GE(peak_acceleration, 1000000.0 * (1 - 1e-9)) << "AMAX is reached with this bow";
  EXPECT_LE(peak_deceleration, 500000.0 * (1 + 1e-9));
  // The braking peak is chosen to end exactly on the target: DMAX within 0.1 %, far from AMAX.
  EXPECT_GE(peak_deceleration, 500000.0 * 0.999) << "DMAX (AP 17) is reached";
  EXPECT_LE(peak_velocity, 200000.0 * (1 + 1e-9));
  for (int k = 0; k < 4; ++k) {
    EXPECT_LE(peak_jerk[k], bow_pps3 * 1.0001) << "phase " << k;
    EXPECT_GE(peak_jerk[k], bow_pps3 * 0.99) << "phase " << k;
  }
}

// AP 128 = 3 during an acceleration keeps the velocity of that moment; AP 130 reads 1 in hold
// mode; back in velocity mode (AP 128 = 2) the axis goes on to AP 2.
TEST(Tmcm142Ramp, hold_mode_keeps_the_velocity_and_ap_130_follows_the_mode) {
  Tmcm142Rig rig;
  use_pps(rig, 100000, 100000);
  set_max_bow(rig, 16777215);
  ASSERT_EQ(rig.command(1, 0, 0, 50000).status, kOk);  // ROR 50000: 0.5 s to reach it
  rig.run_ms(200);
  EXPECT_EQ(rig.gap(128), 2);
  EXPECT_EQ(rig.gap(130), 0) << "still accelerating";
  ASSERT_EQ(rig.sap(128, 3), kOk);
  const int32_t held = rig.gap(3);
  EXPECT_NEAR(held, 20000, 5);
  EXPECT_EQ(rig.gap(128), 3);
  EXPECT_EQ(rig.gap(130), 1) << "hold mode: at its velocity";
  const int32_t start = rig.gap(1);
  rig.run_ms(500);
  EXPECT_EQ(rig.gap(3), held);
  EXPECT_NEAR(rig.gap(1) - start, held / 2, 2) << "half a second at the held velocity";
  EXPECT_EQ(rig.gap(2), 50000) << "AP 2 kept";
  EXPECT_EQ(rig.sap(128, 1), 4) << "mode 1 does not exist";
  EXPECT_EQ(rig.gap(128), 3);
  ASSERT_EQ(rig.sap(128, 2), kOk);
  rig.run_ms(100);
  EXPECT_EQ(rig.gap(130), 0);
  EXPECT_NEAR(rig.gap(3), held + 10000, 5);
  rig.run_ms(250);  // (50000 - held) / 100000 = 0.3 s in all
  EXPECT_EQ(rig.gap(3), 50000);
  EXPECT_EQ(rig.gap(130), 1);
  EXPECT_EQ(rig.gap(129) & 2, 2);
}

TEST(Tmcm142Ramp, velocity_reached_in_position_mode_at_vmax_and_on_the_target) {
  Tmcm142Rig rig;
  use_pps(rig, 100000, 1000000);
  set_max_bow(rig, 16777215);
  ASSERT_EQ(rig.command(4, 0, 0, 100000).status, kOk);  // 1.1 s: 0.1 s up, 0.9 s at VMAX, 0.1 s down
  rig.run_ms(50);
  EXPECT_EQ(rig.gap(130), 0) << "accelerating";
  rig.run_ms(450);
  EXPECT_EQ(rig.gap(3), 100000);
  EXPECT_EQ(rig.gap(130), 1) << "at VMAX";
  rig.run_ms(550);
  EXPECT_EQ(rig.gap(130), 0) << "braking";
  rig.run_ms(100);
  EXPECT_EQ(rig.gap(8), 1);
  EXPECT_EQ(rig.gap(130), 1) << "at rest on the target";
}

}  // namespace
}  // namespace motwin::testing
