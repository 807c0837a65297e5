// CiA-402 homing (TMCM-3216 manual 8.1) against a small simulated axis: a trapezoid ramp that
// carries out the homing commands, limit and home switches as position windows, and an encoder
// index every kIndexPitch microsteps whose position is latched. The axis keeps a machine
// coordinate apart from its position counter, so each test can say where the axis physically
// stands and what the counter reads there.
#include <gtest/gtest.h>

#include <cstdint>
#include <cstdlib>
#include <limits>
#include <utility>

#include "core/cia402/homing.h"
#include "core/motion/trapezoid_ramp.h"

namespace motwin::cia402 {
namespace {

constexpr uint32_t kTickUs = 50;
constexpr int32_t kLeftLimitAt = -200000;  // left limit active at and below
constexpr int32_t kRightLimitAt = 200000;  // right limit active at and above
constexpr int32_t kCamFrom = 10000;        // home switch active from...
constexpr int32_t kCamTo = 30000;          // ...to, inclusive
constexpr int32_t kIndexPitch = 4000;      // one index pulse per 4000 µsteps...
constexpr int32_t kIndexPhase = 1234;      // ...at 1234 + k * 4000
constexpr int32_t kHomeOffset = 5000;

const HomingConfig kConfig{50000, 5000, 500000, kHomeOffset, 0, 0};

// Floor division that works for negative numerators.
int64_t floor_div(int64_t a, int64_t b) { return a >= 0 ? a / b : -((-a + b - 1) / b); }

struct Geometry {
  bool left_limit = true;
  bool right_limit = true;
  int32_t cam_from = kCamFrom;
  int32_t cam_to = kCamTo;
  bool cam = true;
  bool index_pulses = true;
  bool encoder = true;            // index_available
  bool swap_limits = false;       // wiring error
  bool right_limit_stuck = false;
  int32_t index_phase = kIndexPhase;
};

class Axis {
 public:
  explicit Axis(int32_t machine_start, int32_t counter_start = 0, Geometry geometry = {})
      : geometry_(geometry) {
    ramp_.set_position(counter_start);
    shift_ = static_cast<int32_t>(static_cast<uint32_t>(machine_start) - static_cast<uint32_t>(counter_start));
    previous_machine_ = machine_start;
  }

  int32_t counter() const { return ramp_.position(); }
  int32_t machine() const { return to_machine(ramp_.position()); }
  double velocity() const { return ramp_.velocity(); }

  HomingInputs sense() const {
    HomingInputs in;
    const int32_t x = machine();
    bool left = geometry_.left_limit && x <= kLeftLimitAt;
    bool right = geometry_.right_limit && (x >= kRightLimitAt || geometry_.right_limit_stuck);
    if (geometry_.swap_limits) std::swap(left, right);
    in.position_usteps = counter();
    in.left_limit = left;
    in.right_limit = right;
    in.home_switch = geometry_.cam && x >= geometry_.cam_from && x <= geometry_.cam_to;
    in.index_events = index_events_;
    in.index_position_usteps = index_counter_;
    in.index_available = geometry_.encoder;
    in.target_reached = ramp_.mode() == motion::TrapezoidRamp::Mode::kPosition && ramp_.distance_to_target() == 0.0 &&
                        ramp_.velocity() == 0.0;
    return in;
  }

  void apply(const HomingCommand& command) {
    ramp_config_.acceleration = command.acceleration_pps2;
    switch (command.kind) {
      case HomingCommand::Kind::kVelocity:
        ramp_config_.max_velocity = command.velocity_pps < 0 ? -command.velocity_pps : command.velocity_pps;
        ramp_.set_velocity_target(command.velocity_pps);
        break;
      case HomingCommand::Kind::kPosition:
        ramp_config_.max_velocity = command.velocity_pps < 0 ? -command.velocity_pps : command.velocity_pps;
        ramp_.set_position_target(command.target_position_usteps);
        break;
      case HomingCommand::Kind::kDone:
        ++done_commands;
        if (command.set_position) {
          const int32_t here = machine();
          ramp_.set_position(command.new_position);
          shift_ = static_cast<int32_t>(static_cast<uint32_t>(here) - static_cast<uint32_t>(command.new_position));
        }
        ramp_.set_velocity_target(0.0);
        break;
      case HomingCommand::Kind::kError:
        ++error_commands;
        ramp_.set_velocity_target(0.0);
        break;
      case HomingCommand::Kind::kStop:
        ramp_.set_velocity_target(0.0);
        break;
    }
  }

