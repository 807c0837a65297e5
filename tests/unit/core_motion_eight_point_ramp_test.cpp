// The EightPoint ramp generator of the TMCM-3216 on its own: segment rates measured from the
// velocity samples, segment boundaries, stopping distances and durations against the formulas,
// exact arrival, TVMAX and TZEROWAIT, changes during a move, velocity mode, stops, validation.
#include <gtest/gtest.h>

#include <cmath>
#include <cstdint>
#include <initializer_list>
#include <vector>

#include "core/motion/eight_point_ramp.h"

namespace motwin::motion {
namespace {

using Segment = EightPointRamp::Segment;
using Mode = EightPointRamp::Mode;

constexpr double kDt = 50e-6;  // the TMCM-3216 motion tick
constexpr double kTolerance = 1e-6;  // relative, for rates measured from samples

// A jerk-optimised profile: steep A2/D2 in the middle, gentler A1/D1 and AMAX/DMAX.
EightPointConfig profile() {
  EightPointConfig c;
  c.vstart_pps = 500;
  c.a1_pps2 = 200000;
  c.v1_pps = 20000;
  c.a2_pps2 = 400000;
  c.v2_pps = 60000;
  c.vmax_pps = 100000;
  c.amax_pps2 = 100000;
  c.dmax_pps2 = 150000;
  c.d2_pps2 = 450000;
  c.d1_pps2 = 250000;
  c.vstop_pps = 1000;
  return c;
}

EightPointConfig trapezoid() {
  EightPointConfig c = profile();
  c.v1_pps = 0;
  c.v2_pps = 0;
  return c;
}

// Distance from v down to VSTOP through the D bands (manual 1.5 figure 3).
double stopping_distance(const EightPointConfig& c, double v) {
  double s = 0;
  auto band = [&](double hi, double lo, double d) {
    if (v > lo) s += (std::fmin(v, hi) * std::fmin(v, hi) - lo * lo) / (2 * d);
  };
  band(1e300, c.v2_pps, c.dmax_pps2);
  band(c.v2_pps, c.v1_pps, c.d2_pps2);
  band(c.v1_pps, c.vstop_pps, c.d1_pps2);
  return s;
}

struct Sample {
  double velocity;
  double acceleration;
  int32_t position;
  double exact_position;  // µsteps travelled since the start of the move (exact Q32)
  Segment segment;
};

struct MoveRun {
  std::vector<Sample> samples;  // after each tick
  int ticks_to_arrive = -1;
  double max_speed = 0;
  double max_overshoot = 0;  // µsteps past the target along the move's direction
};

// Steps position mode from rest until the target is reached (or max_ticks).
MoveRun run_move(EightPointRamp& ramp, const EightPointConfig& c, int32_t target, int max_ticks = 2000000) {
  const uint64_t start_q32 = ramp.position_q32();
  ramp.set_position_target(target);
  const double travel = ramp.distance_to_target();  // the shorter way round the counter
  const double direction = travel >= 0 ? 1.0 : -1.0;
  MoveRun run;
  for (int tick = 0; tick < max_ticks; ++tick) {
    ramp.step(c, kDt);
    const double exact = static_cast<double>(static_cast<int64_t>(ramp.position_q32() - start_q32)) / 4294967296.0;
    run.samples.push_back({ramp.velocity(), ramp.acceleration(), ramp.position(), exact, ramp.segment()});
    run.max_speed = std::fmax(run.max_speed, std::fabs(ramp.velocity()));
    run.max_overshoot = std::fmax(run.max_overshoot, direction * (exact - travel));
    if (ramp.position_reached()) {
      run.ticks_to_arrive = tick + 1;
      break;
    }
  }
  return run;
}

// Acceleration between consecutive samples whose speeds both lie strictly inside (lo, hi).
struct Rates {
  double min = 1e300;
  double max = -1e300;
  int count = 0;
};
Rates rates_between(const MoveRun& run, double lo, double hi, bool rising) {
  Rates r;
  for (size_t i = 1; i < run.samples.size(); ++i) {
    const double a = std::fabs(run.samples[i - 1].velocity);
    const double b = std::fabs(run.samples[i].velocity);
    if (a <= lo || a >= hi || b <= lo || b >= hi || (b > a) != rising || a == b) continue;
    const double rate = std::fabs(b - a) / kDt;
    r.min = std::fmin(r.min, rate);
    r.max = std::fmax(r.max, rate);
    ++r.count;
  }
  return r;
}

void expect_rate(const Rates& r, double expected, const char* what) {
  EXPECT_GT(r.count, 10) << what;
  EXPECT_NEAR(r.min, expected, expected * kTolerance) << what;
  EXPECT_NEAR(r.max, expected, expected * kTolerance) << what;
}

TEST(EightPointRamp, phase_rates_measured_from_samples_follow_the_eight_points) {
  const auto c = profile();
  EightPointRamp ramp;
  const MoveRun run = run_move(ramp, c, 1000000);
  ASSERT_GT(run.ticks_to_arrive, 0);
  expect_rate(rates_between(run, c.vstart_pps, c.v1_pps, true), c.a1_pps2, "A1");
  expect_rate(rates_between(run, c.v1_pps, c.v2_pps, true), c.a2_pps2, "A2");
  expect_rate(rates_between(run, c.v2_pps, c.vmax_pps, true), c.amax_pps2, "AMAX");
  expect_rate(rates_between(run, c.v2_pps, c.vmax_pps, false), c.dmax_pps2, "DMAX");
  expect_rate(rates_between(run, c.v1_pps, c.v2_pps, false), c.d2_pps2, "D2");
  expect_rate(rates_between(run, c.vstop_pps, c.v1_pps, false), c.d1_pps2, "D1");
  // The first tick jumps to VSTART and accelerates with A1 from there.
  EXPECT_NEAR(run.samples[0].velocity, c.vstart_pps + c.a1_pps2 * kDt, 1e-6);
  EXPECT_EQ(run.samples[0].segment, Segment::kA1);
  // The last tick leaves at most VSTOP + one tick of D1 and lands exactly.
  const Sample& before_end = run.samples[run.samples.size() - 2];
  EXPECT_LE(before_end.velocity, c.vstop_pps + c.d1_pps2 * kDt + 1e-6);
  EXPECT_GE(before_end.velocity, c.vstop_pps);
  EXPECT_EQ(ramp.position(), 1000000);
  EXPECT_EQ(ramp.position_q32(), uint64_t{1000000} << 32);
  EXPECT_EQ(run.max_speed, c.vmax_pps);
  EXPECT_LE(run.max_overshoot, 0.0);
}

TEST(EightPointRamp, segment_labels_change_at_v1_and_v2) {
  const auto c = profile();
  EightPointRamp ramp;
  const MoveRun run = run_move(ramp, c, 1000000);
  ASSERT_GT(run.ticks_to_arrive, 0);
  // The band a tick starts in names it: A1 below V1, A2 below V2, AMAX above; DMAX above V2, D2
  // down to V1, D1 below.
  for (size_t i = 1; i + 1 < run.samples.size(); ++i) {
    const double v = run.samples[i - 1].velocity;
    const Segment s = run.samples[i].segment;
    const bool rising = run.samples[i].velocity > v;
    Segment expected = s;
    if (rising && v < c.v1_pps) expected = Segment::kA1;
    if (rising && v > c.v1_pps && v < c.v2_pps) expected = Segment::kA2;
    if (rising && v > c.v2_pps) expected = Segment::kAmax;
    if (!rising && v == run.samples[i].velocity) expected = Segment::kCruise;
    const bool falling = !rising && v > run.samples[i].velocity;
    if (falling && v > c.v2_pps + c.dmax_pps2 * kDt) expected = Segment::kDmax;
    if (falling && v < c.v2_pps && v > c.v1_pps + c.d2_pps2 * kDt) expected = Segment::kD2;
    if (falling && v < c.v1_pps) expected = Segment::kD1;
    EXPECT_EQ(s, expected) << v;
  }
}

TEST(EightPointRamp, time_to_vmax_and_total_time_match_the_formulas) {
  const auto c = profile();
  EightPointRamp ramp;
  const int32_t target = 1000000;
  const MoveRun run = run_move(ramp, c, target);
  ASSERT_GT(run.ticks_to_arrive, 0);
  int first_at_vmax = -1;
  for (size_t i = 0; i < run.samples.size(); ++i) {
    if (run.samples[i].velocity == c.vmax_pps) {
      first_at_vmax = static_cast<int>(i) + 1;
      break;
    }
  }
  const double t_up = (c.v1_pps - c.vstart_pps) / c.a1_pps2 + (c.v2_pps - c.v1_pps) / c.a2_pps2 +
                      (c.vmax_pps - c.v2_pps) / c.amax_pps2;
  EXPECT_NEAR(first_at_vmax * kDt, t_up, kDt);
  // Up: distance under the A bands; down: the stopping distance; in between: cruise at VMAX.
  const double up_distance = (c.v1_pps * c.v1_pps - c.vstart_pps * c.vstart_pps) / (2 * c.a1_pps2) +
                             (c.v2_pps * c.v2_pps - c.v1_pps * c.v1_pps) / (2 * c.a2_pps2) +
                             (c.vmax_pps * c.vmax_pps - c.v2_pps * c.v2_pps) / (2 * c.amax_pps2);
  const double down = stopping_distance(c, c.vmax_pps);
  const double t_down = (c.vmax_pps - c.v2_pps) / c.dmax_pps2 + (c.v2_pps - c.v1_pps) / c.d2_pps2 +
                        (c.v1_pps - c.vstop_pps) / c.d1_pps2;
  const double t_cruise = (target - up_distance - down) / c.vmax_pps;
  EXPECT_NEAR(run.ticks_to_arrive * kDt, t_up + t_cruise + t_down, 2 * kDt);
}

TEST(EightPointRamp, braking_starts_at_the_stopping_distance) {
  const auto c = profile();
  EightPointRamp ramp;
  const int32_t target = 1000000;
  const MoveRun run = run_move(ramp, c, target);
  ASSERT_GT(run.ticks_to_arrive, 0);
  // Position of the last sample at VMAX: braking begins within one tick of travel after it.
  double braking_from = -1;
  for (size_t i = 1; i < run.samples.size(); ++i) {
    if (run.samples[i - 1].velocity == c.vmax_pps && run.samples[i].velocity < c.vmax_pps) {
      braking_from = run.samples[i - 1].exact_position;
      break;
    }
  }
  const double expected = target - stopping_distance(c, c.vmax_pps);
  EXPECT_NEAR(braking_from, expected, c.vmax_pps * kDt + 1e-3);
  // Segment boundaries on the way down: positions where the speed passes V2 and V1.
  double at_v2 = -1, at_v1 = -1;
  for (size_t i = 1; i < run.samples.size(); ++i) {
    const double a = run.samples[i - 1].velocity, b = run.samples[i].velocity;
    if (b < a && a > c.v2_pps && b <= c.v2_pps) at_v2 = run.samples[i].exact_position;
    if (b < a && a > c.v1_pps && b <= c.v1_pps) at_v1 = run.samples[i].exact_position;
  }
  EXPECT_NEAR(at_v2, target - stopping_distance(c, c.v2_pps), c.v2_pps * kDt);
  EXPECT_NEAR(at_v1, target - stopping_distance(c, c.v1_pps), c.v1_pps * kDt);
}

TEST(EightPointRamp, arrives_exactly_without_overshoot_and_never_above_vmax) {
  for (const auto& c : {profile(), trapezoid()}) {
    for (auto [start, target] : {std::pair{0, 1}, {0, 7}, {0, 100}, {0, 1000}, {0, 12345}, {0, 90000},
                                 {500000, -250000}, {-3, 3}, {0, 2000000}, {INT32_MAX - 500, INT32_MIN + 500}}) {
      EightPointRamp ramp;
      ramp.set_position(start);
      const MoveRun run = run_move(ramp, c, target);
      EXPECT_GT(run.ticks_to_arrive, 0) << start << " -> " << target;
      EXPECT_EQ(ramp.position(), target) << start << " -> " << target;
      EXPECT_LE(run.max_overshoot, 0.0) << start << " -> " << target;
      EXPECT_LE(run.max_speed, c.vmax_pps) << start << " -> " << target;
      EXPECT_EQ(ramp.velocity(), 0.0);
      EXPECT_TRUE(ramp.velocity_reached());
    }
  }
}

TEST(EightPointRamp, wraps_the_short_way_round_the_32_bit_counter) {
  const auto c = profile();
  EightPointRamp ramp;
  ramp.set_position(INT32_MAX - 100);
  const MoveRun run = run_move(ramp, c, INT32_MIN + 100);
  ASSERT_GT(run.ticks_to_arrive, 0);
  EXPECT_GT(ramp.velocity(), -1.0);
  EXPECT_NEAR(run.samples.back().exact_position, 201.0, 1e-9);
  for (const Sample& s : run.samples) EXPECT_GE(s.velocity, 0.0);
}

TEST(EightPointRamp, trapezoid_when_v1_and_v2_are_zero) {
  const auto c = trapezoid();
  EightPointRamp ramp;
  const int32_t target = 600000;
  const MoveRun run = run_move(ramp, c, target);
  ASSERT_GT(run.ticks_to_arrive, 0);
  expect_rate(rates_between(run, c.vstart_pps, c.vmax_pps, true), c.amax_pps2, "AMAX");
  expect_rate(rates_between(run, c.vstop_pps, c.vmax_pps, false), c.dmax_pps2, "DMAX");
  for (const Sample& s : run.samples) {
    EXPECT_NE(s.segment, Segment::kA1);
    EXPECT_NE(s.segment, Segment::kA2);
    EXPECT_NE(s.segment, Segment::kD1);
    EXPECT_NE(s.segment, Segment::kD2);
  }
  const double up = (c.vmax_pps - c.vstart_pps) / c.amax_pps2;
  const double down = (c.vmax_pps - c.vstop_pps) / c.dmax_pps2;
  const double up_distance = (c.vmax_pps * c.vmax_pps - c.vstart_pps * c.vstart_pps) / (2 * c.amax_pps2);
  const double down_distance = (c.vmax_pps * c.vmax_pps - c.vstop_pps * c.vstop_pps) / (2 * c.dmax_pps2);
  EXPECT_NEAR(run.ticks_to_arrive * kDt, up + down + (target - up_distance - down_distance) / c.vmax_pps, 2 * kDt);
}

TEST(EightPointRamp, short_move_peaks_below_vmax_on_the_formula) {
  // Too short for VMAX: the peak is where the acceleration curve meets the braking curve.
  const auto c = trapezoid();
  EightPointRamp ramp;
  const int32_t target = 40000;
  const MoveRun run = run_move(ramp, c, target);
  ASSERT_GT(run.ticks_to_arrive, 0);
  // (vp² - vstart²)/(2 AMAX) + (vp² - vstop²)/(2 DMAX) = target
  const double a = c.amax_pps2, d = c.dmax_pps2;
  const double vp = std::sqrt((2 * target + c.vstart_pps * c.vstart_pps / a + c.vstop_pps * c.vstop_pps / d) /
                              (1 / a + 1 / d));
  ASSERT_LT(vp, c.vmax_pps);
  EXPECT_NEAR(run.max_speed, vp, a * kDt + d * kDt);
  EXPECT_EQ(ramp.position(), target);
}

TEST(EightPointRamp, tvmax_enforces_a_cruise_before_braking) {
  auto c = trapezoid();
  c.tvmax_us = 20000;  // 20 ms
  EightPointRamp ramp;
  const MoveRun run = run_move(ramp, c, 40000);  // too short for VMAX
  ASSERT_GT(run.ticks_to_arrive, 0);
  EXPECT_LT(run.max_speed, c.vmax_pps);
  int cruise_ticks = 0;
  for (size_t i = 1; i < run.samples.size(); ++i) {
    if (run.samples[i].velocity == run.samples[i - 1].velocity && run.samples[i].velocity == run.max_speed) {
      ++cruise_ticks;
    }
  }
  EXPECT_GE(cruise_ticks * kDt, 0.020 - 2 * kDt);
  EXPECT_LE(cruise_ticks * kDt, 0.020 + 3 * kDt);
  EXPECT_EQ(ramp.position(), 40000);
  EXPECT_LE(run.max_overshoot, 0.0);
  // The reduced cruise speed satisfies the formula: ramps + TVMAX at vp fill the distance.
  const double vp = run.max_speed;
  const double covered = (vp * vp - c.vstart_pps * c.vstart_pps) / (2 * c.amax_pps2) + vp * 0.020 +
                         (vp * vp - c.vstop_pps * c.vstop_pps) / (2 * c.dmax_pps2);
  EXPECT_NEAR(covered, 40000, vp * 3 * kDt);
}

TEST(EightPointRamp, tvmax_cruises_between_braking_and_accelerating_again) {
  auto c = trapezoid();
  c.tvmax_us = 10000;  // 10 ms
  EightPointRamp ramp;
  ramp.set_position_target(300000);
  while (!(ramp.segment() == Segment::kDmax && ramp.velocity() < 50000)) ramp.step(c, kDt);
  // A farther target while braking: hold the speed for TVMAX, then accelerate with AMAX.
  ramp.set_position_target(2000000);
  const double held = ramp.velocity();
  int cruise_ticks = 0;
  for (;;) {
    ramp.step(c, kDt);
    if (ramp.velocity() != held) break;
    ++cruise_ticks;
  }
  EXPECT_EQ(cruise_ticks, 200);
  EXPECT_NEAR((ramp.velocity() - held) / kDt, c.amax_pps2, c.amax_pps2 * kTolerance);
  while (!ramp.position_reached()) ramp.step(c, kDt);
  EXPECT_EQ(ramp.position(), 2000000);
}

// Fuzz finding (eight_point_ramp, 2026-11-27): a stop that ended a few Q32 units (1/2^32
// microstep) short of where the next target lay left a move of that fraction. TVMAX reduced its
// speed to what fills the fraction in TVMAX, about 1e-8 pps, which moves the counter by less than
// one Q32 unit a tick: rounded to nothing, for ever. The last fraction now goes without TVMAX.
TEST(EightPointRamp, tvmax_never_stalls_on_the_last_fraction_of_a_microstep) {
  EightPointConfig c;
  c.vmax_pps = 0.0179;
  c.amax_pps2 = 100000;
  c.dmax_pps2 = 100000;
  c.d2_pps2 = 100000;
  c.d1_pps2 = 100000;
  c.tvmax_us = 79929;
  for (const double stop_from_pps : {0.005, 0.0136, 0.02, 0.05}) {
    EightPointRamp ramp;
    ramp.set_state(0, stop_from_pps);
    ramp.stop();
    for (int i = 0; i < 100 && !ramp.standstill(); ++i) ramp.step(c, kDt);
    ASSERT_TRUE(ramp.standstill());
    ramp.set_position_target(ramp.position());  // the integer part: a fraction of a microstep behind
    ASSERT_LT(ramp.distance_to_target(), 0.0) << stop_from_pps;
    int ticks = 0;
    for (; ticks < 100000 && !ramp.position_reached(); ++ticks) ramp.step(c, kDt);
    EXPECT_TRUE(ramp.position_reached()) << "from " << stop_from_pps << " pps: " << ramp.distance_to_target()
                                         << " steps left at " << ramp.velocity() << " pps";
    EXPECT_EQ(ramp.position(), 0);
    EXPECT_LT(ticks, 100) << stop_from_pps;
  }
}

// hfuzz finding: with TVMAX, one tick of AMAX from rest already left no room for the cruise, so
// the ramp held its speed, 0 (VSTART 0), and a short move never started. Now VMAX is reduced to
// the speed whose TVMAX cruise fits: reached in the first tick, held TVMAX, braked with D1.
TEST(EightPointRamp, tvmax_short_move_from_rest_starts_and_arrives) {
  EightPointConfig c;
  c.a1_pps2 = 1e6;
  c.v1_pps = 50000;
  c.a2_pps2 = 1e6;
  c.v2_pps = 50000;
  c.vmax_pps = 50000;
  c.amax_pps2 = 1e6;
  c.dmax_pps2 = 1e6;
  c.d2_pps2 = 1e6;
  c.d1_pps2 = 236;
  c.tvmax_us = 7418;
  ASSERT_EQ(EightPointRamp::validate(c), EightPointConfigError::kNone);
  EightPointRamp ramp;
  const MoveRun run = run_move(ramp, c, 5, 20000);
  ASSERT_GT(run.ticks_to_arrive, 0) << "position " << ramp.position() << " velocity " << ramp.velocity();
  EXPECT_EQ(ramp.position(), 5);
  EXPECT_LE(run.max_overshoot, 0.0);
  // First tick: A1 from 0 to vp (within the tick), then vp; TVMAX at vp; D1 from vp to 0:
  // (1/(2 D1) - 1/(2 A1)) vp^2 + (TVMAX + dt) vp = 5 gives vp = 46.855 pps.
  const double qa = 1 / (2 * c.d1_pps2) - 1 / (2 * c.a1_pps2);
  const double qb = c.tvmax_us * 1e-6 + kDt;
  const double vp = (-qb + std::sqrt(qb * qb + 4 * qa * 5)) / (2 * qa);
  EXPECT_NEAR(vp, 46.855, 0.001);
  EXPECT_NEAR(run.samples[0].velocity, vp, 1e-6);
  EXPECT_NEAR(run.max_speed, vp, 1e-6);
  int cruise_ticks = 0;
  while (cruise_ticks + 1 < static_cast<int>(run.samples.size()) && run.samples[cruise_ticks + 1].velocity == run.samples[0].velocity) {
    ++cruise_ticks;
  }
  EXPECT_GE(cruise_ticks * kDt, 0.007418 - kDt);
  EXPECT_LE(cruise_ticks * kDt, 0.007418 + 2 * kDt);
  // Braking from vp with D1 takes vp / D1 = 198 ms.
  EXPECT_NEAR(run.ticks_to_arrive * kDt, vp / c.d1_pps2 + 0.007418, 3 * kDt);
}

TEST(EightPointRamp, tzerowait_holds_rest_before_the_next_move) {
  auto c = profile();
  c.tzerowait_us = 32 * 3125;  // 2015 = 3125: 100 ms
  EightPointRamp ramp;
  ASSERT_GT(run_move(ramp, c, 20000).ticks_to_arrive, 0);
  EXPECT_TRUE(ramp.waiting());
  ramp.set_position_target(0);
  int rest_ticks = 0;
  while (ramp.velocity() == 0.0 && rest_ticks < 100000) {
    ramp.step(c, kDt);
    ++rest_ticks;
  }
  // 2000 ticks of rest, the move back starts in the next.
  EXPECT_EQ(rest_ticks, 2001);
  EXPECT_LT(ramp.velocity(), 0.0);
}

TEST(EightPointRamp, overshoot_after_a_closer_target_stops_waits_and_comes_back) {
  auto c = profile();
  c.tzerowait_us = 32000;  // 32 ms
  EightPointRamp ramp;
  ramp.set_position_target(1000000);
  while (ramp.velocity() < c.vmax_pps) ramp.step(c, kDt);
  const double here = ramp.position();
  // Far too close to stop: brakes through DMAX/D2/D1, overshoots by about the stopping distance.
  const int32_t target = static_cast<int32_t>(here + 1000);
  ramp.set_position_target(target);
  double furthest = here;
  int rest_ticks = 0;
  bool came_back = false;
  for (int i = 0; i < 400000 && !ramp.position_reached(); ++i) {
    ramp.step(c, kDt);
    furthest = std::fmax(furthest, ramp.position());
    if (ramp.velocity() == 0.0 && !came_back) ++rest_ticks;
    if (ramp.velocity() < 0.0) came_back = true;
  }
  EXPECT_TRUE(ramp.position_reached());
  EXPECT_EQ(ramp.position(), target);
  EXPECT_TRUE(came_back);
  EXPECT_NEAR(furthest - here, stopping_distance(c, c.vmax_pps) - 0.0, c.vmax_pps * 2 * kDt + 
              c.vstop_pps * c.vstop_pps / (2 * c.d1_pps2));
  EXPECT_EQ(rest_ticks, 640 + 1);  // the tick it stops in, then 32 ms of rest
}

TEST(EightPointRamp, farther_target_during_the_move_continues_without_stopping) {
  const auto c = profile();
  EightPointRamp ramp;
  ramp.set_position_target(50000);
  for (int i = 0; i < 3000; ++i) ramp.step(c, kDt);
  ASSERT_GT(ramp.velocity(), 0.0);
  const MoveRun run = run_move(ramp, c, 300000);
  ASSERT_GT(run.ticks_to_arrive, 0);
  EXPECT_EQ(ramp.position(), 300000);
  EXPECT_LE(run.max_overshoot, 0.0);
  for (size_t i = 0; i + 1 < run.samples.size(); ++i) EXPECT_GT(run.samples[i].velocity, 0.0);
}

TEST(EightPointRamp, closer_reachable_target_during_the_move_arrives_without_overshoot) {
  const auto c = profile();
  EightPointRamp ramp;
  ramp.set_position_target(1000000);
  for (int i = 0; i < 4000; ++i) ramp.step(c, kDt);
  const double v = ramp.velocity();
  const int32_t target = ramp.position() + static_cast<int32_t>(stopping_distance(c, v) * 1.5);
  const MoveRun run = run_move(ramp, c, target);
  ASSERT_GT(run.ticks_to_arrive, 0);
  EXPECT_EQ(ramp.position(), target);
  EXPECT_LE(run.max_overshoot, 0.0);
  // No deceleration beyond the profile's steepest band (D2) plus the join.
  for (size_t i = 1; i < run.samples.size() - 1; ++i) {
    EXPECT_LE(run.samples[i - 1].velocity - run.samples[i].velocity, c.d2_pps2 * kDt * (1 + 1e-6));
  }
}

TEST(EightPointRamp, target_behind_the_axis_reverses_after_braking) {
  const auto c = profile();
  EightPointRamp ramp;
  ramp.set_position_target(1000000);
  for (int i = 0; i < 3000; ++i) ramp.step(c, kDt);
  const MoveRun run = run_move(ramp, c, -5000);
  ASSERT_GT(run.ticks_to_arrive, 0);
  EXPECT_EQ(ramp.position(), -5000);
  expect_rate(rates_between(run, c.v1_pps, c.v2_pps, false), c.d2_pps2, "D2 while braking the wrong way");
}

TEST(EightPointRamp, lower_vmax_during_the_move_decelerates_with_the_d_bands) {
  auto c = profile();
  EightPointRamp ramp;
  ramp.set_position_target(2000000);
  while (ramp.velocity() < c.vmax_pps) ramp.step(c, kDt);
  c.vmax_pps = 40000;
  double previous = ramp.velocity();
  int ticks_above = 0;
  for (int i = 0; i < 2000000 && !ramp.position_reached(); ++i) {
    ramp.step(c, kDt);
    const double v = ramp.velocity();
    if (previous > c.v2_pps + c.dmax_pps2 * kDt && v < previous) {
      EXPECT_NEAR((previous - v) / kDt, c.dmax_pps2, c.dmax_pps2 * kTolerance);
    }
    if (v > c.vmax_pps) ++ticks_above;
    previous = v;
  }
  // (100000 - 60000) / DMAX + (60000 - 40000) / D2 = 311 ms
  EXPECT_NEAR(ticks_above * kDt, (100000.0 - 60000) / c.dmax_pps2 + (60000.0 - 40000) / c.d2_pps2, 2 * kDt);
  EXPECT_EQ(ramp.position(), 2000000);
}

TEST(EightPointRamp, rate_changes_during_the_move_take_effect_at_once) {
  auto c = profile();
  EightPointRamp ramp;
  ramp.set_position_target(1500000);
  while (ramp.velocity() < c.v2_pps + 5000) ramp.step(c, kDt);
  // AMAX doubled while accelerating above V2: the next tick uses it.
  c.amax_pps2 *= 2;
  double before = ramp.velocity();
  ramp.step(c, kDt);
  EXPECT_NEAR((ramp.velocity() - before) / kDt, c.amax_pps2, c.amax_pps2 * kTolerance);
  while (ramp.velocity() < c.vmax_pps) ramp.step(c, kDt);
  // DMAX halved while cruising: braking starts earlier, at the new stopping distance.
  c.dmax_pps2 /= 2;
  double braking_from = 0;
  while (!ramp.position_reached()) {
    before = ramp.velocity();
    const double here = static_cast<double>(ramp.position_q32()) / 4294967296.0;
    ramp.step(c, kDt);
    if (braking_from == 0 && ramp.velocity() < before) braking_from = here;
    ASSERT_LE(static_cast<double>(ramp.position_q32()) / 4294967296.0, 1500000.0);
  }
  EXPECT_NEAR(braking_from, 1500000 - stopping_distance(c, c.vmax_pps), c.vmax_pps * kDt + 1e-3);
  EXPECT_EQ(ramp.position(), 1500000);
}

TEST(EightPointRamp, velocity_mode_uses_vstart_amax_both_ways_and_vstop) {
  const auto c = profile();
  EightPointRamp ramp;
  ramp.set_velocity_target(80000);
  ramp.step(c, kDt);
  EXPECT_NEAR(ramp.velocity(), c.vstart_pps + c.amax_pps2 * kDt, 1e-6);  // no A1 in pv
  int ticks = 1;
  while (!ramp.velocity_reached() && ticks < 100000) {
    ramp.step(c, kDt);
    ++ticks;
  }
  EXPECT_EQ(ramp.velocity(), 80000);
  EXPECT_NEAR(ticks * kDt, (80000 - c.vstart_pps) / c.amax_pps2, kDt);
  // Down to 30000 with AMAX (the deceleration parameters are not used in pv).
  ramp.set_velocity_target(30000);
  ramp.step(c, kDt);
  EXPECT_NEAR(ramp.velocity(), 80000 - c.amax_pps2 * kDt, 1e-6);
  EXPECT_FALSE(ramp.velocity_reached());
  // Beyond VMAX: bounded.
  ramp.set_velocity_target(1e9);
  for (int i = 0; i < 20000; ++i) ramp.step(c, kDt);
  EXPECT_EQ(ramp.velocity(), c.vmax_pps);
  EXPECT_TRUE(ramp.velocity_reached());
}

TEST(EightPointRamp, velocity_reversal_drops_at_vstop_and_waits_tzerowait) {
  auto c = profile();
  c.tzerowait_us = 32 * 625;  // 20 ms
  EightPointRamp ramp;
  ramp.set_velocity_target(10000);
  for (int i = 0; i < 2000; ++i) ramp.step(c, kDt);
  ASSERT_EQ(ramp.velocity(), 10000);
  ramp.set_velocity_target(-10000);
  double last_moving = 0;
  int ticks = 0;
  while (ramp.velocity() > 0.0) {
    last_moving = ramp.velocity();
    ramp.step(c, kDt);
    ++ticks;
  }
  EXPECT_GT(last_moving, c.vstop_pps);  // the drop to 0 happens from VSTOP or below
  EXPECT_LE(last_moving, c.vstop_pps + c.amax_pps2 * kDt + 1e-6);
  int rest = 0;
  while (ramp.velocity() == 0.0 && rest < 100000) {
    ramp.step(c, kDt);
    ++rest;
  }
  EXPECT_EQ(rest, 400 + 1);
  EXPECT_NEAR(ramp.velocity(), -(c.vstart_pps + c.amax_pps2 * kDt), 1e-6);
}

TEST(EightPointRamp, quick_stop_with_given_deceleration_stops_at_its_distance) {
  const auto c = profile();
  EightPointRamp ramp;
  ramp.set_position_target(5000000);
  while (ramp.velocity() < c.vmax_pps) ramp.step(c, kDt);
  const double from = static_cast<double>(ramp.position_q32()) / 4294967296.0;
  const double quick_stop_pps2 = 1000000;  // 6085
  ramp.stop(quick_stop_pps2);
  int ticks = 0;
  while (ramp.velocity() != 0.0 && ticks < 100000) {
    ramp.step(c, kDt);
    ++ticks;
    if (ramp.velocity() > c.vstop_pps) {
      EXPECT_EQ(ramp.segment(), Segment::kStopRamp);
    }
  }
  const double travelled = static_cast<double>(ramp.position_q32()) / 4294967296.0 - from;
  const double v = c.vmax_pps, vs = c.vstop_pps;
  EXPECT_NEAR(travelled, (v * v - vs * vs) / (2 * quick_stop_pps2), vs * kDt + 1.0);
  EXPECT_NEAR(ticks * kDt, (v - vs) / quick_stop_pps2, kDt);
  EXPECT_TRUE(ramp.velocity_reached());
  EXPECT_FALSE(ramp.position_reached());
  for (int i = 0; i < 100; ++i) ramp.step(c, kDt);  // stays stopped
  EXPECT_EQ(ramp.velocity(), 0.0);
}

TEST(EightPointRamp, profile_stop_brakes_through_the_d_bands) {
  const auto c = profile();
  EightPointRamp ramp;
  ramp.set_position_target(5000000);
  while (ramp.velocity() < c.vmax_pps) ramp.step(c, kDt);
  const double from = static_cast<double>(ramp.position_q32()) / 4294967296.0;
  ramp.stop();
  while (ramp.velocity() != 0.0) ramp.step(c, kDt);
  const double travelled = static_cast<double>(ramp.position_q32()) / 4294967296.0 - from;
  EXPECT_NEAR(travelled, stopping_distance(c, c.vmax_pps), c.vstop_pps * kDt + 1.0);
}

TEST(EightPointRamp, set_position_and_halt_keep_the_axis_still) {
  const auto c = profile();
  EightPointRamp ramp;
  ramp.set_position_target(0);
  ramp.set_position(12345);
  EXPECT_EQ(ramp.target_position(), 12345);
  ramp.step(c, kDt);
  EXPECT_TRUE(ramp.position_reached());
  ramp.set_velocity_target(50000);
  for (int i = 0; i < 100; ++i) ramp.step(c, kDt);
  ramp.halt();
  EXPECT_EQ(ramp.velocity(), 0.0);
  const int32_t here = ramp.position();
  ramp.step(c, kDt);
  EXPECT_EQ(ramp.position(), here);
  EXPECT_FALSE(ramp.waiting());
}

TEST(EightPointRamp, set_state_takes_over_a_moving_axis_without_a_jump) {
  const auto c = profile();
  EightPointRamp ramp;
  ramp.set_position_target(400000);
  ramp.set_state(100000, 50000);
  ramp.step(c, kDt);
  EXPECT_NEAR(ramp.velocity(), 50000 + c.a2_pps2 * kDt, 1e-6);
  const MoveRun run = run_move(ramp, c, 400000);
  EXPECT_GT(run.ticks_to_arrive, 0);
  EXPECT_EQ(ramp.position(), 400000);
}

TEST(EightPointRamp, validate_refuses_invalid_settings) {
  using E = EightPointConfigError;
  EXPECT_EQ(EightPointRamp::validate(profile()), E::kNone);
  EXPECT_EQ(EightPointRamp::validate(trapezoid()), E::kNone);
  auto with = [](auto change) {
    auto c = profile();
    change(c);
    return c;
  };
  EXPECT_EQ(EightPointRamp::validate(with([](auto& c) { c.a1_pps2 = -1; })), E::kNegativeOrNan);
  EXPECT_EQ(EightPointRamp::validate(with([](auto& c) { c.vmax_pps = NAN; })), E::kNegativeOrNan);
  EXPECT_EQ(EightPointRamp::validate(with([](auto& c) { c.amax_pps2 = 0; })), E::kZeroAmax);
  EXPECT_EQ(EightPointRamp::validate(with([](auto& c) { c.dmax_pps2 = 0; })), E::kZeroDmax);
  EXPECT_EQ(EightPointRamp::validate(with([](auto& c) { c.d1_pps2 = 0; })), E::kZeroD1);
  EXPECT_EQ(EightPointRamp::validate(with([](auto& c) { c.d2_pps2 = 0; })), E::kZeroD2);
  // Manual 1.5: D1 and D2 must not be 0 even for the trapezoid.
  EXPECT_EQ(EightPointRamp::validate(with([](auto& c) { c.v1_pps = c.v2_pps = 0; c.d1_pps2 = 0; })), E::kZeroD1);
  EXPECT_EQ(EightPointRamp::validate(with([](auto& c) { c.a1_pps2 = 0; })), E::kZeroA1);
  EXPECT_EQ(EightPointRamp::validate(with([](auto& c) { c.a2_pps2 = 0; })), E::kZeroA2);
  EXPECT_EQ(EightPointRamp::validate(with([](auto& c) { c.v1_pps = 0; c.a1_pps2 = 0; })), E::kNone);
  EXPECT_EQ(EightPointRamp::validate(with([](auto& c) { c.v1_pps = 70000; })), E::kV1AboveV2);
  EXPECT_EQ(EightPointRamp::validate(with([](auto& c) { c.v2_pps = 0; c.v1_pps = 70000; })), E::kNone);
  EXPECT_EQ(EightPointRamp::validate(with([](auto& c) { c.vstop_pps = 100; })), E::kVstopBelowVstart);
  // Velocity mode needs only AMAX (and no negative values).
  EXPECT_EQ(EightPointRamp::validate(with([](auto& c) { c.vstop_pps = 100; c.d1_pps2 = 0; }), Mode::kVelocity),
            E::kNone);
  EXPECT_EQ(EightPointRamp::validate(with([](auto& c) { c.amax_pps2 = 0; }), Mode::kVelocity), E::kZeroAmax);
}

TEST(EightPointRamp, random_profiles_and_target_changes_always_end_exactly_on_the_target) {
  // A seeded linear congruential generator: the same sequence on every run.
  uint64_t state = 12345;
  auto uniform = [&state](double lo, double hi) {
    state = state * 6364136223846793005ULL + 1442695040888963407ULL;
    return lo + (hi - lo) * static_cast<double>(state >> 11) / 9007199254740992.0;
  };
  for (int trial = 0; trial < 60; ++trial) {
    EightPointConfig c;
    c.vstart_pps = trial % 3 == 0 ? 0.0 : uniform(0, 2000);
    c.vstop_pps = c.vstart_pps + (trial % 4 == 0 ? 0.0 : uniform(0, 3000));
    c.v1_pps = trial % 5 == 0 ? 0.0 : uniform(1000, 30000);
    c.v2_pps = trial % 7 == 0 ? 0.0 : c.v1_pps + uniform(0, 50000);
    c.vmax_pps = uniform(500, 150000);
    c.a1_pps2 = uniform(1e4, 1e6);
    c.a2_pps2 = uniform(1e4, 1e6);
    c.amax_pps2 = uniform(1e4, 1e6);
    c.dmax_pps2 = uniform(1e4, 1e6);
    c.d2_pps2 = uniform(1e4, 1e6);
    c.d1_pps2 = uniform(1e4, 1e6);
    c.tzerowait_us = trial % 2 == 0 ? 0u : static_cast<uint32_t>(uniform(0, 5000));
    c.tvmax_us = trial % 3 == 1 ? static_cast<uint32_t>(uniform(0, 20000)) : 0u;
    ASSERT_EQ(EightPointRamp::validate(c), EightPointConfigError::kNone) << trial;
    const double steepest = std::fmax(std::fmax(std::fmax(c.a1_pps2, c.a2_pps2), std::fmax(c.amax_pps2, c.dmax_pps2)),
                                      std::fmax(c.d1_pps2, c.d2_pps2));
    EightPointRamp ramp;
    double previous = 0.0;
    // Apart from the jumps at VSTART and VSTOP, no tick changes the velocity faster than the
    // steepest segment.
    auto check_rate = [&] {
      const double v = ramp.velocity();
      if (previous != 0.0 && v != 0.0) {
        ASSERT_LE(std::fabs(v - previous), steepest * kDt * (1 + 1e-6)) << trial;
      }
      previous = v;
    };
    int32_t target = 0;
    for (int change = 0; change < 4; ++change) {
      target = static_cast<int32_t>(uniform(-300000, 300000));
      ramp.set_position_target(target);
      const int ticks = static_cast<int>(uniform(0, 20000));
      for (int i = 0; i < ticks; ++i) {
        ramp.step(c, kDt);
        ASSERT_LE(std::fabs(ramp.velocity()), c.vmax_pps) << trial;
        check_rate();
      }
    }
    int i = 0;
    for (; i < 4000000 && !ramp.position_reached(); ++i) {
      ramp.step(c, kDt);
      ASSERT_LE(std::fabs(ramp.velocity()), c.vmax_pps) << trial;
      check_rate();
    }
    EXPECT_TRUE(ramp.position_reached()) << trial;
    EXPECT_EQ(ramp.position(), target) << trial;
  }
}

TEST(EightPointRamp, vmax_zero_does_not_move) {
  auto c = profile();
  c.vmax_pps = 0;
  EightPointRamp ramp;
  ramp.set_position_target(1000);
  for (int i = 0; i < 100; ++i) ramp.step(c, kDt);
  EXPECT_EQ(ramp.position(), 0);
  EXPECT_EQ(ramp.velocity(), 0.0);
  EXPECT_FALSE(ramp.position_reached());
}

// Fuzz finding (campaign 2026-11-27): the last tick of a move ended a Q32 unit past the target,
// one count at 50 µs. The braking curve's ticks were rounded to the nearest Q32 unit, half a unit
// ahead of the curve at worst; near the end of the curve (a slow D1, speeds below 1 pps) that half
// unit is worth more speed than the join allows, the "too fast" branch braked a full tick and
// passed the target. Now the ticks round towards the start. The stops before the moves leave the
// counter at a fraction of a microstep; the first five pairs failed before the change.
TEST(EightPointRamp, a_move_never_passes_its_target_by_a_rounding_error) {
  EightPointConfig c;  // the finding's profile, as the fuzz target printed it
  c.a1_pps2 = 490781768;
  c.v1_pps = 75294.117647058825;
  c.a2_pps2 = 770809.75629021134;
  c.v2_pps = 6481098.5662625171;
  c.vmax_pps = 99.999998527355302;
  c.amax_pps2 = 9832.5771400182803;
  c.dmax_pps2 = 5765.8905162958781;
  c.d2_pps2 = 133679.6875;
  c.d1_pps2 = 5257.5908172753498;
  ASSERT_EQ(EightPointRamp::validate(c), EightPointConfigError::kNone);
  struct Case {
    double stop_from_pps;
    int distance;
  };
  const Case cases[] = {{19.463741722093541, 516}, {66.140244637144988, 1108}, {69.625668723979587, 813},
                        {53.381854310952598, 127}, {3.2650774763871868, 1099}, {0.0, 1},
                        {99.0, 2},                 {41.0, 57},                 {7.5, 300}};
  for (const Case& test_case : cases) {
    EightPointRamp ramp;
    ramp.set_state(0, test_case.stop_from_pps);
    ramp.stop();
    for (int i = 0; i < 100000 && !ramp.standstill(); ++i) ramp.step(c, kDt);
    ASSERT_TRUE(ramp.standstill());
    ramp.set_position_target(ramp.position() + test_case.distance);
    int ticks = 0;
    for (; ticks < 400000 && !ramp.position_reached(); ++ticks) {
      ramp.step(c, kDt);
      ASSERT_GE(ramp.distance_to_target(), 0.0) << "stop from " << test_case.stop_from_pps << " pps, move of "
                                                << test_case.distance << ": past the target after " << ticks
                                                << " ticks at " << ramp.velocity() << " pps";
    }
    EXPECT_TRUE(ramp.position_reached()) << test_case.stop_from_pps << " " << test_case.distance;
  }
}


// Fuzz finding (2026-11-27): in a long tick (10 ms) the braking of the "too fast" branch passed
// DMAX, D2 and D1 down to VSTOP in 7 ms and went on at VSTOP for the rest of the tick, 299 µsteps
// past the target. An axis that can brake to VSTOP before the target ends such a tick on it.
TEST(EightPointRamp, a_long_tick_that_brakes_to_vstop_early_ends_on_the_target) {
  EightPointConfig c;  // the finding's profile
  c.vstart_pps = 77.538749661181868;
  c.a1_pps2 = 724249388;
  c.v1_pps = 118014.70588235294;
  c.a2_pps2 = 724249388;
  c.v2_pps = 2829099;
  c.vmax_pps = 5027013;
  c.amax_pps2 = 334915783;
  c.dmax_pps2 = 334901894;
  c.d2_pps2 = 696112742;
  c.d1_pps2 = 38844297.275056563;
  c.vstop_pps = 107810;
  c.tzerowait_us = 1515520;
  ASSERT_EQ(EightPointRamp::validate(c), EightPointConfigError::kNone);
  EightPointRamp ramp;
  ramp.set_position_target(-502338288);
  int ticks = 0;
  for (; ticks < 20000 && !ramp.position_reached(); ++ticks) {
    ramp.step(c, 0.01);
    ASSERT_LE(ramp.distance_to_target(), 0.0) << "past the target after " << ticks << " ticks at "
                                              << ramp.velocity() << " pps";
  }
  EXPECT_TRUE(ramp.position_reached());
  EXPECT_LT(ticks, 10000);  // arrived in one go: no overshoot, TZEROWAIT and move back
}

// Fuzz finding (2026-11-27): a profile changed to VMAX 0 while moving at -400 pps brakes at DMAX
// (100000 pps², 100 pps per 1 ms tick); the last tick's 100 - 100000 * 0.001 rounded to
// -3.6e-15, and the axis turned to +3.6e-15 pps: a reversal without rest. Every band step now
// ends on its bound at the latest.
TEST(EightPointRamp, braking_to_rest_never_rounds_past_zero_into_a_reversal) {
  EightPointConfig c;  // the finding's profile
  c.vstart_pps = 25.882352941176475;
  c.a1_pps2 = 2588.9764705882353;
  c.v1_pps = 25.837057789014956;
  c.a2_pps2 = 303089162.27157789;
  c.v2_pps = 45.116824258591492;
  c.vmax_pps = 0;
  c.amax_pps2 = 100000;
  c.dmax_pps2 = 100000;
  c.d2_pps2 = 100000;
  c.d1_pps2 = 100000;
  c.vstop_pps = 44613.65922469693;
  c.tzerowait_us = 0;
  ASSERT_EQ(EightPointRamp::validate(c), EightPointConfigError::kNone);
  // From -400 pps, 100 pps per tick: at rest after the 4th tick, never above 0 on the way.
  auto brakes_to_rest = [&c](EightPointRamp& ramp, const char* what) {
    for (int tick = 1; tick <= 5; ++tick) {
      ramp.step(c, 0.001);
      EXPECT_LE(ramp.velocity(), 0.0) << what << ", tick " << tick;
    }
    EXPECT_EQ(ramp.velocity(), 0.0) << what;
  };
  EightPointRamp position;  // VMAX 0: brakes at DMAX and stays at rest
  position.set_state(0, -400.0);
  position.set_position_target(-1145196883);
  brakes_to_rest(position, "position mode");
  // The same in velocity mode and in a stop: the last step lands on the goal, not past it.
  EightPointRamp pv;
  pv.set_state(0, -400.0);
  pv.set_velocity_target(0.0);
  brakes_to_rest(pv, "pv");
  EightPointRamp stop;
  stop.set_state(0, -400.0);
  stop.stop(100000);
  brakes_to_rest(stop, "stop");
}

}  // namespace
}  // namespace motwin::motion
