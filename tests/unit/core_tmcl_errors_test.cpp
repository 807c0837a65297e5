// Each TMCL error status, produced by the bad input that causes it; and the module's state
// and stored data left as they were.
#include <gtest/gtest.h>

#include <cstring>

#include "support/tmcm1636_rig.h"

namespace motwin::testing {
namespace {

using tmcl::Instruction;

TEST(TmclErrors, wrong_checksum_gets_status_1_with_command_0_and_value_0) {
  Tmcm1636Rig rig;
  auto frame = tmcl::encode_request(1, Instruction{5, 43, 0, 1234});
  frame[8] = static_cast<uint8_t>(frame[8] + 1);
  const auto response = rig.send(frame);
  const tmcl::Frame expected{2, 1, 1, 0, 0, 0, 0, 0, 4};
  EXPECT_EQ(response.bytes, expected);
  EXPECT_EQ(rig.gap(43), 4000) << "a frame with a bad checksum is not executed";
}

TEST(TmclErrors, unknown_command_gets_status_2) {
  Tmcm1636Rig rig;
  EXPECT_EQ(rig.command(99, 0, 0, 0).status, 2);
  EXPECT_EQ(rig.command(64, 0, 0, 0).status, 2) << "user functions UF0..UF7 are not built in";
}

TEST(TmclErrors, unknown_parameter_gets_status_3) {
  Tmcm1636Rig rig;
  EXPECT_EQ(rig.command(6, 8, 0, 0).status, 3);    // GAP 8: no such axis parameter
  EXPECT_EQ(rig.command(5, 13, 0, 1).status, 3);   // SAP 13
  EXPECT_EQ(rig.command(10, 68, 0, 0).status, 3);  // GGP 68: not on this module
  EXPECT_EQ(rig.command(36, 6, 0, 0).status, 3);   // CLE type 6
  EXPECT_EQ(rig.command(136, 2, 0, 0).status, 3);  // version type 2
  EXPECT_EQ(rig.command(4, 2, 0, 0).status, 3);    // MVP COORD: not on this module
}

TEST(TmclErrors, read_only_parameter_write_gets_status_3_and_changes_nothing) {
  Tmcm1636Rig rig;
  EXPECT_EQ(rig.command(5, 42, 0, 100).status, 3);  // SAP actual velocity
  EXPECT_EQ(rig.gap(42), 0);
  EXPECT_EQ(rig.command(5, 220, 0, 100).status, 3);  // SAP supply voltage
  EXPECT_EQ(rig.command(9, 128, 0, 1).status, 3);    // SGP application status
  EXPECT_EQ(rig.command(7, 42, 0, 0).status, 3) << "STAP of a parameter without E";
}

TEST(TmclErrors, value_out_of_range_gets_status_4_and_changes_nothing) {
  Tmcm1636Rig rig;
  EXPECT_EQ(rig.command(5, 43, 0, 200001).status, 4);
  EXPECT_EQ(rig.command(5, 43, 0, -1).status, 4);
  EXPECT_EQ(rig.gap(43), 4000);
  EXPECT_EQ(rig.command(1, 0, 0, 200001).status, 4) << "ROR beyond AP 40's range";
  EXPECT_EQ(rig.command(2, 0, 0, INT32_MIN).status, 4) << "ROL of INT32_MIN";
  EXPECT_EQ(rig.gap(40), 0);
  EXPECT_EQ(rig.command(9, 66, 0, 0).status, 4) << "address 0";
  EXPECT_EQ(rig.command(14, 0, 2, 2).status, 4) << "SIO value must be 0 or 1";
  EXPECT_EQ(rig.command(137, 0, 0, 1233).status, 4) << "factory defaults need 1234";
  EXPECT_EQ(rig.command(255, 0, 0, 0).status, 4) << "reset needs 1234";
}

TEST(TmclErrors, motor_or_bank_out_of_range_gets_status_4) {
  Tmcm1636Rig rig;
  EXPECT_EQ(rig.command(6, 43, 1, 0).status, 4);   // GAP motor 1
  EXPECT_EQ(rig.command(1, 0, 1, 100).status, 4);  // ROR motor 1
  EXPECT_EQ(rig.command(10, 0, 1, 0).status, 4);   // GGP bank 1
  EXPECT_EQ(rig.command(15, 0, 3, 0).status, 4);   // GIO bank 3
  EXPECT_EQ(rig.command(14, 0, 0, 1).status, 4);   // SIO bank 0: inputs
  EXPECT_EQ(rig.command(15, 4, 0, 0).status, 3);   // GIO port 4 of bank 0
}

TEST(TmclErrors, failing_eeprom_gets_status_5_and_keeps_ram_and_image) {
  Tmcm1636Rig rig;
  ASSERT_EQ(rig.command(5, 43, 0, 1000).status, 100);
  std::vector<uint8_t> before(rig.nvm.data(), rig.nvm.data() + rig.nvm.size());
  rig.nvm.set_fail_writes(true);
  EXPECT_EQ(rig.command(7, 43, 0, 0).status, 5);
  EXPECT_EQ(rig.command(9, 77, 0, 0).status, 5) << "auto-stored GP 77";
  EXPECT_EQ(rig.command(10, 77, 0, 0).value, 1) << "RAM value reverted with the failed store";
  EXPECT_EQ(0, std::memcmp(before.data(), rig.nvm.data(), before.size()));
}

TEST(TmclErrors, frames_for_other_addresses_get_no_reply) {
  Tmcm1636Rig rig;
  EXPECT_EQ(rig.send(tmcl::encode_request(2, Instruction{6, 43, 0, 0})).length, 0u);
  auto bad = tmcl::encode_request(7, Instruction{6, 43, 0, 0});
  bad[8] = 0;
  EXPECT_EQ(rig.send(bad).length, 0u) << "not even a checksum error for another module";
}

}  // namespace
}  // namespace motwin::testing
