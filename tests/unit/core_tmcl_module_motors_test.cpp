// The TMCL module base (core/tmcl/tmcl_module.h) with several motors, as a module whose EEPROM
// layout has three (make_nvm_layout(3, ...)) gets them: one axis per motor, every row helper of
// module_rows.h reaching the axis of the motor the command names, motor numbers checked by the
// engine, MVP REL relative to that motor's position, per-motor position reached (command 138),
// STAP/RSAP and the power-up restore per motor, the datalogger's axis channels per motor. A small
// fake module: the single-motor modules are tested as they always were.
#include <gtest/gtest.h>

#include <array>
#include <cstdint>
#include <vector>

#include "board/ram_non_volatile_memory.h"
#include "core/params/parameter_table.h"
#include "core/tmcl/engine.h"
#include "core/tmcl/serial_link.h"
#include "support/tmcl_command.h"
#include "core/tmcl/tmcl_module.h"

namespace motwin::testing {
namespace {

struct FakeAxisConfig {
  int32_t max_velocity = 100;  // counts per tick
};

struct FakeAxisState {
  int32_t actual_position = 0;
  int32_t target_position = 0;
  int32_t target_velocity = 0;
  int32_t left_switch_active = 0;
  int32_t right_switch_active = 0;
  int32_t home_switch_active = 0;
};

// An ideal axis: in position mode it moves to the target at max_velocity counts per tick, in
// velocity mode by the target velocity each tick.
class FakeAxis {
 public:
  FakeAxisConfig config;
  FakeAxisState state;

  void reset_state() {
    state = {};
    velocity_mode_ = false;
  }
  bool position_reached() const { return !velocity_mode_ && state.actual_position == state.target_position; }
  int32_t actual_position() const { return state.actual_position; }
  void set_target_position(int32_t position) {
    state.target_position = position;
    velocity_mode_ = false;
  }
  void set_target_velocity(int32_t velocity) {
    state.target_velocity = velocity;
    velocity_mode_ = true;
  }
  void set_actual_position(int32_t position) { state.actual_position = position; }
  void tick() {
    if (velocity_mode_) {
      state.actual_position += state.target_velocity;
      return;
    }
    const int32_t error = state.target_position - state.actual_position;
    const int32_t step = error > config.max_velocity ? config.max_velocity
                         : error < -config.max_velocity ? -config.max_velocity
                                                         : error;
    state.actual_position += step;
  }

 private:
  bool velocity_mode_ = false;
};

struct FakeGlobals {
  int32_t serial_address = 1;
  int32_t serial_host_address = 2;
  int32_t telegram_pause_ms = 0;
  int32_t auto_start_mode = 0;
  int32_t skip_user_variable_restore = 0;
};

class FakeIo {
 public:
  static constexpr uint8_t kDigitalInputCount = 1;
  static constexpr uint8_t kAnalogInputCount = 1;
  static constexpr uint8_t kDigitalOutputCount = 1;
  bool digital_input(uint8_t) const { return false; }
  uint16_t analog_input(uint8_t) const { return 0; }
  void set_digital_output(uint8_t, bool on) { output_ = on; }
  bool digital_output(uint8_t) const { return output_; }

