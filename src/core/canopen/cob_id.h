// CAN identifiers a configurable COB-ID must not take (CiA-301 7.3.5, table 4 "restricted
// CAN-IDs"): they belong to NMT, SYNC/TIME's neighbours, the default SDO channels, LSS and NMT
// error control. One list for every COB-ID object that checks it (PDOs, EMCY 1014, SYNC 1005).
#pragma once

#include <cstdint>

namespace motwin::canopen {

// CANopenNode's CO_IS_RESTRICTED_CAN_ID: 000h..07Fh, 101h..180h, 581h..5FFh, 601h..67Fh,
// 6E0h..6FFh, 701h..7FFh.
constexpr bool restricted_can_id(uint32_t id) {
  return id <= 0x7F || (id >= 0x101 && id <= 0x180) || (id >= 0x581 && id <= 0x5FF) ||
         (id >= 0x601 && id <= 0x67F) || (id >= 0x6E0 && id <= 0x6FF) || id >= 0x701;
}

}  // namespace motwin::canopen
