// TMCM-142 parameter tables: identity, defaults, ranges and status codes, unit mode AP 255,
// storage and power-up, GP 64 (EEPROM magic), GP 73 (EEPROM lock), and the TMCM-1636 still
// refusing the TMCM-142-only commands.
#include <cmath>
#include <string_view>

#include <gtest/gtest.h>

#include "core/modules/tmcm142/tmcm142_hardware.h"
#include "host/module_registry.h"
#include "support/tmcm142_rig.h"
#include "tools/parameter_listing.h"
#include "support/tmcm1636_rig.h"

namespace motwin::testing {
namespace {

using modules::tmcm142::kPpsPerVelocityUnit;

constexpr uint8_t kOk = 100;
constexpr uint8_t kInvalidCommand = 2;
constexpr uint8_t kWrongType = 3;
constexpr uint8_t kInvalidValue = 4;
constexpr uint8_t kEepromLocked = 5;

TEST(Tmcm142Parameters, identity_is_142_v1_06) {
  Tmcm142Rig rig;
  const auto reply = rig.command(136, 1, 0, 0);
  EXPECT_EQ(reply.status, kOk);
  EXPECT_EQ(reply.value, (142 << 16) | (1 << 8) | 6);
  EXPECT_EQ(std::string_view(Tmcm142::kIdentity.version_string), "142V1.06");
  EXPECT_EQ(std::string_view(Tmcm142::kIdentity.version_string).find('B'), std::string_view::npos);
}

TEST(Tmcm142Parameters, every_stored_parameter_reads_its_default_after_power_up) {
  Tmcm142Rig rig;
  int checked = 0;
  for (const auto& row : Tmcm142::axis_parameters().rows()) {
    if (!tmcl::is_stored_parameter(row.info)) continue;
    EXPECT_EQ(rig.gap(static_cast<uint8_t>(row.info.number)), row.info.default_value) << "AP " << row.info.number;
    ++checked;
  }
  for (const auto& row : Tmcm142::global_parameters().rows()) {
    if (!tmcl::is_stored_parameter(row.info)) continue;
    EXPECT_EQ(rig.ggp(static_cast<uint8_t>(row.info.number)), row.info.default_value) << "GP " << row.info.number;
    ++checked;
  }
  EXPECT_GE(checked, 40);
}

TEST(Tmcm142Parameters, motwin_decisions_are_tagged) {
  int decisions = 0;
  for (const auto& row : Tmcm142::axis_parameters().rows()) decisions += params::is_motwin_decision(row.info.description) ? 1 : 0;
  // What no public page gives: 9, 14, 16, 17, 18, 20..23, 26, 28..31, 43, 44, 47, 48, 63, 64.
  EXPECT_EQ(decisions, 20);
  EXPECT_TRUE(params::is_motwin_decision(Tmcm142::axis_parameters().find(18)->info.description));
  EXPECT_FALSE(params::is_motwin_decision(Tmcm142::axis_parameters().find(4)->info.description));
  EXPECT_FALSE(params::is_motwin_decision(Tmcm142::axis_parameters().find(212)->info.description));
}

TEST(Tmcm142Parameters, motwin_params_lists_the_table_with_the_decisions_marked) {
  const host::ModuleDescriptor* source = host::find_module_ignoring_case("tmcm-142");
  ASSERT_NE(source, nullptr);
  const host::ModuleParameterListing listing = source->listing();
  ASSERT_EQ(listing.sections.size(), 3u);
  const std::string table = tools::format_parameter_listing(listing, tools::ListingFormat::kTable);
  EXPECT_NE(table.find("[Motwin decision] jerk of all four changes of acceleration"), std::string::npos);
  EXPECT_NE(table.find("max velocity"), std::string::npos);
  EXPECT_NE(table.find("0..55"), std::string::npos);  // storable user variables
}

TEST(Tmcm142Parameters, bad_values_answer_their_status_and_change_nothing) {
  Tmcm142Rig rig;
  EXPECT_EQ(rig.sap(27, 0), kInvalidValue);   // 2048 microsteps refused
  EXPECT_EQ(rig.sap(27, 12), kInvalidValue);
  EXPECT_EQ(rig.gap(27), 1);
  EXPECT_EQ(rig.sap(27, 4), kOk);              // 128 microsteps
  EXPECT_EQ(rig.module.axis().microsteps_per_full_step(), 128u);
  EXPECT_EQ(rig.sap(128, 1), kInvalidValue);   // ramp mode 1 does not exist
  EXPECT_EQ(rig.gap(128), 0);
  EXPECT_EQ(rig.sap(6, 16), kInvalidValue);
  EXPECT_EQ(rig.sap(5, 0), kInvalidValue);
  EXPECT_EQ(rig.sap(16, 0), kInvalidValue);
  EXPECT_EQ(rig.sap(3, 5), kWrongType);        // read-only
  EXPECT_EQ(rig.sap(9, 5), kWrongType);        // switch status: read-only
  EXPECT_EQ(rig.sap(24, 5), kWrongType);       // no such parameter (the real list skips 24, 25)
  EXPECT_EQ(rig.command(6, 24, 0, 0).status, kWrongType);
  EXPECT_EQ(rig.command(5, 4, 1, 100).status, kInvalidValue);  // motor 1
  EXPECT_EQ(rig.command(7, 0, 0, 0).status, kWrongType);        // STAP of a parameter without E
  EXPECT_EQ(rig.gap(6), 5);
}

TEST(Tmcm142Parameters, current_codes_scale_the_peak_current_in_16_steps) {
  EXPECT_EQ(modules::tmcm142::current_ma_of_code(0), 437);
  EXPECT_EQ(modules::tmcm142::current_ma_of_code(5), 2625);
  EXPECT_EQ(modules::tmcm142::current_ma_of_code(15), 7000);
}

TEST(Tmcm142Parameters, unit_mode_converts_speeds_and_accelerations) {
  Tmcm142Rig rig;
  ASSERT_EQ(rig.sap(4, 51200000), kOk);  // TMC457 units
  EXPECT_NEAR(rig.module.axis().config.max_velocity_pps, 51200000 * kPpsPerVelocityUnit, 1e-6);
  ASSERT_EQ(rig.sap(255, 1), kOk);
  EXPECT_EQ(rig.gap(4), std::lround(51200000 * kPpsPerVelocityUnit));  // 762939 µsteps/s
  EXPECT_EQ(rig.sap(4, 32000000), kInvalidValue);  // manual: 0..31999999 in unit mode 1
  EXPECT_EQ(rig.gap(4), 762939);
  ASSERT_EQ(rig.sap(4, 31999999), kOk);
  ASSERT_EQ(rig.sap(5, 100000), kOk);  // µsteps/s²
  EXPECT_DOUBLE_EQ(rig.module.axis().config.acceleration_pps2, 100000.0);
  EXPECT_EQ(rig.command(1, 0, 0, 32000000).status, kInvalidValue);  // ROR beyond the pps range
  ASSERT_EQ(rig.sap(255, 0), kOk);
  EXPECT_EQ(rig.gap(4), std::lround(31999999 / kPpsPerVelocityUnit));  // 2147483581
  EXPECT_EQ(rig.gap(5), std::lround(100000 / modules::tmcm142::kPps2PerAccelerationUnit));  // 6872
  EXPECT_EQ(rig.command(1, 0, 0, INT32_MAX).status, kOk);
}

// Fuzz finding (tmcm142_engine, 2026-11-27): AP 17 set to the top of its TMC457 range read
// 244140610 after SAP 255 1, beyond its range 0..16777215.
TEST(Tmcm142Parameters, a_switch_to_unit_mode_1_lowers_accelerations_beyond_its_range) {
  Tmcm142Rig rig;
  ASSERT_EQ(rig.sap(5, 16777215), kOk);  // TMC457 units: about 2.4e8 µsteps/s²
  ASSERT_EQ(rig.sap(15, 16777215), kOk);
  ASSERT_EQ(rig.sap(17, 16777215), kOk);
  ASSERT_EQ(rig.sap(255, 1), kOk);
  for (uint8_t ap : {5, 15, 16, 17}) EXPECT_EQ(rig.gap(ap), 16777215) << "AP " << int{ap};
  EXPECT_DOUBLE_EQ(rig.module.axis().config.acceleration_pps2, 16777215.0);
  EXPECT_DOUBLE_EQ(rig.module.axis().config.deceleration_pps2, 16777215.0);
  // Below the bound nothing changes: 100000 µsteps/s² in TMC457 units and back.
  ASSERT_EQ(rig.sap(255, 0), kOk);
  ASSERT_EQ(rig.sap(5, 6872), kOk);
  const double acceleration = rig.module.axis().config.acceleration_pps2;
  ASSERT_EQ(rig.sap(255, 1), kOk);
  EXPECT_DOUBLE_EQ(rig.module.axis().config.acceleration_pps2, acceleration);
}

TEST(Tmcm142Parameters, stored_speeds_come_back_in_their_unit_mode) {
  Tmcm142Rig rig;
  ASSERT_EQ(rig.sap(255, 1), kOk);
  ASSERT_EQ(rig.sap(4, 100000), kOk);
  ASSERT_EQ(rig.command(7, 4, 0, 0).status, kOk);
  ASSERT_EQ(rig.command(7, 255, 0, 0).status, kOk);
  ASSERT_EQ(rig.sap(6, 9), kOk);  // not stored: back to 5
  rig.engine.power_up();
  EXPECT_EQ(rig.gap(255), 1);
  EXPECT_EQ(rig.gap(4), 100000);
  EXPECT_DOUBLE_EQ(rig.module.axis().config.max_velocity_pps, 100000.0);
  EXPECT_EQ(rig.gap(6), 5);
}

TEST(Tmcm142Parameters, eeprom_lock_refuses_stores_until_unlocked_and_survives_power_up) {
  Tmcm142Rig rig;
  EXPECT_EQ(rig.sgp(73, 0, 1), kInvalidValue);
  ASSERT_EQ(rig.sgp(73, 0, 1234), kOk);
  EXPECT_EQ(rig.ggp(73), 1);
  EXPECT_EQ(rig.command(7, 4, 0, 0).status, kEepromLocked);        // STAP
  EXPECT_EQ(rig.sgp(85, 0, 1), kEepromLocked);                     // auto-stored GP
  EXPECT_EQ(rig.ggp(85), 0);                                       // RAM unchanged
  EXPECT_EQ(rig.sgp(0, 2, 42), kOk);                               // user variable in RAM
  EXPECT_EQ(rig.command(11, 0, 2, 0).status, kEepromLocked);       // STGP
  EXPECT_EQ(rig.sap(4, 1000), kOk);                                // RAM writes still work
  rig.engine.power_up();
  EXPECT_EQ(rig.ggp(73), 1);
  EXPECT_EQ(rig.command(7, 4, 0, 0).status, kEepromLocked);
  ASSERT_EQ(rig.sgp(73, 0, 4321), kOk);
  EXPECT_EQ(rig.ggp(73), 0);
  EXPECT_EQ(rig.sgp(85, 0, 1), kOk);
  EXPECT_EQ(rig.ggp(85), 1);
}

TEST(Tmcm142Parameters, wrong_eeprom_magic_reinitialises_the_parameters_at_power_up) {
  Tmcm142Rig rig;
  ASSERT_EQ(rig.sap(4, 1000), kOk);
  ASSERT_EQ(rig.command(7, 4, 0, 0).status, kOk);
  ASSERT_EQ(rig.sgp(85, 0, 1), kOk);
  rig.engine.power_up();
  EXPECT_EQ(rig.gap(4), 1000);
  EXPECT_EQ(rig.ggp(85), 1);
  ASSERT_EQ(rig.sgp(64, 0, 0), kOk);
  rig.engine.power_up();
  EXPECT_EQ(rig.gap(4), modules::tmcm142::kDefaultMaxVelocity);
  EXPECT_EQ(rig.ggp(85), 0);
  EXPECT_EQ(rig.ggp(64), 228);
}

TEST(Tmcm142Parameters, random_numbers_change_on_every_read) {
  Tmcm142Rig rig;
  const int32_t first = rig.ggp(133);
  const int32_t second = rig.ggp(133);
  EXPECT_NE(first, second);
  EXPECT_GE(first, 0);
  EXPECT_GE(second, 0);
}

TEST(Tmcm142Parameters, io_banks_reach_the_board) {
  Tmcm142Rig rig;
  rig.io.digital_inputs[8] = true;
  rig.io.analog_inputs[2] = 3000;
  EXPECT_EQ(rig.command(15, 8, 0, 0).value, 1);
  EXPECT_EQ(rig.command(15, 2, 1, 0).value, 3000);
  EXPECT_EQ(rig.command(15, 9, 0, 0).status, kWrongType);
  EXPECT_EQ(rig.command(14, 2, 2, 1).status, kOk);
  EXPECT_TRUE(rig.io.outputs[2]);
  EXPECT_EQ(rig.command(14, 3, 2, 1).status, kWrongType);
  EXPECT_EQ(rig.command(14, 0, 2, 2).status, kInvalidValue);
  EXPECT_EQ(rig.ggp(0, 1), 0);
  EXPECT_EQ(rig.command(10, 0, 1, 0).status, kInvalidValue);  // no bank 1 parameters
}

TEST(Tmcm142Parameters, tmcm1636_still_answers_invalid_command_for_rfs_and_coordinates) {
  Tmcm1636Rig rig;
  for (const uint8_t cmd : {13, 30, 31, 32, 39}) {
    EXPECT_EQ(rig.command(cmd, 0, 0, 0).status, kInvalidCommand) << "command " << int{cmd};
    EXPECT_EQ(rig.command(cmd, 1, 255, 0).status, kInvalidCommand) << "command " << int{cmd};
  }
  EXPECT_EQ(rig.command(4, 2, 0, 1).status, kWrongType);  // MVP COORD: unchanged
}

}  // namespace
}  // namespace motwin::testing
