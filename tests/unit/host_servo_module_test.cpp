// The virtual TMCM-1636 with a physical motor (`motwin serve --motor`): motor selection, the
// start-up settings of a fresh EEPROM image, and scenario files driving the motor signals
// through the host runtime, deterministically.
#include <gtest/gtest.h>

#include <cmath>
#include <cstring>
#include <fstream>
#include <utility>
#include <string>
#include <vector>

#include "host/host_runtime.h"
#include "host/module_registry.h"
#include "host/modules/tmcm1636/tmcm1636_virtual_module.h"
#include "sim/scenario.h"
#include "support/host_test_support.h"

namespace motwin::host {
namespace {

constexpr uint8_t kRor = 1, kSap = 5, kGap = 6, kStap = 7;

tmcl::CommandResult execute(VirtualModule& module, uint8_t command, uint8_t type, int32_t value) {
  return module.engine().execute(tmcl::Instruction{command, type, 0, value}, tmcl::Origin::kHost, 1);
}
int32_t gap(VirtualModule& module, uint8_t number) { return execute(module, kGap, number, 0).value; }

MakeModuleResult make_with_motor(const std::string& motor, std::optional<std::filesystem::path> state_dir = {},
                                 std::vector<std::string>* log = nullptr, const std::string& firmware = "") {
  ModuleOptions options;
  options.motor = motor;
  options.firmware = firmware;
  options.state_dir = state_dir;
  options.log = [log](const std::string& line) {
    if (log != nullptr) log->push_back(line);
  };
  return make_module("tmcm-1636", options);
}

Tmcm1636VirtualModule& tmcm1636(MakeModuleResult& made) { return static_cast<Tmcm1636VirtualModule&>(**made); }

TEST(ServoModule, the_default_motor_is_ideal) {
  MakeModuleResult made = make_with_motor("");
  ASSERT_TRUE(made) << made.error();
  EXPECT_EQ(tmcm1636(made).board().plant(), nullptr);
  EXPECT_EQ(gap(**made, 14), 0) << "factory motor type";
}

TEST(ServoModule, a_preset_moves_out_of_the_box_with_its_startup_settings) {
  MakeModuleResult made = make_with_motor("default-24v");
  ASSERT_TRUE(made) << made.error();
  ASSERT_NE(tmcm1636(made).board().plant(), nullptr);
  EXPECT_EQ(gap(**made, 14), 3);
  EXPECT_EQ(gap(**made, 15), 2);
  EXPECT_EQ(gap(**made, 100), 4096);
  EXPECT_EQ(execute(**made, kRor, 0, 1000).status, tmcl::Status::kOk);
  (*made)->run_ticks(20'000);
  EXPECT_NEAR(gap(**made, 42), 1000, 10);
  EXPECT_NEAR(*(*made)->signals().read_signal("SPEED_RPM"), 1000.0, 10.0);
  EXPECT_EQ(gap(**made, 220), 240) << "AP 220 reads the bus";
}

TEST(ServoModule, an_unknown_motor_is_refused_before_any_file_is_touched) {
  testing::ScratchDirectory scratch;
  MakeModuleResult made = make_with_motor("turbo", scratch.path() / "state");
  EXPECT_FALSE(made);
  EXPECT_NE(made.error().find("unknown motor \"turbo\""), std::string::npos) << made.error();
  EXPECT_FALSE(std::filesystem::exists(scratch.path() / "state"));
  MakeModuleResult missing = make_with_motor((scratch.path() / "none.json").string());
  EXPECT_NE(missing.error().find("cannot read motor description"), std::string::npos) << missing.error();
}

TEST(ServoModule, a_motor_file_is_loaded) {
  testing::ScratchDirectory scratch;
  const std::string path = (scratch.path() / "m.json").string();
  std::ofstream(path) << sim::motor_description_json(*sim::motor_preset("large-48v"));
  MakeModuleResult made = make_with_motor(path);
  ASSERT_TRUE(made) << made.error();
  EXPECT_EQ(gap(**made, 10), 7);
  EXPECT_EQ(gap(**made, 220), 480) << "48 V supply";
}

// The start-up settings go into new images only; an existing image is the user's.
TEST(ServoModule, an_existing_image_keeps_its_settings) {
  testing::ScratchDirectory scratch;
  {
    MakeModuleResult ideal = make_with_motor("ideal", scratch.path());
    ASSERT_TRUE(ideal);
    EXPECT_EQ(execute(**ideal, kSap, 43, 3000).status, tmcl::Status::kOk);
    EXPECT_EQ(execute(**ideal, kStap, 43, 0).status, tmcl::Status::kOk);
  }
  std::vector<std::string> log;
  MakeModuleResult made = make_with_motor("default-24v", scratch.path(), &log);
  ASSERT_TRUE(made);
  EXPECT_EQ(gap(**made, 14), 0) << "the image says no motor";
  EXPECT_EQ(gap(**made, 43), 3000);
  ASSERT_EQ(log.size(), 1u);
  EXPECT_NE(log[0].find("start-up settings go into new images only"), std::string::npos) << log[0];
}

// A load step at t = 2 s from a scenario file, through the host runtime: the velocity dips and
// recovers; the same run twice gives the same trace bit for bit, whatever the batching.
TEST(ServoModule, a_scenario_load_step_is_rejected_and_runs_are_bit_identical) {
  auto run = [](uint64_t batch) {
    MakeModuleResult made = make_with_motor("default-24v");
    HostRuntime runtime(**made, Pacing::fast());
    const Result<std::vector<sim::ScenarioEvent>> scenario = sim::parse_scenario(
        "2.0 LOAD_TORQUE 0.025\n2.5 REF_R_AT 1e5\n3.0 VSUPPLY 22\n", "step.scn", (*made)->signals().input_signals());
    EXPECT_TRUE(scenario.ok()) << scenario.error();
    runtime.set_scenario(*scenario);
    runtime.start();
    EXPECT_EQ(execute(**made, kSap, 44, 20000).status, tmcl::Status::kOk);
    EXPECT_EQ(execute(**made, kRor, 0, 1500).status, tmcl::Status::kOk);
    std::vector<double> trace;
    double dip = 1e9;
    for (uint64_t done = 0; done < 80'000; done += batch) {
      runtime.advance_ticks(batch);
      const double speed = *(*made)->signals().read_signal("SPEED_RPM");
      if (done > 40'000) dip = std::min(dip, speed);
      trace.push_back(speed);
      trace.push_back(*(*made)->signals().read_signal("VBUS"));
    }
    trace.push_back(dip);
    return trace;
  };
  const std::vector<double> first = run(20);
  EXPECT_LT(first.back(), 1490.0) << "the load step is felt: dip to " << first.back() << " rpm";
  EXPECT_NEAR(first[first.size() - 3], 1500.0, 5.0) << "and rejected";
  const std::vector<double> again = run(20);
  ASSERT_EQ(again.size(), first.size());
  EXPECT_EQ(std::memcmp(again.data(), first.data(), first.size() * sizeof(double)), 0) << "bit-identical";
  const std::vector<double> other_batching = run(400);
  // Sampled every 400 ticks instead of 20: compare the common samples.
  for (size_t i = 0; i + 1 < other_batching.size(); i += 2) {
    const size_t j = (i / 2 + 1) * 20 - 1;
    ASSERT_LT(2 * j + 1, first.size());
    EXPECT_EQ(std::memcmp(&other_batching[i], &first[2 * j], 2 * sizeof(double)), 0) << "sample " << i / 2;
    if (::testing::Test::HasFailure()) break;
  }
}

}  // namespace
}  // namespace motwin::host

namespace motwin::host {
namespace {

// docs/tmcm-1636.md "EEPROM image and firmware changes": starting 1.13 on a 1.09 image keeps the
// settings both have, gives the new rows their defaults, records 1.13 and says so once; going
// back is an update too: AP 7, new to 1.09 from 1.13's side, starts at its default.
TEST(ServoModule, another_firmware_on_a_state_directory_behaves_like_a_firmware_update) {
  testing::ScratchDirectory scratch;
  {
    MakeModuleResult made = make_with_motor("", scratch.path(), nullptr, "1.09");
    ASSERT_TRUE(made) << made.error();
    for (const auto& [number, value] : {std::pair<uint8_t, int32_t>{43, 1234}, {7, 300}}) {
      ASSERT_EQ(execute(**made, kSap, number, value).status, tmcl::Status::kOk);
      ASSERT_EQ(execute(**made, kStap, number, 0).status, tmcl::Status::kOk);
    }
  }
  const std::filesystem::path image = EepromFile::image_path(scratch.path(), "tmcm-1636");
  const auto recorded = [&image] {
    std::ifstream file(image, std::ios::binary);
    char header[64] = {};
    file.read(header, sizeof header);
    return std::string(header + 32);
  };
  EXPECT_EQ(recorded(), "1636V109");
  {
    std::vector<std::string> log;
    MakeModuleResult made = make_with_motor("", scratch.path(), &log, "1.13");
    ASSERT_TRUE(made) << made.error();
    ASSERT_EQ(log.size(), 1u);
    EXPECT_NE(log[0].find("written by firmware 1636V109; 1636V113 takes it over"), std::string::npos) << log[0];
    EXPECT_EQ(recorded(), "1636V113");
    EXPECT_EQ(gap(**made, 43), 1234);
    EXPECT_EQ(gap(**made, 56), 65536);
    EXPECT_EQ(execute(**made, kGap, 7, 0).status, tmcl::Status::kWrongType);
  }
  {
    std::vector<std::string> log;
    MakeModuleResult made = make_with_motor("", scratch.path(), &log, "1.13");
    ASSERT_TRUE(made) << made.error();
    EXPECT_TRUE(log.empty()) << "the same firmware again: nothing to say";
  }
  MakeModuleResult back = make_with_motor("", scratch.path(), nullptr, "1.09");
  ASSERT_TRUE(back) << back.error();
  EXPECT_EQ(gap(**back, 7), 256);
  EXPECT_EQ(gap(**back, 43), 1234);
  EXPECT_EQ(recorded(), "1636V109");
}

}  // namespace
}  // namespace motwin::host
