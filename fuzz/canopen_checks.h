// Checks shared by the CANopen fuzz targets: SDO responses and the object dictionary's ranges.
#pragma once

#include <cstdint>
#include <cstdio>
#include <cstdlib>
#include <cstring>

#include "core/canopen/sdo_abort.h"
#include "core/canopen/sdo_server.h"
#include "fuzz_support.h"

namespace motwin::fuzz {

inline uint32_t le32(const uint8_t* b) {
  return static_cast<uint32_t>(b[0]) | static_cast<uint32_t>(b[1]) << 8 | static_cast<uint32_t>(b[2]) << 16 |
         static_cast<uint32_t>(b[3]) << 24;
}

// `block_upload`: a block upload is under way, so segments (sequence number 1..127, bit 7 = last)
// are valid too.
inline void check_sdo_response(const can::CanFrame& response, const can::CanFrame* request, bool block_upload) {
  FUZZ_CHECK(!response.extended && !response.rtr && response.dlc == 8, "SDO response with dlc %u", response.dlc);
  const uint8_t header = response.data[0];
  if (block_upload && header != 0x80 && (header & 0x7F) != 0) return;
  const uint8_t scs = header >> 5;
  const bool same_mux = request != nullptr && std::memcmp(&response.data[1], &request->data[1], 3) == 0;
  const uint8_t ccs = request != nullptr ? request->data[0] >> 5 : 0xFF;
  switch (scs) {
    case 0:  // upload segment: toggle, unused bytes, last flag
      break;
    case 1:  // download segment response
      FUZZ_CHECK((header & 0x0F) == 0, "download segment response 0x%02x", header);
      break;
    case 2:  // initiate upload response
      FUZZ_CHECK((header & 0x10) == 0, "initiate upload response 0x%02x", header);
      if (ccs == 2) FUZZ_CHECK(same_mux, "initiate upload response for another index");
      break;
    case 3:  // initiate download response
      FUZZ_CHECK(header == 0x60, "initiate download response 0x%02x", header);
      if (ccs == 1) FUZZ_CHECK(same_mux, "initiate download response for another index");
      break;
    case 4: {  // abort
      FUZZ_CHECK(header == 0x80, "abort 0x%02x", header);
      const uint32_t abort = le32(&response.data[4]);
      FUZZ_CHECK(abort != 0 && canopen::describe(abort)[0] != '\0', "abort code %08x is not in CiA-301's table", abort);
      break;
    }
    case 5:  // block upload responses
    case 6:  // block download responses
      break;
    default:
      FUZZ_CHECK(false, "server command specifier %u (0x%02x)", scs, header);
  }
}

inline void check_dictionary_ranges(Tmcm3216& device) {
  auto& dictionary = device.dictionary();
  for (const auto& row : dictionary.rows()) {
    const canopen::EntryInfo& info = row.info;
    if (!canopen::is_numeric(info.type) || info.access != canopen::Access::kRw) continue;
    const uint8_t axes = info.axis_stride == 0 ? 1 : dictionary.axis_count();
    for (uint8_t axis = 0; axis < axes; ++axis) {
      canopen::ObjectRef ref;
      const uint16_t index = static_cast<uint16_t>(info.index + axis * info.axis_stride);
      if (dictionary.find(index, info.sub, ref) != canopen::SdoAbort::kNone) continue;
      uint8_t bytes[8] = {};
      size_t length = 0;
      if (dictionary.read(ref, bytes, sizeof(bytes), length) != canopen::SdoAbort::kNone) continue;
      const int64_t value = canopen::decode_value(info.type, bytes);
      FUZZ_CHECK(canopen::check_range(info, value) == canopen::SdoAbort::kNone,
                 "object %04x sub %u (%.*s) holds %lld, range %lld..%lld", index, info.sub,
                 static_cast<int>(info.name.size()), info.name.data(), static_cast<long long>(value),
                 static_cast<long long>(info.min), static_cast<long long>(info.max));
    }
  }
}


// MOTWIN_FUZZ_TRACE=1 prints every frame in and out: for reading a saved crash input.
inline void trace(const char* direction, const can::CanFrame& frame) {
  static const bool enabled = std::getenv("MOTWIN_FUZZ_TRACE") != nullptr;
  if (!enabled) return;
  std::fprintf(stderr, "%s %03x [%u]", direction, frame.id, frame.dlc);
  for (uint8_t i = 0; i < frame.dlc && i < 8; ++i) std::fprintf(stderr, " %02x", frame.data[i]);
  std::fprintf(stderr, "\n");
}


}  // namespace motwin::fuzz
