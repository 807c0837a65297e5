// TMCM-142 coordinates: SCO/GCO/CCO/ACO, MVP COORD, RAM or EEPROM storage (GP 84), the
// `SCO n, 255, 0` / `GCO n, 255, 0` copies, the EEPROM lock, and bad operands.
#include <gtest/gtest.h>

#include "support/tmcm142_rig.h"

namespace motwin::testing {
namespace {

constexpr uint8_t kOk = 100;
constexpr uint8_t kWrongType = 3;
constexpr uint8_t kInvalidValue = 4;
constexpr uint8_t kEepromLocked = 5;

constexpr uint8_t kSco = 30;
constexpr uint8_t kGco = 31;
constexpr uint8_t kCco = 32;
constexpr uint8_t kAco = 39;

void fast_moves(Tmcm142Rig& rig) {
  ASSERT_EQ(rig.sap(255, 1), kOk);
  ASSERT_EQ(rig.sap(4, 200000), kOk);
  ASSERT_EQ(rig.sap(5, 2000000), kOk);
}

void move_and_wait(Tmcm142Rig& rig, uint8_t type, int32_t value) {
  ASSERT_EQ(rig.command(4, type, 0, value).status, kOk);
  rig.run_ms(1);
  rig.run_until([&] { return rig.gap(8) == 1; }, 5000);
}

TEST(Tmcm142Coordinates, stored_captured_and_moved_to) {
  Tmcm142Rig rig;
  fast_moves(rig);
  EXPECT_EQ(rig.command(kSco, 1, 0, 5000).status, kOk);
  EXPECT_EQ(rig.command(kGco, 1, 0, 0).value, 5000);
  move_and_wait(rig, 0, 7000);
  EXPECT_EQ(rig.command(kCco, 2, 0, 0).status, kOk);  // capture the actual position
  EXPECT_EQ(rig.command(kGco, 2, 0, 0).value, 7000);
  EXPECT_EQ(rig.command(19, 9, 0, -1234).status, kOk);  // CALC LOAD: accumulator = -1234
  EXPECT_EQ(rig.command(kAco, 3, 0, 0).status, kOk);
  EXPECT_EQ(rig.command(kGco, 3, 0, 0).value, -1234);
  move_and_wait(rig, 2, 1);  // MVP COORD 1
  EXPECT_EQ(rig.gap(1), 5000);
  EXPECT_NEAR(rig.rotor_microsteps(), 5000.0, 0.01);
  move_and_wait(rig, 2, 3);
  EXPECT_EQ(rig.gap(1), -1234);
}

TEST(Tmcm142Coordinates, bad_operands_answer_their_status_and_change_nothing) {
  Tmcm142Rig rig;
  EXPECT_EQ(rig.command(kSco, 21, 0, 1).status, kWrongType);
  EXPECT_EQ(rig.command(kSco, 1, 1, 1).status, kInvalidValue);
  EXPECT_EQ(rig.command(kGco, 21, 0, 0).status, kWrongType);
  EXPECT_EQ(rig.command(kCco, 1, 2, 0).status, kInvalidValue);
  EXPECT_EQ(rig.command(4, 2, 0, 21).status, kInvalidValue);  // MVP COORD 21
  EXPECT_EQ(rig.command(4, 3, 0, 0).status, kWrongType);      // no MVP type 3
  EXPECT_EQ(rig.command(kGco, 1, 0, 0).value, 0);
  EXPECT_EQ(rig.gap(0), 0);
}

TEST(Tmcm142Coordinates, ram_storage_copies_to_and_from_the_eeprom_on_request) {
  Tmcm142Rig rig;
  ASSERT_EQ(rig.ggp(84), 0);
  ASSERT_EQ(rig.command(kSco, 1, 0, 111).status, kOk);
  ASSERT_EQ(rig.command(kSco, 2, 0, 222).status, kOk);
  ASSERT_EQ(rig.command(kSco, 1, 255, 0).status, kOk);  // coordinate 1 only
  rig.engine.power_up();
  EXPECT_EQ(rig.command(kGco, 1, 0, 0).value, 0);  // RAM only: not restored
  ASSERT_EQ(rig.command(kGco, 1, 255, 0).status, kOk);
  EXPECT_EQ(rig.command(kGco, 1, 0, 0).value, 111);
  ASSERT_EQ(rig.command(kGco, 2, 255, 0).status, kOk);
  EXPECT_EQ(rig.command(kGco, 2, 0, 0).value, 0);  // 2 was never copied
  // SCO 0, 255, 0 copies all of 1..20.
  ASSERT_EQ(rig.command(kSco, 2, 0, 222).status, kOk);
  ASSERT_EQ(rig.command(kSco, 20, 0, 2020).status, kOk);
  ASSERT_EQ(rig.command(kSco, 0, 255, 0).status, kOk);
  rig.engine.power_up();
  ASSERT_EQ(rig.command(kGco, 0, 255, 0).status, kOk);
  EXPECT_EQ(rig.command(kGco, 2, 0, 0).value, 222);
  EXPECT_EQ(rig.command(kGco, 20, 0, 0).value, 2020);
}

TEST(Tmcm142Coordinates, eeprom_storage_persists_across_power_up) {
  Tmcm142Rig rig;
  fast_moves(rig);
  ASSERT_EQ(rig.sgp(84, 0, 1), kOk);
  ASSERT_EQ(rig.command(kSco, 0, 0, 999).status, kOk);  // coordinate 0: RAM only
  ASSERT_EQ(rig.command(kSco, 4, 0, -800).status, kOk);
  move_and_wait(rig, 0, 3000);
  ASSERT_EQ(rig.command(kCco, 5, 0, 0).status, kOk);
  rig.engine.power_up();
  EXPECT_EQ(rig.ggp(84), 1);
  EXPECT_EQ(rig.command(kGco, 0, 0, 0).value, 0);
  EXPECT_EQ(rig.command(kGco, 4, 0, 0).value, -800);
  EXPECT_EQ(rig.command(kGco, 5, 0, 0).value, 3000);
  fast_moves(rig);
  move_and_wait(rig, 2, 4);
  EXPECT_EQ(rig.gap(1), -800);
}

TEST(Tmcm142Coordinates, locked_eeprom_refuses_stored_coordinates) {
  Tmcm142Rig rig;
  ASSERT_EQ(rig.sgp(84, 0, 1), kOk);
  ASSERT_EQ(rig.command(kSco, 6, 0, 60).status, kOk);
  ASSERT_EQ(rig.sgp(73, 0, 1234), kOk);
  EXPECT_EQ(rig.command(kSco, 6, 0, 61).status, kEepromLocked);
  EXPECT_EQ(rig.command(kGco, 6, 0, 0).value, 60);
  EXPECT_EQ(rig.command(kSco, 6, 255, 0).status, kEepromLocked);
  EXPECT_EQ(rig.command(kSco, 0, 0, 7).status, kOk);  // coordinate 0 is RAM only
  EXPECT_EQ(rig.command(kGco, 0, 0, 0).value, 7);
}

TEST(Tmcm142Coordinates, factory_reset_clears_stored_coordinates_and_keeps_the_program) {
  Tmcm142Rig rig;
  ASSERT_EQ(rig.sgp(84, 0, 1), kOk);
  ASSERT_EQ(rig.command(kSco, 7, 0, 70).status, kOk);
  ASSERT_EQ(rig.command(132, 0, 0, 0).status, kOk);
  ASSERT_EQ(rig.command(4, 0, 0, 1234).status, 101);
  ASSERT_EQ(rig.command(133, 0, 0, 0).status, kOk);
  rig.command(137, 0, 0, 1234);
  EXPECT_EQ(rig.ggp(84), 0);
  ASSERT_EQ(rig.command(kGco, 7, 255, 0).status, kOk);
  EXPECT_EQ(rig.command(kGco, 7, 0, 0).value, 0);
  EXPECT_EQ(rig.command(134, 0, 0, 0).value, 1234);  // the program is kept
}

}  // namespace
}  // namespace motwin::testing
