// Where a virtual module keeps its EEPROM image: a file in the state directory (`--state-dir`,
// host/eeprom_file.h) or, without one, memory holding a fresh factory image. Each module's
// make() opens one before it constructs the firmware on nvm().
#pragma once

#include <cstddef>
#include <functional>
#include <memory>
#include <string>
#include <string_view>
#include <utility>

#include "board/non_volatile_memory.h"
#include "board/ram_non_volatile_memory.h"
#include "host/eeprom_file.h"
#include "host/module_descriptor.h"
#include "types/result.h"

namespace motwin::host {

// The size of a module's image: its parameter layout's (the TMCL modules) or, for a module
// without one (the TMCM-3216's CANopen storage image), Device::kNvmSize.
template <typename Device>
constexpr size_t nvm_image_size_of() {
  if constexpr (requires { Device::kNvmLayout.total_size; }) {
    return Device::kNvmLayout.total_size;
  } else {
    return Device::kNvmSize;
  }
}

template <typename Device>
constexpr std::string_view default_firmware_of() {
  if constexpr (requires { Device::kIdentity.version_string; }) {
    return Device::kIdentity.version_string;
  } else {
    return Device::kFirmwareVersion;
  }
}

// What a module's image file is checked against: the module's name, layout version and size;
// and the firmware it records (by default the module's one version string).
template <typename Device>
EepromImageIdentity eeprom_identity_of(std::string_view firmware_version = default_firmware_of<Device>()) {
  EepromImageIdentity identity{std::string(Device::kName), Device::kNvmLayoutVersion, nvm_image_size_of<Device>(),
                               std::string(firmware_version)};
  // A module that can read its older layouts says so with a static migrate_image().
  if constexpr (requires(uint8_t* image) { Device::migrate_image(uint32_t{1}, image, size_t{0}); }) {
    identity.migrate_layout = [](uint32_t stored_layout_version, uint8_t* payload, size_t size) {
      return Device::migrate_image(stored_layout_version, payload, size);
    };
  }
  return identity;
}

// What starting another firmware on an existing image does to it, before the firmware powers up
// (a firmware update on the real module): `previous` is the recorded firmware's version string.
using FirmwareUpdate = std::function<void(std::string_view previous, board::NonVolatileMemory& nvm)>;

template <size_t kImageSize>
class ModuleEeprom {
 public:
  using MemoryImage = board::RamNonVolatileMemory<kImageSize>;

  // Opens (or creates) the file when options.state_dir is set, otherwise formats a memory image.
  // A file that another firmware wrote is updated by `firmware_update` (one log line says so)
  // and then records the running firmware; a file written before the record existed just gets
  // the record. A file another firmware wrote in its own layout (another protocol's) is
  // converted by `take_over` (EepromImageIdentity::take_over_firmware; the same one line) and
  // written with the running firmware's record. Fails when the file cannot be used.
  Result<void> open(const ModuleOptions& options, const EepromImageIdentity& identity,
                    const FactoryImageFormatter& format_factory_image, const FirmwareUpdate& firmware_update = {},
                    const FirmwareTakeOver& take_over = {}) {
    if (options.state_dir) {
      EepromImageIdentity file_identity = identity;
      if (take_over) file_identity.take_over_firmware = take_over;
      Result<std::unique_ptr<EepromFile>> opened =
          EepromFile::open(*options.state_dir, file_identity, format_factory_image, options.log);
      if (!opened) return Error{opened.error()};
      file_ = std::move(*opened);
      nvm_ = file_.get();
      const std::string previous = file_->recorded_firmware();
      if (!previous.empty() && previous != identity.firmware_version) {
        options.log("motwin: EEPROM image " + file_->path().string() + " was written by firmware " + previous +
                    "; " + identity.firmware_version + " takes it over like a firmware update");
        if (firmware_update && file_->load_outcome() != EepromLoadOutcome::kTakenOver) firmware_update(previous, *nvm_);
      }
      // A failed write was logged; the image in memory is intact, the record follows later.
      (void)file_->record_running_firmware();
    } else {
      memory_image_ = std::make_unique<MemoryImage>();
      format_factory_image(memory_image_->mutable_data(), memory_image_->size());
      nvm_ = memory_image_.get();
    }
    return {};
  }

  board::NonVolatileMemory& nvm() { return *nvm_; }
  const EepromFile* file() const { return file_.get(); }
  // The file's path, or "none" for a memory image (VirtualModule::nvm_location()).
  std::string location() const { return file_ ? file_->path().string() : "none"; }

 private:
  std::unique_ptr<EepromFile> file_;
  std::unique_ptr<MemoryImage> memory_image_;
  board::NonVolatileMemory* nvm_ = nullptr;
};

}  // namespace motwin::host