  // One 50 µs tick of the plant; latches the index like an encoder does.
  void advance() {
    ramp_.step(ramp_config_, kTickUs * 1e-6);
    const int32_t now = machine();
    if (geometry_.index_pulses && now != previous_machine_) {
      const int64_t lo = now > previous_machine_ ? previous_machine_ + 1 : now;
      const int64_t hi = now > previous_machine_ ? now : previous_machine_ - 1;
      // The index pulse crossed last, in the direction of motion.
      const int64_t phase = geometry_.index_phase;
      const int64_t k = now > previous_machine_ ? floor_div(hi - phase, kIndexPitch) : -floor_div(-(lo - phase), kIndexPitch);
      const int64_t pulse = phase + k * kIndexPitch;
      if (pulse >= lo && pulse <= hi) {
        ++index_events_;
        index_counter_ = to_counter(static_cast<int32_t>(pulse));
      }
    }
    previous_machine_ = now;
  }

  int done_commands = 0;
  int error_commands = 0;

 private:
  int32_t to_machine(int32_t counter) const {
    return static_cast<int32_t>(static_cast<uint32_t>(counter) + static_cast<uint32_t>(shift_));
  }
  int32_t to_counter(int32_t machine) const {
    return static_cast<int32_t>(static_cast<uint32_t>(machine) - static_cast<uint32_t>(shift_));
  }

