#include "host/modules/tmcm1636/tmcm1636_firmware_change.h"

#include <optional>

#include "core/modules/tmcm1636/tmcm1636_canopen.h"
#include "core/modules/tmcm1636/tmcm1636_firmware_change.h"
#include "host/canopen_dictionary_view.h"
#include "host/firmware_change.h"
#include "sim/modules/tmcm1636/tmcm1636_sim_io.h"

namespace motwin::host {
namespace {

using namespace modules::tmcm1636;  // the two firmwares and their shared settings

constexpr size_t kTmclImageSize = Tmcm1636::kNvmLayout.total_size;
constexpr size_t kCanopenImageSize = Tmcm1636Canopen::kNvmSize;
constexpr uint8_t kSaveApplicationSubIndex = 3;  // 1010 sub 3: the manufacturer objects

// The TMCL generation that wrote `previous`, if it is a TMCL image.
std::optional<Firmware> tmcl_generation_of(const PreviousFirmwareImage& previous) {
  if (previous.layout_version != Tmcm1636::kNvmLayoutVersion || previous.payload.size() != kTmclImageSize) return {};
  for (const Firmware generation : {Firmware::kV109, Firmware::kV113}) {
    if (previous.firmware == Tmcm1636::identity_of(generation).version_string) return generation;
  }
  return {};
}

bool is_canopen_image(const PreviousFirmwareImage& previous) {
  return previous.firmware == Tmcm1636Canopen::kFirmwareVersion &&
         previous.layout_version == Tmcm1636Canopen::kNvmLayoutVersion && previous.payload.size() == kCanopenImageSize;
}

struct CanopenPeripherals {
  NullCanController can;
  sim::Tmcm1636SimIo io;
};

struct CanopenFirmware : FirmwareOnImage<Tmcm1636Canopen, kCanopenImageSize, CanopenPeripherals> {
  explicit CanopenFirmware(const uint8_t* bytes)
      : FirmwareOnImage(bytes, [](board::NonVolatileMemory& memory, CanopenPeripherals& p) {
          return std::make_unique<Tmcm1636Canopen>(memory, p.can, p.io);
        }) {}
};

struct TmclFirmware : FirmwareOnImage<Tmcm1636, kTmclImageSize, sim::Tmcm1636SimIo> {
  TmclFirmware(const uint8_t* bytes, Firmware generation)
      : FirmwareOnImage(bytes, [generation](board::NonVolatileMemory& memory, sim::Tmcm1636SimIo& io) {
          return std::make_unique<Tmcm1636>(memory, io, generation);
        }) {}
};

constexpr uint8_t kAxes = 1;

}  // namespace

bool tmcm1636_canopen_image_from_tmcl(const PreviousFirmwareImage& previous, uint8_t* image, size_t size) {
  const std::optional<Firmware> generation = tmcl_generation_of(previous);
  if (!generation || size != kCanopenImageSize) return false;
  TmclFirmware tmcl(previous.payload.data(), *generation);
  const SharedSettingValues values = read_tmcl_settings(*tmcl.device, kSharedAxisSettings, kAxes);
  CanopenFirmware canopen(image);
  write_canopen_settings(canopen.device->dictionary(), values, {});
  if (canopen.device->node().store_parameters(kSaveApplicationSubIndex, canopen::kSaveSignature) !=
      canopen::SdoAbort::kNone) {
    return false;
  }
  canopen.copy_image(image);
  return true;
}

FirmwareTakeOver tmcm1636_tmcl_take_over(Firmware running) {
  return [running](const PreviousFirmwareImage& previous, uint8_t* image, size_t size) {
    if (!is_canopen_image(previous) || size != kTmclImageSize) return false;
    CanopenFirmware canopen(previous.payload.data());
    const SharedSettingValues values =
        read_canopen_settings(canopen.device->dictionary(), kSharedAxisSettings, kAxes, {});
    TmclFirmware tmcl(image, running);
    write_tmcl_settings(*tmcl.device, values);
    if (tmcl.device->last_store_failed()) return false;
    tmcl.copy_image(image);
    return true;
  };
}

}  // namespace motwin::host
