// The EEPROM image of a virtual module as a file in the state directory,
// `<state-dir>/<module-name>.eeprom`, written atomically so that a crash (even SIGKILL in the
// middle of a STAP storm) always leaves either the old or the new image, both complete.
//
// File layout (little-endian), see docs/host-runtime.md:
//   0  8  magic "MOTWINEE"
//   8  4  file format version (kFormatVersion)
//  12  4  header size (kHeaderSize)
//  16 16  module name, ASCII, NUL padded ("tmcm-1636")
//  32 16  firmware that last wrote the image, ASCII, NUL padded ("1636V113"); all NUL in an
//         image written before the record existed (the name field was 32 bytes then, always
//         NUL after the name, so old and new readers agree on both fields)
//  48  4  module NVM layout version (e.g. Tmcm1636::kNvmLayoutVersion)
//  52  4  payload size in bytes
//  56  4  CRC-32 of the payload
//  60  4  CRC-32 of bytes 0..59
//  64     payload: the module's image, byte for byte
#pragma once

#include <cstddef>
#include <cstdint>
#include <filesystem>
#include <functional>
#include <memory>
#include <optional>
#include <span>
#include <string>
#include <string_view>
#include <vector>

#include "board/non_volatile_memory.h"
#include "types/result.h"

namespace motwin::host {

// One diagnostic line (without a trailing newline); the default writes it to stderr.
using LogSink = std::function<void(const std::string& line)>;
void log_to_stderr(const std::string& line);

// An intact image (header and payload CRCs right) of the same module that another firmware wrote
// in another layout (docs/host-runtime.md "Changing firmware").
struct PreviousFirmwareImage {
  std::string_view firmware;  // the version string the file records
  uint32_t layout_version;
  std::span<const uint8_t> payload;
};

// Fills `image` (`size` bytes, already the running firmware's factory image) with what the
// previous firmware's image holds that the running one shares; false when it does not know that
// firmware or layout (the file is then damaged, as any foreign file).
using FirmwareTakeOver = std::function<bool(const PreviousFirmwareImage& previous, uint8_t* image, size_t size)>;

struct EepromImageIdentity {
  std::string module_name;  // at most EepromFile::kMaxModuleNameLength characters
  uint32_t layout_version;  // bumped by the module whenever its stored layout changes
  size_t payload_size;
  // The running firmware ("1636V113", at most EepromFile::kMaxFirmwareLength characters),
  // recorded in every write. Another firmware's record is no damage: the module decides what
  // a firmware change does to the image (ModuleEeprom::open).
  std::string firmware_version = {};
  // Brings the payload of an image of an older layout version (the argument) to layout_version
  // in place; false when it cannot. Empty: every other layout version is foreign. A migrated
  // image is rewritten at once with the new layout version (one log line says so).
  std::function<bool(uint32_t stored_layout_version, uint8_t* payload, size_t size)> migrate_layout = {};
  // Takes over an image that another firmware of the module wrote in its own layout (another
  // layout version or size), e.g. the TMCM-3216's CANopen image under its TMCL firmware. Empty:
  // such an image is foreign (damaged). The converted image is not written by open(): the file
  // still records the previous firmware (recorded_firmware()), and ModuleEeprom::open logs the
  // change and writes the new image with the running firmware's record.
  FirmwareTakeOver take_over_firmware = {};
};

// Fills `image` (payload_size bytes) with the module's factory defaults.
using FactoryImageFormatter = std::function<void(uint8_t* image, size_t size)>;

enum class EepromLoadOutcome : uint8_t {
  kLoaded,           // the file was valid
  kCreated,          // there was no file: the factory image was written
  kReplacedDamaged,  // damaged or foreign: reported, kept as <path>.damaged, factory image written
  kMigrated,         // an older layout version that identity.migrate_layout converted (and wrote)
  kTakenOver,        // another firmware's layout that identity.take_over_firmware converted (not yet written)
};

// Steps of an atomic write, in order, for fault injection in tests.
enum class PersistStep : uint8_t { kOpenTemporary, kWriteTemporary, kSyncTemporary, kRename, kSyncDirectory };

// Sees each step of every image write of the process just before it runs (host/persist_crash_hook.h).
using PersistStepObserver = std::function<void(PersistStep)>;

class EepromFile final : public board::NonVolatileMemory {
 public:
  static constexpr char kMagic[8] = {'M', 'O', 'T', 'W', 'I', 'N', 'E', 'E'};
  static constexpr uint32_t kFormatVersion = 1;
  static constexpr size_t kHeaderSize = 64;
  static constexpr size_t kMaxModuleNameLength = 15;
  static constexpr size_t kMaxFirmwareLength = 15;

