#include "host/eeprom_file.h"

#include <cerrno>
#include <cstdio>
#include <cstring>
#include <optional>

#include <fcntl.h>
#include <sys/file.h>
#include <sys/stat.h>
#include <unistd.h>

#include "host/crc32.h"

namespace motwin::host {
namespace {

// Offsets in the header (see eeprom_file.h).
constexpr size_t kFormatVersionOffset = 8;
constexpr size_t kHeaderSizeOffset = 12;
constexpr size_t kModuleNameOffset = 16;
constexpr size_t kModuleNameField = 16;
constexpr size_t kFirmwareOffset = 32;
constexpr size_t kFirmwareField = 16;
static_assert(kModuleNameOffset + kModuleNameField == kFirmwareOffset);
constexpr size_t kLayoutVersionOffset = 48;
constexpr size_t kPayloadSizeOffset = 52;
constexpr size_t kPayloadCrcOffset = 56;
constexpr size_t kHeaderCrcOffset = 60;
static_assert(kHeaderCrcOffset + 4 == EepromFile::kHeaderSize);

// Larger files are not read at all: no module image comes near this.
constexpr off_t kMaxFileSize = 16 * 1024 * 1024;

void put_u32(uint8_t* out, uint32_t value) {
  for (int i = 0; i < 4; ++i) out[i] = static_cast<uint8_t>(value >> (8 * i));
}
uint32_t get_u32(const uint8_t* in) {
  return static_cast<uint32_t>(in[0]) | (static_cast<uint32_t>(in[1]) << 8) | (static_cast<uint32_t>(in[2]) << 16) |
         (static_cast<uint32_t>(in[3]) << 24);
}

std::string errno_text(int error) { return std::strerror(error); }

// The firmware field of a valid file (empty in an image written before the record existed).
std::string recorded_firmware_of(const std::vector<uint8_t>& file) {
  const auto* field = reinterpret_cast<const char*>(&file[kFirmwareOffset]);
  return std::string(field, strnlen(field, kFirmwareField));
}

// Reads a whole file. Returns 0, or the errno (ENOENT for a missing file).
int read_file(const std::filesystem::path& path, std::vector<uint8_t>& out) {
  const int fd = ::open(path.c_str(), O_RDONLY | O_CLOEXEC);
  if (fd < 0) return errno;
  struct stat info {};
  int stat_error = ::fstat(fd, &info) != 0 ? errno : 0;
  if (stat_error == 0 && !S_ISREG(info.st_mode)) stat_error = S_ISDIR(info.st_mode) ? EISDIR : EINVAL;
  if (stat_error != 0) {
    ::close(fd);
    return stat_error;
  }
  // An oversized file is read only in part: validate() then reports it as damaged.
  if (info.st_size > kMaxFileSize) info.st_size = kMaxFileSize;
  out.resize(static_cast<size_t>(info.st_size));
  size_t filled = 0;
  while (filled < out.size()) {
    const ssize_t n = ::read(fd, out.data() + filled, out.size() - filled);
    if (n < 0 && errno == EINTR) continue;
    if (n < 0) {
      const int error = errno;
      ::close(fd);
      return error;
    }
    if (n == 0) break;  // shrank while reading: validate() reports the short file
    filled += static_cast<size_t>(n);
  }
  out.resize(filled);
  ::close(fd);
  return 0;
}

int write_all(int fd, const uint8_t* bytes, size_t length) {
  while (length > 0) {
    const ssize_t n = ::write(fd, bytes, length);
    if (n < 0 && errno == EINTR) continue;
    if (n < 0) return errno;
    if (n == 0) return EIO;
    bytes += n;
    length -= static_cast<size_t>(n);
  }
  return 0;
}

// One per process: the crash hook watches the writes of every module's file.
PersistStepObserver& process_persist_observer() {
  static PersistStepObserver observer;
  return observer;
}

}  // namespace

void log_to_stderr(const std::string& line) {
  std::fprintf(stderr, "%s\n", line.c_str());
  std::fflush(stderr);
}

std::filesystem::path EepromFile::image_path(const std::filesystem::path& state_dir, std::string_view module_name) {
  return state_dir / (std::string(module_name) + ".eeprom");
}

std::vector<uint8_t> EepromFile::encode(const EepromImageIdentity& identity, const uint8_t* payload) {
  std::vector<uint8_t> file(kHeaderSize + identity.payload_size, 0);
  std::memcpy(file.data(), kMagic, sizeof(kMagic));
  put_u32(&file[kFormatVersionOffset], kFormatVersion);
  put_u32(&file[kHeaderSizeOffset], static_cast<uint32_t>(kHeaderSize));
  std::memcpy(&file[kModuleNameOffset], identity.module_name.data(),
              std::min(identity.module_name.size(), kMaxModuleNameLength));
  std::memcpy(&file[kFirmwareOffset], identity.firmware_version.data(),
              std::min(identity.firmware_version.size(), kMaxFirmwareLength));
  put_u32(&file[kLayoutVersionOffset], identity.layout_version);
  put_u32(&file[kPayloadSizeOffset], static_cast<uint32_t>(identity.payload_size));
  if (identity.payload_size > 0) std::memcpy(&file[kHeaderSize], payload, identity.payload_size);
  put_u32(&file[kPayloadCrcOffset], crc32(&file[kHeaderSize], identity.payload_size));
  put_u32(&file[kHeaderCrcOffset], crc32(file.data(), kHeaderCrcOffset));
  return file;
}

Result<void> EepromFile::validate(const EepromImageIdentity& identity, const std::vector<uint8_t>& file) {
  if (file.size() < kHeaderSize) {
    return Error{"truncated: " + std::to_string(file.size()) + " bytes, shorter than the " +
                 std::to_string(kHeaderSize) + "-byte header"};
  }
  if (std::memcmp(file.data(), kMagic, sizeof(kMagic)) != 0) return Error{"bad magic, not a Motwin EEPROM image"};
  if (get_u32(&file[kHeaderCrcOffset]) != crc32(file.data(), kHeaderCrcOffset)) return Error{"header CRC mismatch"};
  const uint32_t format_version = get_u32(&file[kFormatVersionOffset]);
  if (format_version != kFormatVersion || get_u32(&file[kHeaderSizeOffset]) != kHeaderSize) {
    return Error{"unsupported file format version " + std::to_string(format_version)};
  }
  const auto* name_field = reinterpret_cast<const char*>(&file[kModuleNameOffset]);
  const std::string stored_name(name_field, strnlen(name_field, kModuleNameField));
  if (stored_name != identity.module_name) return Error{"image of another module: " + stored_name};
  const uint32_t layout_version = get_u32(&file[kLayoutVersionOffset]);
  if (layout_version != identity.layout_version) {
    return Error{"NVM layout version " + std::to_string(layout_version) + ", expected " +
                 std::to_string(identity.layout_version)};
  }
  const uint32_t payload_size = get_u32(&file[kPayloadSizeOffset]);
  if (payload_size != identity.payload_size) {
    return Error{"payload size " + std::to_string(payload_size) + ", expected " +
                 std::to_string(identity.payload_size)};
  }
  const size_t present = file.size() - kHeaderSize;
  if (present < payload_size) {
    return Error{"truncated: " + std::to_string(present) + " of " + std::to_string(payload_size) + " payload bytes"};
  }
  if (present > payload_size) {
    return Error{std::to_string(present - payload_size) + " unexpected bytes after the payload"};
  }
  if (get_u32(&file[kPayloadCrcOffset]) != crc32(&file[kHeaderSize], payload_size)) {
    return Error{"payload CRC mismatch"};
  }
  return {};
}

Result<std::unique_ptr<EepromFile>> EepromFile::open(const std::filesystem::path& state_dir,
                                                     const EepromImageIdentity& identity,
                                                     const FactoryImageFormatter& format_factory_image,
                                                     const LogSink& log) {
  if (identity.module_name.empty() || identity.module_name.size() > kMaxModuleNameLength) {
    return Error{"module name \"" + identity.module_name + "\" does not fit an EEPROM image header"};
  }
  if (identity.firmware_version.size() > kMaxFirmwareLength) {
    return Error{"firmware \"" + identity.firmware_version + "\" does not fit an EEPROM image header"};
  }
  std::error_code ec;
  std::filesystem::create_directories(state_dir, ec);
  if (ec) return Error{"cannot create state directory " + state_dir.string() + ": " + ec.message()};
  const std::filesystem::path path = image_path(state_dir, identity.module_name);
  const int directory_fd = ::open(state_dir.c_str(), O_RDONLY | O_DIRECTORY | O_CLOEXEC);
  if (directory_fd < 0) return Error{"cannot open state directory " + state_dir.string() + ": " + errno_text(errno)};
  // The lock file is never removed: removing it would race with a second server taking it.
  const std::string lock_path = path.string() + ".lock";
  const int lock_fd = ::open(lock_path.c_str(), O_RDWR | O_CREAT | O_CLOEXEC, 0644);
  if (lock_fd < 0) {
    Error error{"cannot create " + lock_path + ": " + errno_text(errno)};
    ::close(directory_fd);
    return error;
  }
  if (::flock(lock_fd, LOCK_EX | LOCK_NB) != 0) {
    Error error{errno == EWOULDBLOCK
                    ? "EEPROM image " + path.string() + " is in use by another motwin process (use another --state-dir)"
                    : "cannot lock " + lock_path + ": " + errno_text(errno)};
    ::close(lock_fd);
    ::close(directory_fd);
    return error;
  }
  std::unique_ptr<EepromFile> file(new EepromFile(path, identity, directory_fd, lock_fd, log));
  // A temporary file is left only by a crash during a write; the image itself is complete.
  ::unlink(file->temporary_path_.c_str());

  std::vector<uint8_t> bytes;
  std::string other_firmware_damage;
  const int read_error = read_file(path, bytes);
  if (read_error == ENOENT) {
    file->load_outcome_ = EepromLoadOutcome::kCreated;
  } else if (read_error != 0) {
    return Error{"cannot read EEPROM image " + path.string() + ": " + errno_text(read_error)};
  } else if (file->take_over_other_firmware(bytes, format_factory_image, other_firmware_damage)) {
    return file;
  } else if (std::optional<Result<void>> migrated = file->migrate_older_layout(bytes); migrated) {
    if (!*migrated) return Error{migrated->error()};
    return file;
  } else if (const Result<void> valid = validate(identity, bytes); !valid) {
    file->load_outcome_ = EepromLoadOutcome::kReplacedDamaged;
    // Another firmware's image that is damaged in its own layout: that is the reason to give.
    const std::string reason = other_firmware_damage.empty() ? valid.error() : other_firmware_damage;
    log("motwin: EEPROM image " + path.string() + " is damaged (" + reason + "); using factory defaults");
    // Keep the evidence; if even that fails the damaged file is simply overwritten below.
    const std::string damaged_path = path.string() + ".damaged";
    (void)::rename(path.c_str(), damaged_path.c_str());
  } else {
    std::memcpy(file->image_.data(), bytes.data() + kHeaderSize, identity.payload_size);
    file->recorded_firmware_ = recorded_firmware_of(bytes);
    return file;
  }
  format_factory_image(file->image_.data(), file->image_.size());
  if (const int error = file->persist(); error != 0) {
    return Error{"cannot write EEPROM image " + path.string() + ": " + errno_text(error)};
  }
  return file;
}

EepromFile::EepromFile(std::filesystem::path path, EepromImageIdentity identity, int directory_fd, int lock_fd,
                       LogSink log)
    : path_(std::move(path)),
      temporary_path_(path_.string() + ".tmp"),
      identity_(std::move(identity)),
      directory_fd_(directory_fd),
      lock_fd_(lock_fd),
      image_(identity_.payload_size, 0),
      log_(std::move(log)) {}

EepromFile::~EepromFile() {
  ::close(lock_fd_);
  ::close(directory_fd_);
}

// An image that is valid but for an older layout version the module can migrate: converted,
// logged and written back at once. nullopt when this does not apply (the caller validates as
// usual); an error only when the migrated image cannot be written.
std::optional<Result<void>> EepromFile::migrate_older_layout(const std::vector<uint8_t>& bytes) {
  if (!identity_.migrate_layout || bytes.size() < kHeaderSize) return std::nullopt;
  const uint32_t stored_layout = get_u32(&bytes[kLayoutVersionOffset]);
  if (stored_layout == identity_.layout_version) return std::nullopt;
  EepromImageIdentity stored_identity = identity_;
  stored_identity.layout_version = stored_layout;
  if (!validate(stored_identity, bytes)) return std::nullopt;
  std::vector<uint8_t> payload(bytes.begin() + kHeaderSize, bytes.end());
  if (!identity_.migrate_layout(stored_layout, payload.data(), payload.size())) return std::nullopt;
  image_ = std::move(payload);
  recorded_firmware_ = recorded_firmware_of(bytes);
  load_outcome_ = EepromLoadOutcome::kMigrated;
  if (log_) {
    log_("motwin: EEPROM image " + path_.string() + " has NVM layout " + std::to_string(stored_layout) +
         "; migrated to layout " + std::to_string(identity_.layout_version));
  }
  if (const int error = persist(); error != 0) {
    return Result<void>{Error{"cannot write EEPROM image " + path_.string() + ": " + errno_text(error)}};
  }
  return Result<void>{};
}

// An intact image that another firmware of the module wrote in its own layout, which the running
// firmware takes over (identity.take_over_firmware): image_ is its conversion, recorded_firmware_
// the previous firmware, nothing is written yet. False when this does not apply (no hook, the
// file records no other firmware, is not intact in its own header's layout, or the hook refuses
// it: a generation of the running firmware in its own layout is ModuleEeprom's firmware_update):
// the caller goes on as before. `damage`: why a file that records another firmware is not intact.
bool EepromFile::take_over_other_firmware(const std::vector<uint8_t>& bytes,
                                          const FactoryImageFormatter& format_factory_image, std::string& damage) {
  if (!identity_.take_over_firmware || bytes.size() < kHeaderSize) return false;
  const std::string previous = recorded_firmware_of(bytes);
  if (previous.empty() || previous == identity_.firmware_version) return false;
  EepromImageIdentity stored_identity = identity_;
  stored_identity.layout_version = get_u32(&bytes[kLayoutVersionOffset]);
  stored_identity.payload_size = get_u32(&bytes[kPayloadSizeOffset]);
  if (const Result<void> intact = validate(stored_identity, bytes); !intact) {
    damage = intact.error();
    return false;
  }
  format_factory_image(image_.data(), image_.size());
  const PreviousFirmwareImage image{previous, stored_identity.layout_version,
                                    std::span<const uint8_t>(bytes).subspan(kHeaderSize)};
  if (!identity_.take_over_firmware(image, image_.data(), image_.size())) return false;
  recorded_firmware_ = previous;
  load_outcome_ = EepromLoadOutcome::kTakenOver;
  return true;
}

bool EepromFile::record_running_firmware() {
  if (recorded_firmware_ == identity_.firmware_version) return true;
  if (const int error = persist(); error != 0) {
    last_write_errno_ = error;
    if (log_) log_("motwin: cannot write EEPROM image " + path_.string() + ": " + errno_text(error));
    return false;
  }
  return true;
}

bool EepromFile::write(size_t offset, const uint8_t* bytes, size_t length) {
  if (offset > image_.size() || length > image_.size() - offset) return false;
  // Nothing changes: the stored image already holds these bytes, durably.
  if (length == 0 || std::memcmp(image_.data() + offset, bytes, length) == 0) return true;
  std::vector<uint8_t> previous(image_.begin() + static_cast<std::ptrdiff_t>(offset),
                                image_.begin() + static_cast<std::ptrdiff_t>(offset + length));
  std::memcpy(image_.data() + offset, bytes, length);
  if (const int error = persist(); error != 0) {
    std::memcpy(image_.data() + offset, previous.data(), length);
    last_write_errno_ = error;
    if (log_) log_("motwin: cannot write EEPROM image " + path_.string() + ": " + errno_text(error) + "; store refused");
    return false;
  }
  return true;
}

void EepromFile::set_process_persist_observer(PersistStepObserver observer) {
  process_persist_observer() = std::move(observer);
}

int EepromFile::injected_fault(PersistStep step) const {
  if (const PersistStepObserver& observer = process_persist_observer()) observer(step);
  return fault_injector_ ? fault_injector_(step) : 0;
}

int EepromFile::persist() {
  const std::vector<uint8_t> file = encode(identity_, image_.data());
  int error = injected_fault(PersistStep::kOpenTemporary);
  const int fd = error != 0 ? -1 : ::open(temporary_path_.c_str(), O_WRONLY | O_CREAT | O_TRUNC | O_CLOEXEC, 0644);
  if (error == 0 && fd < 0) error = errno;
  if (error == 0) error = injected_fault(PersistStep::kWriteTemporary);
  if (error == 0) error = write_all(fd, file.data(), file.size());
  if (error == 0) error = injected_fault(PersistStep::kSyncTemporary);
  if (error == 0 && ::fsync(fd) != 0) error = errno;
  if (fd >= 0 && ::close(fd) != 0 && error == 0) error = errno;
  if (error == 0) error = injected_fault(PersistStep::kRename);
  if (error == 0 && ::rename(temporary_path_.c_str(), path_.c_str()) != 0) error = errno;
  if (error != 0) {
    // Not renamed: the old image is untouched; only the temporary file has to go.
    ::unlink(temporary_path_.c_str());
    return error;
  }
  // After the rename the file holds the new image; without a durable directory entry a power
  // loss could still bring back the old one, so report the write as failed (docs/host-runtime.md).
  error = injected_fault(PersistStep::kSyncDirectory);
  if (error == 0 && ::fsync(directory_fd_) != 0) error = errno;
  if (error == 0) {
    ++persist_count_;
    recorded_firmware_ = identity_.firmware_version;
  }
  return error;
}

}  // namespace motwin::host
