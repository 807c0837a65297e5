// CiA-402 homing (src/core/cia402/homing.*) on a simulated axis wired as the TMCM-3216's drive
// wires it (AxisDrive::run_homing: an EightPointRamp with the homing acceleration, VMAX = the
// commanded speed): a random method of table 296 (or any number), fast/slow speeds and
// acceleration, limit switches (half-lines), a home switch window, an encoder index every P
// microsteps (or none, or no encoder), a start point, the counter offset against the machine
// and optional search limits.
//
// Invariants:
// - a velocity command runs at the fast or the slow speed, a position command at the slow one,
//   and the axis never moves faster than the larger of the two;
// - the homing ends (attained or error, each reported by exactly one kDone / kError command)
//   within a bound of ticks from the geometry and the speeds, whenever the geometry can end it
//   (both limits present or a search limit set);
// - an error names a reason; kZeroSpeed / kIndexUnavailable exactly when a speed is 0 or the
//   encoder has no index (at the first step);
// - attained: the axis stands still on the home point, which is the switch edge (the first
//   released position in the method's final direction, within one tick of slow travel) or the
//   first index pulse beyond it, or the first pulse from the start (33/34), or the start (35);
//   the counter then reads the home offset;
// - a well-posed machine (both limits, a home switch and index pulses between them with room to
//   brake, no search limits) homes with every method;
// - stop() during the homing (some inputs) interrupts it for good: no kDone / kError after it,
//   and the axis comes to rest on the homing deceleration.
#include <fuzzer/FuzzedDataProvider.h>

#include <algorithm>
#include <cmath>
#include <cstddef>
#include <cstdint>
#include <cstdio>
#include <cstdlib>

#include "core/cia402/homing.h"
#include "core/motion/eight_point_ramp.h"
#include "fuzz_support.h"

namespace {

using motwin::cia402::Homing;
using motwin::cia402::HomingCommand;
using motwin::cia402::HomingConfig;
using motwin::cia402::HomingInputs;
using motwin::motion::EightPointConfig;
using motwin::motion::EightPointRamp;
using Kind = HomingCommand::Kind;

constexpr int8_t kMethods[] = {0, 1, 2, 3, 5, 17, 18, 19, 21, 33, 34, 35};

int64_t floor_div(int64_t a, int64_t b) { return a >= 0 ? a / b : -((-a + b - 1) / b); }

struct Machine {
  bool left_present = true, right_present = true;
  int64_t left_at = -100000;  // left limit active at and below (machine µsteps)
  int64_t right_at = 100000;  // right limit active at and above
  bool cam_present = true;
  int64_t cam_from = 0, cam_to = 1000;
  bool encoder = true;        // index_available
  bool pulses = true;         // the index channel delivers pulses
  int64_t pitch = 4000, phase = 0;

  bool is_pulse(int64_t x) const { return pulses && (x - phase) % pitch == 0; }
};

// The axis: the drive's ramp and counter, the machine coordinate apart (machine = counter + shift).
class Axis {
 public:
  Axis(const Machine& m, int64_t start, int32_t counter_start) : m_(m), machine_(start) {
    ramp_.set_position(counter_start);
    shift_ = static_cast<uint32_t>(static_cast<int32_t>(start)) - static_cast<uint32_t>(counter_start);
  }
  int64_t machine() const { return machine_; }
  int32_t counter() const { return ramp_.position(); }
  double velocity() const { return ramp_.velocity(); }
  bool standstill() const { return ramp_.standstill(); }

  HomingInputs sense() const {
    HomingInputs in;
    in.position_usteps = counter();
    in.left_limit = m_.left_present && machine_ <= m_.left_at;
    in.right_limit = m_.right_present && machine_ >= m_.right_at;
    in.home_switch = m_.cam_present && machine_ >= m_.cam_from && machine_ <= m_.cam_to;
    in.index_events = index_events_;
    in.index_position_usteps = index_counter_;
    in.index_available = m_.encoder;
    in.target_reached = ramp_.mode() == EightPointRamp::Mode::kPosition && ramp_.position_reached();
    return in;
  }

