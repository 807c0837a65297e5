// docs/tmcm-3216-tmcl.md "Changing firmware": the TMCM-3216's TMCL and CANopen firmwares on one
// state directory. Starting the other firmware takes the image over as a firmware update does:
// the settings of core/modules/tmcm3216/tmcm3216_firmware_change.h survive, in both directions,
// the rest start at their defaults, one log line says so, nothing is set aside as damaged; a
// really damaged image still is.
#include <gtest/gtest.h>

#include <algorithm>
#include <cctype>
#include <cmath>
#include <filesystem>
#include <fstream>
#include <initializer_list>
#include <string>
#include <vector>

#include "core/modules/tmcm3216/tmcm3216_firmware_change.h"
#include "host/eeprom_file.h"
#include "host/modules/tmcm3216/tmcm3216_firmware_change.h"
#include "host/modules/tmcm3216/tmcm3216_tmcl_virtual_module.h"
#include "host/modules/tmcm3216/tmcm3216_virtual_module.h"
#include "support/firmware_change_support.h"
#include "support/host_test_support.h"

namespace motwin::host {
namespace {

using modules::tmcm3216::Tmcm3216;
using modules::tmcm3216::Tmcm3216Tmcl;

constexpr const char* kTakeOverToCanopen = "was written by firmware 3216V100; CANopen V1.04 takes it over like a firmware update";
constexpr const char* kTakeOverToTmcl = "was written by firmware CANopen V1.04; 3216V100 takes it over like a firmware update";

using Canopen = testing::CanopenOn<Tmcm3216VirtualModule>;
using Tmcl = testing::TmclOn<Tmcm3216TmclVirtualModule>;
using testing::ApValue;
using testing::ObjectValue;

Canopen open_canopen(const std::filesystem::path& dir, std::vector<std::string>& log) {
  return testing::open_on<Canopen>(&Tmcm3216VirtualModule::make, dir, log);
}

Tmcl open_tmcl(const std::filesystem::path& dir, std::vector<std::string>& log) {
  return testing::open_on<Tmcl>(&Tmcm3216TmclVirtualModule::make, dir, log);
}

std::filesystem::path image_in(const testing::ScratchDirectory& dir) {
  return EepromFile::image_path(dir.path(), Tmcm3216::kName);
}

bool damaged_exists(const testing::ScratchDirectory& dir) { return testing::damaged_exists(dir, Tmcm3216::kName); }

void expect_taken_over(const std::vector<std::string>& log, const char* line, const testing::ScratchDirectory& dir) {
  testing::expect_taken_over(log, line, dir, Tmcm3216::kName);
}

// 1010 sub 4 + n: motor n's parameters.
void store_motor(Canopen& canopen, uint8_t axis) { canopen.store(static_cast<uint8_t>(4 + axis)); }

TEST(Tmcm3216FirmwareChange, tmcl_settings_survive_on_the_canopen_firmware_and_back) {
  testing::ScratchDirectory dir;
  {
    std::vector<std::string> log;
    Tmcl tmcl = open_tmcl(dir.path(), log);
    ASSERT_NE(tmcl.module, nullptr);
    // 6081, 6083, 6084, 2003, 2000, 2017 of axis 1, 2015 of axis 2, 2005 bits 1 and 2 of axis 1;
    // AP 37 has no CANopen object.
    testing::sap_stap_all(tmcl, {{4, 1, 12345}, {5, 1, 2222}, {17, 1, 3333}, {6, 1, 200}, {140, 1, 6}, {35, 1, 40000},
                                 {21, 2, 77}, {12, 1, 1}, {25, 1, 1}, {37, 1, 500}});
    ASSERT_EQ(tmcl.device().set_axis_parameter(4, 0, 777), tmcl::Status::kOk) << "set, never stored";
  }
  {
    std::vector<std::string> log;
    Canopen canopen = open_canopen(dir.path(), log);
    ASSERT_NE(canopen.module, nullptr);
    expect_taken_over(log, kTakeOverToCanopen, dir);
    testing::expect_objects(canopen, {{0x6881, 0, 12345}, {0x6883, 0, 2222}, {0x6884, 0, 3333}, {0x2203, 0, 200}, {0x2200, 0, 6},
                             {0x2217, 0, 40000}, {0x2415, 0, 77},
                             {0x2205, 0, 0b0110},   // right disabled, left inverted
                             {0x6081, 0, 51200},    // only stored values survive
                             {0x2201, 0, 200},      // not shared: the default
                             {0x2003, 0, 128}});
  }
  {
    std::vector<std::string> log;
    Canopen canopen = open_canopen(dir.path(), log);
    ASSERT_NE(canopen.module, nullptr);
    EXPECT_TRUE(log.empty()) << "the new image is the CANopen firmware's own: " << log[0];
    EXPECT_EQ(canopen.read(0x6881), 12345) << "stored by the change";
  }
  {
    std::vector<std::string> log;
    Tmcl tmcl = open_tmcl(dir.path(), log);
    ASSERT_NE(tmcl.module, nullptr);
    expect_taken_over(log, kTakeOverToTmcl, dir);
    testing::expect_aps(tmcl, {{4, 1, 12345}, {35, 1, 40000}, {12, 1, 1}, {13, 1, 0}, {25, 1, 1}, {21, 2, 77},
                      {37, 1, 0}});  // AP 37: the CANopen firmware has no place for it
  }
}

TEST(Tmcm3216FirmwareChange, canopen_settings_survive_on_the_tmcl_firmware_and_back) {
  testing::ScratchDirectory dir;
  // 208C = 0: v = v_reg x fCLK / 2^24, a = a_reg x fCLK² / 2^41 (fCLK 12 MHz).
  const int64_t chip_velocity_1000 = std::lround(1000 * 12e6 / 16777216.0);
  const int64_t chip_acceleration_1000 = std::lround(1000 * 12e6 * 12e6 / 2199023255552.0);
  {
    std::vector<std::string> log;
    Canopen canopen = open_canopen(dir.path(), log);
    ASSERT_NE(canopen.module, nullptr);
    // Axis 2: 6081, 6082, 2004, 2005 left disabled + right inverted + home disabled, 2089 (the
    // setting delay: AP 214), 200A (the enable drive delay, no TMCL parameter).
    testing::write_objects(canopen, {{0x7081, 0, 30000}, {0x7082, 0, 10}, {0x2404, 0, 20}, {0x2405, 0, 1 | 8 | 16},
                                     {0x2489, 0, 50}, {0x240A, 0, 100}});
    store_motor(canopen, 2);
    testing::write_objects(canopen, {{0x208C, 0, 0}, {0x6081, 0, 1000}, {0x6083, 0, 1000}});  // chip units
    store_motor(canopen, 0);
    // Beyond AP 4's range (6081 takes 32 bits): the TMCL firmware refuses it, AP 4 keeps its default.
    testing::write_objects(canopen, {{0x6881, 0, 20000000}, {0x6883, 0, 7777}});
    store_motor(canopen, 1);
  }
  {
    std::vector<std::string> log;
    Tmcl tmcl = open_tmcl(dir.path(), log);
    ASSERT_NE(tmcl.module, nullptr);
    expect_taken_over(log, kTakeOverToTmcl, dir);
    testing::expect_aps(tmcl, {{4, 2, 30000}, {20, 2, 10}, {7, 2, 20}, {13, 2, 1}, {12, 2, 0}, {24, 2, 1}, {25, 2, 0},
                      {214, 2, 50}, {14, 2, 0},  // not shared: the default
                      {4, 1, 51200},  // refused: the default
                      {5, 1, 7777}, {4, 0, chip_velocity_1000}, {5, 0, chip_acceleration_1000}});
  }
  {
    std::vector<std::string> log;
    Canopen canopen = open_canopen(dir.path(), log);
    ASSERT_NE(canopen.module, nullptr);
    expect_taken_over(log, kTakeOverToCanopen, dir);
    testing::expect_objects(canopen, {{0x7081, 0, 30000},
                             {0x2405, 0, 1 | 8},  // the home bits have no TMCL parameter
                             {0x2489, 0, 50},
                             {0x240A, 0, 0},      // not shared: the default
                             {0x208C, 0, 181},    // the TMCL firmware's units
                             {0x6081, 0, chip_velocity_1000}});
  }
}

TEST(Tmcm3216FirmwareChange, a_damaged_image_of_the_other_firmware_is_still_set_aside) {
  testing::ScratchDirectory dir;
  {
    std::vector<std::string> log;
    Tmcl tmcl = open_tmcl(dir.path(), log);
    ASSERT_NE(tmcl.module, nullptr);
    tmcl.sap_stap(4, 1, 12345);
  }
  {
    std::fstream file(image_in(dir), std::ios::binary | std::ios::in | std::ios::out);
    file.seekp(EepromFile::kHeaderSize + 100);
    file.put('\x5a');
  }
  std::vector<std::string> log;
  Canopen canopen = open_canopen(dir.path(), log);
  ASSERT_NE(canopen.module, nullptr);
  ASSERT_EQ(log.size(), 1u);
  EXPECT_NE(log[0].find("is damaged (payload CRC mismatch)"), std::string::npos) << log[0];
  EXPECT_TRUE(damaged_exists(dir));
  EXPECT_EQ(canopen.read(0x6081 + 0x800), 51200);
}

// The take-over refuses what it does not know: another firmware string or layout is foreign.
TEST(Tmcm3216FirmwareChange, an_unknown_firmware_or_layout_is_not_taken_over) {
  std::vector<uint8_t> tmcl(Tmcm3216Tmcl::kNvmLayout.total_size, 0);
  std::vector<uint8_t> canopen(Tmcm3216::kNvmSize, 0);
  Tmcm3216Tmcl::format_factory_image(tmcl.data(), tmcl.size());
  Tmcm3216::format_factory_image(canopen.data(), canopen.size());
  EXPECT_TRUE(tmcm3216_canopen_image_from_tmcl({"3216V100", 1, tmcl}, canopen.data(), canopen.size()));
  EXPECT_FALSE(tmcm3216_canopen_image_from_tmcl({"3216V101", 1, tmcl}, canopen.data(), canopen.size()));
  EXPECT_FALSE(tmcm3216_canopen_image_from_tmcl({"3216V100", 2, tmcl}, canopen.data(), canopen.size()));
  EXPECT_FALSE(tmcm3216_tmcl_image_from_canopen({"3216V100", 1, canopen}, tmcl.data(), tmcl.size()));
  EXPECT_TRUE(tmcm3216_tmcl_image_from_canopen({"CANopen V1.04", 1, canopen}, tmcl.data(), tmcl.size()));
}

}  // namespace
}  // namespace motwin::host

