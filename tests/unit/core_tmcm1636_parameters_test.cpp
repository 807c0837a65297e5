// The TMCM-1636 tables against manual tables 11 and 13, and the storage commands.
#include <gtest/gtest.h>

#include <set>

#include "support/tmcm1636_rig.h"

namespace motwin::testing {
namespace {

using params::Access;
using params::has;

TEST(Tmcm1636Parameters, axis_table_has_every_row_of_manual_table_11) {
  const std::set<int> manual = {0,   1,   2,   3,   4,   5,   6,   7,   10,  11,  12,  14,  15,  16,  17,  18,
                                19,  25,  30,  31,  32,  33,  40,  41,  42,  43,  44,  45,  50,  51,  52,  53,
                                54,  55,  70,  71,  72,  73,  74,  75,  76,  77,  78,  79,  80,  81,  90,  91,
                                92,  93,  100, 101, 102, 103, 104, 105, 106, 107, 108, 110, 120, 121, 122, 123,
                                124, 125, 140, 141, 142, 144, 156, 160, 161, 162, 163, 209, 210, 211, 212, 213,
                                220, 221, 230, 231, 232, 240, 241, 242, 243, 244, 245, 246, 247, 248, 249, 255};
  std::set<int> table;
  for (const auto& row : Tmcm1636::axis_parameters().rows()) table.insert(row.info.number);
  EXPECT_EQ(table, manual);
}

TEST(Tmcm1636Parameters, global_table_has_table_13_plus_gp_85_and_129) {
  // GP 85 is described in manual 6.4, GP 129 (download mode) in docs/tmcl-protocol.md
  // "Control commands"; GP 67 (ASCII interface) is a Motwin extension (docs/ascii-mode.md).
  std::set<int> table;
  for (const auto& row : Tmcm1636::global_parameters().rows()) table.insert(row.info.number);
  EXPECT_EQ(table, (std::set<int>{65, 66, 67, 69, 70, 71, 75, 76, 77, 85, 128, 129, 130, 132}));
}

TEST(Tmcm1636Parameters, every_writable_stored_parameter_reads_its_default_after_power_up) {
  Tmcm1636Rig rig;
  for (const auto& row : Tmcm1636::axis_parameters().rows()) {
    if (!has(row.info.access, Access::kEeprom)) continue;
    EXPECT_EQ(rig.gap(static_cast<uint8_t>(row.info.number)), row.info.default_value) << row.info.name;
  }
  for (const auto& row : Tmcm1636::global_parameters().rows()) {
    if (!has(row.info.access, Access::kAutoStore)) continue;
    EXPECT_EQ(rig.command(10, static_cast<uint8_t>(row.info.number), 0, 0).value, row.info.default_value) << row.info.name;
  }
}

TEST(Tmcm1636Parameters, every_range_limit_is_enforced_for_every_writable_row) {
  Tmcm1636Rig rig;
  for (const auto& row : Tmcm1636::axis_parameters().rows()) {
    if (!has(row.info.access, Access::kWrite)) continue;
    const auto n = static_cast<uint8_t>(row.info.number);
    if (row.info.min > INT32_MIN) {
      EXPECT_EQ(rig.command(5, n, 0, static_cast<int32_t>(row.info.min - 1)).status, 4) << row.info.name;
    }
    if (row.info.max < INT32_MAX) {
      EXPECT_EQ(rig.command(5, n, 0, static_cast<int32_t>(row.info.max + 1)).status, 4) << row.info.name;
    }
    EXPECT_EQ(rig.command(5, n, 0, static_cast<int32_t>(row.info.max)).status, 100) << row.info.name;
    if (n != 50 && n != 52) {
      EXPECT_EQ(rig.gap(n), row.info.max) << row.info.name;
    }
  }
}

TEST(Tmcm1636Parameters, stap_and_rsap_round_trip_through_the_eeprom) {
  Tmcm1636Rig rig;
  ASSERT_EQ(rig.command(5, 43, 0, 1500).status, 100);
  ASSERT_EQ(rig.command(7, 43, 0, 0).status, 100);
  ASSERT_EQ(rig.command(5, 43, 0, 2500).status, 100);
  EXPECT_EQ(rig.gap(43), 2500);
  ASSERT_EQ(rig.command(8, 43, 0, 0).status, 100);
  EXPECT_EQ(rig.gap(43), 1500);
}

TEST(Tmcm1636Parameters, power_up_restores_stored_and_drops_unstored_values) {
  Tmcm1636Rig rig;
  rig.command(5, 43, 0, 1500);
  rig.command(7, 43, 0, 0);
  rig.command(5, 44, 0, 777);  // not stored
  rig.command(9, 10, 2, -42);
  rig.command(11, 10, 2, 0);
  rig.command(9, 60, 2, 99);  // variable 60 cannot be stored
  EXPECT_EQ(rig.command(11, 60, 2, 0).status, 3);
  rig.command(240, 0, 0, 0);
  const auto reset = rig.send(tmcl::encode_request(1, tmcl::Instruction{255, 0, 0, 1234}));
  ASSERT_EQ(reset.length, 9u);
  EXPECT_TRUE(reset.reset_after_send);
  EXPECT_EQ(rig.gap(43), 1500) << "reset only once the reply has gone out";
  rig.engine.complete_reset();
  EXPECT_EQ(rig.gap(43), 1500);
  EXPECT_EQ(rig.gap(44), 2000);
  EXPECT_EQ(rig.command(10, 10, 2, 0).value, -42);
  EXPECT_EQ(rig.command(10, 60, 2, 0).value, 0);
}

TEST(Tmcm1636Parameters, bank_0_writes_are_stored_automatically) {
  Tmcm1636Rig rig;
  ASSERT_EQ(rig.command(9, 77, 0, 0).status, 100);
  ASSERT_EQ(rig.command(9, 75, 0, 20).status, 100);
  rig.engine.power_up();
  EXPECT_EQ(rig.command(10, 77, 0, 0).value, 0);
  EXPECT_EQ(rig.command(10, 75, 0, 0).value, 20);
  EXPECT_EQ(rig.send(tmcl::encode_request(1, tmcl::Instruction{10, 75, 0, 0})).delay_ms, 20) << "GP 75 delays replies";
}

TEST(Tmcm1636Parameters, factory_defaults_restore_everything_and_send_no_reply) {
  Tmcm1636Rig rig;
  rig.command(5, 43, 0, 1500);
  rig.command(7, 43, 0, 0);
  rig.command(9, 66, 0, 5);
  const auto response = rig.send(tmcl::encode_request(5, tmcl::Instruction{137, 0, 0, 1234}));
  EXPECT_EQ(response.length, 0u);
  EXPECT_EQ(rig.gap(43), 4000);
  EXPECT_EQ(rig.command(10, 66, 0, 0).value, 1) << "address back to 1";
  rig.engine.power_up();
  EXPECT_EQ(rig.gap(43), 4000) << "and stored as such";
}

TEST(Tmcm1636Parameters, out_of_range_stored_values_are_not_loaded) {
  Tmcm1636Rig rig;
  tmcl::put_le32(rig.nvm.mutable_data() + Tmcm1636::kNvmLayout.axis_parameter(0, 43), 999999);
  rig.engine.power_up();
  EXPECT_EQ(rig.gap(43), 4000);
  EXPECT_EQ(rig.command(8, 43, 0, 0).status, 4);
}

TEST(Tmcm1636Parameters, supply_voltage_and_temperature_come_from_the_adc_channels) {
  Tmcm1636Rig rig;
  rig.io.analog_inputs[2] = modules::tmcm1636::supply_adc_from_millivolt(48000);
  rig.io.analog_inputs[3] = modules::tmcm1636::temperature_adc_from_celsius(61.0);
  EXPECT_EQ(rig.gap(220), 480);
  EXPECT_EQ(rig.gap(221), 61);
  EXPECT_EQ(rig.command(15, 2, 1, 0).value, rig.io.analog_inputs[2]);
}

TEST(Tmcm1636Parameters, io_banks_read_inputs_and_outputs) {
  Tmcm1636Rig rig;
  rig.io.digital_inputs[3] = true;
  EXPECT_EQ(rig.command(15, 3, 0, 0).value, 1);
  EXPECT_EQ(rig.command(15, 2, 0, 0).value, 0);
  EXPECT_EQ(rig.command(14, 1, 2, 1).status, 100);
  EXPECT_TRUE(rig.io.outputs[1]);
  EXPECT_EQ(rig.command(15, 1, 2, 0).value, 1);
}

TEST(Tmcm1636Parameters, tick_timer_counts_milliseconds_and_is_writable) {
  Tmcm1636Rig rig;
  rig.run_ms(250);
  EXPECT_EQ(rig.command(10, 132, 0, 0).value, 250);
  rig.command(9, 132, 0, 1000);
  rig.run_ms(5);
  EXPECT_EQ(rig.command(10, 132, 0, 0).value, 1005);
}

TEST(Tmcm1636Parameters, direct_mode_reads_never_touch_the_accumulator) {
  Tmcm1636Rig rig;
  rig.command(19, 9, 0, 77);  // CALC LOAD 77
  rig.gap(43);
  rig.command(10, 66, 0, 0);
  rig.command(15, 0, 1, 0);
  EXPECT_EQ(rig.module.runtime().accumulator, 77);
  const auto result = rig.engine.execute(tmcl::Instruction{6, 43, 0, 0}, tmcl::Origin::kHost);
  EXPECT_TRUE(result.loads_accumulator) << "a program would load it";
  EXPECT_EQ(result.value, 4000);
}

}  // namespace
}  // namespace motwin::testing