  // AxisDrive::run_homing's handling of a command, then one tick of the ramp and the plant.
  void apply_and_step(const HomingCommand& command, double dt_s) {
    EightPointConfig config;
    config.amax_pps2 = config.dmax_pps2 = config.d1_pps2 = config.d2_pps2 = command.acceleration_pps2;
    config.vmax_pps = std::fabs(static_cast<double>(command.velocity_pps));
    switch (command.kind) {
      case Kind::kVelocity: ramp_.set_velocity_target(command.velocity_pps); break;
      case Kind::kPosition: ramp_.set_position_target(command.target_position_usteps); break;
      case Kind::kStop:
      case Kind::kError:
        if (ramp_.mode() != EightPointRamp::Mode::kStop) ramp_.stop(command.acceleration_pps2);
        break;
      case Kind::kDone:
        ramp_.halt();
        if (command.set_position) ramp_.set_position(command.new_position);
        shift_ = static_cast<uint32_t>(static_cast<int32_t>(machine_)) - static_cast<uint32_t>(ramp_.position());
        return;
    }
    const int32_t before = ramp_.position();
    ramp_.step(config, dt_s);
    const int64_t moved = static_cast<int32_t>(static_cast<uint32_t>(ramp_.position()) - static_cast<uint32_t>(before));
    const int64_t previous = machine_;
    machine_ += moved;
    if (m_.pulses && moved != 0) {
      // The pulse crossed last in the direction of motion, latched at its counter value.
      const int64_t lo = moved > 0 ? previous + 1 : machine_;
      const int64_t hi = moved > 0 ? machine_ : previous - 1;
      const int64_t pulse = moved > 0 ? m_.phase + floor_div(hi - m_.phase, m_.pitch) * m_.pitch
                                      : m_.phase - floor_div(m_.phase - lo, m_.pitch) * m_.pitch;
      if (pulse >= lo && pulse <= hi) {
        ++index_events_;
        index_counter_ = static_cast<int32_t>(static_cast<uint32_t>(static_cast<int32_t>(pulse)) - shift_);
      }
    }
  }

 private:
  const Machine& m_;
  EightPointRamp ramp_;
  int64_t machine_;
  uint32_t shift_ = 0;
  uint32_t index_events_ = 0;
  int32_t index_counter_ = 0;
};

}  // namespace

