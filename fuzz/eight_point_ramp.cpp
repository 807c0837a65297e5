// The TMCM-3216's EightPoint ramp generator (src/core/motion/eight_point_ramp.*): a random
// profile (only one validate() accepts runs; one it refuses must hold a negative, NaN or zero
// value the rules name), then random position and velocity targets, stops, halts, profile
// changes and counter changes with ticks in between, and at the end one position move from rest.
//
// Invariants, every tick:
// - velocity, acceleration and position are finite;
// - the speed never rises above VMAX (it may be above it only while coming down from a higher
//   one after VMAX was lowered or a moving axis was taken over), and a stop never speeds up;
// - the direction never flips without a tick at rest (reversals pass 0 and TZEROWAIT);
// - apart from the VSTART jump and the drop to 0 from VSTOP, no tick changes the speed faster
//   than the steepest rate of the profile (plus the stop's deceleration);
// - a drop to 0 happens only from VSTOP/VSTART plus one tick of the steepest rate;
// and at the end: a position move from rest ends exactly on the integer target, at rest, without
// overshoot (at every tick length), within the time the profile allows (cruise + ramps +
// TZEROWAIT + TVMAX, with slack).
#include <fuzzer/FuzzedDataProvider.h>

#include <algorithm>
#include <cmath>
#include <cstddef>
#include <cstdint>
#include <cstdio>
#include <cstdlib>
#include <limits>

#include "core/motion/eight_point_ramp.h"
#include "fuzz_support.h"