  // Creates `state_dir` if needed, takes an exclusive lock (`<path>.lock`, so that two servers
  // never write one image), removes a temporary file left by a crash, and loads the image.
  // A missing, damaged or foreign image is replaced by the factory image (written to disk);
  // damaged or foreign also logs exactly one line through `log`. Fails when the state
  // directory is unusable or the image is in use by another process.
  static Result<std::unique_ptr<EepromFile>> open(const std::filesystem::path& state_dir,
                                                  const EepromImageIdentity& identity,
                                                  const FactoryImageFormatter& format_factory_image,
                                                  const LogSink& log = log_to_stderr);

  static std::filesystem::path image_path(const std::filesystem::path& state_dir, std::string_view module_name);

  EepromFile(const EepromFile&) = delete;
  EepromFile& operator=(const EepromFile&) = delete;
  ~EepromFile();

  // board::NonVolatileMemory.
  size_t size() const override { return image_.size(); }
  const uint8_t* data() const override { return image_.data(); }
  // Updates the image and rewrites the whole file atomically (temporary file, fsync, rename,
  // fsync of the directory) before returning true. On false the image in memory is unchanged,
  // the temporary file is gone, the file holds a complete image (normally the old one) and one
  // line saying why went to the log.
  bool write(size_t offset, const uint8_t* bytes, size_t length) override;

  const std::filesystem::path& path() const { return path_; }
  EepromLoadOutcome load_outcome() const { return load_outcome_; }
  // The firmware the file on disk records: the one that last wrote it (empty for an image
  // written before the record existed); after open() and before any write, the firmware the
  // image comes from.
  const std::string& recorded_firmware() const { return recorded_firmware_; }
  // Rewrites the file so that it records the running firmware (identity.firmware_version), if it
  // does not yet. False (and one log line) when the write fails.
  bool record_running_firmware();
  // errno of the last failed write (0 if none failed).
  int last_write_errno() const { return last_write_errno_; }
  size_t persist_count() const { return persist_count_; }

  // Test hook: called before each step of a write; a non-zero return is taken as that step
  // failing with that errno.
  void set_fault_injector(std::function<int(PersistStep)> injector) { fault_injector_ = std::move(injector); }
  // Test hook for the whole process (every EepromFile, including the factory image written by
  // open()): called before each step of a write, before the file's fault injector. nullptr: none.
  static void set_process_persist_observer(PersistStepObserver observer);

  // Encodes a complete file for `payload` (exposed for tests and tools).
  static std::vector<uint8_t> encode(const EepromImageIdentity& identity, const uint8_t* payload);
  // Success when `file_bytes` is a valid image for `identity`, otherwise why not ("bad magic" ...).
  static Result<void> validate(const EepromImageIdentity& identity, const std::vector<uint8_t>& file_bytes);

 private:
  EepromFile(std::filesystem::path path, EepromImageIdentity identity, int directory_fd, int lock_fd, LogSink log);
  std::optional<Result<void>> migrate_older_layout(const std::vector<uint8_t>& bytes);
  bool take_over_other_firmware(const std::vector<uint8_t>& bytes, const FactoryImageFormatter& format_factory_image,
                                std::string& damage);
  // Writes image_ to disk atomically; on failure returns the errno.
  int persist();
  int injected_fault(PersistStep step) const;

  std::filesystem::path path_;
  std::filesystem::path temporary_path_;
  EepromImageIdentity identity_;
  int directory_fd_;
  int lock_fd_;
  std::vector<uint8_t> image_;
  std::string recorded_firmware_;
  EepromLoadOutcome load_outcome_ = EepromLoadOutcome::kLoaded;
  int last_write_errno_ = 0;
  size_t persist_count_ = 0;
  std::function<int(PersistStep)> fault_injector_;
  LogSink log_;
};

}  // namespace motwin::host
