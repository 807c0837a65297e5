// The TMCM-1636 start-up image the host writes for a physical motor
// (src/host/modules/tmcm1636/tmcm1636_startup_image.*): the named start-up settings of the
// presets give the very images the numbered lists of docs/tmcm-1636-servo.md ("Presets") gave,
// byte for byte; a description file's numbered axis parameters come after them; a value the
// firmware would refuse is an error naming the file and the setting.
#include <gtest/gtest.h>

#include <fstream>
#include <string>
#include <utility>
#include <vector>

#include "core/modules/tmcm1636/tmcm1636.h"
#include "core/tmcl/nvm_layout.h"
#include "host/modules/tmcm1636/tmcm1636_startup_image.h"
#include "sim/modules/tmcm1636/motor_description.h"
#include "support/host_test_support.h"

namespace motwin::host {
namespace {

using modules::tmcm1636::Tmcm1636;
using Numbered = std::vector<std::pair<uint8_t, int32_t>>;

// The presets' start-up lists as the motor descriptions held them before the settings were
// named (and as the docs list them).
const std::pair<const char*, Numbered> kPresetLists[] = {
    {"default-24v",
     {{10, 4}, {11, 2000}, {12, 1000}, {14, 3}, {15, 2}, {25, 1}, {70, 461}, {71, 3932}, {72, 1200}, {73, 4800},
      {74, 75}, {92, 1}, {100, 4096}, {102, 2}}},
    {"qbl4208-61-04-013",
     {{10, 4}, {11, 2000}, {12, 1000}, {14, 3}, {15, 2}, {25, 1}, {70, 461}, {71, 3539}, {72, 1200}, {73, 4800},
      {74, 75}, {90, 1}, {92, 1}, {100, 4096}, {101, 1}, {102, 2}}},
    {"large-48v",
     {{10, 7}, {11, 10000}, {12, 3000}, {14, 3}, {15, 2}, {25, 1}, {70, 20}, {71, 639}, {72, 13100}, {73, 25200},
      {74, 28}, {92, 1}, {100, 8192}, {102, 2}, {141, 520}}},
    {"dc-24v",
     {{10, 1}, {11, 2000}, {14, 1}, {15, 3}, {25, 1}, {70, 768}, {71, 19660}, {72, 1200}, {73, 2320}, {74, 28},
      {100, 2048}}},
};

std::vector<uint8_t> factory_image() {
  std::vector<uint8_t> image(Tmcm1636::kNvmLayout.total_size);
  Tmcm1636::format_factory_image(image.data(), image.size());
  return image;
}

std::vector<uint8_t> image_of(const sim::MotorDescription& motor) {
  std::vector<uint8_t> image = factory_image();
  write_tmcm1636_startup_image(motor, image.data(), image.size());
  return image;
}

int32_t axis_parameter(const std::vector<uint8_t>& image, uint8_t number) {
  return tmcl::get_le32(image.data() + Tmcm1636::kNvmLayout.axis_parameter(0, number));
}

TEST(Tmcm1636StartupImage, the_presets_give_the_images_of_their_numbered_lists) {
  for (const auto& [name, list] : kPresetLists) {
    SCOPED_TRACE(name);
    const sim::MotorDescription motor = *sim::motor_preset(name);
    Numbered parameters;
    for (const Tmcm1636StartupParameter& p : tmcm1636_startup_parameters(motor)) parameters.emplace_back(p.number, p.value);
    EXPECT_EQ(parameters, list);
    std::vector<uint8_t> expected = factory_image();
    for (const auto& [number, value] : list) {
      tmcl::put_le32(expected.data() + Tmcm1636::kNvmLayout.axis_parameter(0, number), value);
    }
    EXPECT_EQ(image_of(motor), expected);
    EXPECT_NE(image_of(motor), factory_image());
  }
}

TEST(Tmcm1636StartupImage, a_motor_without_startup_settings_keeps_the_factory_image) {
  sim::MotorDescription motor = *sim::motor_preset("default-24v");
  motor.startup.reset();
  EXPECT_TRUE(tmcm1636_startup_parameters(motor).empty());
  EXPECT_EQ(image_of(motor), factory_image());
  EXPECT_FALSE(tmcm1636_image_configures_motor(factory_image().data(), factory_image().size()));
}

TEST(Tmcm1636StartupImage, numbered_parameters_of_a_file_come_after_the_named_ones) {
  sim::MotorDescription motor = *sim::motor_preset("default-24v");
  motor.axis_parameters = {{11, 1500}, {30, 0}};
  const std::vector<Tmcm1636StartupParameter> parameters = tmcm1636_startup_parameters(motor);
  ASSERT_EQ(parameters.size(), 16u);
  EXPECT_EQ(parameters[14].number, 11);
  EXPECT_EQ(parameters[14].source, "axis_parameters");
  const std::vector<uint8_t> image = image_of(motor);
  EXPECT_EQ(axis_parameter(image, 11), 1500) << "the file's number wins over max_current_ma";
  EXPECT_EQ(axis_parameter(image, 12), 1000);
}

TEST(Tmcm1636StartupImage, a_value_the_table_refuses_is_not_written) {
  sim::MotorDescription motor = *sim::motor_preset("default-24v");
  motor.startup->max_current_ma = 70000;  // AP 11 takes 0..60000
  motor.axis_parameters = {{42, 1}};      // not stored
  const std::vector<uint8_t> image = image_of(motor);
  EXPECT_EQ(axis_parameter(image, 11), 2000) << "factory default";
  EXPECT_EQ(axis_parameter(image, 42), 0);
  EXPECT_EQ(axis_parameter(image, 14), 3);
}

TEST(Tmcm1636StartupImage, check_names_the_table_rule_that_fails) {
  EXPECT_TRUE(check_tmcm1636_axis_parameter(11, 60000).ok());
  EXPECT_EQ(check_tmcm1636_axis_parameter(11, 60001).error(), "axis parameter 11 takes 0 to 60000, got 60001");
  EXPECT_EQ(check_tmcm1636_axis_parameter(42, 1).error(), "axis parameter 42 is not stored in the EEPROM");
  EXPECT_EQ(check_tmcm1636_axis_parameter(300, 1).error(), "axis parameter 300 does not exist");
  EXPECT_EQ(check_tmcm1636_axis_parameter(-1, 1).error(), "axis parameter -1 does not exist");
}

TEST(Tmcm1636StartupImage, a_file_with_named_settings_loads_and_writes_like_the_preset) {
  testing::ScratchDirectory scratch;
  const std::string path = (scratch.path() / "large.json").string();
  const sim::MotorDescription preset = *sim::motor_preset("large-48v");
  std::ofstream(path) << sim::motor_description_json(preset);
  const Result<sim::MotorChoice> loaded = resolve_tmcm1636_motor(path);
  ASSERT_TRUE(loaded && *loaded) << loaded.error();
  EXPECT_EQ(image_of(**loaded), image_of(preset));
  EXPECT_EQ(axis_parameter(image_of(**loaded), 141), 520);
}

TEST(Tmcm1636StartupImage, a_file_the_module_cannot_start_with_names_file_and_setting) {
  testing::ScratchDirectory scratch;
  const std::string named = (scratch.path() / "named.json").string();
  std::ofstream(named) << R"({"flux_linkage_wb": 0.005, "startup": {"max_current_ma": 70000}})";
  EXPECT_EQ(resolve_tmcm1636_motor(named).error(),
            named + ": startup: max_current_ma: axis parameter 11 takes 0 to 60000, got 70000");
  EXPECT_FALSE(resolve_tmcm1636_motor(named).ok());
  const std::string numbered = (scratch.path() / "numbered.json").string();
  std::ofstream(numbered) << R"({"flux_linkage_wb": 0.005, "axis_parameters": {"42": 1}})";
  EXPECT_EQ(resolve_tmcm1636_motor(numbered).error(),
            numbered + ": axis_parameters: axis parameter 42 is not stored in the EEPROM");
  EXPECT_TRUE(resolve_tmcm1636_motor("ideal").error().empty());
  EXPECT_TRUE(*resolve_tmcm1636_motor("dc-24v"));
}

}  // namespace
}  // namespace motwin::host
