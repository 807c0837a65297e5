// The jerk-limited S-ramp generator on its own: bounds, exact arrival, changes during a move,
// the trapezoid corner case, velocity mode and the 32-bit counter.
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <cstdint>
#include <random>
#include <string>

#include "core/motion/s_ramp.h"

namespace motwin::motion {
namespace {

constexpr double kDt = 50e-6;
constexpr double kQ32 = 4294967296.0;

SRampConfig make_config(double vmax, double amax, double dmax, double bow0, double bow1, double bow2, double bow3) {
  SRampConfig config;
  config.max_velocity = vmax;
  config.acceleration = amax;
  config.deceleration = dmax;
  config.bow[0] = bow0;
  config.bow[1] = bow1;
  config.bow[2] = bow2;
  config.bow[3] = bow3;
  return config;
}

// The position with its fraction, relative to `origin` along the shorter way.
double exact_position(const SRamp& ramp, int32_t origin) {
  const uint64_t origin_q32 = static_cast<uint64_t>(static_cast<uint32_t>(origin)) << 32;
  return origin + static_cast<double>(static_cast<int64_t>(ramp.position_q32() - origin_q32)) / kQ32;
}

// Bounds seen while stepping a ramp.
struct Observer {
  double max_speed = 0.0;
  double max_accelerating = 0.0;  // |a| while a speeds the axis up
  double max_decelerating = 0.0;  // |a| while a slows it down
  double max_jerk = 0.0;
  double previous_acceleration = 0.0;
  void see(const SRamp& ramp) {
    const double a = ramp.acceleration();
    const double v = ramp.velocity();
    max_speed = std::max(max_speed, std::fabs(v));
    if (a * v > 0.0) max_accelerating = std::max(max_accelerating, std::fabs(a));
    if (a * v < 0.0) max_decelerating = std::max(max_decelerating, std::fabs(a));
    max_jerk = std::max(max_jerk, std::fabs(a - previous_acceleration) / kDt);
    previous_acceleration = a;
  }
};

struct MoveResult {
  Observer bounds;
  double overshoot = 0.0;  // furthest past the target, µsteps
  int64_t ticks = -1;      // until position_reached()
  int32_t final_position = 0;
};

// Steps until the ramp reports position reached (or max_ticks), checking the bounds.
MoveResult run_to_target(SRamp& ramp, const SRampConfig& config, int64_t max_ticks, int32_t origin) {
  MoveResult result;
  result.bounds.previous_acceleration = ramp.acceleration();
  const int32_t target = ramp.target_position();
  const double start = exact_position(ramp, origin);
  const double direction = target >= start ? 1.0 : -1.0;
  for (int64_t tick = 0; tick < max_ticks; ++tick) {
    ramp.step(config, kDt);
    result.bounds.see(ramp);
    result.overshoot = std::max(result.overshoot, direction * (exact_position(ramp, origin) - target));
    if (ramp.position_reached()) {
      result.ticks = tick + 1;
      break;
    }
  }
  result.final_position = ramp.position();
  return result;
}

double max_bow(const SRampConfig& config) {
  double largest = 0.0;
  for (double bow : config.bow) largest = std::max(largest, bow);
  return largest;
}

TEST(SRamp, parameter_sweep_arrives_exactly_within_the_bounds) {
  const double velocities[] = {800.0, 51200.0, 600000.0};
  const double accelerations[] = {2000.0, 100000.0, 8e6};
  const double bow_factors[] = {0.0, 3.0, 40.0, 1e5};  // bow = factor x AMAX; 0 = trapezoid
  const int32_t targets[] = {1, 7, 333, 12345, -54321, 1000000};
  int moves = 0;
  for (double vmax : velocities) {
    for (double amax : accelerations) {
      for (double dmax : {0.0, amax / 3.0}) {
        for (double factor : bow_factors) {
          for (int32_t target : targets) {
            const double decel = dmax > 0.0 ? dmax : amax;
            // Skip moves of more than 4 simulated seconds (keeps the sweep quick).
            const double slower = std::min(amax, decel);
            const double distance = std::fabs(target);
            const double estimate = (distance > vmax * vmax / slower ? distance / vmax + vmax / slower
                                                                     : 2.0 * std::sqrt(distance / slower)) +
                                    (factor > 0.0 ? 4.0 / factor : 0.0);
            if (estimate > 4.0) continue;
            // Uneven bows: the build-ups steeper than the reductions.
            const SRampConfig config = make_config(vmax, amax, dmax, factor * amax, 0.5 * factor * amax,
                                                   2.0 * factor * amax, 0.7 * factor * amax);
            const std::string label = "vmax " + std::to_string(vmax) + " amax " + std::to_string(amax) + " dmax " +
                                      std::to_string(dmax) + " bow x" + std::to_string(factor) + " target " +
                                      std::to_string(target);
            SRamp ramp;
            ramp.set_position(0);
            ramp.set_position_target(target);
            const MoveResult result = run_to_target(ramp, config, 200000, 0);
            ++moves;
            ASSERT_GT(result.ticks, 0) << label;
            EXPECT_EQ(result.final_position, target) << label;
            EXPECT_EQ(ramp.position_q32(), static_cast<uint64_t>(static_cast<uint32_t>(target)) << 32) << label;
            EXPECT_EQ(ramp.velocity(), 0.0) << label;
            EXPECT_EQ(ramp.acceleration(), 0.0) << label;
            EXPECT_LE(result.overshoot, 1e-6) << label;
            EXPECT_LE(result.bounds.max_speed, vmax * (1 + 1e-12)) << label;
            EXPECT_LE(result.bounds.max_accelerating, amax * (1 + 1e-9)) << label;
            EXPECT_LE(result.bounds.max_decelerating, decel * (1 + 1e-9)) << label;
            if (factor > 0.0) {
              EXPECT_LE(result.bounds.max_jerk, max_bow(config) * (1 + 1e-6)) << label;
            }
            // It stays there.
            for (int i = 0; i < 10; ++i) ramp.step(config, kDt);
            EXPECT_EQ(ramp.position(), target) << label;
            EXPECT_TRUE(ramp.position_reached()) << label;
          }
        }
      }
    }
  }
  EXPECT_GT(moves, 250);
}

// Seeded random histories (targets, velocity targets, times) with random limits, then a final
// target: the ramp always arrives exactly, within the bounds, whatever state the history left.
TEST(SRamp, random_histories_then_a_final_target_arrive_exactly) {
  std::mt19937_64 random(20261122);
  auto uniform = [&random](double low, double high) {
    return low + (high - low) * static_cast<double>(random() >> 11) * 0x1.0p-53;
  };
  for (int trial = 0; trial < 100; ++trial) {
    const double amax = std::pow(10.0, uniform(4.0, 7.0));
    const double dmax = uniform(0.0, 1.0) < 0.5 ? 0.0 : std::pow(10.0, uniform(4.0, 7.0));
    const double bow_factor = uniform(0.0, 1.0) < 0.2 ? 0.0 : std::pow(10.0, uniform(0.0, 4.0));
    const SRampConfig config =
        make_config(std::pow(10.0, uniform(3.6, 6.0)), amax, dmax, bow_factor * amax * uniform(0.3, 3.0),
                    bow_factor * amax * uniform(0.3, 3.0), bow_factor * amax * uniform(0.3, 3.0),
                    bow_factor * amax * uniform(0.3, 3.0));
    SRamp ramp;
    const int changes = 1 + static_cast<int>(uniform(0.0, 5.0));
    for (int change = 0; change < changes; ++change) {
      if (uniform(0.0, 1.0) < 0.7) {
        ramp.set_position_target(static_cast<int32_t>(uniform(-2e5, 2e5)));
      } else {
        ramp.set_velocity_target(uniform(-1e6, 1e6));
      }
      const int ticks = static_cast<int>(uniform(1.0, 20000.0));
      for (int i = 0; i < ticks; ++i) ramp.step(config, kDt);
    }
    const auto target = static_cast<int32_t>(uniform(-2e5, 2e5));
    const std::string label = "trial " + std::to_string(trial);
    ramp.set_position_target(target);
    const MoveResult result = run_to_target(ramp, config, 4000000, 0);
    ASSERT_GT(result.ticks, 0) << label;
    EXPECT_EQ(result.final_position, target) << label;
    EXPECT_LE(result.bounds.max_speed, config.max_velocity * (1 + 1e-12)) << label;
    const double decel = dmax > 0.0 ? dmax : amax;
    EXPECT_LE(std::max(result.bounds.max_accelerating, result.bounds.max_decelerating),
              std::max(amax, decel) * (1 + 1e-9))
        << label;
    if (bow_factor > 0.0) {
      EXPECT_LE(result.bounds.max_jerk, max_bow(config) * (1 + 1e-6)) << label;
    }
  }
}

TEST(SRamp, each_bow_limits_its_own_change_of_acceleration) {
  const SRampConfig config = make_config(100000.0, 400000.0, 250000.0, 2e6, 1e6, 3e6, 5e5);
  SRamp ramp;
  ramp.set_position_target(300000);
  double jerk_limit_seen[4] = {0, 0, 0, 0};
  double previous_a = 0.0;
  double previous_v = 0.0;
  for (int tick = 0; tick < 200000 && !ramp.position_reached(); ++tick) {
    ramp.step(config, kDt);
    const double a = ramp.acceleration();
    const double v = ramp.velocity();
    // Only ticks that stay within one kind of change (no sign change of a or v).
    if (a * previous_a > 0.0 && v * previous_v > 0.0 && a != previous_a) {
      const bool speeding_up = a * v > 0.0;
      const bool magnitude_up = std::fabs(a) > std::fabs(previous_a);
      const int kind = speeding_up ? (magnitude_up ? 0 : 1) : (magnitude_up ? 2 : 3);
      jerk_limit_seen[kind] = std::max(jerk_limit_seen[kind], std::fabs(a - previous_a) / kDt);
    }
    previous_a = a;
    previous_v = v;
  }
  ASSERT_TRUE(ramp.position_reached());
  for (int kind = 0; kind < 4; ++kind) {
    // Each limit is used (reached within a few percent) and not exceeded.
    EXPECT_LE(jerk_limit_seen[kind], config.bow[kind] * (1 + 1e-6)) << kind;
    EXPECT_GE(jerk_limit_seen[kind], config.bow[kind] * 0.97) << kind;
  }
}

TEST(SRamp, long_move_takes_the_s_curve_time) {
  // Equal bows J, AMAX = DMAX = A, VMAX reached: t = d / V + V / A + A / J.
  const SRampConfig config = make_config(100000.0, 200000.0, 0.0, 1e6, 1e6, 1e6, 1e6);
  SRamp ramp;
  ramp.set_position_target(200000);
  const MoveResult result = run_to_target(ramp, config, 100000, 0);
  EXPECT_EQ(result.final_position, 200000);
  const double expected_s = 200000.0 / 100000.0 + 100000.0 / 200000.0 + 200000.0 / 1e6;  // 2.7 s
  EXPECT_NEAR(result.ticks * kDt, expected_s, 2 * kDt);
  EXPECT_NEAR(result.bounds.max_accelerating, 200000.0, 1e-6);
  EXPECT_NEAR(result.bounds.max_decelerating, 200000.0, 1e-6);
  EXPECT_EQ(result.bounds.max_speed, 100000.0);
}

TEST(SRamp, trapezoid_when_the_bows_are_zero) {
  const SRampConfig config = make_config(100000.0, 200000.0, 0.0, 0, 0, 0, 0);
  SRamp ramp;
  ramp.set_position_target(200000);
  ramp.step(config, kDt);
  // The acceleration jumps to AMAX at once.
  EXPECT_EQ(ramp.acceleration(), 200000.0);
  EXPECT_NEAR(ramp.velocity(), 200000.0 * kDt, 1e-9);
  int ticks_to_vmax = 1;
  while (ramp.velocity() < 100000.0 && ticks_to_vmax < 100000) {
    ramp.step(config, kDt);
    ++ticks_to_vmax;
    if (ramp.velocity() < 100000.0) {
      ASSERT_NEAR(ramp.velocity(), 200000.0 * kDt * ticks_to_vmax, 1e-6);
    }
  }
  // VMAX / AMAX = 0.5 s = 10000 ticks.
  EXPECT_EQ(ticks_to_vmax, 10000);
  EXPECT_EQ(ramp.acceleration(), 0.0);
  EXPECT_TRUE(ramp.velocity_reached());
  const MoveResult result = run_to_target(ramp, config, 100000, 0);
  EXPECT_EQ(result.final_position, 200000);
  // d / V + V / A = 2.5 s.
  EXPECT_NEAR((ticks_to_vmax + result.ticks) * kDt, 2.5, 2 * kDt);
  EXPECT_EQ(result.bounds.max_decelerating, 200000.0);
  EXPECT_LE(result.overshoot, 0.0);
}

TEST(SRamp, huge_bows_give_the_trapezoid_time) {
  const SRampConfig trapezoid = make_config(100000.0, 200000.0, 0.0, 0, 0, 0, 0);
  const SRampConfig steep = make_config(100000.0, 200000.0, 0.0, 1e12, 1e12, 1e12, 1e12);
  SRamp a;
  SRamp b;
  a.set_position_target(150000);
  b.set_position_target(150000);
  const MoveResult ra = run_to_target(a, trapezoid, 100000, 0);
  const MoveResult rb = run_to_target(b, steep, 100000, 0);
  EXPECT_EQ(ra.final_position, 150000);
  EXPECT_EQ(rb.final_position, 150000);
  EXPECT_NEAR(ra.ticks, rb.ticks, 1);
}

TEST(SRamp, target_moved_further_during_the_move) {
  const SRampConfig config = make_config(50000.0, 200000.0, 0.0, 1e6, 1e6, 1e6, 1e6);
  SRamp ramp;
  ramp.set_position_target(40000);
  Observer bounds;
  for (int i = 0; i < 100000 && ramp.acceleration() >= 0.0; ++i) {  // until braking has begun
    ramp.step(config, kDt);
    bounds.see(ramp);
  }
  ASSERT_LT(ramp.acceleration(), 0.0);
  ASSERT_LT(ramp.position(), 35000);
  ramp.set_position_target(90000);
  MoveResult result = run_to_target(ramp, config, 100000, 0);
  EXPECT_EQ(result.final_position, 90000);
  EXPECT_LE(result.overshoot, 1e-6);
  EXPECT_LE(result.bounds.max_jerk, 1e6 * (1 + 1e-6));
  EXPECT_LE(std::max(bounds.max_speed, result.bounds.max_speed), 50000.0);
  // It accelerated again after the change: back at VMAX.
  EXPECT_EQ(result.bounds.max_speed, 50000.0);
}

TEST(SRamp, target_moved_nearer_but_still_reachable) {
  const SRampConfig config = make_config(50000.0, 200000.0, 0.0, 1e6, 1e6, 1e6, 1e6);
  SRamp ramp;
  ramp.set_position_target(200000);
  for (int i = 0; i < 20000; ++i) ramp.step(config, kDt);  // cruising at 1 s, near 37500
  ASSERT_EQ(ramp.velocity(), 50000.0);
  const double position = exact_position(ramp, 0);
  // Stopping from VMAX needs V²/(2D) + V·D/(2J)... about 11250 µsteps; leave room.
  ramp.set_position_target(static_cast<int32_t>(position) + 15000);
  const MoveResult result = run_to_target(ramp, config, 100000, 0);
  EXPECT_EQ(result.final_position, static_cast<int32_t>(position) + 15000);
  EXPECT_LE(result.overshoot, 1e-6);
  EXPECT_LE(result.bounds.max_jerk, 1e6 * (1 + 1e-6));
  EXPECT_LE(result.bounds.max_decelerating, 200000.0 * (1 + 1e-9));
}

TEST(SRamp, target_too_near_to_stop_on_overshoots_and_comes_back) {
  const SRampConfig config = make_config(50000.0, 200000.0, 0.0, 1e6, 1e6, 1e6, 1e6);
  SRamp ramp;
  ramp.set_position_target(200000);
  for (int i = 0; i < 20000; ++i) ramp.step(config, kDt);
  ASSERT_EQ(ramp.velocity(), 50000.0);
  const auto new_target = static_cast<int32_t>(exact_position(ramp, 0)) + 2000;
  ramp.set_position_target(new_target);
  double furthest = 0.0;
  Observer bounds;
  for (int tick = 0; tick < 100000 && !ramp.position_reached(); ++tick) {
    ramp.step(config, kDt);
    bounds.see(ramp);
    furthest = std::max(furthest, exact_position(ramp, 0));
  }
  EXPECT_TRUE(ramp.position_reached());
  EXPECT_EQ(ramp.position(), new_target);
  // Stopping from 50000 µsteps/s at the limits takes about 11250 µsteps: well past the target.
  EXPECT_GT(furthest, new_target + 5000.0);
  EXPECT_LE(bounds.max_jerk, 1e6 * (1 + 1e-6));
  EXPECT_LE(bounds.max_decelerating, 200000.0 * (1 + 1e-9));
  EXPECT_LE(bounds.max_accelerating, 200000.0 * (1 + 1e-9));
}

TEST(SRamp, reversal_to_a_target_behind) {
  const SRampConfig config = make_config(50000.0, 200000.0, 0.0, 1e6, 1e6, 1e6, 1e6);
  SRamp ramp;
  ramp.set_position(1000);
  ramp.set_position_target(100000);
  for (int i = 0; i < 8000; ++i) ramp.step(config, kDt);
  ASSERT_GT(ramp.velocity(), 0.0);
  ramp.set_position_target(-30000);
  bool went_negative = false;
  Observer bounds;
  bounds.previous_acceleration = ramp.acceleration();
  for (int tick = 0; tick < 100000 && !ramp.position_reached(); ++tick) {
    ramp.step(config, kDt);
    bounds.see(ramp);
    went_negative = went_negative || ramp.velocity() < 0.0;
  }
  EXPECT_TRUE(ramp.position_reached());
  EXPECT_EQ(ramp.position(), -30000);
  EXPECT_TRUE(went_negative);
  EXPECT_DOUBLE_EQ(bounds.max_speed, 50000.0);
  EXPECT_LE(bounds.max_jerk, 1e6 * (1 + 1e-6));
}

TEST(SRamp, vmax_change_during_the_move) {
  SRampConfig config = make_config(50000.0, 200000.0, 0.0, 1e6, 1e6, 1e6, 1e6);
  SRamp ramp;
  ramp.set_position_target(300000);
  for (int i = 0; i < 20000; ++i) ramp.step(config, kDt);
  ASSERT_EQ(ramp.velocity(), 50000.0);
  config.max_velocity = 20000.0;
  Observer slower;
  int ticks_to_new_vmax = 0;
  while (ramp.velocity() != 20000.0 && ticks_to_new_vmax < 100000) {
    ramp.step(config, kDt);
    slower.see(ramp);
    ++ticks_to_new_vmax;
  }
  EXPECT_EQ(ramp.velocity(), 20000.0);
  EXPECT_TRUE(ramp.velocity_reached());
  EXPECT_LE(slower.max_jerk, 1e6 * (1 + 1e-6));
  // 30000 µsteps/s less does not need DMAX (the peak would be sqrt(30000 x 1e6) = 173205
  // µsteps/s²): two jerk phases of sqrt(30000 / 1e6) s each.
  EXPECT_NEAR(ticks_to_new_vmax * kDt, 2.0 * std::sqrt(30000.0 / 1e6), 2 * kDt);
  // Faster again, then arrival.
  config.max_velocity = 80000.0;
  const MoveResult result = run_to_target(ramp, config, 200000, 0);
  EXPECT_EQ(result.final_position, 300000);
  EXPECT_EQ(result.bounds.max_speed, 80000.0);
  EXPECT_LE(result.overshoot, 1e-6);
}

TEST(SRamp, amax_change_during_the_move) {
  SRampConfig config = make_config(50000.0, 200000.0, 0.0, 1e6, 1e6, 1e6, 1e6);
  SRamp ramp;
  ramp.set_position_target(100000);
  for (int i = 0; i < 3000; ++i) ramp.step(config, kDt);  // building up the acceleration
  config.acceleration = 50000.0;
  const MoveResult result = run_to_target(ramp, config, 200000, 0);
  EXPECT_EQ(result.final_position, 100000);
  EXPECT_LE(result.overshoot, 1e-6);
  EXPECT_LE(result.bounds.max_decelerating, 50000.0 * (1 + 1e-9));
}

TEST(SRamp, velocity_mode_s_transitions_and_flags) {
  const SRampConfig config = make_config(100000.0, 200000.0, 0.0, 1e6, 1e6, 1e6, 1e6);
  SRamp ramp;
  ramp.set_velocity_target(80000.0);
  EXPECT_EQ(ramp.mode(), SRamp::Mode::kVelocity);
  EXPECT_TRUE(ramp.standstill());
  // First jerk phase: a = J t, v = J t² / 2.
  for (int i = 0; i < 100; ++i) ramp.step(config, kDt);
  EXPECT_NEAR(ramp.acceleration(), 1e6 * 100 * kDt, 1e-6);
  EXPECT_NEAR(ramp.velocity(), 0.5 * 1e6 * (100 * kDt) * (100 * kDt), 1e-6);
  EXPECT_FALSE(ramp.velocity_reached());
  EXPECT_FALSE(ramp.standstill());
  int ticks = 100;
  Observer bounds;
  bounds.previous_acceleration = ramp.acceleration();
  while (!ramp.velocity_reached() && ticks < 100000) {
    ramp.step(config, kDt);
    bounds.see(ramp);
    ++ticks;
  }
  EXPECT_EQ(ramp.velocity(), 80000.0);
  EXPECT_EQ(ramp.acceleration(), 0.0);
  // 80000 / 200000 + 200000 / 1e6 = 0.6 s.
  EXPECT_NEAR(ticks * kDt, 0.6, 2 * kDt);
  EXPECT_LE(bounds.max_jerk, 1e6 * (1 + 1e-6));
  // Reversal through zero, S-shaped on both sides, monotonic velocity.
  ramp.set_velocity_target(-50000.0);
  double previous = ramp.velocity();
  bool monotonic = true;
  bool passed_zero = false;
  Observer reversal;
  reversal.previous_acceleration = ramp.acceleration();
  for (int i = 0; i < 100000 && !ramp.velocity_reached(); ++i) {
    ramp.step(config, kDt);
    reversal.see(ramp);
    monotonic = monotonic && ramp.velocity() <= previous;
    passed_zero = passed_zero || ramp.velocity() < 0.0;
    previous = ramp.velocity();
  }
  EXPECT_TRUE(monotonic);
  EXPECT_TRUE(passed_zero);
  EXPECT_EQ(ramp.velocity(), -50000.0);
  EXPECT_LE(reversal.max_jerk, 1e6 * (1 + 1e-6));
  EXPECT_LE(reversal.max_decelerating, 200000.0 * (1 + 1e-9));
  // A target beyond VMAX runs at VMAX and counts as reached there.
  ramp.set_velocity_target(-1e9);
  for (int i = 0; i < 100000 && !ramp.velocity_reached(); ++i) ramp.step(config, kDt);
  EXPECT_EQ(ramp.velocity(), -100000.0);
  // To rest: standstill.
  ramp.set_velocity_target(0.0);
  for (int i = 0; i < 100000 && !ramp.standstill(); ++i) ramp.step(config, kDt);
  EXPECT_TRUE(ramp.standstill());
  EXPECT_TRUE(ramp.velocity_reached());
  EXPECT_EQ(ramp.acceleration(), 0.0);
}

TEST(SRamp, hold_mode_keeps_the_velocity) {
  const SRampConfig config = make_config(100000.0, 200000.0, 0.0, 1e6, 1e6, 1e6, 1e6);
  SRamp ramp;
  ramp.set_velocity_target(80000.0);
  for (int i = 0; i < 2000; ++i) ramp.step(config, kDt);
  const double velocity = ramp.velocity();
  ASSERT_GT(velocity, 0.0);
  ramp.hold();
  ramp.set_velocity_target(0.0);  // a target given in hold mode switches to velocity mode
  EXPECT_EQ(ramp.mode(), SRamp::Mode::kVelocity);
  ramp.hold();
  const uint64_t before = ramp.position_q32();
  for (int i = 0; i < 1000; ++i) ramp.step(config, kDt);
  EXPECT_EQ(ramp.mode(), SRamp::Mode::kHold);
  EXPECT_EQ(ramp.velocity(), velocity);
  EXPECT_EQ(ramp.acceleration(), 0.0);
  EXPECT_TRUE(ramp.velocity_reached());
  EXPECT_NEAR(static_cast<double>(ramp.position_q32() - before) / kQ32, velocity * 1000 * kDt, 1e-3);
}

TEST(SRamp, zero_acceleration_keeps_the_velocity) {
  SRampConfig config = make_config(100000.0, 200000.0, 0.0, 1e6, 1e6, 1e6, 1e6);
  SRamp ramp;
  ramp.set_velocity_target(50000.0);
  for (int i = 0; i < 2000; ++i) ramp.step(config, kDt);
  const double velocity = ramp.velocity();
  ASSERT_GT(velocity, 0.0);
  config.acceleration = 0.0;
  ramp.set_velocity_target(0.0);
  for (int i = 0; i < 100; ++i) ramp.step(config, kDt);
  EXPECT_EQ(ramp.velocity(), velocity);
  EXPECT_EQ(ramp.acceleration(), 0.0);
  // At rest nothing moves towards a target either.
  SRamp resting;
  resting.set_position_target(1000);
  for (int i = 0; i < 100; ++i) resting.step(config, kDt);
  EXPECT_EQ(resting.position_q32(), 0u);
  EXPECT_FALSE(resting.position_reached());
}

TEST(SRamp, position_reached_and_velocity_reached_in_position_mode) {
  const SRampConfig config = make_config(20000.0, 200000.0, 0.0, 2e6, 2e6, 2e6, 2e6);
  SRamp ramp;
  ramp.set_position_target(30000);
  EXPECT_FALSE(ramp.position_reached());
  bool seen_vmax_flag = false;
  while (!ramp.position_reached()) {
    ramp.step(config, kDt);
    if (ramp.velocity_reached() && !ramp.position_reached()) {
      seen_vmax_flag = true;
      EXPECT_EQ(std::fabs(ramp.velocity()), 20000.0);
    }
  }
  EXPECT_TRUE(seen_vmax_flag);
  EXPECT_TRUE(ramp.velocity_reached());
  EXPECT_TRUE(ramp.standstill());
}

TEST(SRamp, stop_now_halts_at_once_and_stays) {
  const SRampConfig config = make_config(50000.0, 200000.0, 0.0, 1e6, 1e6, 1e6, 1e6);
  SRamp ramp;
  ramp.set_position_target(100000);
  for (int i = 0; i < 5000; ++i) ramp.step(config, kDt);
  ramp.stop_now();
  EXPECT_EQ(ramp.velocity(), 0.0);
  EXPECT_EQ(ramp.acceleration(), 0.0);
  const int32_t stopped_at = ramp.position();
  EXPECT_EQ(ramp.target_position(), stopped_at);
  EXPECT_GT(stopped_at, 0);
  for (int i = 0; i < 100; ++i) ramp.step(config, kDt);
  EXPECT_EQ(ramp.position(), stopped_at);
  EXPECT_TRUE(ramp.position_reached());
  // Velocity mode: the target velocity becomes 0.
  ramp.set_velocity_target(30000.0);
  for (int i = 0; i < 1000; ++i) ramp.step(config, kDt);
  ramp.stop_now();
  EXPECT_EQ(ramp.target_velocity(), 0.0);
  ramp.step(config, kDt);
  EXPECT_EQ(ramp.velocity(), 0.0);
}

TEST(SRamp, set_position_moves_the_counter_and_the_target) {
  const SRampConfig config = make_config(50000.0, 200000.0, 0.0, 1e6, 1e6, 1e6, 1e6);
  SRamp ramp;
  ramp.set_position_target(0);
  ramp.set_position(-777);
  EXPECT_EQ(ramp.position(), -777);
  EXPECT_EQ(ramp.target_position(), -777);
  for (int i = 0; i < 100; ++i) ramp.step(config, kDt);
  EXPECT_EQ(ramp.position(), -777);
  EXPECT_TRUE(ramp.position_reached());
}

TEST(SRamp, counter_wraps_at_32_bits_and_targets_go_the_short_way) {
  const SRampConfig config = make_config(50000.0, 200000.0, 0.0, 1e6, 1e6, 1e6, 1e6);
  SRamp ramp;
  ramp.set_position(INT32_MAX - 100);
  ramp.set_position_target(INT32_MIN + 100);  // 201 µsteps ahead across the wrap
  bool backwards = false;
  for (int tick = 0; tick < 100000 && !ramp.position_reached(); ++tick) {
    ramp.step(config, kDt);
    backwards = backwards || ramp.velocity() < 0.0;
  }
  EXPECT_TRUE(ramp.position_reached());
  EXPECT_EQ(ramp.position(), INT32_MIN + 100);
  EXPECT_FALSE(backwards);
  // Velocity mode across the wrap backwards: -1000 µsteps/s for 2 s. The S-shaped start (no
  // AMAX phase: peak sqrt(v J)) lasts 2 sqrt(v / J) and covers half its time at full speed less.
  ramp.set_position(INT32_MIN + 10);
  const uint64_t start_q32 = ramp.position_q32();
  ramp.set_velocity_target(-1000.0);
  for (int i = 0; i < 40000; ++i) ramp.step(config, kDt);
  const double travelled = static_cast<double>(static_cast<int64_t>(start_q32 - ramp.position_q32())) / kQ32;
  const double expected = 2.0 * 1000.0 - 1000.0 * std::sqrt(1000.0 / 1e6);
  EXPECT_NEAR(travelled, expected, 1e-5);  // rounding to 2^-32 µstep per tick
  EXPECT_EQ(ramp.position(), static_cast<int32_t>(std::floor(INT32_MAX + 11.0 - expected)));
}

}  // namespace
}  // namespace motwin::motion
