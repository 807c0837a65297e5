// TMCM-142 parameters at the real module's numbers (docs/tmcm-142.md): what each new one does on
// the simulated TMC457 board (shaft, position limits, switch status, warn distance, compare
// position, N-channel latch, microstep table position, driver status, PID tolerance), and the
// migration of an NVM layout 1 image (four bows at AP 16..19, encoder direction AP 46, standby
// delay AP 214) to the real numbering.
#include <gtest/gtest.h>

#include "core/tmcl/nvm_layout.h"
#include "support/tmcm142_rig.h"

namespace motwin::testing {
namespace {

constexpr uint8_t kOk = 100;
constexpr uint8_t kWrongType = 3;

void use_pps(Tmcm142Rig& rig, int32_t vmax, int32_t acceleration) {
  ASSERT_EQ(rig.sap(255, 1), kOk);
  ASSERT_EQ(rig.sap(4, vmax), kOk);
  ASSERT_EQ(rig.sap(5, acceleration), kOk);
  ASSERT_EQ(rig.sap(18, modules::tmcm142::kMaxBow), kOk);
}

TEST(Tmcm142RealNumbering, shaft_turns_the_motor_the_other_way_and_the_encoder_follows) {
  Tmcm142Rig rig;
  use_pps(rig, 200000, 1000000);
  ASSERT_EQ(rig.sap(19, 1), kOk);
  ASSERT_EQ(rig.command(4, 0, 0, 51200).status, kOk);
  rig.run_until([&] { return rig.gap(8) == 1; }, 2000);
  EXPECT_EQ(rig.gap(1), 51200);
  EXPECT_NEAR(rig.rotor_microsteps(), -51200.0, 0.01) << "the rotor turned backwards";
  EXPECT_NEAR(rig.gap(41), 51200, 52) << "the encoder counts with the mirrored axis";
  ASSERT_EQ(rig.sap(19, 0), kOk);
  ASSERT_EQ(rig.command(4, 0, 0, 102400).status, kOk);
  rig.run_until([&] { return rig.gap(8) == 1; }, 2000);
  EXPECT_NEAR(rig.rotor_microsteps(), 0.0, 0.01) << "forwards again by the same 51200";
}

TEST(Tmcm142RealNumbering, position_limits_clip_targets_and_stop_velocity_mode) {
  Tmcm142Rig rig;
  use_pps(rig, 100000, 1000000);
  ASSERT_EQ(rig.sap(50, 30000), kOk);
  ASSERT_EQ(rig.sap(51, -20000), kOk);
  // Not enabled yet: a move beyond runs through.
  ASSERT_EQ(rig.command(4, 0, 0, 40000).status, kOk);
  rig.run_until([&] { return rig.gap(8) == 1; }, 2000);
  EXPECT_EQ(rig.gap(1), 40000);
  ASSERT_EQ(rig.command(4, 0, 0, 0).status, kOk);
  rig.run_until([&] { return rig.gap(8) == 1; }, 2000);
  ASSERT_EQ(rig.sap(52, 1), kOk);
  ASSERT_EQ(rig.sap(53, 1), kOk);
  ASSERT_EQ(rig.command(4, 0, 0, 40000).status, kOk);
  EXPECT_EQ(rig.gap(0), 30000) << "target clipped to the right limit";
  rig.run_until([&] { return rig.gap(8) == 1; }, 2000);
  EXPECT_EQ(rig.gap(1), 30000);
  // Velocity mode to the left: stops at once on passing the left limit (hard stop, AP 14 = 0).
  ASSERT_EQ(rig.command(2, 0, 0, 100000).status, kOk);  // ROL
  rig.run_until([&] { return rig.gap(1) <= -20000; }, 3000);
  rig.run_ms(10);
  EXPECT_EQ(rig.gap(3), 0);
  EXPECT_LE(rig.gap(1), -20000);
  EXPECT_GE(rig.gap(1), -20000 - 6) << "within one tick's travel (5 µsteps at 100000 µsteps/s)";
  // Away from the limit still runs.
  ASSERT_EQ(rig.command(1, 0, 0, 100000).status, kOk);  // ROR
  rig.run_ms(200);
  EXPECT_GT(rig.gap(1), -10000);
}

TEST(Tmcm142RealNumbering, switch_status_has_one_bit_per_switch) {
  Tmcm142Rig rig;
  EXPECT_EQ(rig.gap(9), 0);
  rig.place_limit_switches(-1e9, -1.0);  // right switch closed at the start, left open
  rig.run_ms(1);
  EXPECT_EQ(rig.gap(9), 0b001);
  EXPECT_EQ(rig.gap(10), 1);
  rig.place_limit_switches(1.0, 1e9);  // left closed, right open
  rig.run_ms(1);
  EXPECT_EQ(rig.gap(9), 0b010);
  EXPECT_EQ(rig.sap(9, 0), kWrongType);
}

TEST(Tmcm142RealNumbering, warn_distance_sets_status_bit_3_without_stopping) {
  Tmcm142Rig rig;
  use_pps(rig, 100000, 1000000);
  ASSERT_EQ(rig.sap(47, 1000), kOk);
  rig.run_ms(1);
  EXPECT_EQ(rig.gap(129) & 8, 0);
  ASSERT_EQ(rig.sap(41, 1500), kOk);  // the encoder 1500 µsteps ahead of AP 1
  rig.run_ms(1);
  EXPECT_EQ(rig.gap(129) & 8, 8);
  ASSERT_EQ(rig.command(4, 0, 0, 10000).status, kOk);
  rig.run_until([&] { return rig.gap(8) == 1; }, 2000);
  EXPECT_EQ(rig.gap(1), 10000) << "a warning only: the move completes";
  EXPECT_EQ(rig.gap(207), 0);
  ASSERT_EQ(rig.sap(47, 2000), kOk);
  rig.run_ms(1);
  EXPECT_EQ(rig.gap(129) & 8, 0);
}

TEST(Tmcm142RealNumbering, compare_output_is_high_from_the_compare_position_on) {
  Tmcm142Rig rig;
  use_pps(rig, 100000, 1000000);
  ASSERT_EQ(rig.sap(48, 5000), kOk);
  rig.run_ms(1);
  EXPECT_EQ(rig.gap(26) & 4, 0);
  ASSERT_EQ(rig.command(4, 0, 0, 5000).status, kOk);
  rig.run_until([&] { return rig.gap(8) == 1; }, 2000);
  EXPECT_EQ(rig.gap(26) & 4, 4);
  ASSERT_EQ(rig.command(4, 0, 0, 4999).status, kOk);
  rig.run_until([&] { return rig.gap(8) == 1; }, 2000);
  EXPECT_EQ(rig.gap(26) & 4, 0);
}

TEST(Tmcm142RealNumbering, driver_status_shows_standby_and_undervoltage) {
  Tmcm142Rig rig;
  ASSERT_EQ(rig.sap(20, 10), kOk);  // 100 ms
  rig.run_ms(50);
  EXPECT_EQ(rig.gap(26) & 1, 0);
  rig.run_ms(60);
  EXPECT_EQ(rig.gap(26) & 1, 1) << "standby current after AP 20";
  EXPECT_EQ(rig.gap(26) & 2, 0);
  rig.stage.feedback.supply_millivolt = 12000;
  rig.module.tick_axis();
  EXPECT_EQ(rig.gap(26) & 2, 2);
}

TEST(Tmcm142RealNumbering, microstep_table_position_counts_1024_per_full_step) {
  Tmcm142Rig rig;
  use_pps(rig, 100000, 1000000);
  EXPECT_EQ(rig.gap(63), 0);
  ASSERT_EQ(rig.command(4, 0, 0, 256).status, kOk);
  rig.run_until([&] { return rig.gap(8) == 1; }, 1000);
  EXPECT_EQ(rig.gap(63), 256);
  ASSERT_EQ(rig.sap(27, 3), kOk);  // 256 microsteps: one is 4 table entries
  ASSERT_EQ(rig.command(4, 0, 0, 256 + 100).status, kOk);
  rig.run_until([&] { return rig.gap(8) == 1; }, 1000);
  EXPECT_EQ(rig.gap(63), 256 + 400);
  ASSERT_EQ(rig.command(4, 0, 0, 256 + 1024 + 100).status, kOk);  // one electrical period on
  rig.run_until([&] { return rig.gap(8) == 1; }, 2000);
  EXPECT_EQ(rig.gap(63), 256 + 400) << "the table wraps after 4096 entries";
}

TEST(Tmcm142RealNumbering, null_channel_latches_encoder_and_position) {
  Tmcm142Rig rig;
  auto config = rig.sensors.config();
  config.encoder.index_revolutions = 0.25;
  rig.sensors.set_config(config);
  use_pps(rig, 100000, 1000000);
  ASSERT_EQ(rig.sap(43, 2), kOk);  // latch at each N pulse
  ASSERT_EQ(rig.command(4, 0, 0, 102400).status, kOk);  // half a revolution, past 0.25
  rig.run_until([&] { return rig.gap(8) == 1; }, 3000);
  EXPECT_EQ(rig.gap(45), 51200) << "the encoder position at the pulse";
  EXPECT_NEAR(rig.gap(46), 51200, 5) << "the actual position in the tick of the pulse";
  EXPECT_EQ(rig.gap(44), 1);
  EXPECT_EQ(rig.gap(44), 0) << "cleared by reading";
  // Bit 2: the encoder restarts from 0 at the pulse (the next one is at 1.25 revolutions).
  ASSERT_EQ(rig.sap(43, 6), kOk);
  ASSERT_EQ(rig.command(4, 0, 0, 204800 + 51200 + 10000).status, kOk);
  rig.run_until([&] { return rig.gap(8) == 1; }, 5000);
  EXPECT_NEAR(rig.gap(41), 10000, 52);
  EXPECT_EQ(rig.gap(45), 256000);
}

TEST(Tmcm142RealNumbering, new_stored_settings_survive_a_power_up) {
  Tmcm142Rig rig;
  const uint8_t stored[] = {17, 18, 19, 20, 21, 22, 23, 28, 29, 43, 47, 48, 50, 51, 52, 53, 64};
  const int32_t values[] = {500, 2000, 1, 30, 1, 1, 7, 12, 3, 5, 900, -4000, 60000, -60000, 1, 1, 20};
  for (size_t i = 0; i < sizeof stored; ++i) {
    ASSERT_EQ(rig.sap(stored[i], values[i]), kOk) << "AP " << int{stored[i]};
    ASSERT_EQ(rig.command(7, stored[i], 0, 0).status, kOk) << "STAP " << int{stored[i]};
  }
  for (const uint8_t number : {68, 81, 82, 83, 87}) ASSERT_EQ(rig.sgp(number, 0, 2), kOk) << "GP " << int{number};
  rig.engine.power_up();
  for (size_t i = 0; i < sizeof stored; ++i) EXPECT_EQ(rig.gap(stored[i]), values[i]) << "AP " << int{stored[i]};
  for (const uint8_t number : {68, 81, 82, 83, 87}) EXPECT_EQ(rig.ggp(number), 2) << "GP " << int{number};
  EXPECT_EQ(rig.command(7, 16, 0, 0).status, kWrongType) << "AP 16 is stored with AP 5";
}

TEST(Tmcm142RealNumbering, pid_tolerance_hides_a_small_error_from_the_easy_pid) {
  Tmcm142Rig rig;
  ASSERT_EQ(rig.sap(40, 1), kOk);   // easyPID, P = 65536 (factory)
  ASSERT_EQ(rig.sap(41, 100), kOk);  // the encoder 100 µsteps ahead of AP 1
  rig.tick();
  EXPECT_EQ(rig.gap(38), 100);
  EXPECT_EQ(rig.gap(39), -100 * 65536 / 256) << "P part: -pid_e * P / 256";
  ASSERT_EQ(rig.sap(41, 100), kOk);
  ASSERT_EQ(rig.sap(28, 100), kOk);
  rig.tick();
  EXPECT_EQ(rig.gap(38), 0) << "AP 38 shows the error the loop sees";
  EXPECT_EQ(rig.gap(39), 0) << "within the tolerance: no correction";
}

TEST(Tmcm142RealNumbering, gp_131_keeps_the_status_of_the_last_failed_command) {
  Tmcm142Rig rig;
  EXPECT_EQ(rig.ggp(131), 0);
  EXPECT_EQ(rig.sap(27, 0), 4);       // invalid value
  EXPECT_EQ(rig.ggp(131), 4);
  EXPECT_EQ(rig.sap(4, 1000), kOk);  // a success leaves it
  EXPECT_EQ(rig.ggp(131), 4);
  EXPECT_EQ(rig.sap(24, 0), kWrongType);
  EXPECT_EQ(rig.ggp(131), 3);
  EXPECT_EQ(rig.command(200, 0, 0, 0).status, 2);  // no such command
  EXPECT_EQ(rig.ggp(131), 2);
  EXPECT_EQ(rig.sgp(131, 0, 0), kWrongType) << "read-only";
  rig.engine.power_up();
  EXPECT_EQ(rig.ggp(131), 0);
}

// An image as layout 1 left it: its slots are its parameter numbers.
TEST(Tmcm142RealNumbering, layout_1_image_migrates_to_the_real_numbers) {
  Tmcm142Nvm nvm;
  Tmcm142::format_factory_image(nvm.mutable_data(), nvm.size());
  constexpr tmcl::NvmLayout layout = Tmcm142::kNvmLayout;
  uint8_t* image = nvm.mutable_data();
  const auto put_axis = [&](uint8_t number, int32_t value) { tmcl::put_le32(image + layout.axis_parameter(0, number), value); };
  // Layout 1's rows that moved, with what its factory image left in the new rows' slots (0).
  put_axis(16, 900);
  put_axis(17, 700);
  put_axis(18, 1200);
  put_axis(19, 800);
  put_axis(46, 1);
  put_axis(214, 75);
  put_axis(20, 0);
  put_axis(43, 0);
  put_axis(5, 30000);
  tmcl::put_le32(image + layout.global_parameter(66), 4);
  ASSERT_FALSE(Tmcm142::migrate_image(3, image, nvm.size())) << "an unknown layout";
  ASSERT_FALSE(Tmcm142::migrate_image(1, image, nvm.size() - 1));
  ASSERT_TRUE(Tmcm142::migrate_image(1, image, nvm.size()));

  ScriptedTmcm142Io io;
  board::StepperPowerStage stage;
  Tmcm142 module(nvm, stage, io);
  module.engine().power_up();
  const auto gap = [&](uint8_t number) {
    int32_t value = 0;
    EXPECT_EQ(module.get_axis_parameter(number, 0, value), tmcl::Status::kOk) << "AP " << int{number};
    return value;
  };
  EXPECT_EQ(gap(5), 30000);
  EXPECT_EQ(gap(16), 30000) << "AP 16 is AP 5";
  EXPECT_EQ(gap(17), 0) << "deceleration as the acceleration, as layout 1 always had it";
  EXPECT_EQ(gap(18), 700) << "the gentlest of the four bows";
  EXPECT_EQ(gap(19), 0) << "shaft not inverted";
  EXPECT_EQ(gap(20), 75) << "standby delay from AP 214";
  EXPECT_EQ(gap(43), 1) << "encoder direction AP 46 became encoder mode bit 0";
  EXPECT_EQ(gap(46), 0) << "position latch, not a stored setting";
  int32_t address = 0;
  EXPECT_EQ(module.get_global_parameter(66, 0, address), tmcl::Status::kOk);
  EXPECT_EQ(address, 4);
}

}  // namespace
}  // namespace motwin::testing
