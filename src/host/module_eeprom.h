// Where a virtual module keeps its EEPROM image: a file in the state directory (`--state-dir`,
// host/eeprom_file.h) or, without one, memory holding a fresh factory image. Each module's
// make() opens one before it constructs the firmware on nvm().
#pragma once

#include <cstddef>
#include <memory>
#include <string>
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

// What a module's image file is checked against: the module's name, layout version and size.
template <typename Device>
EepromImageIdentity eeprom_identity_of() {
  return EepromImageIdentity{std::string(Device::kName), Device::kNvmLayoutVersion, nvm_image_size_of<Device>()};
}

template <size_t kImageSize>
class ModuleEeprom {
 public:
  using MemoryImage = board::RamNonVolatileMemory<kImageSize>;

  // Opens (or creates) the file when options.state_dir is set, otherwise formats a memory image.
  // Fails when the file cannot be used.
  Result<void> open(const ModuleOptions& options, const EepromImageIdentity& identity,
                    const FactoryImageFormatter& format_factory_image) {
    if (options.state_dir) {
      Result<std::unique_ptr<EepromFile>> opened =
          EepromFile::open(*options.state_dir, identity, format_factory_image, options.log);
      if (!opened) return Error{opened.error()};
      file_ = std::move(*opened);
      nvm_ = file_.get();
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