  Geometry geometry_;
  motion::TrapezoidRamp ramp_;
  motion::TrapezoidRampConfig ramp_config_{0.0, 0.0, true};
  int32_t shift_ = 0;  // machine = counter + shift
  int32_t previous_machine_ = 0;
  uint32_t index_events_ = 0;
  int32_t index_counter_ = 0;
};

struct HomingRun {
  Homing::State state = Homing::State::kIdle;
  Homing::Reason reason = Homing::Reason::kNone;
  int ticks = 0;
};

// Steps the homing and the axis until the homing is over, then lets the axis come to rest.
HomingRun run(Homing& homing, Axis& axis, int max_ticks = 2'000'000) {
  HomingRun result;
  for (; result.ticks < max_ticks && homing.active(); ++result.ticks) {
    axis.apply(homing.step(axis.sense(), kTickUs));
    axis.advance();
  }
  for (int i = 0; i < 20000 && axis.velocity() != 0.0; ++i) {
    axis.apply(homing.step(axis.sense(), kTickUs));
    axis.advance();
  }
  result.state = homing.state();
  result.reason = homing.reason();
  return result;
}

struct Case {
  int8_t method;
  int32_t start;
  int32_t home;  // machine coordinate of the home point
};

// The home point of each method for the geometry above: the first position that reads
// "released" when the switch is left in the method's final direction, then (methods 1..5)
// the first index pulse beyond it.
//   17: left limit active <= -200000, left towards +: -199999.   1: then index >= -199999: -198766
//   18: right limit active >= 200000, left towards -: 199999.    2: then index <= 199999: 197234
//   19: cam 10000..30000, left towards -: 9999.                  3: then index <= 9999: 9234
//   21: cam 10000..30000, left towards +: 30001.                 5: then index >= 30001: 33234
const Case kCases[] = {
    {17, 0, -199999},      {17, -210000, -199999}, {17, 250000, -199999},
    {18, 0, 199999},       {18, 210000, 199999},   {18, -250000, 199999},
    {19, 0, 9999},         {19, 20000, 9999},      {19, 50000, 9999},   {19, -250000, 9999},
    {21, 0, 30001},        {21, 20000, 30001},     {21, 50000, 30001},  {21, 250000, 30001},
    {1, 0, -198766},       {1, -210000, -198766},  {1, -199000, -198766},
    {2, 0, 197234},        {2, 210000, 197234},    {2, 199000, 197234},
    {3, 0, 9234},          {3, 20000, 9234},       {3, 50000, 9234},
    {5, 0, 33234},         {5, 20000, 33234},      {5, 50000, 33234},
    {33, 0, -2766},        {33, 1234, -2766},      {33, 1235, 1234},    {33, 20000, 17234},
    {34, 0, 1234},         {34, 1234, 5234},       {34, 1233, 1234},    {34, -20000, -18766},
    {35, 0, 0},            {35, 12345, 12345},
};

TEST(Cia402Homing, every_method_from_both_sides_stands_at_home_with_the_home_offset) {
  for (const Case& c : kCases) {
    SCOPED_TRACE(testing::Message() << "method " << int{c.method} << " from " << c.start);
    Homing homing;
    Axis axis(c.start, 777);
    homing.start(c.method, kConfig);
    const HomingRun result = run(homing, axis);
    EXPECT_EQ(result.state, Homing::State::kAttained) << Homing::reason_name(result.reason);
    EXPECT_EQ(axis.machine(), c.home);         // where the axis physically stands
    EXPECT_EQ(axis.counter(), kHomeOffset);    // what 6064 reads there
    EXPECT_EQ(axis.velocity(), 0.0);
    EXPECT_EQ(axis.done_commands, 1);
    EXPECT_EQ(homing.home_point_usteps(), c.home - c.start + 777);  // in the counter's values before homing
  }
}

TEST(Cia402Homing, home_point_does_not_depend_on_the_fast_speed) {
  for (int32_t fast : {20000, 50000, 200000, 400000}) {
    for (int8_t method : {int8_t{19}, int8_t{21}, int8_t{17}}) {
      SCOPED_TRACE(testing::Message() << "method " << int{method} << " fast " << fast);
      HomingConfig config = kConfig;
      config.fast_speed_pps = fast;
      Homing homing;
      Axis axis(50000);
      homing.start(method, config);
      EXPECT_EQ(run(homing, axis).state, Homing::State::kAttained);
      EXPECT_EQ(axis.machine(), method == 19 ? 9999 : (method == 21 ? 30001 : -199999));
      EXPECT_EQ(axis.counter(), kHomeOffset);
    }
  }
}

TEST(Cia402Homing, narrow_home_switch_passed_while_braking_is_found_exactly) {
  // 500 µsteps of cam; braking from the fast speed takes 2500 µsteps.
  Geometry narrow;
  narrow.cam_from = 10000;
  narrow.cam_to = 10500;
  for (int32_t start : {0, 10200, 50000}) {
    SCOPED_TRACE(start);
    for (int8_t method : {int8_t{19}, int8_t{21}}) {
      Homing homing;
      Axis axis(start, 0, narrow);
      homing.start(method, kConfig);
      EXPECT_EQ(run(homing, axis).state, Homing::State::kAttained);
      EXPECT_EQ(axis.machine(), method == 19 ? 9999 : 10501);
      EXPECT_EQ(axis.counter(), kHomeOffset);
    }
  }
}

TEST(Cia402Homing, index_pulse_at_the_edge_counts_one_on_the_switch_does_not) {
  // Method 3 leaves the cam (active from 10000) towards -: edge 9999.
  struct {
    int32_t index_phase;
    int32_t home;
  } cases[] = {{9999, 9999}, {10000, 6000}, {9998, 9998}};
  for (const auto& c : cases) {
    SCOPED_TRACE(c.index_phase);
    Geometry geometry;
    geometry.index_phase = c.index_phase;
    for (int32_t start : {0, 20000}) {
      Homing homing;
      Axis axis(start, 0, geometry);
      homing.start(3, kConfig);
      EXPECT_EQ(run(homing, axis).state, Homing::State::kAttained);
      EXPECT_EQ(axis.machine(), c.home);
      EXPECT_EQ(axis.counter(), kHomeOffset);
    }
  }
}

TEST(Cia402Homing, home_offset_sign_and_zero) {
  for (int32_t offset : {0, -12345, 12345}) {
    HomingConfig config = kConfig;
    config.home_offset_usteps = offset;
    Homing homing;
    Axis axis(0);
    homing.start(19, config);
    EXPECT_EQ(run(homing, axis).state, Homing::State::kAttained);
    EXPECT_EQ(axis.machine(), 9999);
    EXPECT_EQ(axis.counter(), offset);  // home position = home offset: zero lies offset before home
  }
}

TEST(Cia402Homing, counter_wrapping_during_the_search) {
  Homing homing;
  Axis axis(0, std::numeric_limits<int32_t>::max() - 3000);  // wraps after 3000 µsteps to the right
  homing.start(3, kConfig);
  EXPECT_EQ(run(homing, axis).state, Homing::State::kAttained);
  EXPECT_EQ(axis.machine(), 9234);
  EXPECT_EQ(axis.counter(), kHomeOffset);
}

TEST(Cia402Homing, method_0_does_nothing_and_is_attained) {
  Homing homing;
  Axis axis(4321, 99);
  homing.start(0, kConfig);
  const HomingRun result = run(homing, axis);
  EXPECT_EQ(result.state, Homing::State::kAttained);
  EXPECT_EQ(result.ticks, 1);
  EXPECT_EQ(axis.counter(), 99);
  EXPECT_EQ(axis.machine(), 4321);
}

TEST(Cia402Homing, method_35_sets_the_position_at_once_without_moving) {
  Homing homing;
  Axis axis(4321, 99);
  homing.start(35, kConfig);
  EXPECT_TRUE(homing.active());
  // No motion needed, so no ramp either: done in the first step (works outside operation enabled).
  const HomingCommand first = homing.step(axis.sense(), kTickUs);
  EXPECT_EQ(first.kind, HomingCommand::Kind::kDone);
  EXPECT_TRUE(first.set_position);
  EXPECT_EQ(first.new_position, kHomeOffset);
  EXPECT_TRUE(homing.attained());
  EXPECT_EQ(homing.home_point_usteps(), 99);
  const HomingCommand second = homing.step(axis.sense(), kTickUs);
  EXPECT_EQ(second.kind, HomingCommand::Kind::kStop);
  EXPECT_FALSE(second.set_position);
}

TEST(Cia402Homing, unsupported_methods_are_refused) {
  for (int8_t method : {int8_t{-1}, int8_t{4}, int8_t{6}, int8_t{20}, int8_t{36}, int8_t{37}}) {
    EXPECT_FALSE(Homing::is_supported(method));
    Homing homing;
    Axis axis(0);
    homing.start(method, kConfig);
    const HomingRun result = run(homing, axis);
    EXPECT_EQ(result.state, Homing::State::kError);
    EXPECT_EQ(result.reason, Homing::Reason::kUnsupportedMethod);
    EXPECT_EQ(axis.machine(), 0);
  }
  for (int8_t method : {0, 1, 2, 3, 5, 17, 18, 19, 21, 33, 34, 35}) EXPECT_TRUE(Homing::is_supported(method));
}

TEST(Cia402Homing, zero_speeds_are_an_error_without_motion) {
  HomingConfig no_fast = kConfig;
  no_fast.fast_speed_pps = 0;
  HomingConfig no_slow = kConfig;
  no_slow.slow_speed_pps = 0;
  struct {
    int8_t method;
    const HomingConfig& config;
    Homing::State state;
  } cases[] = {{19, no_fast, Homing::State::kError},
               {19, no_slow, Homing::State::kError},
               {34, no_slow, Homing::State::kError},
               {34, no_fast, Homing::State::kAttained},  // index methods only use the slow speed
               {35, no_slow, Homing::State::kAttained}};
  for (const auto& c : cases) {
    Homing homing;
    Axis axis(0);
    homing.start(c.method, c.config);
    const HomingRun result = run(homing, axis);
    EXPECT_EQ(result.state, c.state);
    if (c.state == Homing::State::kError) {
      EXPECT_EQ(result.reason, Homing::Reason::kZeroSpeed);
      EXPECT_EQ(axis.machine(), 0);
      EXPECT_EQ(axis.error_commands, 1);
    }
  }
}

TEST(Cia402Homing, home_switch_missing_between_the_limits_fails_after_both) {
  Geometry no_cam;
  no_cam.cam = false;
  for (int8_t method : {int8_t{19}, int8_t{21}, int8_t{3}, int8_t{5}}) {
    SCOPED_TRACE(int{method});
    Homing homing;
    Axis axis(0, 0, no_cam);
    homing.start(method, kConfig);
    const HomingRun result = run(homing, axis);
    EXPECT_EQ(result.state, Homing::State::kError);
    EXPECT_EQ(result.reason, Homing::Reason::kSwitchNotFound);
    EXPECT_EQ(axis.velocity(), 0.0);
    // Stopped with the homing deceleration just past the second limit it reached.
    const int32_t second_limit = (method == 19 || method == 3) ? kLeftLimitAt : kRightLimitAt;
    EXPECT_LE(std::abs(axis.machine() - second_limit), 2600);
    EXPECT_EQ(axis.counter(), axis.machine());  // position not set
  }
}

TEST(Cia402Homing, index_methods_need_an_encoder_index) {
  Geometry no_encoder;
  no_encoder.encoder = false;
  for (int8_t method : {int8_t{1}, int8_t{2}, int8_t{3}, int8_t{5}, int8_t{33}, int8_t{34}}) {
    Homing homing;
    Axis axis(0, 0, no_encoder);
    homing.start(method, kConfig);
    const HomingRun result = run(homing, axis);
    EXPECT_EQ(result.reason, Homing::Reason::kIndexUnavailable);
    EXPECT_EQ(axis.machine(), 0);
  }
}

TEST(Cia402Homing, no_index_pulse_fails_at_the_limit_or_the_search_limit) {
  Geometry silent;
  silent.index_pulses = false;
  {
    Homing homing;
    Axis axis(0, 0, silent);
    homing.start(1, kConfig);  // edge at -199999, then towards + until the right limit
    const HomingRun result = run(homing, axis);
    EXPECT_EQ(result.reason, Homing::Reason::kIndexNotFound);
    EXPECT_GE(axis.machine(), kRightLimitAt);
  }
  {
    HomingConfig limited = kConfig;
    limited.index_search_limit_usteps = 8000;
    Homing homing;
    Axis axis(0, 0, silent);
    homing.start(3, limited);  // method 3: edge at 9999 leaving towards -
    const HomingRun result = run(homing, axis);
    EXPECT_EQ(result.reason, Homing::Reason::kIndexNotFound);
    // Gave up 8001 µsteps past the edge and braked from the slow speed (25 µsteps).
    EXPECT_LE(axis.machine(), 9999 - 8001);
    EXPECT_GE(axis.machine(), 9999 - 8001 - 30);
  }
  {
    Homing homing;
    Axis axis(0, 0, silent);
    homing.start(34, kConfig);
    EXPECT_EQ(run(homing, axis).reason, Homing::Reason::kIndexNotFound);
    EXPECT_GE(axis.machine(), kRightLimitAt);
  }
}

TEST(Cia402Homing, limit_switch_errors) {
  {  // the switches are swapped: the "right" switch comes on at the left end
    Geometry swapped;
    swapped.swap_limits = true;
    Homing homing;
    Axis axis(0, 0, swapped);
    homing.start(17, kConfig);
    const HomingRun result = run(homing, axis);
    EXPECT_EQ(result.reason, Homing::Reason::kLimitSwitch);
    EXPECT_LE(axis.machine(), kLeftLimitAt);
  }
  {  // the right switch never releases: the slow approach reaches the left limit
    Geometry stuck;
    stuck.right_limit_stuck = true;
    Homing homing;
    Axis axis(0, 0, stuck);
    homing.start(18, kConfig);
    const HomingRun result = run(homing, axis);
    EXPECT_EQ(result.reason, Homing::Reason::kLimitSwitch);
    EXPECT_LE(axis.machine(), kLeftLimitAt);
  }
  {  // no left limit at all: the total search limit ends it
    Geometry no_left;
    no_left.left_limit = false;
    HomingConfig limited = kConfig;
    limited.search_limit_usteps = 300000;
    Homing homing;
    Axis axis(0, 0, no_left);
    homing.start(17, limited);
    const HomingRun result = run(homing, axis);
    EXPECT_EQ(result.reason, Homing::Reason::kSwitchNotFound);
    EXPECT_LE(axis.machine(), -300000);
    EXPECT_GE(axis.machine(), -300000 - 2600);
  }
}

TEST(Cia402Homing, stop_interrupts_without_setting_the_position_and_restart_homes) {
  Homing homing;
  Axis axis(0, 0);
  homing.start(17, kConfig);
  for (int i = 0; i < 20000; ++i) {  // 1 s: well on the way to the left limit
    axis.apply(homing.step(axis.sense(), kTickUs));
    axis.advance();
  }
  EXPECT_TRUE(homing.active());
  const int32_t at_stop = axis.machine();
  EXPECT_LT(at_stop, -40000);
  axis.apply(homing.stop());
  const HomingRun stopped = run(homing, axis);
  EXPECT_EQ(stopped.state, Homing::State::kInterrupted);
  EXPECT_FALSE(homing.active());
  EXPECT_FALSE(homing.attained());
  EXPECT_FALSE(homing.error());
  // Braked from 50000 pps at 500000 pps²: 2500 µsteps.
  EXPECT_NEAR(axis.machine(), at_stop - 2500, 5);
  EXPECT_EQ(axis.counter(), axis.machine());

  homing.start(17, kConfig);
  EXPECT_EQ(run(homing, axis).state, Homing::State::kAttained);
  EXPECT_EQ(axis.machine(), -199999);
  EXPECT_EQ(axis.counter(), kHomeOffset);

  // Homing again from home gives the same home.
  homing.start(19, kConfig);
  EXPECT_EQ(run(homing, axis).state, Homing::State::kAttained);
  EXPECT_EQ(axis.machine(), 9999);
  EXPECT_EQ(axis.counter(), kHomeOffset);
}

TEST(Cia402Homing, restart_while_moving_begins_anew) {
  Homing homing;
  Axis axis(0, 0);
  homing.start(18, kConfig);
  for (int i = 0; i < 20000; ++i) {
    axis.apply(homing.step(axis.sense(), kTickUs));
    axis.advance();
  }
  EXPECT_GT(axis.velocity(), 40000.0);
  homing.start(21, kConfig);  // moving right past the cam at 50000 pps
  EXPECT_EQ(run(homing, axis).state, Homing::State::kAttained);
  EXPECT_EQ(axis.machine(), 30001);
  EXPECT_EQ(axis.counter(), kHomeOffset);
}

TEST(Cia402Homing, commands_carry_the_homing_acceleration_and_speeds) {
  Homing homing;
  Axis axis(0);
  homing.start(19, kConfig);
  const HomingCommand first = homing.step(axis.sense(), kTickUs);
  EXPECT_EQ(first.kind, HomingCommand::Kind::kVelocity);
  EXPECT_EQ(first.velocity_pps, 50000);  // towards the switch, fast
  EXPECT_EQ(first.acceleration_pps2, 500000);
  Homing on_switch;
  Axis on(20000);
  on_switch.start(19, kConfig);
  EXPECT_EQ(on_switch.step(on.sense(), kTickUs).velocity_pps, -5000);  // off the switch, slow
}

}  // namespace
}  // namespace motwin::cia402
