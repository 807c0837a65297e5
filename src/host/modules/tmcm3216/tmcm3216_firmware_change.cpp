#include "host/modules/tmcm3216/tmcm3216_firmware_change.h"

#include <cstring>
#include <memory>

#include "board/ram_non_volatile_memory.h"
#include "core/modules/tmcm3216/tmcm3216.h"
#include "core/modules/tmcm3216/tmcm3216_firmware_change.h"
#include "core/modules/tmcm3216/tmcm3216_tmcl.h"
#include "host/canopen_dictionary_view.h"
#include "host/firmware_change.h"
#include "host/zeroed_allocation.h"

namespace motwin::host {
namespace {

using namespace modules::tmcm3216;  // the two firmwares, their axis count and shared settings

constexpr size_t kTmclImageSize = Tmcm3216Tmcl::kNvmLayout.total_size;
constexpr size_t kCanopenImageSize = Tmcm3216::kNvmSize;
using TmclImage = board::RamNonVolatileMemory<kTmclImageSize>;
using CanopenImage = board::RamNonVolatileMemory<kCanopenImageSize>;

// 1010 sub 4 + n: save motor n's parameters.
constexpr uint8_t kSaveMotorSubIndex = 4;

bool is_tmcl_image(const PreviousFirmwareImage& previous) {
  return previous.firmware == Tmcm3216Tmcl::kIdentity.version_string &&
         previous.layout_version == Tmcm3216Tmcl::kNvmLayoutVersion && previous.payload.size() == kTmclImageSize;
}

bool is_canopen_image(const PreviousFirmwareImage& previous) {
  return previous.firmware == Tmcm3216::kFirmwareVersion && previous.layout_version == Tmcm3216::kNvmLayoutVersion &&
         previous.payload.size() == kCanopenImageSize;
}

// The CANopen firmware on a copy of `bytes`, powered up (every object from the image).
struct CanopenFirmware {
  explicit CanopenFirmware(const uint8_t* bytes) : nvm(std::make_unique<CanopenImage>()) {
    std::memcpy(nvm->mutable_data(), bytes, kCanopenImageSize);
    device = make_unique_zeroed<Tmcm3216>(*nvm, can, board);
    device->power_up();
  }
  CanopenAxisUnits units() {
    return [this](uint8_t axis) { return device->drive(axis).units(); };
  }

  std::unique_ptr<CanopenImage> nvm;
  NullCanController can;
  board::Tmcm3216Board board{};
  std::unique_ptr<Tmcm3216> device;
};

// The TMCL firmware on a copy of `bytes`, powered up (every stored parameter from the image).
struct TmclFirmware {
  explicit TmclFirmware(const uint8_t* bytes) : nvm(std::make_unique<TmclImage>()) {
    std::memcpy(nvm->mutable_data(), bytes, kTmclImageSize);
    device = make_unique_zeroed<Tmcm3216Tmcl>(*nvm, board);
    device->power_up();
  }

  std::unique_ptr<TmclImage> nvm;
  board::Tmcm3216Board board{};
  std::unique_ptr<Tmcm3216Tmcl> device;
};

}  // namespace

bool tmcm3216_canopen_image_from_tmcl(const PreviousFirmwareImage& previous, uint8_t* image, size_t size) {
  if (!is_tmcl_image(previous) || size != kCanopenImageSize) return false;
  TmclFirmware tmcl(previous.payload.data());
  const SharedSettingValues values = read_tmcl_settings(*tmcl.device, kSharedAxisSettings, kAxisCount);
  CanopenFirmware canopen(image);
  write_canopen_settings(canopen.device->dictionary(), values, canopen.units());
  for (uint8_t axis = 0; axis < kAxisCount; ++axis) {
    const canopen::SdoAbort saved =
        canopen.device->store_parameters(static_cast<uint8_t>(kSaveMotorSubIndex + axis), Tmcm3216::kSaveSignature);
    if (saved != canopen::SdoAbort::kNone) return false;
  }
  std::memcpy(image, canopen.nvm->data(), size);
  return true;
}

bool tmcm3216_tmcl_image_from_canopen(const PreviousFirmwareImage& previous, uint8_t* image, size_t size) {
  if (!is_canopen_image(previous) || size != kTmclImageSize) return false;
  CanopenFirmware canopen(previous.payload.data());
  const SharedSettingValues values =
      read_canopen_settings(canopen.device->dictionary(), kSharedAxisSettings, kAxisCount, canopen.units());
  TmclFirmware tmcl(image);
  write_tmcl_settings(*tmcl.device, values);
  if (tmcl.device->last_store_failed()) return false;
  std::memcpy(image, tmcl.nvm->data(), size);
  return true;
}

}  // namespace motwin::host