namespace {

// Tick budgets of one input (fuzz/README.md, Decisions): the random phase runs at most
// kRandomPhaseTicks, at most kTicksPerOperation after each operation; the final stop and move
// are skipped when their bound exceeds kStopBoundTicks / kMoveBoundTicks, and the final move's
// distance is drawn so that it fits kMoveBudgetTicks at the profile's speeds.
constexpr int kRandomPhaseTicks = 4'000;
constexpr int kTicksPerOperation = 300;
constexpr double kStopBoundTicks = 60'000;  // TZEROWAIT's longest (2.1 s) at 50 µs fits
constexpr double kMoveBudgetTicks = 20'000;
constexpr double kMoveBoundTicks = 2 * kMoveBudgetTicks;

using motwin::motion::EightPointConfig;
using motwin::motion::EightPointConfigError;
using motwin::motion::EightPointRamp;
using Mode = EightPointRamp::Mode;

// Speeds and rates spread over the decades a user can set (the TMC5160's VMAX is about 6e6 pps
// at 12 MHz; accelerations from a crawl to a jerk).
double speed(FuzzedDataProvider& in) {
  switch (in.ConsumeIntegralInRange<int>(0, 4)) {
    case 0: return 0.0;
    case 1: return in.ConsumeFloatingPointInRange<double>(0.0, 100.0);
    case 2: return in.ConsumeFloatingPointInRange<double>(0.0, 1e5);
    case 3: return static_cast<double>(in.ConsumeIntegralInRange<int32_t>(0, 8'000'000));
    default: return in.ConsumeFloatingPointInRange<double>(0.0, 8e6);
  }
}

double rate(FuzzedDataProvider& in) {
  switch (in.ConsumeIntegralInRange<int>(0, 4)) {
    case 0: return 0.0;
    case 1: return in.ConsumeFloatingPointInRange<double>(1.0, 1e4);
    case 2: return in.ConsumeFloatingPointInRange<double>(1e3, 1e6);
    case 3: return static_cast<double>(in.ConsumeIntegralInRange<int32_t>(1, 1'000'000'000));
    default: return in.ConsumeFloatingPointInRange<double>(1e5, 1e9);
  }
}

EightPointConfig random_config(FuzzedDataProvider& in) {
  EightPointConfig c;
  c.vstart_pps = speed(in);
  c.a1_pps2 = rate(in);
  c.v1_pps = speed(in);
  c.a2_pps2 = rate(in);
  c.v2_pps = speed(in);
  c.vmax_pps = speed(in);
  c.amax_pps2 = rate(in);
  c.dmax_pps2 = rate(in);
  c.d2_pps2 = rate(in);
  c.d1_pps2 = rate(in);
  c.vstop_pps = speed(in);
  // Mostly repaired towards the rules, so that most profiles run; sometimes left as they came.
  if (in.ConsumeIntegralInRange<int>(0, 7) != 0) {
    if (c.v1_pps > c.v2_pps && c.v2_pps > 0.0) std::swap(c.v1_pps, c.v2_pps);
    if (c.vstop_pps < c.vstart_pps) std::swap(c.vstart_pps, c.vstop_pps);
    for (double* r : {&c.amax_pps2, &c.dmax_pps2, &c.d1_pps2, &c.d2_pps2, &c.a1_pps2, &c.a2_pps2}) {
      if (*r == 0.0) *r = 1e5;
    }
  }
  // 2015 is 16 bits of 32 µs (up to 2.1 s, 42 000 ticks of 50 µs: mostly shorter, as every
  // reversal and stop rests it out within the tick budget); TVMAX has no object (0) but the
  // class takes any.
  switch (in.ConsumeIntegralInRange<int>(0, 7)) {
    case 0: case 1: case 2: case 3: c.tzerowait_us = 0; break;
    case 7: c.tzerowait_us = 32u * in.ConsumeIntegral<uint16_t>(); break;
    default: c.tzerowait_us = 32u * in.ConsumeIntegral<uint8_t>(); break;
  }
  c.tvmax_us = in.ConsumeIntegralInRange<int>(0, 3) == 0 ? in.ConsumeIntegralInRange<uint32_t>(0, 100'000) : 0u;
  if (in.ConsumeIntegralInRange<int>(0, 31) == 0) {  // what a broken caller might pass
    double* values[] = {&c.vstart_pps, &c.a1_pps2, &c.v1_pps, &c.a2_pps2, &c.v2_pps, &c.vmax_pps,
                        &c.amax_pps2,  &c.dmax_pps2, &c.d2_pps2, &c.d1_pps2, &c.vstop_pps};
    *values[in.ConsumeIntegralInRange<size_t>(0, 10)] =
        in.ConsumeBool() ? std::numeric_limits<double>::quiet_NaN() : -in.ConsumeFloatingPointInRange<double>(1e-9, 1e6);
  }
  return c;
}

// The refusal names a rule the profile breaks.
void check_refusal(const EightPointConfig& c, EightPointConfigError error) {
  using E = EightPointConfigError;
  bool broken = false;
  switch (error) {
    case E::kNone: return;
    case E::kNegativeOrNan:
      for (double v : {c.vstart_pps, c.a1_pps2, c.v1_pps, c.a2_pps2, c.v2_pps, c.vmax_pps, c.amax_pps2, c.dmax_pps2,
                       c.d2_pps2, c.d1_pps2, c.vstop_pps}) {
        broken = broken || !(v >= 0.0);
      }
      break;
    case E::kZeroAmax: broken = c.amax_pps2 == 0.0; break;
    case E::kZeroDmax: broken = c.dmax_pps2 == 0.0; break;
    case E::kZeroD1: broken = c.d1_pps2 == 0.0; break;
    case E::kZeroD2: broken = c.d2_pps2 == 0.0; break;
    case E::kZeroA1: broken = c.v1_pps > 0.0 && c.a1_pps2 == 0.0; break;
    case E::kZeroA2: broken = c.v2_pps > 0.0 && c.a2_pps2 == 0.0; break;
    case E::kV1AboveV2: broken = c.v1_pps > 0.0 && c.v2_pps > 0.0 && c.v1_pps > c.v2_pps; break;
    case E::kVstopBelowVstart: broken = c.vstop_pps < c.vstart_pps; break;
  }
  FUZZ_CHECK(broken, "validate() refused with %d a profile that keeps that rule", static_cast<int>(error));
}

// Written out rather than looped over a list: it runs every tick.
double steepest_rate(const EightPointConfig& c) {
  return std::fmax(std::fmax(std::fmax(0.0, std::fmax(c.a1_pps2, c.a2_pps2)), std::fmax(c.amax_pps2, c.dmax_pps2)),
                   std::fmax(c.d2_pps2, c.d1_pps2));
}

struct Checker {
  EightPointRamp& ramp;
  double previous_velocity = 0.0;  // of the last tick (or as halt()/set_state() left it)
  double stop_rate_pps2 = 0.0;  // the deceleration given to the last stop()
  // steepest_rate() of the profile: set by use() wherever the input changes the profile (the
  // only places it changes), not recomputed every tick.
  double steepest_pps2 = 0.0;

  void use(const EightPointConfig& c) { steepest_pps2 = steepest_rate(c); }

  void tick(const EightPointConfig& c, double dt_s) {
    const Mode mode = ramp.mode();
    ramp.step(c, dt_s);
    const double v = ramp.velocity();
    const double before = std::fabs(previous_velocity);
    const double now = std::fabs(v);
    FUZZ_CHECK(std::isfinite(v) && std::isfinite(ramp.acceleration()) && std::isfinite(ramp.distance_to_target()),
               "velocity %g, acceleration %g", v, ramp.acceleration());
    const double tolerance = 1e-9 * (1.0 + before);
    // VMAX bounds the speed (VSTART jumps are capped at VMAX or the target speed); above it the
    // axis only comes down.
    FUZZ_CHECK(now <= std::fmax(c.vmax_pps, before) + tolerance, "speed %.17g above VMAX %.17g (before %.17g), mode %d",
               now, c.vmax_pps, before, static_cast<int>(mode));
    if (mode == Mode::kStop) FUZZ_CHECK(now <= before + tolerance, "a stop speeds up: %.17g -> %.17g", before, now);
    FUZZ_CHECK(!(previous_velocity > 0.0 && v < 0.0) && !(previous_velocity < 0.0 && v > 0.0),
               "direction flipped without rest: %.17g -> %.17g", previous_velocity, v);
    const double steepest = std::fmax(steepest_pps2, stop_rate_pps2);
    const double one_tick = steepest * dt_s * (1.0 + 1e-6) + 1e-6 * (1.0 + before);
    if (previous_velocity != 0.0 && v != 0.0) {
      FUZZ_CHECK(std::fabs(v - previous_velocity) <= one_tick, "velocity %.17g -> %.17g in one tick (steepest %g)",
                 previous_velocity, v, steepest);
    }
    if (previous_velocity != 0.0 && v == 0.0) {
      FUZZ_CHECK(before <= std::fmax(c.vstop_pps, c.vstart_pps) + one_tick,
                 "dropped to 0 from %.17g (VSTOP %g, VSTART %g)", before, c.vstop_pps, c.vstart_pps);
    }
    previous_velocity = v;
  }
};

}  // namespace

extern "C" int LLVMFuzzerTestOneInput(const uint8_t* data, size_t size) {
  FuzzedDataProvider in(data, size);
  // The drive's tick (50 µs) mostly; longer ticks reach long profiles within the tick budget.
  const double dt_s = in.ConsumeBool() ? 50e-6 : (in.ConsumeBool() ? 1e-3 : 10e-3);
  EightPointConfig config = random_config(in);
  const EightPointConfigError error = EightPointRamp::validate(config);
  check_refusal(config, error);
  if (error != EightPointConfigError::kNone) return 0;

  EightPointRamp ramp;
  Checker checker{ramp};
  checker.use(config);
  uint32_t longest_tzerowait_us = config.tzerowait_us;  // a wait under way keeps its length
  int ticks_left = kRandomPhaseTicks;  // the final move has its own bound
  for (int op = 0; op < 24 && in.remaining_bytes() > 0 && ticks_left > 0; ++op) {
    switch (in.ConsumeIntegralInRange<int>(0, 9)) {
      case 0:
      case 1:
      case 2: {
        const int32_t delta = in.ConsumeBool() ? in.ConsumeIntegralInRange<int32_t>(-100'000, 100'000)
                                               : in.ConsumeIntegral<int32_t>();
        ramp.set_position_target(static_cast<int32_t>(static_cast<uint32_t>(ramp.position()) + static_cast<uint32_t>(delta)));
        break;
      }
      case 3:
        ramp.set_velocity_target(in.ConsumeFloatingPointInRange<double>(-1.5, 1.5) * config.vmax_pps);
        break;
      case 4:
        checker.stop_rate_pps2 = in.ConsumeBool() ? 0.0 : rate(in);
        ramp.stop(checker.stop_rate_pps2);
        break;
      case 5:
        ramp.halt();
        checker.previous_velocity = 0.0;  // halt() stops at once, outside a tick
        break;
      case 6: {  // another profile during the motion (the master writes 6081, 6083 ... any time)
        const EightPointConfig next = random_config(in);
        const EightPointConfigError next_error = EightPointRamp::validate(next);
        check_refusal(next, next_error);
        if (next_error == EightPointConfigError::kNone) {
          config = next;
          checker.use(config);
          longest_tzerowait_us = std::max(longest_tzerowait_us, next.tzerowait_us);
        }
        break;
      }
      case 7:
        if (ramp.standstill()) ramp.set_position(in.ConsumeIntegral<int32_t>());
        break;
      case 8:  // another mode's motion taken over (csp/csv, homing)
        ramp.set_state(in.ConsumeIntegral<int32_t>(), in.ConsumeFloatingPointInRange<double>(-1.0, 1.0) * config.vmax_pps);
        checker.previous_velocity = ramp.velocity();
        break;
      default:
        break;
    }
    const int ticks = in.ConsumeIntegralInRange<int>(0, kTicksPerOperation);
    for (int i = 0; i < ticks && ticks_left > 0; ++i, --ticks_left) checker.tick(config, dt_s);
  }

  // The final move: stop with the profile, rest out TZEROWAIT, then a move from rest.
  const double d_min = std::fmin(std::fmin(config.dmax_pps2, config.d1_pps2), config.d2_pps2);
  double a_min = config.amax_pps2;
  if (config.v1_pps > 0.0) a_min = std::fmin(a_min, config.a1_pps2);
  if (config.v2_pps > 0.0) a_min = std::fmin(a_min, config.a2_pps2);
  const double tzerowait_s = longest_tzerowait_us * 1e-6;
  const double tvmax_s = config.tvmax_us * 1e-6;
  checker.stop_rate_pps2 = 0.0;
  ramp.stop();
  {
    const double speed_now = std::fabs(ramp.velocity());
    const double stop_bound_s = 2.0 * speed_now / d_min + tzerowait_s + 20 * dt_s;
    if (stop_bound_s / dt_s > kStopBoundTicks) return 0;  // beyond the budget of one input
    const long bound = static_cast<long>(stop_bound_s / dt_s) + 2;
    long i = 0;
    for (; i < bound && (!ramp.standstill() || ramp.waiting()); ++i) checker.tick(config, dt_s);
    FUZZ_CHECK(ramp.standstill() && !ramp.waiting(), "a stop from %g pps did not end within %ld ticks", speed_now, bound);
  }
  if (config.vmax_pps <= 0.0) {  // VMAX 0: a move never starts
    const int32_t here = ramp.position();
    ramp.set_position_target(static_cast<int32_t>(static_cast<uint32_t>(here) + 1000u));
    for (int i = 0; i < 100; ++i) checker.tick(config, dt_s);
    FUZZ_CHECK(ramp.standstill() && ramp.position() == here, "VMAX 0 but moving at %g", ramp.velocity());
    return 0;
  }
  // MOTWIN_FUZZ_TRACE=1: the profile of the final move, for reading a saved input.
  if (std::getenv("MOTWIN_FUZZ_TRACE") != nullptr) {
    std::fprintf(stderr,
                 "dt %g s; VSTART %.17g A1 %.17g V1 %.17g A2 %.17g V2 %.17g VMAX %.17g AMAX %.17g DMAX %.17g D2 %.17g "
                 "D1 %.17g VSTOP %.17g TZEROWAIT %u us TVMAX %u us\n",
                 dt_s, config.vstart_pps, config.a1_pps2, config.v1_pps, config.a2_pps2, config.v2_pps, config.vmax_pps,
                 config.amax_pps2, config.dmax_pps2, config.d2_pps2, config.d1_pps2, config.vstop_pps,
                 config.tzerowait_us, config.tvmax_us);
  }
  // A distance the tick budget can drive at the profile's speeds.
  const double fixed_s = config.vmax_pps / a_min + config.vmax_pps / d_min + tvmax_s;
  const double budget_s = kMoveBudgetTicks * dt_s;
  if (fixed_s > budget_s) return 0;
  const double reachable = std::fmin(2e9, (budget_s - fixed_s) * config.vmax_pps * 0.5);
  const int64_t distance = static_cast<int64_t>(in.ConsumeFloatingPointInRange<double>(-1.0, 1.0) * reachable);
  const int32_t start = ramp.position();
  const int32_t target = static_cast<int32_t>(static_cast<uint32_t>(start) + static_cast<uint32_t>(distance));
  ramp.set_position_target(target);
  // The stop may have left a fraction of a µstep: the exact distance (a slow VMAX takes long
  // even for that).
  const double move_s =
      1.5 * (std::fabs(ramp.distance_to_target()) / config.vmax_pps + fixed_s) + 2.0 * tvmax_s + 20 * dt_s;
  if (move_s / dt_s > kMoveBoundTicks) return 0;  // beyond the budget of one input
  const long bound = static_cast<long>(move_s / dt_s) + 2;
  long i = 0;
  for (; i < bound && !ramp.position_reached(); ++i) {
    checker.tick(config, dt_s);
    // No overshoot: the axis stays between start and target (wrapping arithmetic), at every tick
    // length (the long ticks pass several bands within one tick).
    const int64_t travelled = static_cast<int32_t>(static_cast<uint32_t>(ramp.position()) - static_cast<uint32_t>(start));
    FUZZ_CHECK(distance >= 0 ? (travelled >= 0 && travelled <= distance) : (travelled <= 0 && travelled >= distance),
               "move of %lld from %d: at %lld after %ld ticks (velocity %g)", static_cast<long long>(distance), start,
               static_cast<long long>(travelled), i, ramp.velocity());
  }
  FUZZ_CHECK(ramp.position_reached() && ramp.position() == target && ramp.standstill(),
             "move of %lld not done within %ld ticks of %g s: at %d (target %d), velocity %g, segment %d",
             static_cast<long long>(distance), bound, dt_s, ramp.position(), target, ramp.velocity(),
             static_cast<int>(ramp.segment()));
  return 0;
}
