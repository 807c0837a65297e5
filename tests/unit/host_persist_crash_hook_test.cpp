// MOTWIN_CRASH_AT_PERSIST_STEP (host/persist_crash_hook.h): the values it takes and refuses, and
// where exactly a process dies with it (death tests: the SIGKILL hits a forked child).
#include <gtest/gtest.h>

#include <csignal>
#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <iterator>
#include <optional>
#include <string>
#include <vector>

#include "host/eeprom_file.h"
#include "host/persist_crash_hook.h"
#include "support/host_test_support.h"

namespace motwin::host {
namespace {

using testing::ScratchDirectory;

// Sets the variable for one test and puts back what was there.
class CrashVariable {
 public:
  CrashVariable() {
    if (const char* saved = std::getenv(kCrashAtPersistStepVariable)) saved_ = saved;
  }
  CrashVariable(const CrashVariable&) = delete;
  CrashVariable& operator=(const CrashVariable&) = delete;
  ~CrashVariable() {
    if (saved_) {
      ::setenv(kCrashAtPersistStepVariable, saved_->c_str(), 1);
    } else {
      ::unsetenv(kCrashAtPersistStepVariable);
    }
  }
  void set(const char* value) { ::setenv(kCrashAtPersistStepVariable, value, 1); }
  void unset() { ::unsetenv(kCrashAtPersistStepVariable); }