extern "C" int LLVMFuzzerTestOneInput(const uint8_t* data, size_t size) {
  FuzzedDataProvider in(data, size);
  const int8_t method = in.ConsumeIntegralInRange<int>(0, 15) == 0 ? in.ConsumeIntegral<int8_t>()
                                                                      : kMethods[in.ConsumeIntegralInRange<size_t>(0, 11)];
  const uint32_t dt_us = in.PickValueInArray({50u, 50u, 250u, 1000u});
  const double dt_s = dt_us * 1e-6;

  HomingConfig config;
  // At least half a microstep per tick: slower homings are fine but too slow to simulate here.
  const int32_t lowest = static_cast<int32_t>(std::ceil(0.5 / dt_s));
  config.fast_speed_pps = in.ConsumeIntegralInRange<int32_t>(lowest, in.ConsumeBool() ? 4 * lowest : 2'000'000);
  config.slow_speed_pps = in.ConsumeIntegralInRange<int32_t>(lowest, in.ConsumeBool() ? 4 * lowest : 200'000);
  if (in.ConsumeIntegralInRange<int>(0, 15) == 0) config.fast_speed_pps = 0;
  if (in.ConsumeIntegralInRange<int>(0, 15) == 0) config.slow_speed_pps = 0;
  const double max_speed = std::fmax(config.fast_speed_pps, config.slow_speed_pps);
  const double min_speed = std::fmax(1.0, std::fmin(config.fast_speed_pps, config.slow_speed_pps));
  // Ramps of at most ~500 ticks and braking distances of at most ~1000 ticks at the lower
  // speed: the run stays within a tick budget of a few thousand (fuzz/README.md, Decisions).
  const double min_acceleration =
      std::fmax(1.0, std::fmax(max_speed / (500 * dt_s), max_speed * max_speed / (2.0 * min_speed * 1000 * dt_s)));
  config.acceleration_pps2 = static_cast<int32_t>(
      std::fmin(2e9, min_acceleration * in.ConsumeFloatingPointInRange<double>(1.0, in.ConsumeBool() ? 4.0 : 1000.0)));
  config.home_offset_usteps = in.ConsumeIntegral<int32_t>();

  // Lengths in units of one tick at the lower speed: every crossing takes at most about a thousand ticks.
  const int64_t unit = static_cast<int64_t>(std::ceil(min_speed * dt_s));
  const auto length = [&](int64_t lo, int64_t hi) { return unit * in.ConsumeIntegralInRange<int64_t>(lo, hi); };
  Machine m;
  m.left_present = in.ConsumeIntegralInRange<int>(0, 7) != 0;
  m.right_present = in.ConsumeIntegralInRange<int>(0, 7) != 0;
  m.left_at = -length(0, 500);
  m.right_at = m.left_at + length(1, 1000);
  m.cam_present = in.ConsumeIntegralInRange<int>(0, 7) != 0;
  m.cam_from = m.left_at + length(-50, 1050);
  m.cam_to = m.cam_from + (in.ConsumeBool() ? in.ConsumeIntegralInRange<int64_t>(0, 3 * unit) : length(0, 250));
  m.encoder = in.ConsumeIntegralInRange<int>(0, 15) != 0;
  m.pulses = in.ConsumeIntegralInRange<int>(0, 15) != 0;
  m.pitch = in.ConsumeBool() ? in.ConsumeIntegralInRange<int64_t>(1, 4 * unit) : length(1, 250);
  m.phase = in.ConsumeIntegralInRange<int64_t>(0, m.pitch - 1);
  int64_t start = m.left_at + length(-75, 1075);
  const int32_t counter_start = in.ConsumeIntegral<int32_t>();
  if (in.ConsumeIntegralInRange<int>(0, 3) == 0 || !m.left_present || !m.right_present) {
    config.search_limit_usteps = static_cast<uint32_t>(length(1, 3000));
  }
  if (in.ConsumeIntegralInRange<int>(0, 3) == 0) config.index_search_limit_usteps = static_cast<uint32_t>(length(1, 750));

  // Braking from either speed; room to brake and a tick of travel on both sides of a switch.
  const double brake = max_speed * max_speed / (2.0 * config.acceleration_pps2);
  const int64_t margin = static_cast<int64_t>(2.0 * brake + 4.0 * max_speed * dt_s) + 2;
  if (in.ConsumeBool()) {
    // A tidy machine (the well-posed case below): both limits, the switch between them with room
    // to brake and to find an index beyond each edge, the start anywhere in between.
    m.left_present = m.right_present = m.cam_present = m.encoder = m.pulses = true;
    config.search_limit_usteps = config.index_search_limit_usteps = 0;
    const int64_t room = margin + m.pitch + 1;
    m.cam_from = m.left_at + room + length(0, 125);
    m.cam_to = m.cam_from + static_cast<int64_t>(4.0 * max_speed * dt_s) + 3 + length(0, 125);
    m.right_at = m.cam_to + room + length(0, 125);
    start = m.left_at + room + in.ConsumeIntegralInRange<int64_t>(0, m.right_at - m.left_at - 2 * room);
  }

  // A bound of ticks for the whole homing: every phase crosses the machine at most once at the
  // lower speed, plus a ramp up and down per phase.
  const double span = static_cast<double>(std::max<int64_t>(m.right_at, std::max(start, m.cam_to)) -
                                          std::min<int64_t>(m.left_at, std::min(start, m.cam_from))) +
                      static_cast<double>(m.pitch) + 2.0 * brake;
  // Without both limits only the search limit ends a search (the caller sets one then).
  const double searched = config.search_limit_usteps + 2.0 * brake + static_cast<double>(m.pitch);
  const double travel = !(m.left_present && m.right_present) ? searched
                        : config.search_limit_usteps != 0    ? std::fmin(span, searched)
                                                             : span;
  const double bound_s = 10.0 * (travel + static_cast<double>(m.pitch)) / min_speed +
                         20.0 * max_speed / config.acceleration_pps2 + 200 * dt_s;
  const long bound_ticks = static_cast<long>(bound_s / dt_s) + 10;
  if (bound_ticks > 1'500'000) return 0;  // beyond one input's budget

  const bool well_posed = Homing::is_supported(method) && m.left_present && m.right_present && m.cam_present && m.encoder && m.pulses &&
                          config.fast_speed_pps > 0 && config.slow_speed_pps > 0 && config.search_limit_usteps == 0 &&
                          config.index_search_limit_usteps == 0 && m.cam_from - m.left_at > margin + m.pitch &&
                          m.right_at - m.cam_to > margin + m.pitch && m.cam_to - m.cam_from > 4.0 * max_speed * dt_s + 2 &&
                          start - m.left_at > margin + m.pitch && m.right_at - start > margin + m.pitch;

  // MOTWIN_FUZZ_TRACE=1: the machine and every command change, for reading a saved input.
  static const bool tracing = std::getenv("MOTWIN_FUZZ_TRACE") != nullptr;
  if (tracing) {
    std::fprintf(stderr,
                 "method %d dt %u us fast %d slow %d acc %d offset %d; left %d@%lld right %d@%lld cam %d %lld..%lld;"
                 " encoder %d pulses %d pitch %lld phase %lld; start %lld counter %d; limits %u/%u; bound %ld ticks;"
                 " well-posed %d\n",
                 method, dt_us, config.fast_speed_pps, config.slow_speed_pps, config.acceleration_pps2,
                 config.home_offset_usteps, m.left_present, static_cast<long long>(m.left_at), m.right_present,
                 static_cast<long long>(m.right_at), m.cam_present, static_cast<long long>(m.cam_from),
                 static_cast<long long>(m.cam_to), m.encoder, m.pulses, static_cast<long long>(m.pitch),
                 static_cast<long long>(m.phase), static_cast<long long>(start), counter_start,
                 config.search_limit_usteps, config.index_search_limit_usteps, bound_ticks, well_posed);
  }
  HomingCommand last_command;
  last_command.kind = Kind::kDone;
  Axis axis(m, start, counter_start);
  Homing homing;
  homing.start(method, config);
  int done_commands = 0, error_commands = 0;
  bool first = true;
  int64_t done_at = 0;
  long tick = 0;
  // Sometimes the master ends the homing early (controlword bit 4 falls, halt, quick stop).
  const long stop_at_tick = in.ConsumeIntegralInRange<int>(0, 3) == 0 ? in.ConsumeIntegralInRange<long>(0, 1250) : -1;
  bool stopped = false;
  for (; tick < bound_ticks; ++tick) {
    const HomingInputs inputs = axis.sense();
    HomingCommand command;
    if (tick == stop_at_tick && homing.active()) {
      command = homing.stop();
      stopped = true;
      FUZZ_CHECK(homing.interrupted() && command.kind == Kind::kStop, "stop(): state %d, command %d",
                 static_cast<int>(homing.state()), static_cast<int>(command.kind));
    } else {
      command = homing.step(inputs, dt_us);
    }
    if (tracing && (command.kind != last_command.kind || command.velocity_pps != last_command.velocity_pps ||
                    command.target_position_usteps != last_command.target_position_usteps)) {
      std::fprintf(stderr, "tick %ld machine %lld v %g: L%d R%d H%d idx %u@%d -> kind %d v %d target %d\n", tick,
                   static_cast<long long>(axis.machine()), axis.velocity(), inputs.left_limit, inputs.right_limit,
                   inputs.home_switch, inputs.index_events, inputs.index_position_usteps, static_cast<int>(command.kind),
                   command.velocity_pps, command.target_position_usteps);
    }
    last_command = command;
    switch (command.kind) {
      case Kind::kVelocity: {
        const int32_t v = std::abs(command.velocity_pps);
        FUZZ_CHECK(v == config.fast_speed_pps || v == config.slow_speed_pps, "velocity command %d (fast %d, slow %d)",
                   command.velocity_pps, config.fast_speed_pps, config.slow_speed_pps);
        break;
      }
      case Kind::kPosition:
        FUZZ_CHECK(command.velocity_pps == config.slow_speed_pps, "position command at %d (slow %d)",
                   command.velocity_pps, config.slow_speed_pps);
        break;
      case Kind::kDone:
        ++done_commands;
        done_at = axis.machine();
        FUZZ_CHECK(homing.attained(), "kDone without attained");
        FUZZ_CHECK(command.set_position == (method != 0) && (method == 0 || command.new_position == config.home_offset_usteps),
                   "done: set_position %d new_position %d (home offset %d)", command.set_position, command.new_position,
                   config.home_offset_usteps);
        FUZZ_CHECK(axis.standstill() || !Homing::moves(method), "done while moving at %g", axis.velocity());
        break;
      case Kind::kError:
        ++error_commands;
        FUZZ_CHECK(homing.error() && homing.reason() != Homing::Reason::kNone, "kError without an error reason");
        break;
      case Kind::kStop:
        break;
    }
    if (first && !stopped) {
      const bool supported = Homing::is_supported(method);
      const bool switch_method = method == 1 || method == 2 || method == 3 || method == 5 || (method >= 17 && method <= 21);
      const bool index_method = method == 1 || method == 2 || method == 3 || method == 5 || method == 33 || method == 34;
      const bool zero_speed = Homing::moves(method) &&
                              (config.slow_speed_pps <= 0 || (switch_method && config.fast_speed_pps <= 0));
      using R = Homing::Reason;
      const R expected = !supported ? R::kUnsupportedMethod
                         : zero_speed ? R::kZeroSpeed
                         : (index_method && !m.encoder) ? R::kIndexUnavailable
                                                        : R::kNone;
      if (expected != R::kNone) {
        FUZZ_CHECK(homing.error() && homing.reason() == expected, "method %d: reason %s, expected %s", method,
                   Homing::reason_name(homing.reason()), Homing::reason_name(expected));
      } else {
        FUZZ_CHECK(!homing.error() || homing.reason() != R::kZeroSpeed, "method %d refused for a zero speed", method);
      }
      first = false;
    }
    axis.apply_and_step(command, dt_s);
    FUZZ_CHECK(std::fabs(axis.velocity()) <= max_speed * (1 + 1e-9) + 1e-6, "moving at %g, fast %d, slow %d",
               axis.velocity(), config.fast_speed_pps, config.slow_speed_pps);
    if (!homing.active() && axis.standstill()) break;  // ended, and a failed homing's stop is done
  }
  FUZZ_CHECK(!homing.active(), "method %d still homing after %ld ticks (%g s), machine at %lld, phase state %d", method,
             tick, tick * dt_s, static_cast<long long>(axis.machine()), static_cast<int>(homing.state()));
  if (stopped) {  // interrupted: stays so, no kDone / kError afterwards, the axis at rest
    FUZZ_CHECK(homing.interrupted() && done_commands + error_commands == 0 && axis.standstill(),
               "after stop(): state %d, %d kDone, %d kError, velocity %g", static_cast<int>(homing.state()),
               done_commands, error_commands, axis.velocity());
    return 0;
  }
  FUZZ_CHECK(done_commands + error_commands == 1, "%d kDone and %d kError commands", done_commands, error_commands);
  FUZZ_CHECK(!well_posed || homing.attained(), "method %d failed on a well-posed machine: %s", method,
             Homing::reason_name(homing.reason()));
  if (!homing.attained()) return 0;

  // Where the home point must be, in machine coordinates.
  const int64_t slack = static_cast<int64_t>(std::ceil(std::fmax(config.slow_speed_pps, 1) * dt_s)) + 1;
  int64_t edge = start;  // the first released position in the final direction (33/34: the start)
  int final_direction = 1;
  bool index = false;
  switch (method) {
    case 1: edge = m.left_at + 1; final_direction = 1; index = true; break;
    case 17: edge = m.left_at + 1; final_direction = 1; break;
    case 2: edge = m.right_at - 1; final_direction = -1; index = true; break;
    case 18: edge = m.right_at - 1; final_direction = -1; break;
    case 3: edge = m.cam_from - 1; final_direction = -1; index = true; break;
    case 19: edge = m.cam_from - 1; final_direction = -1; break;
    case 5: edge = m.cam_to + 1; final_direction = 1; index = true; break;
    case 21: edge = m.cam_to + 1; final_direction = 1; break;
    case 33: final_direction = -1; index = true; break;
    case 34: final_direction = 1; index = true; break;
    default: break;  // 0, 35: no motion
  }
  const int64_t beyond = (done_at - edge) * final_direction;
  if (!Homing::moves(method)) {
    FUZZ_CHECK(done_at == start, "method %d moved the axis to %lld from %lld", method, static_cast<long long>(done_at),
               static_cast<long long>(start));
  } else if (!index) {
    FUZZ_CHECK(beyond >= 0 && beyond < slack, "method %d: home %lld, switch edge at %lld (slack %lld)", method,
               static_cast<long long>(done_at), static_cast<long long>(edge), static_cast<long long>(slack));
  } else {
    FUZZ_CHECK(m.is_pulse(done_at), "method %d: home %lld is no index pulse", method, static_cast<long long>(done_at));
    const int64_t lower = method >= 33 ? 1 : 0;
    // The encoder latches the last pulse of a tick: with pulses closer than a tick's travel the
    // first one beyond the edge is known only to that travel.
    FUZZ_CHECK(beyond >= lower && beyond <= std::max(m.pitch, slack) + slack, "method %d: index home %lld, edge %lld, pitch %lld", method,
               static_cast<long long>(done_at), static_cast<long long>(edge), static_cast<long long>(m.pitch));
  }
  FUZZ_CHECK(axis.machine() == done_at && axis.standstill(), "the axis left home");
  if (method != 0) {
    FUZZ_CHECK(axis.counter() == config.home_offset_usteps, "counter %d at home, home offset %d", axis.counter(),
               config.home_offset_usteps);
  }
  return 0;
}