 private:
  bool output_ = false;
};

inline constexpr uint8_t kMotors = 3;
inline constexpr tmcl::ModuleFacts kThreeAxisFacts{
    .name = "three-axis",
    .identity = {3000, 1, 0, "3000V100"},
    .nvm_layout = tmcl::make_nvm_layout(kMotors, 4, 16),
    .nvm_layout_version = 1,
    .control_tick_us = 1000,
    .motion = {.target_position = 0, .target_velocity = 2},
};

class ThreeAxisModule final
    : public tmcl::TmclModule<ThreeAxisModule, FakeAxis, FakeGlobals, FakeIo, kThreeAxisFacts> {
 public:
  ThreeAxisModule(board::NonVolatileMemory& nvm, FakeIo& io) : TmclModule(nvm, io) {}

  static const Table& axis_parameters() {
    using params::access;
    using params::Unit;
    // clang-format off
    static constexpr Row kRows[] = {
      {{0, "target position", kMin32, kMax32, 0, access("RW"), Unit::kNone, ""}, axis_command<&FakeAxisState::target_position, &FakeAxis::set_target_position>()},
      {{1, "actual position", kMin32, kMax32, 0, access("RW"), Unit::kNone, ""}, axis_command<&FakeAxisState::actual_position, &FakeAxis::set_actual_position>()},
      {{2, "target velocity", -1000, 1000, 0, access("RW"), Unit::kNone, ""}, axis_command<&FakeAxisState::target_velocity, &FakeAxis::set_target_velocity>()},
      {{4, "max velocity", 0, 1000, 100, access("RWE"), Unit::kNone, ""}, config_field<&FakeAxisConfig::max_velocity>()},
      {{8, "position reached", 0, 1, 0, access("R"), Unit::kNone, ""}, axis_value<&FakeAxis::position_reached>()},
      {{10, "right switch", 0, 1, 0, access("R"), Unit::kNone, ""}, state_value<&FakeAxisState::right_switch_active>()},
    };
    // clang-format on
    static constexpr Table kTable = params::sorted_table<ThreeAxisModule>(kRows);
    return kTable;
  }
  static const Table& global_parameters() {
    using params::access;
    using params::Unit;
    // clang-format off
    static constexpr Row kSettingRows[] = {
      {{66, "serial address", 1, 255, 1, access("RWA"), Unit::kAddress, ""}, global_field<&FakeGlobals::serial_address>()},
      {{77, "auto start mode", 0, 1, 0, access("RWA"), Unit::kNone, ""}, global_field<&FakeGlobals::auto_start_mode>()},
    };
    // clang-format on
    static constexpr auto kRows = params::join_rows<ThreeAxisModule>(kSettingRows, program_status_rows());
    static constexpr Table kTable = params::sorted_table<ThreeAxisModule>(kRows);
    return kTable;
  }

  void tick_axis() {
    for (uint8_t motor = 0; motor < kMotorCount; ++motor) axis(motor).tick();
  }
};

using ThreeAxisNvm = board::RamNonVolatileMemory<ThreeAxisModule::kNvmLayout.total_size>;

struct ThreeAxisRig {
  ThreeAxisNvm nvm;
  FakeIo io;
  ThreeAxisModule module{nvm, io};
  tmcl::TmclEngine& engine{module.engine()};

  ThreeAxisRig() {
    ThreeAxisModule::format_factory_image(nvm.mutable_data(), nvm.size());
    engine.power_up();
  }
  tmcl::Reply command(uint8_t cmd, uint8_t type, uint8_t motor, int32_t value) {
    return serial_command(engine, cmd, type, motor, value);
  }
  int32_t gap(uint8_t number, uint8_t motor) { return command(kGap, number, motor, 0).value; }
  void run_ticks(int ticks) {
    for (int i = 0; i < ticks; ++i) module.tick();
  }