 private:
  std::optional<std::string> saved_;
};

constexpr size_t kPayloadBytes = 64;
const EepromImageIdentity kIdentity{"tmcm-1636", 1, kPayloadBytes};
const uint8_t kNewBytes[4] = {0x5A, 0x5A, 0x5A, 0x5A};

void fill_factory_image(uint8_t* image, size_t size) {
  for (size_t i = 0; i < size; ++i) image[i] = 0x11;
}

std::vector<uint8_t> file_bytes(const std::filesystem::path& path) {
  std::ifstream file(path, std::ios::binary);
  return std::vector<uint8_t>(std::istreambuf_iterator<char>(file), {});
}

// The complete file a write of kNewBytes at offset 0 over the factory image produces.
std::vector<uint8_t> new_image_file() {
  std::vector<uint8_t> payload(kPayloadBytes, 0x11);
  std::copy(std::begin(kNewBytes), std::end(kNewBytes), payload.begin());
  return EepromFile::encode(kIdentity, payload.data());
}
std::vector<uint8_t> factory_image_file() {
  const std::vector<uint8_t> payload(kPayloadBytes, 0x11);
  return EepromFile::encode(kIdentity, payload.data());
}

TEST(PersistCrashPoint, takes_each_step_name_with_and_without_a_write_number) {
  const std::pair<const char*, PersistStep> steps[] = {
      {"open-temporary", PersistStep::kOpenTemporary}, {"write-temporary", PersistStep::kWriteTemporary},
      {"sync-temporary", PersistStep::kSyncTemporary}, {"rename", PersistStep::kRename},
      {"sync-directory", PersistStep::kSyncDirectory}};
  for (const auto& [name, step] : steps) {
    SCOPED_TRACE(name);
    Result<PersistCrashPoint> point = parse_persist_crash_point(name);
    ASSERT_TRUE(point) << point.error();
    EXPECT_EQ(point->step, step);
    EXPECT_EQ(point->persist_number, 1u);
    EXPECT_EQ(persist_step_name(step), name);
    point = parse_persist_crash_point(std::string(name) + ":7");
    ASSERT_TRUE(point) << point.error();
    EXPECT_EQ(point->step, step);
    EXPECT_EQ(point->persist_number, 7u);
  }
  const Result<PersistCrashPoint> largest = parse_persist_crash_point("rename:1000000000");
  ASSERT_TRUE(largest) << largest.error();
  EXPECT_EQ(largest->persist_number, 1'000'000'000u);
}

TEST(PersistCrashPoint, refuses_anything_else_with_a_message_naming_the_variable_and_the_form) {
  const char* bad_values[] = {"",          "bogus",        "Rename",    "rename ",      " rename",
                              "rename:",   "rename:0",     "rename:-1", "rename:+1",    "rename: 2",
                              "rename:2x", "rename:2:3",   ":2",        "sync:1",       "rename:1000000001",
                              "rename:99999999999999999999"};
  for (const char* value : bad_values) {
    SCOPED_TRACE(value);
    const Result<PersistCrashPoint> point = parse_persist_crash_point(value);
    EXPECT_FALSE(point);
    EXPECT_EQ(point.error(), std::string("MOTWIN_CRASH_AT_PERSIST_STEP=\"") + value +
                         "\": expected STEP or STEP:N with STEP one of open-temporary, write-temporary, "
                         "sync-temporary, rename, sync-directory and N the image write to crash in (1 to 1000000000)");
  }
}

TEST(PersistCrashPoint, unset_or_empty_variable_installs_nothing_and_a_bad_one_is_an_error) {
  CrashVariable variable;
  variable.unset();
  EXPECT_TRUE(install_persist_crash_hook_from_environment());
  variable.set("");
  const Result<void> installed = install_persist_crash_hook_from_environment();
  EXPECT_TRUE(installed);
  EXPECT_EQ(installed.error(), "");
  variable.set("rename:zero");
  const Result<void> refused = install_persist_crash_hook_from_environment();
  EXPECT_FALSE(refused);
  EXPECT_NE(refused.error().find("MOTWIN_CRASH_AT_PERSIST_STEP=\"rename:zero\""), std::string::npos) << refused.error();
  // Nothing was installed: this process still writes images (a crash hook would kill the test).
  ScratchDirectory scratch;
  Result<std::unique_ptr<EepromFile>> opened = EepromFile::open(scratch.path(), kIdentity, fill_factory_image);
  ASSERT_TRUE(opened) << opened.error();
  EXPECT_TRUE((*opened)->write(0, kNewBytes, sizeof kNewBytes));
}

// What a crash just before each step leaves on disk: the temporary file as far as the write got,
// and the old image until the rename has run.
struct CrashOutcome {
  const char* variable_value;
  std::optional<std::vector<uint8_t>> temporary_file;  // nullopt: no temporary file
  std::vector<uint8_t> image_file;
};

TEST(PersistCrashPoint, the_process_dies_by_sigkill_just_before_the_step_of_the_nth_write) {
  // Write 1 is the factory image written by open() into the empty directory; write 2 the store.
  const std::vector<CrashOutcome> outcomes = {
      {"open-temporary:2", std::nullopt, factory_image_file()},
      {"write-temporary:2", std::vector<uint8_t>{}, factory_image_file()},
      {"sync-temporary:2", new_image_file(), factory_image_file()},
      {"rename:2", new_image_file(), factory_image_file()},
      {"sync-directory:2", std::nullopt, new_image_file()},
  };
  // The default ("fast") death test style forks: the child writes into this test's directory.
  for (const CrashOutcome& outcome : outcomes) {
    SCOPED_TRACE(outcome.variable_value);
    ScratchDirectory scratch;
    CrashVariable variable;
    variable.set(outcome.variable_value);
    EXPECT_EXIT(
        {
          if (!install_persist_crash_hook_from_environment()) std::_Exit(3);
          Result<std::unique_ptr<EepromFile>> opened = EepromFile::open(scratch.path(), kIdentity, fill_factory_image);
          if (!opened) std::_Exit(4);
          (*opened)->write(0, kNewBytes, sizeof kNewBytes);
          std::_Exit(0);  // not reached when the hook fires
        },
        ::testing::KilledBySignal(SIGKILL), "");
    const std::filesystem::path image = EepromFile::image_path(scratch.path(), kIdentity.module_name);
    const std::filesystem::path temporary = image.string() + ".tmp";
    EXPECT_EQ(file_bytes(image), outcome.image_file);
    ASSERT_EQ(std::filesystem::exists(temporary), outcome.temporary_file.has_value());
    if (outcome.temporary_file) {
      EXPECT_EQ(file_bytes(temporary), *outcome.temporary_file);
    }
  }
}

TEST(PersistCrashPoint, the_first_write_of_the_process_is_the_default) {
  ScratchDirectory scratch;
  CrashVariable variable;
  variable.set("rename");
  EXPECT_EXIT(
      {
        if (!install_persist_crash_hook_from_environment()) std::_Exit(3);
        (void)EepromFile::open(scratch.path(), kIdentity, fill_factory_image);  // write 1: the factory image
        std::_Exit(0);
      },
      ::testing::KilledBySignal(SIGKILL), "");
  const std::filesystem::path image = EepromFile::image_path(scratch.path(), kIdentity.module_name);
  EXPECT_FALSE(std::filesystem::exists(image));
  EXPECT_EQ(file_bytes(image.string() + ".tmp"), factory_image_file());
}

}  // namespace
}  // namespace motwin::host
