// The trapezoidal ramp generator on its own, with exact (Q16) positions.
#include <gtest/gtest.h>

#include <cmath>

#include "core/motion/trapezoid_ramp.h"

namespace motwin::motion {
namespace {

constexpr double kDt = 50e-6;
const TrapezoidRampConfig kConfig{4000.0 * 8192 / 60, 2000.0 * 8192 / 60, true};

struct MoveResult {
  double max_overshoot_counts = 0;
  double max_acceleration = 0;  // counts/s², away from the join with the braking curve
  int ticks_to_arrive = -1;
  int32_t final_position = 0;
};

MoveResult move(int32_t start, int32_t target, const TrapezoidRampConfig& config) {
  TrapezoidRamp ramp;
  ramp.set_position(start);
  ramp.set_position_target(target);
  MoveResult result;
  const double direction = target > start ? 1.0 : -1.0;
  double previous_velocity = 0;
  for (int tick = 0; tick < 400000; ++tick) {
    ramp.step(config, kDt);
    const double past = direction * (static_cast<double>(ramp.position_q16()) / 65536.0 - target);
    result.max_overshoot_counts = std::max(result.max_overshoot_counts, past);
    result.max_acceleration = std::max(result.max_acceleration, std::fabs(ramp.velocity() - previous_velocity) / kDt);
    previous_velocity = ramp.velocity();
    if (result.ticks_to_arrive < 0 && ramp.position_q16() == int64_t{target} * 65536 && ramp.velocity() == 0.0) {
      result.ticks_to_arrive = tick + 1;
      break;
    }
  }
  result.final_position = ramp.position();
  return result;
}

TEST(TrapezoidRamp, arrives_exactly_without_overshoot_from_rest) {
  for (auto [start, target] : {std::pair{0, 20000}, {0, 90000}, {20000, -10000}, {1000, 0}, {0, 1}, {0, 8192},
                               {-5, 5}, {0, 2000000}}) {
    const auto result = move(start, target, kConfig);
    EXPECT_EQ(result.final_position, target) << start << " -> " << target;
    EXPECT_GT(result.ticks_to_arrive, 0) << start << " -> " << target;
    EXPECT_LE(result.max_overshoot_counts, 0.0) << start << " -> " << target;
    // Joining the braking curve may take up to 3 ticks' worth of velocity change in one tick.
    EXPECT_LE(result.max_acceleration, 4.0 * kConfig.acceleration) << start << " -> " << target;
  }
}

TEST(TrapezoidRamp, long_move_takes_the_trapezoid_time) {
  // 2000000 counts: accelerate to 4000 rpm in 2 s (546133 counts/s), cruise, decelerate 2 s.
  const auto result = move(0, 2000000, kConfig);
  const double v = kConfig.max_velocity;
  const double a = kConfig.acceleration;
  const double expected_s = 2000000.0 / v + v / a;
  EXPECT_NEAR(result.ticks_to_arrive * kDt, expected_s, 0.002);
}

TEST(TrapezoidRamp, velocity_mode_changes_velocity_at_the_acceleration) {
  TrapezoidRamp ramp;
  ramp.set_velocity_target(100000.0);
  for (int i = 0; i < 20; ++i) ramp.step(kConfig, kDt);
  EXPECT_NEAR(ramp.velocity(), 20 * kDt * kConfig.acceleration, 1e-6);
  ramp.set_velocity_target(-1e9);
  for (int i = 0; i < 400000; ++i) ramp.step(kConfig, kDt);
  EXPECT_EQ(ramp.velocity(), -kConfig.max_velocity);
}

TEST(TrapezoidRamp, position_counter_wraps_at_32_bits) {
  TrapezoidRamp ramp;
  ramp.set_position(INT32_MAX - 10);
  ramp.set_velocity_target(20.0 / kDt);  // 20 counts per tick
  const TrapezoidRampConfig jump{1e9, 0, false};
  ramp.step(jump, kDt);  // the jump tick integrates half of the new velocity: 10 counts
  ramp.step(jump, kDt);  // then 20 counts per tick
  EXPECT_EQ(ramp.position(), INT32_MIN + 19);
}

}  // namespace
}  // namespace motwin::motion
