#include "host/modules/tmcm3216/tmcm3216_firmware_change.h"

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

struct CanopenPeripherals {
  NullCanController can;
  board::Tmcm3216Board board{};
};

// The CANopen firmware on a copy of `bytes`, with the units of its axes.
struct CanopenFirmware : FirmwareOnImage<Tmcm3216, kCanopenImageSize, CanopenPeripherals> {
  explicit CanopenFirmware(const uint8_t* bytes)
      : FirmwareOnImage(bytes, [](board::NonVolatileMemory& memory, CanopenPeripherals& p) {
          return make_unique_zeroed<Tmcm3216>(memory, p.can, p.board);
        }) {}
  CanopenAxisUnits units() {
    return [this](uint8_t axis) { return device->drive(axis).units(); };
  }
};

struct TmclFirmware : FirmwareOnImage<Tmcm3216Tmcl, kTmclImageSize, board::Tmcm3216Board> {
  explicit TmclFirmware(const uint8_t* bytes)
      : FirmwareOnImage(bytes, [](board::NonVolatileMemory& memory, board::Tmcm3216Board& board) {
          return make_unique_zeroed<Tmcm3216Tmcl>(memory, board);
        }) {}
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
  canopen.copy_image(image);
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
  tmcl.copy_image(image);
  return true;
}

}  // namespace motwin::host