  static constexpr uint8_t kRor = 1, kMst = 3, kMvp = 4, kSap = 5, kGap = 6, kStap = 7, kRsap = 8;
};

TEST(TmclModuleMotors, the_layout_gives_the_module_its_motor_count) {
  EXPECT_EQ(ThreeAxisModule::kMotorCount, 3);
  ThreeAxisRig rig;
  EXPECT_EQ(rig.module.motor_count(), 3);
}

TEST(TmclModuleMotors, sap_and_gap_reach_the_axis_of_the_motor_named) {
  ThreeAxisRig rig;
  EXPECT_EQ(rig.command(ThreeAxisRig::kSap, 4, 2, 7).status, 100);   // config field
  EXPECT_EQ(rig.command(ThreeAxisRig::kSap, 1, 1, 500).status, 100);  // axis command
  EXPECT_EQ(rig.module.axis(2).config.max_velocity, 7);
  EXPECT_EQ(rig.module.axis(0).config.max_velocity, 100);
  EXPECT_EQ(rig.module.axis(1).config.max_velocity, 100);
  EXPECT_EQ(rig.module.axis(1).state.actual_position, 500);
  EXPECT_EQ(rig.module.axis(0).state.actual_position, 0);
  EXPECT_EQ(rig.gap(4, 2), 7);
  EXPECT_EQ(rig.gap(1, 1), 500);
  EXPECT_EQ(rig.gap(1, 2), 0);
  rig.module.axis(2).state.right_switch_active = 1;  // state value
  EXPECT_EQ(rig.gap(10, 2), 1);
  EXPECT_EQ(rig.gap(10, 0), 0);
}

TEST(TmclModuleMotors, a_motor_beyond_the_last_answers_status_4_and_changes_nothing) {
  ThreeAxisRig rig;
  for (uint8_t cmd : {ThreeAxisRig::kSap, ThreeAxisRig::kGap, ThreeAxisRig::kRor, ThreeAxisRig::kMvp}) {
    EXPECT_EQ(rig.command(cmd, 4, 3, 9).status, 4) << "command " << int{cmd};
  }
  for (uint8_t motor = 0; motor < kMotors; ++motor) {
    EXPECT_EQ(rig.module.axis(motor).config.max_velocity, 100);
    EXPECT_EQ(rig.module.axis(motor).state.target_velocity, 0);
  }
}

TEST(TmclModuleMotors, motion_commands_move_only_their_motor_and_mvp_rel_adds_to_its_position) {
  ThreeAxisRig rig;
  EXPECT_EQ(rig.command(ThreeAxisRig::kSap, 1, 1, 1000).status, 100);
  EXPECT_EQ(rig.command(ThreeAxisRig::kMvp, 1, 1, 250).status, 100);  // REL on motor 1: 1250
  EXPECT_EQ(rig.gap(0, 1), 1250);
  EXPECT_EQ(rig.gap(0, 0), 0);
  EXPECT_EQ(rig.command(ThreeAxisRig::kMvp, 0, 2, -300).status, 100);  // ABS on motor 2
  EXPECT_EQ(rig.command(ThreeAxisRig::kRor, 0, 0, 5).status, 100);     // motor 0 turns
  EXPECT_EQ(rig.gap(8, 1), 0);
  EXPECT_EQ(rig.gap(8, 2), 0);
  rig.run_ticks(3);
  EXPECT_EQ(rig.gap(1, 1), 1250);
  EXPECT_EQ(rig.gap(1, 2), -300);
  EXPECT_EQ(rig.gap(1, 0), 15);
  EXPECT_EQ(rig.gap(8, 1), 1);
  EXPECT_EQ(rig.gap(8, 0), 0);  // rotating
  EXPECT_EQ(rig.command(ThreeAxisRig::kMst, 0, 0, 0).status, 100);
  EXPECT_EQ(rig.gap(2, 0), 0);
  EXPECT_EQ(rig.gap(2, 1), 0);
}

TEST(TmclModuleMotors, command_138_waits_for_every_motor_of_its_mask) {
  struct Sink final : tmcl::ReplySink {
    std::vector<tmcl::Reply> replies;
    void deliver(tmcl::ChannelId, const tmcl::Reply& reply) override { replies.push_back(reply); }
  } sink;
  ThreeAxisRig rig;
  EXPECT_EQ(rig.command(ThreeAxisRig::kMvp, 0, 0, 100).status, 100);  // there after one tick
  EXPECT_EQ(rig.command(ThreeAxisRig::kMvp, 0, 2, 500).status, 100);  // after five
  EXPECT_EQ(rig.command(138, 0, 0, 0b1000).status, 4);  // motor 3 does not exist
  EXPECT_EQ(rig.command(138, 0, 0, 0b101).status, 100);  // motors 0 and 2
  int ticks = 0;
  for (; ticks < 10 && sink.replies.empty(); ++ticks) {
    rig.run_ticks(1);
    rig.engine.collect_events(sink);
  }
  ASSERT_EQ(sink.replies.size(), 1u);
  EXPECT_EQ(sink.replies[0].status, 128);
  EXPECT_EQ(ticks, 5) << "not before motor 2 is there";
  EXPECT_TRUE(rig.module.position_reached(0));
  EXPECT_TRUE(rig.module.position_reached(2));
}

TEST(TmclModuleMotors, stap_and_rsap_store_each_motor_apart_and_power_up_restores_them) {
  ThreeAxisRig rig;
  EXPECT_EQ(rig.command(ThreeAxisRig::kSap, 4, 0, 11).status, 100);
  EXPECT_EQ(rig.command(ThreeAxisRig::kSap, 4, 2, 33).status, 100);
  EXPECT_EQ(rig.command(ThreeAxisRig::kStap, 4, 2, 0).status, 100);  // only motor 2's
  EXPECT_EQ(rig.command(ThreeAxisRig::kRsap, 4, 0, 0).status, 100);  // motor 0 back to its stored 100
  EXPECT_EQ(rig.gap(4, 0), 100);
  EXPECT_EQ(rig.gap(4, 2), 33);
  constexpr auto layout = ThreeAxisModule::kNvmLayout;
  EXPECT_EQ(tmcl::get_le32(rig.nvm.data() + layout.axis_parameter(2, 4)), 33);
  EXPECT_EQ(tmcl::get_le32(rig.nvm.data() + layout.axis_parameter(1, 4)), 100);
  EXPECT_EQ(rig.command(ThreeAxisRig::kSap, 4, 1, 22).status, 100);  // not stored
  rig.engine.power_up();
  EXPECT_EQ(rig.gap(4, 0), 100);
  EXPECT_EQ(rig.gap(4, 1), 100);
  EXPECT_EQ(rig.gap(4, 2), 33);
}

TEST(TmclModuleMotors, power_up_clears_the_state_of_every_axis) {
  ThreeAxisRig rig;
  for (uint8_t motor = 0; motor < kMotors; ++motor) {
    EXPECT_EQ(rig.command(ThreeAxisRig::kSap, 1, motor, 10 + motor).status, 100);
  }
  rig.engine.power_up();
  for (uint8_t motor = 0; motor < kMotors; ++motor) EXPECT_EQ(rig.gap(1, motor), 0) << "motor " << int{motor};
}

TEST(TmclModuleMotors, the_datalogger_resolves_an_axis_channel_of_any_motor) {
  ThreeAxisRig rig;
  EXPECT_EQ(rig.command(ThreeAxisRig::kSap, 1, 2, 4242).status, 100);
  tmcl::RamDebugProbe probe{};
  const uint32_t motor_2_position = (2u << 24) | 1u;
  ASSERT_EQ(rig.module.resolve_parameter_channel(tmcl::ram_debug::channel_type::kAxisParameter, motor_2_position, probe),
            tmcl::Status::kOk);
  EXPECT_EQ(rig.module.read_parameter_channel(probe), 4242);
  EXPECT_EQ(rig.module.resolve_parameter_channel(tmcl::ram_debug::channel_type::kAxisParameter, (3u << 24) | 1u, probe),
            tmcl::Status::kInvalidValue);
}

}  // namespace
}  // namespace motwin::testing

