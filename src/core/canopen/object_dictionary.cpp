#include "core/canopen/object_dictionary.h"

namespace motwin::canopen {

void encode_value(DataType type, int64_t value, uint8_t* out) {
  const uint64_t bits = static_cast<uint64_t>(value);
  for (uint8_t i = 0; i < type_size(type); ++i) out[i] = static_cast<uint8_t>(bits >> (8 * i));
}

int64_t decode_value(DataType type, const uint8_t* data) {
  const uint8_t size = type_size(type);
  uint64_t bits = 0;
  for (uint8_t i = 0; i < size; ++i) bits |= static_cast<uint64_t>(data[i]) << (8 * i);
  if (is_signed(type) && size > 0 && size < 8) {
    const uint64_t sign = uint64_t{1} << (8 * size - 1);
    if ((bits & sign) != 0) bits |= ~((sign << 1) - 1);
  }
  return static_cast<int64_t>(bits);
}

SdoAbort check_range(const EntryInfo& info, int64_t value) {
  if (value > info.max) return SdoAbort::kValueTooHigh;
  if (value < info.min) return SdoAbort::kValueTooLow;
  return SdoAbort::kNone;
}

bool index_matches(const EntryInfo& info, uint16_t index, uint8_t axis_count, uint8_t& axis) {
  if (index < info.index) return false;
  const uint32_t delta = static_cast<uint32_t>(index - info.index);
  if (info.axis_stride == 0) {
    axis = 0;
    return delta == 0;
  }
  if (delta % info.axis_stride != 0) return false;
  const uint32_t n = delta / info.axis_stride;
  if (n >= axis_count) return false;
  axis = static_cast<uint8_t>(n);
  return true;
}

}  // namespace motwin::canopen
