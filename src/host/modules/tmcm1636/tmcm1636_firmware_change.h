// A firmware change on one state directory of the TMCM-1636 between its TMCL firmware (1.09 or
// 1.13) and its CANopen firmware (docs/tmcm-1636-canopen.md "Changing firmware"), through the
// shared settings of core/modules/tmcm1636/tmcm1636_firmware_change.h (host/firmware_change.h).
// Between the two TMCL generations the image keeps its layout: ModuleEeprom's firmware_update.
#pragma once

#include <cstddef>
#include <cstdint>

#include "core/modules/tmcm1636/tmcm1636.h"
#include "host/eeprom_file.h"

namespace motwin::host {

// The CANopen firmware's image (`size` bytes, at factory defaults) from either TMCL generation's.
bool tmcm1636_canopen_image_from_tmcl(const PreviousFirmwareImage& previous, uint8_t* image, size_t size);
// The take-over of the TMCL generation `running` of the CANopen firmware's image.
FirmwareTakeOver tmcm1636_tmcl_take_over(modules::tmcm1636::Firmware running);

}  // namespace motwin::host
