// Helpers that build EntryRow tables (object_dictionary.h) of any module: a row per sub-index
// with the manual's columns, VARs, the "highest sub-index" entry of arrays and records, and the
// per-axis and PDO-mapping flags. constexpr, so a module's table is built at compile time.
#pragma once

#include <cstdint>
#include <string_view>

#include "core/canopen/object_dictionary.h"

namespace motwin::canopen::rows {

inline constexpr int64_t kU8Max = 0xFF;
inline constexpr int64_t kU16Max = 0xFFFF;
inline constexpr int64_t kU32Max = 0xFFFF'FFFF;
inline constexpr int64_t kI32Min = -2147483648LL;
inline constexpr int64_t kI32Max = 2147483647LL;

// One row. `entry` is the sub-index name, `object` the index name.
template <class Owner>
constexpr EntryRow<Owner> row(uint16_t index, uint8_t sub, ObjectCode code, std::string_view object,
                              std::string_view entry, DataType type, Access access, int64_t min, int64_t max,
                              int64_t default_value, EntryBinding<Owner> binding = {},
                              StorageGroup storage = StorageGroup::kNone) {
  return EntryRow<Owner>{EntryInfo{index, sub, code, object, entry, type, access, false, min, max, default_value,
                                   false, 0, storage, nullptr},
                         binding};
}

template <class Owner>
constexpr EntryRow<Owner> var(uint16_t index, std::string_view name, DataType type, Access access, int64_t min,
                              int64_t max, int64_t default_value, EntryBinding<Owner> binding = {},
                              StorageGroup storage = StorageGroup::kNone) {
  return row<Owner>(index, 0, ObjectCode::kVar, name, name, type, access, min, max, default_value, binding, storage);
}

// Sub-index 0 of an ARRAY or RECORD: "highest sub-index supported", read-only.
template <class Owner>
constexpr EntryRow<Owner> highest_sub(uint16_t index, ObjectCode code, std::string_view object, uint8_t highest,
                                      std::string_view entry = "Highest sub-index supported") {
  return row<Owner>(index, 0, code, object, entry, DataType::kUnsigned8, Access::kRo, highest, highest, highest);
}

template <class Owner>
constexpr EntryRow<Owner> per_axis(EntryRow<Owner> r, uint16_t stride) {
  r.info.axis_stride = stride;
  return r;
}

template <class Owner>
constexpr EntryRow<Owner> mappable(EntryRow<Owner> r) {
  r.info.pdo_mappable = true;
  return r;
}

// A read-only binding.
template <class Owner>
constexpr EntryBinding<Owner> getter(int64_t (*get)(Owner&, uint8_t)) {
  EntryBinding<Owner> b;
  b.get = get;
  return b;
}

// A binding with an extra write check.
template <class Owner>
constexpr EntryBinding<Owner> checked(EntryBinding<Owner> b, SdoAbort (*check)(Owner&, uint8_t, int64_t)) {
  b.check = check;
  return b;
}

}  // namespace motwin::canopen::rows
