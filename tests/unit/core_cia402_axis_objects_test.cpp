// The mode objects of one CiA-402 axis that shape a move: positioning option code 60F2, position
// window 6067/6068, csp offset 60B0 and interpolation period 60C2, halt 605D and quick stop 605A
// stop distances, and software limits 607D in every mode (pv/csv brake onto them). Each test
// asserts the numbers the formulas give (v²/2a, v/a, one tick = 50 µs).
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <limits>

#include "core/cia402/axis_drive.h"
#include "support/cia402_axis_rig.h"

namespace motwin::cia402 {
namespace {

struct Axis : testing::Cia402AxisRig {
  // With 606A = 0 or -1 alike the encoder reads the demand minus encoder_lag.
  Axis() { encoder_always_follows = true; }
  void new_set_point(int32_t target, uint16_t extra_bits = 0) {
    drive.objects.target_position = target;
    drive.write_controlword(static_cast<uint16_t>(0x1F | extra_bits));
    drive.write_controlword(0x0F);
  }
  bool standstill() const { return drive.velocity_pps() == 0.0; }
};

// --- 60F2: relative to the previous target, the demand or the actual position ---------------

TEST(Cia402AxisObjects, PositioningOption1IsRelativeToTheDemand) {
  Axis a;
  a.drive.objects.positioning_option = 1;
  a.enable(1);
  a.new_set_point(20000);
  a.run_ms(100);  // 5120 pps, 256 µsteps in: the stopping distance (256) is below 1000
  const int32_t demand = a.drive.position_demand();
  ASSERT_EQ(demand, 256);
  a.new_set_point(1000, 0x60);  // bit 6 relative, bit 5 at once
  EXPECT_TRUE(a.run_until([&] { return (a.drive.statusword() & kSwTargetReached) != 0; }, 5) > 0);
  EXPECT_EQ(a.drive.position_demand(), demand + 1000) << "6062 + 1000, not 20000 + 1000";
}

TEST(Cia402AxisObjects, PositioningOption2IsRelativeToTheActualPosition) {
  Axis a;
  a.drive.objects.sensor_selection = 0;  // 6064 from the encoder, 40 µsteps behind
  a.drive.objects.positioning_option = 2;
  a.encoder_lag = 40;
  a.enable(1);
  a.new_set_point(20000);
  a.run_ms(100);
  const int32_t actual = a.drive.position_actual();
  ASSERT_NE(actual, a.drive.position_demand());
  a.new_set_point(1000, 0x60);
  EXPECT_TRUE(a.run_until([&] { return (a.drive.statusword() & kSwTargetReached) != 0; }, 5) > 0);
  EXPECT_EQ(a.drive.position_demand(), actual + 1000);
  // 6064 is the encoder reading of the last tick: the demand before that tick (255) - 40.
  EXPECT_EQ(a.drive.position_demand(), 215 + 1000);
}

TEST(Cia402AxisObjects, PositioningOption0IsRelativeToThePreviousTarget) {
  Axis a;
  a.enable(1);
  a.new_set_point(20000);
  a.run_ms(100);
  a.new_set_point(1000, 0x60);
  EXPECT_TRUE(a.run_until([&] { return (a.drive.statusword() & kSwTargetReached) != 0; }, 5) > 0);
  EXPECT_EQ(a.drive.position_demand(), 21000);
}

// An RPDO mapping 6040 before 607A (RPDO 3) writes the controlword first: its edge takes the 607A
// of the same frame. A 607A written a tick later does not touch the running move.
TEST(Cia402AxisObjects, SetPointOfAnRpdoWithControlwordBeforeTargetIsTheFramesTarget) {
  Axis a;
  a.enable(1);
  a.drive.objects.target_position = 0;
  a.drive.write_controlword(0x1F);  // RPDO: 6040 = 0x1F ...
  a.drive.objects.target_position = 25600;
  a.drive.target_position_written();  // ... then 607A = 25600, same instant
  a.drive.write_controlword(0x0F);
  a.run_ms(10);
  a.drive.objects.target_position = 777;
  a.drive.target_position_written();  // a later 607A waits for the next edge
  EXPECT_GT(a.run_until([&] { return (a.drive.statusword() & kSwTargetReached) != 0; }, 5), 0);
  EXPECT_EQ(a.drive.position_demand(), 25600);
  // Relative (bit 6) from the previous target, the same way.
  a.drive.objects.target_position = 0;
  a.drive.write_controlword(0x5F);
  a.drive.objects.target_position = -600;
  a.drive.target_position_written();
  a.drive.write_controlword(0x0F);
  EXPECT_GT(a.run_until([&] { return (a.drive.statusword() & kSwTargetReached) != 0; }, 5), 0);
  EXPECT_EQ(a.drive.position_demand(), 25000);
}

// --- 6067 / 6068: target reached needs the actual position in the window for the window time ---

TEST(Cia402AxisObjects, PositionWindowTimeDelaysTargetReached) {
  Axis a;
  a.drive.objects.sensor_selection = 0;
  a.drive.objects.position_window = 10;
  a.drive.objects.position_window_time_ms = 5;
  a.encoder_lag = 30;  // outside the window while the motor settles
  a.enable(1);
  a.new_set_point(1000);
  ASSERT_GT(a.run_until([&] { return a.drive.ramp().position_reached(); }, 2), 0);
  ASSERT_EQ(a.drive.position_demand(), 1000);
  a.run_ms(20);
  EXPECT_EQ(a.drive.statusword() & kSwTargetReached, 0) << "|6064 - 607A| = 30 > 6067";
  a.encoder_lag = -8;  // 8 past the target: inside the window
  a.run_ticks(99);
  EXPECT_EQ(a.drive.statusword() & kSwTargetReached, 0) << "4.95 ms in the window";
  a.run_ticks(1);
  EXPECT_NE(a.drive.statusword() & kSwTargetReached, 0) << "5 ms in the window";
  a.encoder_lag = 11;  // out again: bit 10 drops, the time starts anew
  a.run_ticks(1);
  EXPECT_EQ(a.drive.statusword() & kSwTargetReached, 0);
  a.encoder_lag = 10;
  a.run_ticks(100);
  EXPECT_NE(a.drive.statusword() & kSwTargetReached, 0);
}

// --- 60B0 and 60C2 in csp ---------------------------------------------------------------------

TEST(Cia402AxisObjects, CyclicSyncPositionAddsThePositionOffset) {
  Axis a;
  a.drive.objects.position_offset = 500;
  a.enable(8);
  for (int cycle = 1; cycle <= 5; ++cycle) {
    a.drive.objects.target_position = cycle * 100;
    a.drive.on_sync();
    const int32_t from = a.drive.position_demand();
    a.run_ticks(10);
    EXPECT_EQ(a.drive.position_demand(), from + (cycle * 100 + 500 - from) / 2) << cycle;
    a.run_ticks(10);
    EXPECT_EQ(a.drive.position_demand(), cycle * 100 + 500) << cycle;
  }
}

// Fuzz finding (2026-11-27): a csp set-point half the counter away, interpolated over a short
// period, is a velocity beyond 606C's int32 (4.2e11 units); converting it was undefined behaviour.
// 606C now saturates.
TEST(Cia402AxisObjects, VelocityActualSaturatesBeyondInt32) {
  for (const int32_t target : {2'000'000'000, -2'000'000'000}) {
    Axis a;
    a.drive.objects.interpolation_period = 1;
    a.drive.objects.interpolation_index = -4;  // 0.1 ms: two ticks of 1e9 µsteps
    a.enable(8);
    a.drive.objects.target_position = target;
    a.drive.on_sync();
    a.run_ticks(1);
    EXPECT_EQ(a.drive.velocity_actual_value(),
              target > 0 ? std::numeric_limits<int32_t>::max() : std::numeric_limits<int32_t>::min());
  }
}

TEST(Cia402AxisObjects, CyclicSyncPositionInterpolatesOverA2msPeriod) {
  Axis a;
  a.drive.objects.interpolation_period = 2;  // 2 x 10^-3 s
  a.enable(8);
  for (int cycle = 1; cycle <= 5; ++cycle) {
    a.drive.objects.target_position = cycle * 400;
    a.drive.on_sync();
    a.run_ms(1);
    EXPECT_EQ(a.drive.position_demand(), (cycle - 1) * 400 + 200) << "halfway after 1 ms";
    a.run_ms(1);
    EXPECT_EQ(a.drive.position_demand(), cycle * 400) << "on the set-point after 2 ms";
  }
  // 5 x 10^-4 s: the same step is done after 0.5 ms.
  a.drive.objects.interpolation_period = 5;
  a.drive.objects.interpolation_index = -4;
  a.drive.objects.target_position = 3000;
  a.drive.on_sync();
  a.run_ticks(5);
  EXPECT_EQ(a.drive.position_demand(), 2500);
  a.run_ticks(5);
  EXPECT_EQ(a.drive.position_demand(), 3000);
}

// --- Halt (605D = 1) in pp and quick stop 605A = 1 / 5: the slow-down ramp 6084 / 6083 ---------

TEST(Cia402AxisObjects, HaltInProfilePositionStopsOn6084AndResumes) {
  Axis a;
  a.drive.objects.profile_deceleration = 102400;   // 6084
  a.drive.objects.quick_stop_deceleration = 400000;  // 6085: not used by halt
  a.enable(1);
  a.new_set_point(500000);
  a.run_ms(1500);  // at 6081 = 51200 pps since 1 s
  ASSERT_EQ(a.drive.velocity_pps(), 51200.0);
  const int32_t at_halt = a.drive.position_demand();
  a.drive.write_controlword(0x10F);
  const double t = a.run_until([&] { return a.standstill(); }, 5);
  EXPECT_NEAR(t, 51200.0 / 102400, 0.001) << "v / 6084";
  EXPECT_NEAR(a.drive.position_demand() - at_halt, 51200.0 * 51200 / (2 * 102400), 3) << "v² / (2 x 6084)";
  EXPECT_NE(a.drive.statusword() & kSwTargetReached, 0) << "bit 10 at standstill while halted";
  EXPECT_EQ(a.drive.statusword() & 0x6F, 0x27);
  const int32_t stopped = a.drive.position_demand();
  a.run_ms(200);
  EXPECT_EQ(a.drive.position_demand(), stopped) << "stays while bit 8 is set";
  a.drive.write_controlword(0x0F);
  a.run_ticks(1);
  EXPECT_EQ(a.drive.statusword() & kSwTargetReached, 0) << "the move resumes";
  EXPECT_GT(a.run_until([&] { return (a.drive.statusword() & kSwTargetReached) != 0; }, 20), 0);
  EXPECT_EQ(a.drive.position_demand(), 500000);
}

TEST(Cia402AxisObjects, QuickStopOption1StopsOnTheSlowDownRampThenDisables) {
  Axis a;
  a.drive.objects.quick_stop_option = 1;
  a.drive.objects.profile_acceleration = 51200;     // pv's slow-down ramp
  a.drive.objects.quick_stop_deceleration = 200000;  // not used with option 1
  a.enable(3);
  a.drive.objects.target_velocity = 51200;
  a.drive.target_velocity_written();
  a.run_ms(1100);
  const int32_t at_stop = a.drive.position_demand();
  a.drive.write_controlword(0x0B);
  EXPECT_EQ(a.drive.statusword() & 0x6F, 0x07);
  const double t = a.run_until([&] { return a.standstill(); }, 5);
  EXPECT_NEAR(t, 1.0, 0.001) << "51200 pps / 6083";
  EXPECT_NEAR(a.drive.position_demand() - at_stop, 25600, 3);
  a.run_ticks(1);
  EXPECT_EQ(a.drive.statusword() & 0x4F, 0x40) << "then switch on disabled";
  EXPECT_FALSE(a.drive.demand().power_enabled);
}

TEST(Cia402AxisObjects, QuickStopOption5StopsOnTheSlowDownRampAndStays) {
  Axis a;
  a.drive.objects.quick_stop_option = 5;
  a.drive.objects.profile_deceleration = 102400;  // pp's slow-down ramp
  a.drive.objects.quick_stop_deceleration = 400000;
  a.enable(1);
  a.new_set_point(500000);
  a.run_ms(1500);
  const int32_t at_stop = a.drive.position_demand();
  a.drive.write_controlword(0x02);
  const double t = a.run_until([&] { return a.standstill(); }, 5);
  EXPECT_NEAR(t, 0.5, 0.001);
  EXPECT_NEAR(a.drive.position_demand() - at_stop, 12800, 3);
  a.run_ms(100);
  EXPECT_EQ(a.drive.statusword() & 0x6F, 0x07) << "stays in quick stop active";
  EXPECT_TRUE(a.drive.demand().power_enabled) << "holding the motor";
  const int32_t held = a.drive.position_demand();
  a.drive.write_controlword(0x0F);  // transition 16
  EXPECT_EQ(a.drive.statusword() & 0x6F, 0x27);
  a.run_ms(100);
  EXPECT_EQ(a.drive.position_demand(), held) << "the interrupted move is not resumed";
}

// --- Software limits 607D ---------------------------------------------------------------------

// EMCY FF01 for software limits comes from the module's monitor (tests/unit/
// core_tmcm3216_emergencies_module_test.cpp, core_tmcm3216_drive_test.cpp); here: bit 11 and positions.
TEST(Cia402AxisObjects, ProfilePositionClampedToALimitSetsBit11) {
  Axis a;
  a.drive.objects.software_limit_max = 10000;
  a.drive.objects.software_limit_min = -6000;
  a.drive.objects.home_offset = 2000;  // corrected: -8000 .. 8000
  a.enable(1);
  a.new_set_point(50000);
  EXPECT_GT(a.run_until([&] { return (a.drive.statusword() & kSwTargetReached) != 0; }, 5), 0);
  EXPECT_EQ(a.drive.position_demand(), 8000);
  a.run_ticks(1);
  EXPECT_NE(a.drive.statusword() & kSwInternalLimit, 0);
  a.new_set_point(-50000);
  a.run_ms(100);
  EXPECT_EQ(a.drive.statusword() & kSwInternalLimit, 0) << "left the limit";
  EXPECT_GT(a.run_until([&] { return (a.drive.statusword() & kSwTargetReached) != 0; }, 10), 0);
  a.run_ticks(1);
  EXPECT_EQ(a.drive.position_demand(), -8000);
  EXPECT_NE(a.drive.statusword() & kSwInternalLimit, 0);
}

// pv and csv: the axis brakes on 6085 so that it stands exactly on the limit (docs "Decisions").
TEST(Cia402AxisObjects, ProfileVelocityBrakesOntoTheSoftwareLimit) {
  Axis a;
  a.drive.objects.software_limit_max = 36100;
  a.drive.objects.quick_stop_deceleration = 51200;
  a.enable(3);
  a.drive.objects.target_velocity = 20000;
  a.drive.target_velocity_written();
  int32_t highest = 0;
  double braking_starts_at = -1;
  a.run_until([&] {
    highest = std::max(highest, a.drive.position_demand());
    if (braking_starts_at < 0 && a.drive.velocity_pps() > 0 && a.drive.velocity_pps() < 20000 &&
        a.drive.position_demand() > 10000) {
      braking_starts_at = a.drive.position_demand();
    }
    return a.standstill() && a.drive.position_demand() > 0;
  }, 5);
  EXPECT_EQ(highest, 36100) << "never past the limit";
  EXPECT_EQ(a.drive.position_demand(), 36100);
  // Braking on 6085 from 20000 pps needs 20000² / (2 x 51200) = 3906 µsteps.
  EXPECT_NEAR(braking_starts_at, 36100 - 3906, 25);
  a.run_ticks(1);
  EXPECT_NE(a.drive.statusword() & kSwInternalLimit, 0);
  a.run_ms(500);
  EXPECT_EQ(a.drive.position_demand(), 36100) << "60FF still points into the limit: the axis stays";
  a.drive.objects.target_velocity = -20000;  // away from it: runs again
  a.drive.target_velocity_written();
  a.run_ms(100);
  EXPECT_LT(a.drive.velocity_pps(), 0.0);
  EXPECT_EQ(a.drive.statusword() & kSwInternalLimit, 0);
}

TEST(Cia402AxisObjects, ProfileVelocityBrakesOntoTheNegativeLimitCorrectedByHomeOffset) {
  Axis a;
  a.drive.objects.software_limit_min = -5000;
  a.drive.objects.home_offset = 1000;  // corrected: -6000
  a.drive.objects.quick_stop_deceleration = 100000;
  a.enable(3);
  a.drive.objects.target_velocity = -30000;
  a.drive.target_velocity_written();
  int32_t lowest = 0;
  a.run_until([&] {
    lowest = std::min(lowest, a.drive.position_demand());
    return a.standstill() && a.drive.position_demand() < 0;
  }, 5);
  EXPECT_EQ(lowest, -6000);
  EXPECT_EQ(a.drive.position_demand(), -6000);
  a.run_ticks(1);
  EXPECT_NE(a.drive.statusword() & kSwInternalLimit, 0);
}

TEST(Cia402AxisObjects, CyclicSyncVelocityBrakesOntoTheSoftwareLimit) {
  Axis a;
  a.drive.objects.software_limit_max = 20000;
  a.drive.objects.quick_stop_deceleration = 200000;
  a.enable(9);
  int32_t highest = 0;
  for (int cycle = 0; cycle < 2000; ++cycle) {
    a.drive.objects.target_velocity = 25000;
    a.drive.on_sync();
    for (int i = 0; i < 20; ++i) {
      a.run_ticks(1);
      highest = std::max(highest, a.drive.position_demand());
    }
  }
  EXPECT_EQ(highest, 20000);
  EXPECT_EQ(a.drive.position_demand(), 20000);
  EXPECT_EQ(a.drive.velocity_pps(), 0.0);
  EXPECT_NE(a.drive.statusword() & kSwInternalLimit, 0);
}

TEST(Cia402AxisObjects, VelocityAwayFromTheLimitStopsOnItsOwnRampWhenThatFits) {
  Axis a;
  a.drive.objects.software_limit_max = 100000;
  a.enable(3);
  a.drive.objects.target_velocity = 20000;
  a.drive.target_velocity_written();
  a.run_ms(1000);
  const int32_t at_stop = a.drive.position_demand();
  a.drive.objects.target_velocity = 0;  // 6083 = 51200: 3906 µsteps, far from the limit
  a.drive.target_velocity_written();
  a.run_until([&] { return a.standstill(); }, 5);
  EXPECT_NEAR(a.drive.position_demand() - at_stop, 20000.0 * 20000 / (2 * 51200), 3);
  EXPECT_EQ(a.drive.statusword() & kSwInternalLimit, 0);
}

}  // namespace
}  // namespace motwin::cia402
