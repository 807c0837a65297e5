// docs/tmcm-1636-canopen.md "Changing firmware": the TMCM-1636's TMCL firmware (1.09, 1.13) and
// its CANopen firmware on one state directory. Starting the other one takes the image over as a
// firmware update does: the settings of core/modules/tmcm1636/tmcm1636_firmware_change.h survive,
// the rest start at their defaults, one log line says so, nothing is set aside as damaged.
#include <gtest/gtest.h>

#include <filesystem>
#include <string>
#include <vector>

#include "core/modules/tmcm1636/tmcm1636_canopen.h"
#include "core/modules/tmcm1636/tmcm1636_firmware_change.h"
#include "host/modules/tmcm1636/tmcm1636_canopen_virtual_module.h"
#include "host/modules/tmcm1636/tmcm1636_virtual_module.h"
#include "support/firmware_change_support.h"
#include "support/host_test_support.h"

namespace motwin::host {
namespace {

using modules::tmcm1636::Firmware;
using modules::tmcm1636::Tmcm1636;
using Canopen = testing::CanopenOn<Tmcm1636CanopenVirtualModule>;
using Tmcl = testing::TmclOn<Tmcm1636VirtualModule>;

constexpr uint8_t kSaveApplication = 3;  // 1010 sub 3: the manufacturer objects

TEST(Tmcm1636FirmwareChange, tmcl_settings_survive_on_the_canopen_firmware_and_on_another_generation) {
  testing::ScratchDirectory dir;
  const auto open_canopen = [&dir](std::vector<std::string>& log) {
    return testing::open_on<Canopen>(&Tmcm1636CanopenVirtualModule::make, dir.path(), log);
  };
  const auto open_tmcl = [&dir](std::vector<std::string>& log, const char* generation) {
    return testing::open_on<Tmcl>(&Tmcm1636VirtualModule::make, dir.path(), log, generation);
  };
  {
    std::vector<std::string> log;
    Tmcl tmcl = open_tmcl(log, "1.13");
    ASSERT_NE(tmcl.module, nullptr);
    // max current, velocity P, pole pairs, position scaler and absolute encoder position start
    // (1.13 only); AP 43 (max velocity, rpm) is not shared.
    testing::sap_stap_all(tmcl, {{11, 0, 5000}, {72, 0, 300}, {10, 0, 7}, {56, 0, 1000}, {166, 0, 3}, {43, 0, 1234}});
  }
  {
    std::vector<std::string> log;
    Canopen canopen = open_canopen(log);
    ASSERT_NE(canopen.module, nullptr);
    testing::expect_taken_over(log, "was written by firmware 1636V113; CANopen V1.12 takes it over like a firmware update",
                               dir, Tmcm1636::kName);
    testing::expect_objects(canopen, {{0x2003, 0, 5000}, {0x2042, 1, 300}, {0x2056, 0, 7}, {0x2058, 0, 1000},
                                      {0x2085, 6, 3},
                                      {0x2042, 2, 0},     // velocity I: the default
                                      {0x6081, 0, 0}});   // not shared: the default
    testing::write_objects(canopen, {{0x2070, 1, 1}});  // hall polarity
    canopen.store(kSaveApplication);
  }
  {
    std::vector<std::string> log;
    Tmcl tmcl = open_tmcl(log, "1.09");
    ASSERT_NE(tmcl.module, nullptr);
    testing::expect_taken_over(log, "was written by firmware CANopen V1.12; 1636V109 takes it over like a firmware update",
                               dir, Tmcm1636::kName);
    testing::expect_aps(tmcl, {{11, 0, 5000}, {72, 0, 300}, {10, 0, 7}, {90, 0, 1},
                               {43, 0, 4000}});  // not shared: the default
    int32_t value = 0;
    EXPECT_EQ(tmcl.device().get_axis_parameter(56, 0, value), tmcl::Status::kWrongType) << "1.09 has no AP 56";
  }
  {
    std::vector<std::string> log;
    Tmcl tmcl = open_tmcl(log, "1.13");
    ASSERT_NE(tmcl.module, nullptr);
    testing::expect_taken_over(log, "was written by firmware 1636V109; 1636V113 takes it over like a firmware update",
                               dir, Tmcm1636::kName);
    testing::expect_aps(tmcl, {{11, 0, 5000}, {90, 0, 1}, {56, 0, 65536}});  // AP 56 did not pass through 1.09
  }
}

// Every row is a stored AP of 1.13 (which has every AP of 1.09 and more) and a stored object.
TEST(Tmcm1636FirmwareChange, every_shared_row_is_a_stored_ap_and_a_stored_object) {
  testing::ScratchDirectory dir;
  std::vector<std::string> log;
  Canopen canopen = testing::open_on<Canopen>(&Tmcm1636CanopenVirtualModule::make, dir.path(), log);
  ASSERT_NE(canopen.module, nullptr);
  for (const params::SharedAxisSetting& shared : modules::tmcm1636::kSharedAxisSettings) {
    const auto* parameter = Tmcm1636::axis_parameters(Firmware::kV113).find(shared.parameter);
    ASSERT_NE(parameter, nullptr) << "AP " << int{shared.parameter};
    EXPECT_TRUE(tmcl::is_stored_parameter(parameter->info)) << "AP " << int{shared.parameter};
    canopen::ObjectRef ref;
    ASSERT_EQ(canopen.device().dictionary().find(shared.index, shared.sub, ref), canopen::SdoAbort::kNone)
        << std::hex << shared.index << " sub " << int{shared.sub};
    EXPECT_NE(ref.info->storage, canopen::StorageGroup::kNone) << std::hex << shared.index;
  }
}

}  // namespace
}  // namespace motwin::host
