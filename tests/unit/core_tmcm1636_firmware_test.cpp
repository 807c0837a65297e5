// The TMCM-1636's firmware generations (docs/tmcm-1636.md "Firmware generations"): 1.09, the
// default, and 1.13 with its other axis-parameter rows, one module chosen at construction.
#include <gtest/gtest.h>

#include <string>

#include "support/tmcm1636_rig.h"

namespace motwin::testing {
namespace {

using modules::tmcm1636::Firmware;

constexpr uint8_t kSap = 5;
constexpr uint8_t kGap = 6;
constexpr uint8_t kStap = 7;
constexpr uint8_t kVersion = 136;
constexpr uint8_t kOk = 100;
constexpr uint8_t kWrongType = 3;
constexpr uint8_t kInvalidValue = 4;

std::string version_string(Tmcm1636Rig& rig) {
  const tmcl::SerialResponse response = rig.send(tmcl::encode_request(1, tmcl::Instruction{kVersion, 0, 0, 0}));
  return std::string(response.bytes.begin() + 1, response.bytes.begin() + 9);
}

TEST(Tmcm1636Firmware, command_136_answers_each_generations_version) {
  Tmcm1636Rig v109;
  EXPECT_EQ(version_string(v109), "1636V109");
  EXPECT_EQ(v109.command(kVersion, 1, 0, 0).value, 0x06640109);
  Tmcm1636Rig v113(Firmware::kV113);
  EXPECT_EQ(version_string(v113), "1636V113");
  EXPECT_EQ(v113.command(kVersion, 1, 0, 0).value, 0x0664010D);
  EXPECT_EQ(v113.module.firmware(), Firmware::kV113);
}

TEST(Tmcm1636Firmware, ap26_exists_on_1_13_only_and_ap7_on_1_09_only) {
  Tmcm1636Rig v109;
  EXPECT_EQ(v109.command(kGap, 26, 0, 0).status, kWrongType);
  EXPECT_EQ(v109.command(kSap, 26, 0, 1).status, kWrongType);
  EXPECT_EQ(v109.command(kGap, 7, 0, 0).status, kOk);
  EXPECT_EQ(v109.gap(7), 256);
  Tmcm1636Rig v113(Firmware::kV113);
  EXPECT_EQ(v113.command(kGap, 26, 0, 0).status, kOk);
  EXPECT_EQ(v113.gap(26), 0);
  EXPECT_EQ(v113.command(kSap, 26, 0, 2).status, kOk);
  EXPECT_EQ(v113.gap(26), 2);
  EXPECT_EQ(v113.command(kGap, 7, 0, 0).status, kWrongType);
  EXPECT_EQ(v113.command(kSap, 7, 0, 256).status, kWrongType);
  EXPECT_EQ(v113.command(kStap, 7, 0, 0).status, kWrongType);
}

TEST(Tmcm1636Firmware, every_added_row_is_missing_on_1_09) {
  Tmcm1636Rig v109;
  for (uint8_t number : {13, 26, 56, 94, 109, 165, 166, 167}) {
    EXPECT_EQ(v109.command(kGap, number, 0, 0).status, kWrongType) << "AP " << int{number};
  }
}

TEST(Tmcm1636Firmware, added_rows_have_their_defaults_and_ranges_on_1_13) {
  Tmcm1636Rig rig(Firmware::kV113);
  struct Expected {
    uint8_t number;
    int32_t default_value;
    int32_t min;
    int32_t max;
  };
  for (const Expected& row : {Expected{13, 0, 0, 1}, Expected{26, 0, 0, 2}, Expected{56, 65536, 1, 16777215},
                              Expected{165, 16, 1, 32}, Expected{166, 0, 0, 31}, Expected{167, 16, 1, 32}}) {
    SCOPED_TRACE(row.number);
    EXPECT_EQ(rig.command(kGap, row.number, 0, 0).status, kOk);
    EXPECT_EQ(rig.gap(row.number), row.default_value);
    EXPECT_EQ(rig.command(kSap, row.number, 0, row.min - 1).status, kInvalidValue);
    EXPECT_EQ(rig.command(kSap, row.number, 0, row.max + 1).status, kInvalidValue);
    EXPECT_EQ(rig.gap(row.number), row.default_value) << "nothing changes on error";
    EXPECT_EQ(rig.command(kSap, row.number, 0, row.max).status, kOk);
    EXPECT_EQ(rig.gap(row.number), row.max);
  }
  // The input levels are read-only; the ideal motor has no sensors behind them.
  for (uint8_t number : {94, 109}) {
    EXPECT_EQ(rig.command(kGap, number, 0, 0).status, kOk);
    EXPECT_EQ(rig.gap(number), 0);
    EXPECT_EQ(rig.command(kSap, number, 0, 1).status, kWrongType);
  }
}

TEST(Tmcm1636Firmware, added_settings_are_stored_and_restored) {
  Tmcm1636Rig rig(Firmware::kV113);
  ASSERT_EQ(rig.command(kSap, 56, 0, 4096).status, kOk);
  ASSERT_EQ(rig.command(kStap, 56, 0, 0).status, kOk);
  ASSERT_EQ(rig.command(kSap, 56, 0, 8192).status, kOk);
  rig.engine.power_up();
  EXPECT_EQ(rig.gap(56), 4096);
}

// The rows share the image's slots, so another generation on an image behaves like a firmware
// update: common parameters keep their stored values, new ones start at their defaults.
TEST(Tmcm1636Firmware, a_1_09_image_starts_1_13_with_defaults_for_the_new_rows) {
  Tmcm1636Nvm nvm;
  ScriptedTmcm1636Io io;
  Tmcm1636::format_factory_image(nvm.mutable_data(), nvm.size(), Tmcm1636::axis_parameters(Firmware::kV109));
  {
    Tmcm1636 old_firmware(nvm, io, Firmware::kV109);
    old_firmware.engine().power_up();
    ASSERT_EQ(old_firmware.set_axis_parameter(43, 0, 1234), tmcl::Status::kOk);
    ASSERT_EQ(old_firmware.store_axis_parameter(43, 0), tmcl::Status::kOk);
  }
  Tmcm1636 new_firmware(nvm, io, Firmware::kV113);
  new_firmware.engine().power_up();
  const auto ap = [&](uint8_t number) {
    int32_t value = 0;
    EXPECT_EQ(new_firmware.get_axis_parameter(number, 0, value), tmcl::Status::kOk) << int{number};
    return value;
  };
  EXPECT_EQ(ap(43), 1234);
  for (const auto& row : Tmcm1636::axis_parameters(Firmware::kV113).rows()) {
    if (Tmcm1636::axis_parameters(Firmware::kV109).find(row.info.number) != nullptr) continue;
    if (!tmcl::is_stored_parameter(row.info)) continue;
    EXPECT_EQ(ap(static_cast<uint8_t>(row.info.number)), row.info.default_value) << "AP " << row.info.number;
  }
}

// What the host does when the image records the other generation: rows new to the running one
// get their defaults even where the slot holds something a value in range (left by the other
// generation, or by a 1.13 factory reset that wrote 0 over AP 7); shared rows stay.
TEST(Tmcm1636Firmware, a_firmware_update_gives_the_new_rows_their_defaults_and_keeps_the_rest) {
  constexpr tmcl::NvmLayout kLayout = Tmcm1636::kNvmLayout;
  Tmcm1636Nvm nvm;
  Tmcm1636::format_factory_image(nvm.mutable_data(), nvm.size(), Tmcm1636::axis_parameters(Firmware::kV109));
  const auto slot = [&](uint32_t offset) { return tmcl::get_le32(nvm.data() + offset); };
  const auto put = [&](uint32_t offset, int32_t value) {
    uint8_t bytes[4];
    tmcl::put_le32(bytes, value);
    ASSERT_TRUE(nvm.write(offset, bytes, sizeof bytes));
  };
  put(kLayout.axis_parameter(0, 56), 24);    // in AP 56's range: power-up alone would take it
  put(kLayout.axis_parameter(0, 13), 1);     // likewise AP 13
  put(kLayout.axis_parameter(0, 7), 300);    // 1.09's dual shunt factor, as stored
  put(kLayout.axis_parameter(0, 43), 1234);  // a row both generations have
  put(kLayout.global_parameter(77), 0);
  put(kLayout.user_variable(3), -5);

  ASSERT_TRUE(Tmcm1636::update_image_for_firmware(nvm, Tmcm1636::axis_parameters(Firmware::kV109),
                                                  Tmcm1636::axis_parameters(Firmware::kV113)));
  EXPECT_EQ(slot(kLayout.axis_parameter(0, 56)), 65536);
  EXPECT_EQ(slot(kLayout.axis_parameter(0, 13)), 0);
  EXPECT_EQ(slot(kLayout.axis_parameter(0, 7)), 300);  // 1.13 leaves a slot it has no row for alone
  EXPECT_EQ(slot(kLayout.axis_parameter(0, 43)), 1234);
  EXPECT_EQ(slot(kLayout.global_parameter(77)), 0);
  EXPECT_EQ(slot(kLayout.user_variable(3)), -5);

  // And back: AP 7 is new to 1.09 coming from 1.13, whatever its slot holds.
  ASSERT_TRUE(Tmcm1636::update_image_for_firmware(nvm, Tmcm1636::axis_parameters(Firmware::kV113),
                                                  Tmcm1636::axis_parameters(Firmware::kV109)));
  EXPECT_EQ(slot(kLayout.axis_parameter(0, 7)), 256);
  EXPECT_EQ(slot(kLayout.axis_parameter(0, 43)), 1234);
  EXPECT_EQ(slot(kLayout.axis_parameter(0, 56)), 65536);  // 1.09 has no AP 56: the slot is kept
}

// AP 56 = AP 100 (8192, the factory encoder steps): the host counts as the axis does, so that
// these tests see the direction alone (the scaler: ap56_...).
void count_positions_as_the_axis(Tmcm1636Rig& rig) { ASSERT_EQ(rig.command(kSap, 56, 0, 8192).status, kOk); }

TEST(Tmcm1636Firmware, ap13_inverts_the_motion_of_the_ideal_motor) {
  Tmcm1636Rig rig(Firmware::kV113);
  count_positions_as_the_axis(rig);
  ASSERT_EQ(rig.command(kSap, 13, 0, 1).status, kOk);
  ASSERT_EQ(rig.command(1, 0, 0, 1000).status, kOk);  // ROR 1000
  rig.run_ms(1000);
  // The host's frame stays its own: velocity and target as commanded, position growing ...
  EXPECT_EQ(rig.gap(40), 1000);
  EXPECT_EQ(rig.gap(42), 1000);
  EXPECT_EQ(rig.gap(41), 1000);
  EXPECT_GT(rig.gap(52), 0);
  // ... while the motor turns the other way.
  EXPECT_EQ(rig.module.axis().state.actual_velocity_rpm, -1000);
  EXPECT_LT(rig.module.axis().state.actual_position, 0);
  EXPECT_EQ(rig.module.axis().state.actual_position, -rig.gap(52));

  ASSERT_EQ(rig.command(4, 0, 0, 5000).status, kOk);  // MVP ABS 5000
  rig.run_ms(3000);
  EXPECT_EQ(rig.gap(50), 5000);
  EXPECT_EQ(rig.gap(52), 5000);
  EXPECT_EQ(rig.gap(55), 1);
  EXPECT_EQ(rig.module.axis().state.actual_position, -5000);
  ASSERT_EQ(rig.command(4, 1, 0, -1000).status, kOk);  // MVP REL from the host's position
  EXPECT_EQ(rig.gap(50), 4000);
  rig.run_ms(2000);
  EXPECT_EQ(rig.gap(52), 4000);
  EXPECT_EQ(rig.module.axis().state.actual_position, -4000);

  // Writing the actual position and the torque target go through the same inversion.
  ASSERT_EQ(rig.command(kSap, 52, 0, 100).status, kOk);
  EXPECT_EQ(rig.gap(52), 100);
  EXPECT_EQ(rig.module.axis().state.actual_position, -100);
  ASSERT_EQ(rig.command(kSap, 30, 0, 500).status, kOk);
  EXPECT_EQ(rig.gap(30), 500);
  EXPECT_EQ(rig.module.axis().state.target_torque_ma, -500);
}

TEST(Tmcm1636Firmware, ap13_at_0_leaves_the_motion_as_on_1_09) {
  Tmcm1636Rig rig(Firmware::kV113);
  count_positions_as_the_axis(rig);
  ASSERT_EQ(rig.command(1, 0, 0, 1000).status, kOk);
  rig.run_ms(1000);
  EXPECT_EQ(rig.gap(42), 1000);
  EXPECT_EQ(rig.module.axis().state.actual_velocity_rpm, 1000);
  EXPECT_EQ(rig.module.axis().state.actual_position, rig.gap(52));
}

// AP 56 (docs/tmcm-1636.md "Firmware generations"): the host's positions count AP 56 per
// revolution, the axis AP 100, whatever the sensor; AP 53 is in the host's counts too. The
// factory values (65536 and 8192) make one host count an eighth of an encoder count.
TEST(Tmcm1636Firmware, ap56_scales_the_positions_the_host_sees_and_commands) {
  Tmcm1636Rig rig(Firmware::kV113);
  ASSERT_EQ(rig.command(4, 0, 0, 65536).status, kOk);  // MVP ABS: one revolution
  rig.run_ms(3000);
  EXPECT_EQ(rig.module.axis().state.actual_position, 8192);
  EXPECT_EQ(rig.gap(50), 65536);
  EXPECT_EQ(rig.gap(52), 65536);
  EXPECT_EQ(rig.gap(55), 1);
  ASSERT_EQ(rig.command(4, 1, 0, -32768).status, kOk);  // MVP REL: half a revolution back
  EXPECT_EQ(rig.gap(50), 32768);
  rig.run_ms(2000);
  EXPECT_EQ(rig.module.axis().state.actual_position, 4096);

  // The examples' setting: hall steps per revolution on a 4096-count encoder (a host count is
  // 170.67 encoder counts), MVP 4000 as hall_position_mode sends it.
  ASSERT_EQ(rig.command(kSap, 100, 0, 4096).status, kOk);
  ASSERT_EQ(rig.command(kSap, 56, 0, 24).status, kOk);
  ASSERT_EQ(rig.command(kSap, 52, 0, 0).status, kOk);
  EXPECT_EQ(rig.module.axis().state.actual_position, 0);
  ASSERT_EQ(rig.command(4, 0, 0, 4000).status, kOk);
  EXPECT_EQ(rig.module.axis().target_position(), 682667);  // 4000 * 4096 / 24, rounded
  rig.run_ms(12000);  // 166.7 revolutions at AP 43's 2000 rpm (factory ramp)
  EXPECT_EQ(rig.gap(52), 4000);
  EXPECT_EQ(rig.gap(55), 1);
  // AP 53 = 1 host count (the factory 5 would be 853 encoder counts): a target one host count
  // away (170 encoder counts) is within it, two (341) are not. The ideal motor updates AP 55 as
  // the target is written.
  ASSERT_EQ(rig.command(kSap, 53, 0, 1).status, kOk);
  ASSERT_EQ(rig.command(kSap, 50, 0, 4001).status, kOk);
  EXPECT_EQ(rig.module.axis().target_position(), 682837);
  EXPECT_EQ(rig.gap(55), 1);
  ASSERT_EQ(rig.command(kSap, 50, 0, 4002).status, kOk);
  EXPECT_EQ(rig.gap(55), 0);
}

TEST(Tmcm1636Firmware, positions_on_1_09_are_the_axis_counts_whatever_ap56_would_say) {
  Tmcm1636Rig rig;  // 1.09: no AP 56
  ASSERT_EQ(rig.command(4, 0, 0, 65536).status, kOk);
  rig.run_ms(9000);
  EXPECT_EQ(rig.module.axis().state.actual_position, 65536);
  EXPECT_EQ(rig.gap(52), 65536);
}

}  // namespace
}  // namespace motwin::testing