namespace motwin::host {
namespace {

// The CANopen objects (2xxx, 6xxx) a TMCL row's description names.
std::vector<uint16_t> objects_named(std::string_view description) {
  std::vector<uint16_t> objects;
  const auto hex = [](char c) { return (c >= '0' && c <= '9') || (c >= 'A' && c <= 'F'); };
  for (size_t i = 0; i + 4 <= description.size(); ++i) {
    const bool starts_word = i == 0 || !std::isalnum(static_cast<unsigned char>(description[i - 1]));
    const bool ends_word = i + 4 == description.size() || !std::isalnum(static_cast<unsigned char>(description[i + 4]));
    if (!starts_word || !ends_word || (description[i] != '2' && description[i] != '6')) continue;
    if (!hex(description[i + 1]) || !hex(description[i + 2]) || !hex(description[i + 3])) continue;
    objects.push_back(static_cast<uint16_t>(std::stoul(std::string(description.substr(i, 4)), nullptr, 16)));
  }
  return objects;
}

// The table keeps up with the TMCL parameter table: every stored AP whose description names a
// CANopen object has a row with one of those objects (a new AP that forgets its row fails here),
// and every row is a stored AP and a stored per-axis object of every axis.
TEST(Tmcm3216FirmwareChange, the_shared_table_covers_every_stored_ap_that_names_an_object) {
  using modules::tmcm3216::kSharedAxisSettings;
  for (const auto& row : Tmcm3216Tmcl::axis_parameters().rows()) {
    if (!tmcl::is_stored_parameter(row.info)) continue;
    const std::vector<uint16_t> named = objects_named(row.info.description);
    if (named.empty()) continue;
    bool found = false;
    for (const params::SharedAxisSetting& shared : kSharedAxisSettings) {
      if (shared.parameter != row.info.number) continue;
      found = true;
      EXPECT_NE(std::find(named.begin(), named.end(), shared.index), named.end())
          << "AP " << row.info.number << " maps to " << std::hex << shared.index << ", its description: "
          << row.info.description;
    }
    EXPECT_TRUE(found) << "AP " << row.info.number << " names a CANopen object but has no row: "
                       << row.info.description;
  }
  testing::ScratchDirectory dir;
  std::vector<std::string> log;
  Canopen canopen = open_canopen(dir.path(), log);
  ASSERT_NE(canopen.module, nullptr);
  for (const params::SharedAxisSetting& shared : kSharedAxisSettings) {
    const auto* parameter = Tmcm3216Tmcl::axis_parameters().find(shared.parameter);
    ASSERT_NE(parameter, nullptr) << "AP " << int{shared.parameter};
    EXPECT_TRUE(tmcl::is_stored_parameter(parameter->info)) << "AP " << int{shared.parameter};
    for (uint8_t axis = 0; axis < modules::tmcm3216::kAxisCount; ++axis) {
      canopen::ObjectRef ref;
      ASSERT_EQ(canopen.device().dictionary().find(shared.index_of(axis), shared.sub, ref), canopen::SdoAbort::kNone)
          << std::hex << shared.index_of(axis);
      EXPECT_EQ(ref.axis, axis) << std::hex << shared.index_of(axis);
      EXPECT_EQ(ref.info->storage, canopen::StorageGroup::kAxis) << std::hex << shared.index_of(axis);
    }
  }
}

}  // namespace
}  // namespace motwin::host