namespace motwin::testing {
namespace {

// The device's own entry points refuse a motor it does not have as the engine does (status 4),
// for callers that do not go through the engine (the datalogger, tools, the fuzz targets): no
// read or write of an axis beyond the last, no EEPROM slot beyond the axis area.
TEST(TmclModuleMotors, direct_calls_for_a_motor_beyond_the_last_are_refused) {
  ThreeAxisRig rig;
  const std::vector<uint8_t> image_before(rig.nvm.data(), rig.nvm.data() + rig.nvm.size());
  int32_t value = 12345;
  EXPECT_EQ(rig.module.get_axis_parameter(4, 3, value), tmcl::Status::kInvalidValue);
  EXPECT_EQ(value, 12345);
  EXPECT_EQ(rig.module.set_axis_parameter(4, 3, 7), tmcl::Status::kInvalidValue);
  EXPECT_EQ(rig.module.store_axis_parameter(4, 255), tmcl::Status::kInvalidValue);
  EXPECT_EQ(rig.module.restore_axis_parameter(4, 3), tmcl::Status::kInvalidValue);
  EXPECT_EQ(rig.module.rotate(3, 10), tmcl::Status::kInvalidValue);
  EXPECT_EQ(rig.module.move(3, 0, 10), tmcl::Status::kInvalidValue);
  EXPECT_FALSE(rig.module.position_reached(3));
  EXPECT_FALSE(rig.module.stop_switch_active(3, true));
  EXPECT_FALSE(rig.module.home_switch_active(200));
  EXPECT_EQ(std::vector<uint8_t>(rig.nvm.data(), rig.nvm.data() + rig.nvm.size()), image_before);
  for (uint8_t motor = 0; motor < kMotors; ++motor) EXPECT_EQ(rig.gap(4, motor), 100);
}

}  // namespace
}  // namespace motwin::testing
