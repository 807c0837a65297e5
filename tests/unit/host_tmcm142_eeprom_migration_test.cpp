// A TMCM-142 EEPROM image file that Motwin wrote with NVM layout 1 (tests/data/README.md says how)
// opens as layout 2 with every setting at its new number, once, and is never taken for a layout 2
// image or thrown away; an image of a layout Motwin does not know is still replaced.
#include <gtest/gtest.h>

#include <filesystem>
#include <fstream>
#include <iterator>
#include <string>
#include <vector>

#include "host/eeprom_file.h"
#include "host/module_eeprom.h"
#include "support/host_test_support.h"
#include "support/tmcm142_rig.h"

namespace motwin::testing {
namespace {

const std::filesystem::path kLayout1Image =
    std::filesystem::path(MOTWIN_SOURCE_DIR) / ".." / "tests" / "data" / "tmcm142_nvm_layout1.eeprom";

std::vector<uint8_t> read_bytes(const std::filesystem::path& path) {
  std::ifstream in(path, std::ios::binary);
  return {std::istreambuf_iterator<char>(in), std::istreambuf_iterator<char>()};
}

struct Opened {
  std::unique_ptr<host::EepromFile> file;
  std::vector<std::string> log;
};

Opened open_in(const std::filesystem::path& dir) {
  Opened opened;
  auto result = host::EepromFile::open(
      dir, host::eeprom_identity_of<Tmcm142>(),
      [](uint8_t* image, size_t size) { Tmcm142::format_factory_image(image, size); },
      [&](const std::string& line) { opened.log.push_back(line); });
  EXPECT_TRUE(result) << (result ? "" : result.error());
  if (result) opened.file = std::move(*result);
  return opened;
}

TEST(Tmcm142EepromMigration, a_layout_1_file_loads_with_its_settings_at_the_real_numbers) {
  ScratchDirectory dir;
  ASSERT_TRUE(std::filesystem::exists(kLayout1Image)) << kLayout1Image;
  std::filesystem::copy_file(kLayout1Image, dir.path() / "tmcm-142.eeprom");
  {
    Opened opened = open_in(dir.path());
    ASSERT_NE(opened.file, nullptr);
    EXPECT_EQ(opened.file->load_outcome(), host::EepromLoadOutcome::kMigrated);
    ASSERT_EQ(opened.log.size(), 1u);
    EXPECT_NE(opened.log[0].find("has NVM layout 1; migrated to layout 2"), std::string::npos) << opened.log[0];
    EXPECT_EQ(opened.file->recorded_firmware(), "142V1.06");

    ScriptedTmcm142Io io;
    board::StepperPowerStage stage;
    Tmcm142 module(*opened.file, stage, io);
    module.engine().power_up();
    const auto gap = [&](uint8_t number) {
      int32_t value = 0;
      EXPECT_EQ(module.get_axis_parameter(number, 0, value), tmcl::Status::kOk) << "AP " << int{number};
      return value;
    };
    const auto ggp = [&](uint8_t number, uint8_t bank) {
      int32_t value = 0;
      EXPECT_EQ(module.get_global_parameter(number, bank, value), tmcl::Status::kOk) << "GP " << int{number};
      return value;
    };
    // As stored by layout 1 (tests/data/README.md).
    EXPECT_EQ(gap(4), 1000000);
    EXPECT_EQ(gap(5), 20000);
    EXPECT_EQ(gap(6), 7);
    EXPECT_EQ(gap(42), 6710886);
    EXPECT_EQ(gap(212), 100);
    EXPECT_EQ(gap(16), 20000) << "max. acceleration is AP 5";
    EXPECT_EQ(gap(17), 0) << "deceleration follows AP 5, as in layout 1";
    EXPECT_EQ(gap(18), 500) << "the gentlest of the bows 500, 600, 700, 800";
    EXPECT_EQ(gap(19), 0) << "the old bow 4 is not taken for shaft";
    EXPECT_EQ(gap(20), 50) << "standby delay, from AP 214";
    EXPECT_EQ(gap(43), 1) << "encoder direction 1 (AP 46) is encoder mode bit 0";
    EXPECT_EQ(gap(46), 0) << "position latch";
    EXPECT_EQ(ggp(66, 0), 3);
    EXPECT_EQ(ggp(5, 2), 12345);
    EXPECT_EQ(ggp(84, 0), 1);
    int32_t coordinate = 0;
    EXPECT_EQ(module.get_coordinate(3, 0, coordinate), tmcl::Status::kOk);
    EXPECT_EQ(coordinate, 4444);
    EXPECT_EQ(ggp(68, 0), 0);
  }
  // Written back as layout 2 at once: the next start loads it as it is.
  const std::vector<uint8_t> migrated = read_bytes(dir.path() / "tmcm-142.eeprom");
  EXPECT_TRUE(host::EepromFile::validate(host::eeprom_identity_of<Tmcm142>(), migrated));
  Opened again = open_in(dir.path());
  ASSERT_NE(again.file, nullptr);
  EXPECT_EQ(again.file->load_outcome(), host::EepromLoadOutcome::kLoaded);
  EXPECT_TRUE(again.log.empty());
  EXPECT_FALSE(std::filesystem::exists(dir.path() / "tmcm-142.eeprom.damaged"));
}

TEST(Tmcm142EepromMigration, an_unknown_layout_is_still_replaced_and_kept_aside) {
  ScratchDirectory dir;
  host::EepromImageIdentity future = host::eeprom_identity_of<Tmcm142>();
  future.layout_version = 9;
  std::vector<uint8_t> payload(future.payload_size, 0x5A);
  const std::vector<uint8_t> bytes = host::EepromFile::encode(future, payload.data());
  {
    std::ofstream out(dir.path() / "tmcm-142.eeprom", std::ios::binary);
    out.write(reinterpret_cast<const char*>(bytes.data()), static_cast<std::streamsize>(bytes.size()));
  }
  Opened opened = open_in(dir.path());
  ASSERT_NE(opened.file, nullptr);
  EXPECT_EQ(opened.file->load_outcome(), host::EepromLoadOutcome::kReplacedDamaged);
  ASSERT_EQ(opened.log.size(), 1u);
  EXPECT_NE(opened.log[0].find("NVM layout version 9, expected 2"), std::string::npos) << opened.log[0];
  EXPECT_TRUE(std::filesystem::exists(dir.path() / "tmcm-142.eeprom.damaged"));
}

}  // namespace
}  // namespace motwin::testing
