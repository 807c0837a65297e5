// What the TMCL module base (core/tmcl/tmcl_module.h) gives both TMCL modules alike: the EEPROM
// layout of their facts, GP 128..132 in their bank-0 tables, MST as ROR 0, the tick timer, and
// the row helpers of module_rows.h.
#include <gtest/gtest.h>

#include <cstdint>
#include <string_view>

#include "core/params/parameter_table.h"
#include "support/tmcm142_rig.h"
#include "support/tmcm1636_rig.h"

namespace motwin::testing {
namespace {

using modules::tmcm142::Tmcm142;

constexpr uint8_t kMst = 3;
constexpr uint8_t kRor = 1;

// The image sizes existing EEPROM files have: a change here orphans every user's image.
TEST(TmclModuleBase, the_facts_keep_the_eeprom_layouts) {
  EXPECT_EQ(Tmcm1636::kNvmLayout.program_offset, 2u * 1024 + 56 * 4);
  EXPECT_EQ(Tmcm1636::kNvmLayout.total_size, 2u * 1024 + 56 * 4 + 2048 * 8);
  EXPECT_EQ(Tmcm142::kNvmLayout.coordinates_offset, 2u * 1024 + 56 * 4);
  EXPECT_EQ(Tmcm142::kNvmLayout.program_offset, 2u * 1024 + 56 * 4 + 21 * 4);
  EXPECT_EQ(Tmcm142::kNvmLayout.total_size, 2u * 1024 + 56 * 4 + 21 * 4 + 2048 * 8);
  EXPECT_EQ(Tmcm1636::kName, std::string_view("tmcm-1636"));
  EXPECT_EQ(Tmcm142::kName, std::string_view("tmcm-142"));
  EXPECT_EQ(Tmcm1636::kIdentity.binary_version(), (1636 << 16) | (1 << 8) | 9);
  EXPECT_EQ(Tmcm142::kIdentity.binary_version(), (142 << 16) | (1 << 8) | 6);
}

template <class Module, bool kHasLastError>
void expect_program_status_rows() {
  const auto& table = Module::global_parameters();
  for (uint16_t number : {128, 129, 130, 132}) {
    const auto* row = table.find(number);
    ASSERT_NE(row, nullptr) << "GP " << number;
    EXPECT_EQ(row->info.default_value, 0);
    EXPECT_NE(row->binding.get, nullptr);
    EXPECT_EQ(row->binding.set != nullptr, number == 132) << "GP " << number;
  }
  // GP 131 (last TMCL error) is the TMCM-142's own row, between the base's 130 and 132.
  EXPECT_EQ(table.find(131) != nullptr, kHasLastError);
}

TEST(TmclModuleBase, both_bank0_tables_list_the_program_status_of_the_base) {
  expect_program_status_rows<Tmcm1636, false>();
  expect_program_status_rows<Tmcm142, true>();
  EXPECT_NE(Tmcm142::global_parameters().find(133), nullptr);  // after the base's rows
}

TEST(TmclModuleBase, mst_writes_target_velocity_zero_through_the_table) {
  Tmcm1636Rig rig;
  EXPECT_EQ(rig.command(kRor, 0, 0, 1200).status, 100);
  EXPECT_EQ(rig.gap(40), 1200);
  EXPECT_EQ(rig.command(kMst, 0, 0, 0).status, 100);
  EXPECT_EQ(rig.gap(40), 0);

  Tmcm142Rig stepper;
  EXPECT_EQ(stepper.sap(255, 1), 100);  // speeds in µsteps/s
  EXPECT_EQ(stepper.command(kRor, 0, 0, 5000).status, 100);
  EXPECT_EQ(stepper.gap(2), 5000);
  EXPECT_EQ(stepper.command(kMst, 0, 0, 0).status, 100);
  EXPECT_EQ(stepper.gap(2), 0);
}

TEST(TmclModuleBase, the_tick_timer_counts_milliseconds_and_a_write_restarts_the_running_one) {
  Tmcm1636Rig rig;
  rig.run_ms(7);
  EXPECT_EQ(rig.module.tick_timer_ms(), 7u);
  for (int i = 0; i < 10; ++i) rig.module.tick();  // half a millisecond
  EXPECT_EQ(rig.command(9, 132, 0, 1000).status, 100);
  for (int i = 0; i < 19; ++i) rig.module.tick();
  EXPECT_EQ(rig.command(10, 132, 0, 0).value, 1000);
  rig.module.tick();
  EXPECT_EQ(rig.command(10, 132, 0, 0).value, 1001);
}

TEST(TmclModuleBase, axis_command_rows_convert_the_wire_value_to_the_setter_type) {
  Tmcm1636Rig rig;
  // AP 255 binds set_driver_enabled(bool): any non-zero value in range enables.
  EXPECT_EQ(rig.command(5, 255, 0, 0).status, 100);
  EXPECT_EQ(rig.module.axis().state.driver_enabled, 0);
  EXPECT_EQ(rig.command(5, 255, 0, 1).status, 100);
  EXPECT_EQ(rig.gap(255), 1);
  // AP 15 binds set_commutation_mode(CommutationMode).
  EXPECT_EQ(rig.command(5, 15, 0, 2).status, 100);
  EXPECT_EQ(rig.module.axis().config.commutation_mode, modules::tmcm1636::CommutationMode::kDigitalHall);
  EXPECT_EQ(rig.gap(15), 2);
  // AP 240..249 are the elements of one array.
  EXPECT_EQ(rig.command(5, 243, 0, -77).status, 100);
  EXPECT_EQ(rig.module.axis().state.debug_values[3], -77);
  EXPECT_EQ(rig.gap(243), -77);
  EXPECT_EQ(rig.gap(242), 0);
}

}  // namespace
}  // namespace motwin::testing
