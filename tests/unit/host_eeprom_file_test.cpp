#include <gtest/gtest.h>

#include <fcntl.h>
#include <unistd.h>

#include <cerrno>
#include <cstdlib>
#include <cstring>
#include <filesystem>
#include <fstream>
#include <iterator>
#include <string>
#include <vector>

#include "host/crc32.h"
#include "host/eeprom_file.h"
#include "host/state_dir.h"
#include "support/host_test_support.h"

namespace motwin::host {
namespace {

using testing::ScratchDirectory;

constexpr size_t kPayloadSize = 256;

EepromImageIdentity identity(std::string name = "tmcm-1636", uint32_t layout_version = 1, size_t size = kPayloadSize,
                             std::string firmware = "1636V113") {
  return EepromImageIdentity{std::move(name), layout_version, size, std::move(firmware)};
}

// A factory image that is not all zeros, so that "factory" is recognisable.
void factory(uint8_t* image, size_t size) {
  for (size_t i = 0; i < size; ++i) image[i] = static_cast<uint8_t>(0xA0 + i % 7);
}
std::vector<uint8_t> factory_bytes(size_t size = kPayloadSize) {
  std::vector<uint8_t> bytes(size);
  factory(bytes.data(), size);
  return bytes;
}

std::vector<uint8_t> read_all(const std::filesystem::path& path) {
  std::ifstream file(path, std::ios::binary);
  return std::vector<uint8_t>(std::istreambuf_iterator<char>(file), {});
}
void write_all(const std::filesystem::path& path, const std::vector<uint8_t>& bytes) {
  std::ofstream(path, std::ios::binary | std::ios::trunc).write(reinterpret_cast<const char*>(bytes.data()),
                                                                 static_cast<std::streamsize>(bytes.size()));
}
std::vector<uint8_t> payload_of(const std::vector<uint8_t>& file) {
  return std::vector<uint8_t>(file.begin() + EepromFile::kHeaderSize, file.end());
}

struct Opened {
  struct {
    std::unique_ptr<EepromFile> file;
    std::string error;  // when file is null
  } result;
  std::vector<std::string> log;
};
Opened open_in(const std::filesystem::path& dir, const EepromImageIdentity& id = identity()) {
  Opened opened;
  Result<std::unique_ptr<EepromFile>> result =
      EepromFile::open(dir, id, factory, [&opened](const std::string& line) { opened.log.push_back(line); });
  if (result) {
    opened.result.file = std::move(*result);
  } else {
    opened.result.error = result.error();
  }
  return opened;
}

TEST(Crc32, matches_the_standard_check_value) {
  const char* text = "123456789";
  EXPECT_EQ(crc32(reinterpret_cast<const uint8_t*>(text), 9), 0xCBF43926u);
  EXPECT_EQ(crc32(nullptr, 0), 0u);
}

TEST(EepromFile, a_missing_file_is_created_with_the_factory_image) {
  ScratchDirectory scratch;
  const auto dir = scratch.path() / "state" / "nested";  // created on demand
  Opened opened = open_in(dir);
  ASSERT_TRUE(opened.result.file) << opened.result.error;
  EepromFile& file = *opened.result.file;
  EXPECT_EQ(file.load_outcome(), EepromLoadOutcome::kCreated);
  EXPECT_EQ(file.path(), dir / "tmcm-1636.eeprom");
  EXPECT_TRUE(opened.log.empty());
  EXPECT_EQ(std::vector<uint8_t>(file.data(), file.data() + file.size()), factory_bytes());
  const std::vector<uint8_t> on_disk = read_all(file.path());
  EXPECT_EQ(EepromFile::validate(identity(), on_disk).error(), "");
  EXPECT_EQ(payload_of(on_disk), factory_bytes());
}

TEST(EepromFile, header_fields_are_where_the_documentation_says) {
  const std::vector<uint8_t> payload = factory_bytes();
  const std::vector<uint8_t> file = EepromFile::encode(identity("tmcm-1636", 7), payload.data());
  ASSERT_EQ(file.size(), 64 + kPayloadSize);
  EXPECT_EQ(std::string(file.begin(), file.begin() + 8), "MOTWINEE");
  EXPECT_EQ(file[8], 1);   // format version, little-endian
  EXPECT_EQ(file[12], 64); // header size
  EXPECT_EQ(std::string(reinterpret_cast<const char*>(&file[16])), "tmcm-1636");
  EXPECT_EQ(std::string(reinterpret_cast<const char*>(&file[32])), "1636V113");  // firmware
  EXPECT_EQ(file[48], 7);  // layout version
  EXPECT_EQ(file[52] | (file[53] << 8), static_cast<int>(kPayloadSize));
  const uint32_t payload_crc = crc32(payload.data(), payload.size());
  EXPECT_EQ(file[56], payload_crc & 0xFF);
  EXPECT_EQ(file[59], payload_crc >> 24);
  const uint32_t header_crc = crc32(file.data(), 60);
  EXPECT_EQ(file[60], header_crc & 0xFF);
}

TEST(EepromFile, writes_survive_a_reopen) {
  ScratchDirectory scratch;
  {
    Opened opened = open_in(scratch.path());
    ASSERT_TRUE(opened.result.file);
    const uint8_t value[4] = {1, 2, 3, 4};
    EXPECT_TRUE(opened.result.file->write(100, value, 4));
    EXPECT_EQ(opened.result.file->data()[102], 3);
    EXPECT_EQ(opened.result.file->persist_count(), 2u);  // factory image, then the write
    // Writing the same bytes again changes nothing and costs no disk write.
    EXPECT_TRUE(opened.result.file->write(100, value, 4));
    EXPECT_EQ(opened.result.file->persist_count(), 2u);
  }
  Opened reopened = open_in(scratch.path());
  ASSERT_TRUE(reopened.result.file) << reopened.result.error;
  EXPECT_EQ(reopened.result.file->load_outcome(), EepromLoadOutcome::kLoaded);
  EXPECT_TRUE(reopened.log.empty());
  std::vector<uint8_t> expected = factory_bytes();
  expected[100] = 1;
  expected[101] = 2;
  expected[102] = 3;
  expected[103] = 4;
  EXPECT_EQ(std::vector<uint8_t>(reopened.result.file->data(), reopened.result.file->data() + kPayloadSize), expected);
}

// The firmware record (docs/host-runtime.md "EEPROM image files"): another firmware's image is
// loaded, not replaced, and says which firmware wrote it until the running one rewrites it.
TEST(EepromFile, records_the_firmware_that_last_wrote_it) {
  ScratchDirectory scratch;
  const EepromImageIdentity old_firmware = identity("tmcm-1636", 1, kPayloadSize, "1636V109");
  {
    Opened created = open_in(scratch.path(), old_firmware);
    ASSERT_TRUE(created.result.file) << created.result.error;
    EXPECT_EQ(created.result.file->recorded_firmware(), "1636V109");
    const uint8_t value[4] = {9, 8, 7, 6};
    ASSERT_TRUE(created.result.file->write(40, value, 4));
  }
  Opened opened = open_in(scratch.path(), identity());
  ASSERT_TRUE(opened.result.file) << opened.result.error;
  EepromFile& file = *opened.result.file;
  EXPECT_EQ(file.load_outcome(), EepromLoadOutcome::kLoaded);
  EXPECT_TRUE(opened.log.empty());
  EXPECT_EQ(file.recorded_firmware(), "1636V109");
  EXPECT_EQ(file.data()[41], 8);
  EXPECT_EQ(std::string(reinterpret_cast<const char*>(&read_all(file.path())[32])), "1636V109");
  ASSERT_TRUE(file.record_running_firmware());
  EXPECT_EQ(file.recorded_firmware(), "1636V113");
  const std::vector<uint8_t> on_disk = read_all(file.path());
  EXPECT_EQ(std::string(reinterpret_cast<const char*>(&on_disk[32])), "1636V113");
  EXPECT_EQ(on_disk[64 + 41], 8);
  const size_t writes = file.persist_count();
  ASSERT_TRUE(file.record_running_firmware());
  EXPECT_EQ(file.persist_count(), writes) << "already recorded: no write";
}

// An image from before the record (a 32-byte name field, NUL after the name) loads as it is and
// records no firmware; a name that would run into the record does not fit.
TEST(EepromFile, an_image_without_a_firmware_record_loads_and_long_names_are_refused) {
  ScratchDirectory scratch;
  const std::vector<uint8_t> payload = factory_bytes();
  write_all(EepromFile::image_path(scratch.path(), "tmcm-1636"),
            EepromFile::encode(identity("tmcm-1636", 1, kPayloadSize, ""), payload.data()));
  Opened opened = open_in(scratch.path());
  ASSERT_TRUE(opened.result.file) << opened.result.error;
  EXPECT_EQ(opened.result.file->load_outcome(), EepromLoadOutcome::kLoaded);
  EXPECT_EQ(opened.result.file->recorded_firmware(), "");

  ScratchDirectory other;
  Opened long_name = open_in(other.path(), identity("a-sixteen-chars!", 1));
  EXPECT_FALSE(long_name.result.file);
  EXPECT_NE(long_name.result.error.find("does not fit"), std::string::npos) << long_name.result.error;
  Opened long_firmware = open_in(other.path(), identity("tmcm-1636", 1, kPayloadSize, "1636V1130000000000"));
  EXPECT_FALSE(long_firmware.result.file);
  EXPECT_NE(long_firmware.result.error.find("does not fit"), std::string::npos) << long_firmware.result.error;
}

TEST(EepromFile, writes_out_of_bounds_are_refused) {
  ScratchDirectory scratch;
  Opened opened = open_in(scratch.path());
  ASSERT_TRUE(opened.result.file);
  const uint8_t value[4] = {9, 9, 9, 9};
  EXPECT_FALSE(opened.result.file->write(kPayloadSize - 2, value, 4));
  EXPECT_FALSE(opened.result.file->write(kPayloadSize + 1, value, 0));
  EXPECT_EQ(payload_of(read_all(opened.result.file->path())), factory_bytes());
}

// Each damaged file: exactly one log line, factory image, the old file kept as .damaged.
struct Damage {
  const char* name;
  std::vector<uint8_t> (*make)(std::vector<uint8_t> good);
  const char* reason;
};

const Damage kDamages[] = {
    {"payload byte flipped", [](std::vector<uint8_t> f) { f[64 + 10] ^= 0xFF; return f; }, "payload CRC mismatch"},
    {"magic", [](std::vector<uint8_t> f) { f[0] = 'X'; return f; }, "bad magic, not a Motwin EEPROM image"},
    {"header byte flipped", [](std::vector<uint8_t> f) { f[50] ^= 1; return f; }, "header CRC mismatch"},
    {"truncated payload", [](std::vector<uint8_t> f) { return std::vector<uint8_t>(f.begin(), f.end() - 1); },
     "truncated: 255 of 256 payload bytes"},
    {"truncated header", [](std::vector<uint8_t> f) { return std::vector<uint8_t>(f.begin(), f.begin() + 20); },
     "truncated: 20 bytes, shorter than the 64-byte header"},
    {"empty", [](std::vector<uint8_t>) { return std::vector<uint8_t>(); },
     "truncated: 0 bytes, shorter than the 64-byte header"},
    {"appended byte", [](std::vector<uint8_t> f) { f.push_back(0); return f; }, "1 unexpected bytes after the payload"},
    {"foreign module",
     [](std::vector<uint8_t> f) { return EepromFile::encode(identity("tmcm-142"), payload_of(f).data()); },
     "image of another module: tmcm-142"},
    {"other layout version",
     [](std::vector<uint8_t> f) { return EepromFile::encode(identity("tmcm-1636", 2), payload_of(f).data()); },
     "NVM layout version 2, expected 1"},
    {"other payload size",
     [](std::vector<uint8_t> f) { return EepromFile::encode(identity("tmcm-1636", 1, 128), payload_of(f).data()); },
     "payload size 128, expected 256"},
};

TEST(EepromFile, damaged_or_foreign_images_give_one_log_line_and_the_factory_image) {
  for (const Damage& damage : kDamages) {
    SCOPED_TRACE(damage.name);
    ScratchDirectory scratch;
    std::vector<uint8_t> stored = factory_bytes();
    stored[10] = 0x55;  // a stored value that must not survive
    const std::vector<uint8_t> bad = damage.make(EepromFile::encode(identity(), stored.data()));
    const auto path = EepromFile::image_path(scratch.path(), "tmcm-1636");
    write_all(path, bad);

    Opened opened = open_in(scratch.path());
    ASSERT_TRUE(opened.result.file) << opened.result.error;
    EXPECT_EQ(opened.result.file->load_outcome(), EepromLoadOutcome::kReplacedDamaged);
    ASSERT_EQ(opened.log.size(), 1u);
    EXPECT_EQ(opened.log[0], "motwin: EEPROM image " + path.string() + " is damaged (" + damage.reason +
                                 "); using factory defaults");
    EXPECT_EQ(std::vector<uint8_t>(opened.result.file->data(), opened.result.file->data() + kPayloadSize),
              factory_bytes());
    EXPECT_EQ(read_all(path.string() + ".damaged"), bad);
    EXPECT_EQ(EepromFile::validate(identity(), read_all(path)).error(), "");
  }
}

TEST(EepromFile, a_failed_write_leaves_memory_and_file_as_they_were_and_no_temporary_file) {
  const PersistStep steps[] = {PersistStep::kOpenTemporary, PersistStep::kWriteTemporary, PersistStep::kSyncTemporary,
                               PersistStep::kRename};
  for (PersistStep failing : steps) {
    SCOPED_TRACE(static_cast<int>(failing));
    ScratchDirectory scratch;
    Opened opened = open_in(scratch.path());
    ASSERT_TRUE(opened.result.file);
    EepromFile& file = *opened.result.file;
    const std::vector<uint8_t> before = read_all(file.path());
    file.set_fault_injector([failing](PersistStep step) { return step == failing ? ENOSPC : 0; });
    const uint8_t value[4] = {7, 7, 7, 7};
    EXPECT_FALSE(file.write(8, value, 4));
    EXPECT_EQ(file.last_write_errno(), ENOSPC);
    EXPECT_EQ(std::vector<uint8_t>(file.data(), file.data() + kPayloadSize), factory_bytes());
    EXPECT_EQ(read_all(file.path()), before);
    EXPECT_FALSE(std::filesystem::exists(file.path().string() + ".tmp"));
    ASSERT_EQ(opened.log.size(), 1u);
    EXPECT_EQ(opened.log[0], "motwin: cannot write EEPROM image " + file.path().string() +
                                 ": No space left on device; store refused");
    // The medium recovers: the next write goes through.
    file.set_fault_injector(nullptr);
    EXPECT_TRUE(file.write(8, value, 4));
    EXPECT_EQ(payload_of(read_all(file.path()))[8], 7);
  }
}

TEST(EepromFile, a_failed_directory_sync_reports_failure_yet_leaves_a_complete_image) {
  ScratchDirectory scratch;
  Opened opened = open_in(scratch.path());
  ASSERT_TRUE(opened.result.file);
  EepromFile& file = *opened.result.file;
  file.set_fault_injector([](PersistStep step) { return step == PersistStep::kSyncDirectory ? EIO : 0; });
  const uint8_t value[1] = {0x11};
  EXPECT_FALSE(file.write(0, value, 1));
  EXPECT_EQ(file.data()[0], factory_bytes()[0]);
  EXPECT_EQ(EepromFile::validate(identity(), read_all(file.path())).error(), "");
}

TEST(EepromFile, a_write_where_no_file_can_be_created_fails_and_keeps_the_old_file) {
  ScratchDirectory scratch;
  Opened opened = open_in(scratch.path());
  ASSERT_TRUE(opened.result.file);
  EepromFile& file = *opened.result.file;
  const std::vector<uint8_t> before = read_all(file.path());
  // A directory in the way of the temporary file: open() fails even for root (EISDIR).
  std::filesystem::create_directory(file.path().string() + ".tmp");
  const uint8_t value[4] = {1, 1, 1, 1};
  EXPECT_FALSE(file.write(0, value, 4));
  EXPECT_EQ(file.last_write_errno(), EISDIR);
  EXPECT_EQ(read_all(file.path()), before);
  EXPECT_EQ(file.data()[0], factory_bytes()[0]);
}

TEST(EepromFile, a_read_only_state_directory_refuses_writes_and_keeps_the_old_file) {
  if (::geteuid() == 0) GTEST_SKIP() << "root ignores directory permissions";
  ScratchDirectory scratch;
  Opened opened = open_in(scratch.path());
  ASSERT_TRUE(opened.result.file);
  EepromFile& file = *opened.result.file;
  const std::vector<uint8_t> before = read_all(file.path());
  std::filesystem::permissions(scratch.path(), std::filesystem::perms::owner_write, std::filesystem::perm_options::remove);
  const uint8_t value[4] = {1, 1, 1, 1};
  EXPECT_FALSE(file.write(0, value, 4));
  EXPECT_EQ(file.last_write_errno(), EACCES);
  EXPECT_EQ(read_all(file.path()), before);
}

TEST(EepromFile, a_temporary_file_left_by_a_crash_is_removed_and_the_image_loads) {
  ScratchDirectory scratch;
  { ASSERT_TRUE(open_in(scratch.path()).result.file); }
  const auto path = EepromFile::image_path(scratch.path(), "tmcm-1636");
  write_all(path.string() + ".tmp", {1, 2, 3});  // a write cut short by SIGKILL
  Opened opened = open_in(scratch.path());
  ASSERT_TRUE(opened.result.file);
  EXPECT_EQ(opened.result.file->load_outcome(), EepromLoadOutcome::kLoaded);
  EXPECT_TRUE(opened.log.empty());
  EXPECT_FALSE(std::filesystem::exists(path.string() + ".tmp"));
}

TEST(EepromFile, a_second_user_of_the_same_image_is_refused) {
  ScratchDirectory scratch;
  Opened first = open_in(scratch.path());
  ASSERT_TRUE(first.result.file);
  Opened second = open_in(scratch.path());
  EXPECT_FALSE(second.result.file);
  EXPECT_EQ(second.result.error, "EEPROM image " + first.result.file->path().string() +
                                     " is in use by another motwin process (use another --state-dir)");
  // Another module in the same directory is fine.
  EXPECT_TRUE(open_in(scratch.path(), identity("tmcm-142")).result.file);
}

TEST(EepromFile, an_unusable_state_directory_is_an_error) {
  ScratchDirectory scratch;
  write_all(scratch.path() / "file", {0});
  Opened opened = open_in(scratch.path() / "file" / "state");
  EXPECT_FALSE(opened.result.file);
  EXPECT_NE(opened.result.error.find("cannot create state directory"), std::string::npos) << opened.result.error;
}

TEST(StateDir, follows_xdg_data_home_then_home) {
  const char* saved_xdg = std::getenv("XDG_DATA_HOME");
  const char* saved_home = std::getenv("HOME");
  const std::string xdg = saved_xdg ? saved_xdg : "";
  const std::string home = saved_home ? saved_home : "";
  ::setenv("XDG_DATA_HOME", "/data/alice", 1);
  ::setenv("HOME", "/home/alice", 1);
  EXPECT_EQ(default_state_dir(), std::filesystem::path("/data/alice/motwin"));
  ::setenv("XDG_DATA_HOME", "relative/ignored", 1);
  EXPECT_EQ(default_state_dir(), std::filesystem::path("/home/alice/.local/share/motwin"));
  ::unsetenv("XDG_DATA_HOME");
  EXPECT_EQ(default_state_dir(), std::filesystem::path("/home/alice/.local/share/motwin"));
  if (saved_xdg) ::setenv("XDG_DATA_HOME", xdg.c_str(), 1);
  if (saved_home) {
    ::setenv("HOME", home.c_str(), 1);
  } else {
    ::unsetenv("HOME");
  }
}

}  // namespace
}  // namespace motwin::host
