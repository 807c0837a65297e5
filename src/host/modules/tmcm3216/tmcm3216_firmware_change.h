// A firmware change on one state directory of the TMCM-3216 (docs/tmcm-3216-tmcl.md "Changing
// firmware"): the CANopen firmware taking over the TMCL firmware's image and the reverse, through
// the shared settings of core/modules/tmcm3216/tmcm3216_firmware_change.h (host/firmware_change.h).
// Each is an EepromImageIdentity::take_over_firmware: false for any other previous firmware or
// layout, so that the image is then damaged as before.
#pragma once

#include <cstddef>
#include <cstdint>

#include "host/eeprom_file.h"

namespace motwin::host {

// The CANopen firmware's image (`size` bytes, at factory defaults) from the TMCL firmware's.
bool tmcm3216_canopen_image_from_tmcl(const PreviousFirmwareImage& previous, uint8_t* image, size_t size);
// The TMCL firmware's image (`size` bytes, at factory defaults) from the CANopen firmware's.
bool tmcm3216_tmcl_image_from_canopen(const PreviousFirmwareImage& previous, uint8_t* image, size_t size);

}  // namespace motwin::host
