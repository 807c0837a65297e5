// The ideal motor of the TMCM-1636 following its ramp generator (AP 40..55).
#include <gtest/gtest.h>

#include <cmath>
#include <cstdlib>

#include "support/tmcm1636_rig.h"

namespace motwin::testing {
namespace {

constexpr double kCountsPerRpmSecond = 8192.0 / 60.0;  // AP 100 default

TEST(Tmcm1636Motion, ror_accelerates_at_ap44_up_to_the_target_velocity) {
  Tmcm1636Rig rig;
  ASSERT_EQ(rig.command(1, 0, 0, 1000).status, 100);
  rig.run_ms(250);  // 2000 rpm/s for 0.25 s
  EXPECT_NEAR(rig.gap(42), 500, 1);
  rig.run_ms(500);
  EXPECT_EQ(rig.gap(42), 1000);
  EXPECT_EQ(rig.gap(41), 1000);
  // Distance of 0.5 s at 1000 rpm after a 0.5 s ramp: 0.25 + 0.25 s-equivalents at full speed.
  const double expected_counts = kCountsPerRpmSecond * (0.5 * 1000 * 0.5 + 1000 * 0.25);
  EXPECT_NEAR(rig.gap(52), expected_counts, 2.0);
}

TEST(Tmcm1636Motion, rol_runs_backwards_and_max_velocity_limits) {
  Tmcm1636Rig rig;
  rig.command(5, 43, 0, 300);
  rig.command(2, 0, 0, 1000);
  rig.run_ms(1000);
  EXPECT_EQ(rig.gap(42), -300);
  EXPECT_LT(rig.gap(52), 0);
}

TEST(Tmcm1636Motion, mst_stops_with_the_ramp) {
  Tmcm1636Rig rig;
  rig.command(1, 0, 0, 2000);
  rig.run_ms(1500);
  ASSERT_EQ(rig.gap(42), 2000);
  rig.command(3, 0, 0, 0);
  rig.run_ms(500);
  EXPECT_NEAR(rig.gap(42), 1000, 1) << "decelerating at 2000 rpm/s";
  rig.run_ms(600);
  EXPECT_EQ(rig.gap(42), 0);
  EXPECT_EQ(rig.gap(40), 0);
}

TEST(Tmcm1636Motion, mvp_arrives_exactly_and_sets_position_reached) {
  Tmcm1636Rig rig;
  ASSERT_EQ(rig.command(4, 0, 0, 90000).status, 100);
  EXPECT_EQ(rig.gap(55), 0);
  int max_velocity = 0;
  int ms = 0;
  while (rig.gap(55) == 0 && ms < 20000) {
    rig.run_ms(1);
    ++ms;
    max_velocity = std::max(max_velocity, std::abs(rig.gap(42)));
    ASSERT_LE(rig.gap(52), 90000) << "no overshoot";
  }
  rig.run_ms(50);
  EXPECT_EQ(rig.gap(52), 90000);
  EXPECT_EQ(rig.gap(51), 90000);
  EXPECT_EQ(rig.gap(42), 0);
  EXPECT_EQ(rig.gap(55), 1);
  EXPECT_LE(max_velocity, 4000);
  // Triangle profile (never reaches AP 43): time = 2 * sqrt(distance / acceleration).
  const double distance_rev = 90000.0 / 8192.0;
  const double accel_rev_s2 = 2000.0 / 60.0;
  const double expected_ms = 2000.0 * std::sqrt(distance_rev / accel_rev_s2);
  EXPECT_NEAR(ms, expected_ms, 0.05 * expected_ms);
}

TEST(Tmcm1636Motion, mvp_rel_moves_from_the_actual_position) {
  Tmcm1636Rig rig;
  rig.command(5, 52, 0, 5000);
  rig.command(4, 1, 0, -10000);
  EXPECT_EQ(rig.gap(50), -5000);
  rig.run_ms(3000);
  EXPECT_EQ(rig.gap(52), -5000);
}

TEST(Tmcm1636Motion, target_change_during_a_move_reverses_without_jumps) {
  Tmcm1636Rig rig;
  rig.command(4, 0, 0, 200000);
  rig.run_ms(800);
  const int position = rig.gap(52);
  rig.command(4, 0, 0, 0);
  int previous_velocity = rig.gap(42);
  for (int i = 0; i < 6000; ++i) {
    rig.run_ms(1);
    const int velocity = rig.gap(42);
    ASSERT_LE(std::abs(velocity - previous_velocity), 3) << "acceleration limited at 2 rpm/ms";
    previous_velocity = velocity;
  }
  EXPECT_GT(position, 0);
  EXPECT_EQ(rig.gap(52), 0);
  EXPECT_EQ(rig.gap(55), 1);
}

TEST(Tmcm1636Motion, ramp_disabled_moves_at_max_velocity_and_stops_exactly) {
  Tmcm1636Rig rig;
  rig.command(5, 45, 0, 0);
  rig.command(5, 43, 0, 600);
  rig.command(4, 0, 0, 8192);  // one revolution at 600 rpm = 100 ms
  rig.run_ms(1);
  EXPECT_EQ(rig.gap(42), 600);
  rig.run_ms(105);
  EXPECT_EQ(rig.gap(52), 8192);
  EXPECT_EQ(rig.gap(42), 0);
}

TEST(Tmcm1636Motion, more_than_2_pow_31_away_takes_the_shorter_way_round) {
  Tmcm1636Rig rig;
  rig.command(5, 52, 0, 2147483000);
  rig.command(4, 0, 0, -2147483000);  // 1296 counts forward through the wrap
  rig.run_ms(1);
  EXPECT_GT(rig.gap(42), 0);
  rig.run_ms(2000);
  EXPECT_EQ(rig.gap(52), -2147483000);
}

TEST(Tmcm1636Motion, writing_actual_position_does_not_move_the_axis) {
  Tmcm1636Rig rig;
  rig.command(4, 0, 0, 1000);
  rig.run_ms(2000);
  rig.command(5, 52, 0, 0);
  rig.run_ms(100);
  EXPECT_EQ(rig.gap(52), 0);
  EXPECT_EQ(rig.gap(50), 0);
}

TEST(Tmcm1636Motion, enabled_reference_switch_stops_motion_towards_it) {
  Tmcm1636Rig rig;
  rig.command(5, 209, 0, 1);   // right switch enabled
  rig.command(5, 210, 0, 1);   // right switch high active
  rig.command(1, 0, 0, 500);
  rig.run_ms(100);
  rig.io.reference_switch_levels[0] = true;
  rig.run_ms(1);
  EXPECT_EQ(rig.gap(211), 1);
  EXPECT_EQ(rig.gap(42), 0);
  const int stopped_at = rig.gap(52);
  rig.run_ms(100);
  EXPECT_EQ(rig.gap(52), stopped_at);
  rig.command(2, 0, 0, 500);  // away from it is allowed
  rig.run_ms(100);
  EXPECT_LT(rig.gap(52), stopped_at);
}

TEST(Tmcm1636Motion, disabled_driver_holds_the_axis) {
  Tmcm1636Rig rig;
  rig.command(5, 255, 0, 0);
  rig.command(1, 0, 0, 500);
  rig.run_ms(100);
  EXPECT_EQ(rig.gap(52), 0);
  rig.command(5, 255, 0, 1);
  rig.run_ms(100);
  EXPECT_GT(rig.gap(52), 0);
}

TEST(Tmcm1636Motion, position_event_138_fires_once_when_the_target_is_reached) {
  struct Sink final : tmcl::ReplySink {
    std::vector<std::pair<tmcl::ChannelId, tmcl::Reply>> replies;
    void deliver(tmcl::ChannelId channel, const tmcl::Reply& reply) override { replies.emplace_back(channel, reply); }
  } sink;
  Tmcm1636Rig rig;
  rig.command(4, 0, 0, 20000);
  const auto ack = rig.send(tmcl::encode_request(1, tmcl::Instruction{138, 0, 0, 1}), 7);
  EXPECT_EQ(ack.bytes[2], 100);
  EXPECT_EQ(rig.command(138, 0, 0, 2).status, 4) << "motor 1 does not exist";
  rig.engine.collect_events(sink);
  EXPECT_TRUE(sink.replies.empty());
  for (int i = 0; i < 5000 && sink.replies.empty(); ++i) {
    rig.run_ms(1);
    rig.engine.collect_events(sink);
  }
  ASSERT_EQ(sink.replies.size(), 1u);
  EXPECT_EQ(sink.replies[0].first, 7);
  EXPECT_EQ(sink.replies[0].second.status, 128);
  EXPECT_EQ(sink.replies[0].second.command, 138);
  EXPECT_NEAR(rig.gap(52), 20000, 5) << "within the position reached distance (AP 53)";
  rig.engine.collect_events(sink);
  EXPECT_EQ(sink.replies.size(), 1u) << "one event per request";
}

// The ramp limits in counts/s are derived only when AP 43, 44 or 100 change: each change
// still takes effect in the next tick.
TEST(Tmcm1636Motion, ramp_limits_follow_ap43_ap44_and_ap100_changed_mid_move) {
  Tmcm1636Rig rig;
  rig.command(1, 0, 0, 1500);
  rig.run_ms(1000);
  ASSERT_EQ(rig.gap(42), 1500);
  rig.command(5, 43, 0, 700);  // max velocity below the target: down at 2000 rpm/s in 0.4 s
  rig.run_ms(200);
  EXPECT_NEAR(rig.gap(42), 1100, 1);
  rig.run_ms(300);
  EXPECT_EQ(rig.gap(42), 700);
  // Fewer counts per revolution: the ramp's 700 rpm of 8192 counts are now above 700 rpm of
  // 4000, so it brakes (2000 rpm/s of 4000 counts: 0.37 s) to the same rpm in fewer counts/s.
  rig.command(5, 100, 0, 4000);
  rig.run_ms(500);
  const int32_t start = rig.gap(52);
  rig.run_ms(600);
  EXPECT_EQ(rig.gap(42), 700);
  EXPECT_NEAR(rig.gap(52) - start, 700.0 * 4000.0 / 60.0 * 0.6, 2.0);
  rig.command(5, 44, 0, 9000);
  rig.command(5, 43, 0, 3000);  // up to the target at 9000 rpm/s: 800 rpm in 89 ms
  rig.run_ms(45);
  EXPECT_NEAR(rig.gap(42), 1105, 1);
  rig.run_ms(50);
  EXPECT_EQ(rig.gap(42), 1500);
}

TEST(Tmcm1636Motion, same_inputs_give_the_same_trajectory_bit_for_bit) {
  auto trajectory = [] {
    Tmcm1636Rig rig;
    rig.command(4, 0, 0, 123457);
    std::vector<int64_t> samples;
    for (int i = 0; i < 300; ++i) {
      rig.run_ms(7);
      samples.push_back(rig.module.axis().ramp().position_q16());
      if (i == 100) rig.command(4, 0, 0, -5000);
    }
    return samples;
  };
  EXPECT_EQ(trajectory(), trajectory());
}

}  // namespace
}  // namespace motwin::testing
