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
#include <string>
#include <vector>

#include "core/modules/tmcm3216/tmcm3216_firmware_change.h"
#include "host/eeprom_file.h"
#include "host/modules/tmcm3216/tmcm3216_firmware_change.h"
#include "host/modules/tmcm3216/tmcm3216_tmcl_virtual_module.h"
#include "host/modules/tmcm3216/tmcm3216_virtual_module.h"
#include "support/host_test_support.h"

namespace motwin::host {
namespace {

using modules::tmcm3216::Tmcm3216;
using modules::tmcm3216::Tmcm3216Tmcl;

constexpr const char* kTakeOverToCanopen = "was written by firmware 3216V100; CANopen V1.04 takes it over like a firmware update";
constexpr const char* kTakeOverToTmcl = "was written by firmware CANopen V1.04; 3216V100 takes it over like a firmware update";

ModuleOptions options_in(const std::filesystem::path& dir, std::vector<std::string>& log) {
  ModuleOptions options;
  options.state_dir = dir;
  options.log = [&log](const std::string& line) { log.push_back(line); };
  return options;
}

struct Canopen {
  std::unique_ptr<VirtualModule> module;
  Tmcm3216& device() { return static_cast<Tmcm3216VirtualModule&>(*module).device(); }
  int64_t read(uint16_t index, uint8_t sub = 0) {
    canopen::ObjectRef ref;
    EXPECT_EQ(device().dictionary().find(index, sub, ref), canopen::SdoAbort::kNone) << std::hex << index;
    return device().dictionary().value(ref);
  }
  void write(uint16_t index, int64_t value, uint8_t sub = 0) {
    canopen::ObjectRef ref;
    ASSERT_EQ(device().dictionary().find(index, sub, ref), canopen::SdoAbort::kNone) << std::hex << index;
    uint8_t bytes[8] = {};
    canopen::encode_value(ref.info->type, value, bytes);
    ASSERT_EQ(device().dictionary().write(ref, bytes, canopen::type_size(ref.info->type)), canopen::SdoAbort::kNone)
        << std::hex << index;
  }
  void store_motor(uint8_t axis) {
    ASSERT_EQ(device().store_parameters(static_cast<uint8_t>(4 + axis), Tmcm3216::kSaveSignature),
              canopen::SdoAbort::kNone);
  }
};

struct Tmcl {
  std::unique_ptr<VirtualModule> module;
  Tmcm3216Tmcl& device() { return static_cast<Tmcm3216TmclVirtualModule&>(*module).device(); }
  int32_t gap(uint8_t number, uint8_t motor) {
    int32_t value = 0;
    EXPECT_EQ(device().get_axis_parameter(number, motor, value), tmcl::Status::kOk) << "AP " << int{number};
    return value;
  }
  void sap_stap(uint8_t number, uint8_t motor, int32_t value) {
    ASSERT_EQ(device().set_axis_parameter(number, motor, value), tmcl::Status::kOk) << "AP " << int{number};
    ASSERT_EQ(device().store_axis_parameter(number, motor), tmcl::Status::kOk) << "AP " << int{number};
  }
};

Canopen open_canopen(const std::filesystem::path& dir, std::vector<std::string>& log) {
  MakeModuleResult made = Tmcm3216VirtualModule::make(options_in(dir, log));
  EXPECT_TRUE(made) << (made ? "" : made.error());
  return Canopen{made ? std::move(*made) : nullptr};
}

Tmcl open_tmcl(const std::filesystem::path& dir, std::vector<std::string>& log) {
  MakeModuleResult made = Tmcm3216TmclVirtualModule::make(options_in(dir, log));
  EXPECT_TRUE(made) << (made ? "" : made.error());
  return Tmcl{made ? std::move(*made) : nullptr};
}

size_t lines_with(const std::vector<std::string>& log, const std::string& text) {
  size_t count = 0;
  for (const std::string& line : log) count += line.find(text) != std::string::npos ? 1 : 0;
  return count;
}

std::filesystem::path image_in(const testing::ScratchDirectory& dir) {
  return EepromFile::image_path(dir.path(), Tmcm3216::kName);
}

bool damaged_exists(const testing::ScratchDirectory& dir) {
  return std::filesystem::exists(image_in(dir).string() + ".damaged");
}

TEST(Tmcm3216FirmwareChange, tmcl_settings_survive_on_the_canopen_firmware_and_back) {
  testing::ScratchDirectory dir;
  {
    std::vector<std::string> log;
    Tmcl tmcl = open_tmcl(dir.path(), log);
    ASSERT_NE(tmcl.module, nullptr);
    tmcl.sap_stap(4, 1, 12345);   // 6081 of axis 1
    tmcl.sap_stap(5, 1, 2222);    // 6083
    tmcl.sap_stap(17, 1, 3333);   // 6084
    tmcl.sap_stap(6, 1, 200);     // 2003
    tmcl.sap_stap(140, 1, 6);     // 2000
    tmcl.sap_stap(35, 1, 40000);  // 2017
    tmcl.sap_stap(21, 2, 77);     // 2015 of axis 2
    tmcl.sap_stap(12, 1, 1);      // 2005 bit 1
    tmcl.sap_stap(25, 1, 1);      // 2005 bit 2
    tmcl.sap_stap(37, 1, 500);    // no CANopen object
    ASSERT_EQ(tmcl.device().set_axis_parameter(4, 0, 777), tmcl::Status::kOk) << "set, never stored";
  }
  {
    std::vector<std::string> log;
    Canopen canopen = open_canopen(dir.path(), log);
    ASSERT_NE(canopen.module, nullptr);
    EXPECT_EQ(log.size(), 1u);
    EXPECT_EQ(lines_with(log, kTakeOverToCanopen), 1u) << (log.empty() ? "" : log[0]);
    EXPECT_FALSE(damaged_exists(dir));
    EXPECT_EQ(canopen.read(0x6081 + 0x800), 12345);
    EXPECT_EQ(canopen.read(0x6083 + 0x800), 2222);
    EXPECT_EQ(canopen.read(0x6084 + 0x800), 3333);
    EXPECT_EQ(canopen.read(0x2003 + 0x200), 200);
    EXPECT_EQ(canopen.read(0x2000 + 0x200), 6);
    EXPECT_EQ(canopen.read(0x2017 + 0x200), 40000);
    EXPECT_EQ(canopen.read(0x2015 + 0x400), 77);
    EXPECT_EQ(canopen.read(0x2005 + 0x200), 0b0110) << "right disabled, left inverted";
    EXPECT_EQ(canopen.read(0x6081), 51200) << "only stored values survive";
    EXPECT_EQ(canopen.read(0x2001 + 0x200), 200) << "not shared: the default";
    EXPECT_EQ(canopen.read(0x2003), 128);
  }
  {
    std::vector<std::string> log;
    Canopen canopen = open_canopen(dir.path(), log);
    ASSERT_NE(canopen.module, nullptr);
    EXPECT_TRUE(log.empty()) << "the new image is the CANopen firmware's own: " << log[0];
    EXPECT_EQ(canopen.read(0x6081 + 0x800), 12345) << "stored by the change";
  }
  {
    std::vector<std::string> log;
    Tmcl tmcl = open_tmcl(dir.path(), log);
    ASSERT_NE(tmcl.module, nullptr);
    EXPECT_EQ(lines_with(log, kTakeOverToTmcl), 1u);
    EXPECT_EQ(log.size(), 1u);
    EXPECT_EQ(tmcl.gap(4, 1), 12345);
    EXPECT_EQ(tmcl.gap(35, 1), 40000);
    EXPECT_EQ(tmcl.gap(12, 1), 1);
    EXPECT_EQ(tmcl.gap(13, 1), 0);
    EXPECT_EQ(tmcl.gap(25, 1), 1);
    EXPECT_EQ(tmcl.gap(21, 2), 77);
    EXPECT_EQ(tmcl.gap(37, 1), 0) << "the CANopen firmware has no place for it";
  }
  EXPECT_FALSE(damaged_exists(dir));
}

TEST(Tmcm3216FirmwareChange, canopen_settings_survive_on_the_tmcl_firmware_and_back) {
  testing::ScratchDirectory dir;
  {
    std::vector<std::string> log;
    Canopen canopen = open_canopen(dir.path(), log);
    ASSERT_NE(canopen.module, nullptr);
    canopen.write(0x6081 + 0x1000, 30000);        // axis 2
    canopen.write(0x6082 + 0x1000, 10);
    canopen.write(0x2004 + 0x400, 20);
    canopen.write(0x2005 + 0x400, 1 | 8 | 16);    // left disabled, right inverted, home disabled
    canopen.write(0x2089 + 0x400, 50);            // setting delay: no TMCL parameter
    canopen.store_motor(2);
    canopen.write(0x208C, 0);                     // axis 0 in the chip's units
    canopen.write(0x6081, 1000);
    canopen.write(0x6083, 1000);
    canopen.store_motor(0);
  }
  {
    std::vector<std::string> log;
    Tmcl tmcl = open_tmcl(dir.path(), log);
    ASSERT_NE(tmcl.module, nullptr);
    EXPECT_EQ(log.size(), 1u);
    EXPECT_EQ(lines_with(log, kTakeOverToTmcl), 1u) << (log.empty() ? "" : log[0]);
    EXPECT_FALSE(damaged_exists(dir));
    EXPECT_EQ(tmcl.gap(4, 2), 30000);
    EXPECT_EQ(tmcl.gap(20, 2), 10);
    EXPECT_EQ(tmcl.gap(7, 2), 20);
    EXPECT_EQ(tmcl.gap(13, 2), 1);
    EXPECT_EQ(tmcl.gap(12, 2), 0);
    EXPECT_EQ(tmcl.gap(24, 2), 1);
    EXPECT_EQ(tmcl.gap(25, 2), 0);
    EXPECT_EQ(tmcl.gap(14, 2), 0) << "not shared: the default";
    EXPECT_EQ(tmcl.gap(4, 1), 51200);
    // 208C = 0: v = v_reg x fCLK / 2^24, a = a_reg x fCLK² / 2^41 (fCLK 12 MHz).
    EXPECT_EQ(tmcl.gap(4, 0), std::lround(1000 * 12e6 / 16777216.0));
    EXPECT_EQ(tmcl.gap(5, 0), std::lround(1000 * 12e6 * 12e6 / 2199023255552.0));
  }
  {
    std::vector<std::string> log;
    Canopen canopen = open_canopen(dir.path(), log);
    ASSERT_NE(canopen.module, nullptr);
    EXPECT_EQ(lines_with(log, kTakeOverToCanopen), 1u);
    EXPECT_EQ(canopen.read(0x6081 + 0x1000), 30000);
    EXPECT_EQ(canopen.read(0x2005 + 0x400), 1 | 8) << "the home bits have no TMCL parameter";
    EXPECT_EQ(canopen.read(0x2089 + 0x400), 200) << "not shared: the default";
    EXPECT_EQ(canopen.read(0x208C), 181) << "the TMCL firmware's units";
    EXPECT_EQ(canopen.read(0x6081), std::lround(1000 * 12e6 / 16777216.0));
  }
  EXPECT_FALSE(damaged_exists(dir));
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
