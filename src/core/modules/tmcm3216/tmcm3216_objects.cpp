// The TMCM-3216 object dictionary as data: communication area (manual chapter 3, tables 7-47),
// the node ID / bit rate objects (4.2.62-4.2.66), the manufacturer objects of the stepper axes
// and the I/O (tmcm3216_manufacturer_objects.h), the ramp and unit objects and the CiA-402 profile
// area (tmcm3216_profile_objects.h). One row per sub-index; rows with an axis
// stride exist once per motor (PDO parameters: + 0x40 per axis, manual 3.1.15-3.1.18).
#include <array>

#include "core/canopen/cob_id.h"
#include "core/modules/tmcm3216/tmcm3216.h"
#include "core/modules/tmcm3216/tmcm3216_manufacturer_objects.h"
#include "core/modules/tmcm3216/tmcm3216_profile_objects.h"

namespace motwin::modules::tmcm3216 {
namespace {

using canopen::Access;
using canopen::DataType;
using canopen::EntryBinding;
using canopen::EntryInfo;
using canopen::ObjectCode;
using canopen::SdoAbort;
using canopen::StorageGroup;
using Row = Tmcm3216::Row;
using Binding = EntryBinding<Tmcm3216>;

constexpr int64_t kU8Max = 0xFF;
constexpr int64_t kU16Max = 0xFFFF;
constexpr int64_t kU32Max = 0xFFFF'FFFF;
constexpr uint32_t kCobIdInvalid = 0x8000'0000;  // bit 31: PDO / EMCY not valid
constexpr uint32_t kCobIdExtended = 0x2000'0000; // bit 29: 29-bit identifier
constexpr uint32_t kCobIdMask = 0x7FF;

// One row. `entry` names are the sub-index names; `object` the index name.
constexpr Row row(uint16_t index, uint8_t sub, ObjectCode code, std::string_view object, std::string_view entry,
                  DataType type, Access access, int64_t min, int64_t max, int64_t default_value, Binding binding = {},
                  StorageGroup storage = StorageGroup::kNone) {
  return Row{EntryInfo{index, sub, code, object, entry, type, access, false, min, max, default_value, false, 0,
                       storage, nullptr},
             binding};
}

constexpr Row var(uint16_t index, std::string_view name, DataType type, Access access, int64_t min, int64_t max,
                  int64_t default_value, Binding binding = {}, StorageGroup storage = StorageGroup::kNone) {
  return row(index, 0, ObjectCode::kVar, name, name, type, access, min, max, default_value, binding, storage);
}

constexpr Row string_var(uint16_t index, std::string_view name, std::string_view (*get)(Tmcm3216&, uint8_t)) {
  Binding binding;
  binding.get_string = get;
  return row(index, 0, ObjectCode::kVar, name, name, DataType::kVisibleString, Access::kConst, 0, 0, 0, binding);
}

// Sub-index 0 of an ARRAY or RECORD: "highest sub-index supported", read-only.
constexpr Row highest_sub(uint16_t index, ObjectCode code, std::string_view object, uint8_t highest,
                          std::string_view entry = "Highest sub-index supported") {
  return row(index, 0, code, object, entry, DataType::kUnsigned8, Access::kRo, highest, highest, highest);
}

constexpr Row with_binding(Row r, Binding binding) {
  r.binding = binding;
  return r;
}

constexpr Row per_axis(Row r, uint16_t stride, int64_t (*axis_default)(uint8_t) = nullptr) {
  r.info.axis_stride = stride;
  r.info.axis_default = axis_default;
  return r;
}

constexpr Row plus_node_id(Row r) {
  r.info.default_plus_node_id = true;
  return r;
}

// --- Checks of SDO writes (CiA-301 rules the manual relies on) --------------------------------

using canopen::restricted_can_id;

// A COB-ID of a PDO: 11-bit only, no restricted ID, and its ID does not change while it is valid
// (set bit 31 first, as the manual's procedure and python-canopen do). Bit 30 (RTR) is accepted
// either way: RTR is never answered (manual 1.1).
SdoAbort check_pdo_cob_id(uint32_t current, int64_t value) {
  const uint32_t v = static_cast<uint32_t>(value);
  if ((v & kCobIdExtended) != 0 || (v & 0x1FFF'F800) != 0) return SdoAbort::kInvalidValue;
  const bool valid_now = (current & kCobIdInvalid) == 0;
  const bool valid_next = (v & kCobIdInvalid) == 0;
  if (!valid_next) return SdoAbort::kNone;
  if (restricted_can_id(v & kCobIdMask)) return SdoAbort::kInvalidValue;
  if (valid_now && ((v ^ current) & kCobIdMask) != 0) return SdoAbort::kInvalidValue;
  return SdoAbort::kNone;
}

// Manual 3.1.15/3.1.17: FF or FE (event driven) or 1..240 (synchronous); "other values are not
// supported".
SdoAbort check_transmission_type(int64_t value) {
  return (value >= 1 && value <= 240) || value == 0xFE || value == 0xFF ? SdoAbort::kNone : SdoAbort::kInvalidValue;
}

using canopen::pdo_valid;

// A mapping entry `index << 16 | sub << 8 | bits` (CiA-301 7.5.2.36): the object exists, may be
// mapped, and its size is `bits`. Both directions may map the dummy types 0002..0007 (sub 0): an
// RPDO skips their bytes, a TPDO sends zeros (as CANopenNode).
SdoAbort check_mapping_entry(Tmcm3216& device, bool receive, uint32_t entry) {
  const uint16_t index = static_cast<uint16_t>(entry >> 16);
  const uint8_t bits = static_cast<uint8_t>(entry);
  if (bits == 0 || bits % 8 != 0) return SdoAbort::kNotMappable;
  const uint8_t sub = static_cast<uint8_t>(entry >> 8);
  if (canopen::is_dummy_mapping(entry)) {
    return canopen::type_size(static_cast<DataType>(index)) * 8 == bits ? SdoAbort::kNone : SdoAbort::kNotMappable;
  }
  canopen::ObjectRef ref;
  if (device.dictionary().find(index, sub, ref) != SdoAbort::kNone) return SdoAbort::kNotMappable;
  const EntryInfo& info = *ref.info;
  if (!info.pdo_mappable || canopen::type_size(info.type) * 8 != bits) return SdoAbort::kNotMappable;
  if (receive ? !canopen::writable(info.access) : !canopen::readable(info.access)) return SdoAbort::kNotMappable;
  return SdoAbort::kNone;
}

// Sub 0 of a mapping: only while the PDO is not valid; entries 1..n must be valid and fit in 8 bytes.
SdoAbort check_mapping_count(Tmcm3216& device, bool receive, const PdoCommunication& pdo, const PdoMapping& mapping,
                             int64_t count) {
  if (pdo_valid(pdo)) return SdoAbort::kDeviceState;
  uint32_t bits = 0;
  for (int64_t i = 0; i < count; ++i) {
    const uint32_t entry = mapping.entries[i];
    if (entry == 0) return SdoAbort::kNotMappable;
    if (const SdoAbort abort = check_mapping_entry(device, receive, entry); abort != SdoAbort::kNone) return abort;
    bits += entry & 0xFF;
  }
  return bits > 64 ? SdoAbort::kMappingTooLong : SdoAbort::kNone;
}

// An entry: only while the PDO is not valid and sub 0 is 0 (manual 3.1.16 procedure).
SdoAbort check_mapping_write(Tmcm3216& device, bool receive, const PdoCommunication& pdo, const PdoMapping& mapping,
                             int64_t value) {
  if (pdo_valid(pdo) || mapping.count != 0) return SdoAbort::kDeviceState;
  if (value == 0) return SdoAbort::kNone;
  return check_mapping_entry(device, receive, static_cast<uint32_t>(value));
}

// --- PDO rows, one set per PDO number K (0..3) of axis 0 -----------------------------------------

constexpr std::string_view kRpdoCommunicationNames[kPdosPerAxis] = {
    "RPDO 1 communication parameter", "RPDO 2 communication parameter", "RPDO 3 communication parameter",
    "RPDO 4 communication parameter"};
constexpr std::string_view kRpdoMappingNames[kPdosPerAxis] = {"RPDO 1 mapping parameter", "RPDO 2 mapping parameter",
                                                              "RPDO 3 mapping parameter", "RPDO 4 mapping parameter"};
constexpr std::string_view kTpdoCommunicationNames[kPdosPerAxis] = {
    "TPDO 1 communication parameter", "TPDO 2 communication parameter", "TPDO 3 communication parameter",
    "TPDO 4 communication parameter"};
constexpr std::string_view kTpdoMappingNames[kPdosPerAxis] = {"TPDO 1 mapping parameter", "TPDO 2 mapping parameter",
                                                              "TPDO 3 mapping parameter", "TPDO 4 mapping parameter"};
constexpr std::string_view kMappingEntryNames[kMaxMappedObjects] = {"Mapping entry 1", "Mapping entry 2",
                                                                    "Mapping entry 3"};

// Tables 41, 43, 45, 47 (axis 0).
constexpr uint32_t kRpdoCobIdBase[kPdosPerAxis] = {0x200, 0x300, 0x400, 0x500};
constexpr uint8_t kRpdoTransmissionType[kPdosPerAxis] = {0xFF, 0xFF, 0xFF, 0xFE};
constexpr uint8_t kRpdoMappingCount[kPdosPerAxis] = {1, 2, 2, 2};
constexpr uint32_t kRpdoMapping[kPdosPerAxis][kMaxMappedObjects] = {
    {0x6040'0010, 0, 0}, {0x6040'0010, 0x6060'0008, 0}, {0x6040'0010, 0x607A'0020, 0}, {0x6040'0010, 0x60FF'0020, 0}};
constexpr uint32_t kTpdoCobIdBase[kPdosPerAxis] = {0x180, 0x280, 0x380, 0x480};
constexpr uint8_t kTpdoTransmissionType[kPdosPerAxis] = {0xFF, 0xFF, 0x01, 0x01};
constexpr uint8_t kTpdoMappingCount[kPdosPerAxis] = {1, 2, 2, 2};
constexpr uint32_t kTpdoMapping[kPdosPerAxis][kMaxMappedObjects] = {
    {0x6041'0010, 0, 0}, {0x6041'0010, 0x6061'0008, 0}, {0x6041'0010, 0x6064'0020, 0}, {0x6041'0010, 0x606C'0020, 0}};

// Axes 1 and 2: the manual gives defaults for axis 0 only. Their PDOs start not valid (bit 31)
// with axis 0's identifiers, so that nothing collides until a master configures them, and their
// mappings name the same objects of their own axis (+ 0x800 per axis, manual 2.6.1).
template <size_t K, bool Receive>
int64_t pdo_cob_id_default(uint8_t axis) {
  const uint32_t base = Receive ? kRpdoCobIdBase[K] : kTpdoCobIdBase[K];
  return axis == 0 ? base : (base | kCobIdInvalid);
}
template <size_t K, size_t E, bool Receive>
int64_t mapping_default(uint8_t axis) {
  const uint32_t entry = Receive ? kRpdoMapping[K][E] : kTpdoMapping[K][E];
  return entry == 0 ? 0 : entry + static_cast<uint32_t>(axis) * 0x0800'0000u;
}

template <size_t K, bool Receive>
PdoCommunication& pdo_of(Tmcm3216& d, uint8_t axis) {
  const size_t i = static_cast<size_t>(axis) * kPdosPerAxis + K;
  return Receive ? d.communication().rpdo[i] : d.communication().tpdo[i];
}
template <size_t K, bool Receive>
PdoMapping& mapping_of(Tmcm3216& d, uint8_t axis) {
  const size_t i = static_cast<size_t>(axis) * kPdosPerAxis + K;
  return Receive ? d.communication().rpdo_mapping[i] : d.communication().tpdo_mapping[i];
}

template <size_t K, bool Receive>
constexpr Binding cob_id_binding() {
  Binding b = canopen::field_binding<Tmcm3216, [](Tmcm3216& d, uint8_t axis) -> uint32_t& {
    return pdo_of<K, Receive>(d, axis).cob_id;
  }>();
  b.check = [](Tmcm3216& d, uint8_t axis, int64_t v) { return check_pdo_cob_id(pdo_of<K, Receive>(d, axis).cob_id, v); };
  return b;
}

template <size_t K, bool Receive>
constexpr Binding transmission_type_binding() {
  Binding b = canopen::field_binding<Tmcm3216, [](Tmcm3216& d, uint8_t axis) -> uint8_t& {
    return pdo_of<K, Receive>(d, axis).transmission_type;
  }>();
  b.check = [](Tmcm3216&, uint8_t, int64_t v) { return check_transmission_type(v); };
  return b;
}

template <size_t K>
constexpr Binding inhibit_time_binding() {
  Binding b = canopen::field_binding<Tmcm3216, [](Tmcm3216& d, uint8_t axis) -> uint16_t& {
    return pdo_of<K, false>(d, axis).inhibit_time_100us;
  }>();
  // CiA-301 7.5.2.35: not changeable while the PDO is valid.
  b.check = [](Tmcm3216& d, uint8_t axis, int64_t) {
    return pdo_valid(pdo_of<K, false>(d, axis)) ? SdoAbort::kInvalidValue : SdoAbort::kNone;
  };
  return b;
}

template <size_t K>
constexpr Binding event_timer_binding() {
  return canopen::field_binding<Tmcm3216, [](Tmcm3216& d, uint8_t axis) -> uint16_t& {
    return pdo_of<K, false>(d, axis).event_timer_ms;
  }>();
}

template <size_t K, bool Receive>
constexpr Binding mapping_count_binding() {
  Binding b = canopen::field_binding<Tmcm3216, [](Tmcm3216& d, uint8_t axis) -> uint8_t& {
    return mapping_of<K, Receive>(d, axis).count;
  }>();
  b.check = [](Tmcm3216& d, uint8_t axis, int64_t v) {
    return check_mapping_count(d, Receive, pdo_of<K, Receive>(d, axis), mapping_of<K, Receive>(d, axis), v);
  };
  return b;
}

template <size_t K, size_t E, bool Receive>
constexpr Binding mapping_entry_binding() {
  Binding b = canopen::field_binding<Tmcm3216, [](Tmcm3216& d, uint8_t axis) -> uint32_t& {
    return mapping_of<K, Receive>(d, axis).entries[E];
  }>();
  b.check = [](Tmcm3216& d, uint8_t axis, int64_t v) {
    return check_mapping_write(d, Receive, pdo_of<K, Receive>(d, axis), mapping_of<K, Receive>(d, axis), v);
  };
  return b;
}

// --- Other bindings ---------------------------------------------------------------------------------

template <uint8_t Sub>
constexpr Binding store_binding() {
  Binding b;
  b.set = [](Tmcm3216& d, uint8_t, int64_t v) { return d.store_parameters(Sub, static_cast<uint32_t>(v)); };
  return b;
}

template <uint8_t Sub>
constexpr Binding restore_binding() {
  Binding b;
  b.set = [](Tmcm3216& d, uint8_t, int64_t v) { return d.restore_parameters(Sub, static_cast<uint32_t>(v)); };
  return b;
}

// 1005: bit 30 makes the module the SYNC producer (with 1006), a Motwin extension: the manual's
// module is a consumer only (1.1), and the factory value keeps it one. 29-bit identifiers are not
// supported (table 12), restricted identifiers are refused, and the identifier is fixed while
// bit 30 is set (docs/canopen.md "SDO abort codes").
constexpr Binding sync_cob_id_binding() {
  Binding b;
  b.get = [](Tmcm3216& d, uint8_t) { return static_cast<int64_t>(d.communication().sync_cob_id); };
  b.set = [](Tmcm3216& d, uint8_t, int64_t v) {
    d.communication().sync_cob_id = static_cast<uint32_t>(v);
    d.sync().set_cob_id(static_cast<uint32_t>(v));
    return SdoAbort::kNone;
  };
  b.check = [](Tmcm3216& d, uint8_t, int64_t value) {
    const uint32_t v = static_cast<uint32_t>(value);
    const uint32_t current = d.communication().sync_cob_id;
    const uint32_t allowed = kCobIdMask | canopen::kSyncProducerBit;
    if ((v & ~allowed) != 0) return SdoAbort::kInvalidValue;
    // The restricted identifiers the PDO and EMCY COB-IDs refuse too (CiA-301 7.3.5).
    if (restricted_can_id(v & kCobIdMask)) return SdoAbort::kInvalidValue;
    // CiA-301 7.5.2.5: bits 29..0 do not change while the node produces SYNC (bit 30 set now);
    // a master clears bit 30 first (same identifier), then writes the new one.
    constexpr uint32_t kIdentifierBits = 0x3FFF'FFFF;
    if ((current & canopen::kSyncProducerBit) != 0 && ((v ^ current) & kIdentifierBits) != 0) {
      return SdoAbort::kInvalidValue;
    }
    return SdoAbort::kNone;
  };
  return b;
}

// 1006 (CiA-301 7.5.2.6), µs; the producer's period when 1005 bit 30 is set.
constexpr Binding sync_period_binding() {
  Binding b;
  b.get = [](Tmcm3216& d, uint8_t) { return static_cast<int64_t>(d.communication().sync_period_us); };
  b.set = [](Tmcm3216& d, uint8_t, int64_t v) {
    d.communication().sync_period_us = static_cast<uint32_t>(v);
    d.sync().set_cycle_period_us(static_cast<uint32_t>(v));
    return SdoAbort::kNone;
  };
  return b;
}

// 1014: bit 31 switches EMCY off; 11-bit identifiers only; the ID does not change while valid.
constexpr Binding emcy_cob_id_binding() {
  Binding b;
  b.get = [](Tmcm3216& d, uint8_t) { return static_cast<int64_t>(d.communication().emcy_cob_id); };
  b.set = [](Tmcm3216& d, uint8_t, int64_t v) {
    d.communication().emcy_cob_id = static_cast<uint32_t>(v);
    d.emergency().set_cob_id(static_cast<uint32_t>(v));
    return SdoAbort::kNone;
  };
  b.check = [](Tmcm3216& d, uint8_t, int64_t value) {
    const uint32_t v = static_cast<uint32_t>(value);
    const uint32_t current = d.communication().emcy_cob_id;
    if ((v & 0x7FFF'F800) != 0) return SdoAbort::kInvalidValue;
    if ((v & kCobIdInvalid) != 0) return SdoAbort::kNone;
    if ((current & kCobIdInvalid) == 0 && ((v ^ current) & kCobIdMask) != 0) return SdoAbort::kInvalidValue;
    return restricted_can_id(v & kCobIdMask) && (v & kCobIdMask) != 0x80u + d.node_id() ? SdoAbort::kInvalidValue
                                                                                       : SdoAbort::kNone;
  };
  return b;
}

// 1016 sub 1: bits 31..24 reserved, node ID 1..127 in bits 23..16 (or 0: entry unused).
constexpr Binding consumer_heartbeat_binding() {
  Binding b;
  b.get = [](Tmcm3216& d, uint8_t) { return static_cast<int64_t>(d.communication().consumer_heartbeat[0]); };
  b.set = [](Tmcm3216& d, uint8_t, int64_t v) {
    d.communication().consumer_heartbeat[0] = static_cast<uint32_t>(v);
    d.heartbeat_consumer().configure(static_cast<uint32_t>(v));
    return SdoAbort::kNone;
  };
  b.check = [](Tmcm3216&, uint8_t, int64_t value) {
    const uint32_t v = static_cast<uint32_t>(value);
    return (v >> 24) != 0 || ((v >> 16) & 0xFF) > 127 ? SdoAbort::kInvalidValue : SdoAbort::kNone;
  };
  return b;
}

constexpr Binding producer_heartbeat_binding() {
  Binding b;
  b.get = [](Tmcm3216& d, uint8_t) { return static_cast<int64_t>(d.communication().producer_heartbeat_ms); };
  b.set = [](Tmcm3216& d, uint8_t, int64_t v) {
    d.communication().producer_heartbeat_ms = static_cast<uint16_t>(v);
    d.nmt().set_heartbeat_period_ms(static_cast<uint16_t>(v));
    return SdoAbort::kNone;
  };
  return b;
}

template <size_t I>
constexpr Binding error_behavior_binding() {
  return canopen::field_binding<Tmcm3216, [](Tmcm3216& d, uint8_t) -> uint8_t& {
    return d.communication().error_behavior[I];
  }>();
}

// 2704: table 177 lists the allowed bit rates.
constexpr Binding bit_rate_binding() {
  Binding b = canopen::field_binding<Tmcm3216, [](Tmcm3216& d, uint8_t) -> uint16_t& {
    return d.node_settings().bit_rate_kbit;
  }>();
  b.check = [](Tmcm3216&, uint8_t, int64_t v) {
    switch (v) {
      case 20: case 50: case 100: case 125: case 250: case 500: case 800: case 1000: return SdoAbort::kNone;
      default: return SdoAbort::kInvalidValue;
    }
  };
  return b;
}

// 2705: 1..127 and 255 (LSS unconfigured), table 179.
constexpr Binding node_id_binding() {
  Binding b = canopen::field_binding<Tmcm3216, [](Tmcm3216& d, uint8_t) -> uint8_t& {
    return d.node_settings().node_id;
  }>();
  b.check = [](Tmcm3216&, uint8_t, int64_t v) {
    return (v >= 1 && v <= 127) || v == 255 ? SdoAbort::kNone : SdoAbort::kInvalidValue;
  };
  return b;
}

constexpr Binding getter(int64_t (*get)(Tmcm3216&, uint8_t)) {
  Binding b;
  b.get = get;
  return b;
}

// --- The table ------------------------------------------------------------------------------------

constexpr size_t kCapacity = 360;

struct Table {
  std::array<Row, kCapacity> rows{};
  size_t count = 0;
  constexpr void add(const Row& r) { rows[count++] = r; }
};

template <size_t K>
constexpr void add_pdo_rows(Table& t) {
  using enum ObjectCode;
  constexpr uint16_t kStride = kPdoAxisStride;
  constexpr StorageGroup kComm = StorageGroup::kCommunication;
  // RPDO communication (1400 + K), table 41.
  {
    const uint16_t index = static_cast<uint16_t>(0x1400 + K);
    const std::string_view name = kRpdoCommunicationNames[K];
    t.add(per_axis(highest_sub(index, kRecord, name, 2), kStride));
    t.add(per_axis(plus_node_id(row(index, 1, kRecord, name, "COB-ID used by RPDO", DataType::kUnsigned32, Access::kRw,
                                    0, kU32Max, kRpdoCobIdBase[K], cob_id_binding<K, true>(), kComm)),
                   kStride, &pdo_cob_id_default<K, true>));
    t.add(per_axis(row(index, 2, kRecord, name, "Transmission type", DataType::kUnsigned8, Access::kRw, 0, kU8Max,
                       kRpdoTransmissionType[K], transmission_type_binding<K, true>(), kComm),
                   kStride));
  }
  // RPDO mapping (1600 + K), table 43.
  {
    const uint16_t index = static_cast<uint16_t>(0x1600 + K);
    const std::string_view name = kRpdoMappingNames[K];
    t.add(per_axis(row(index, 0, kRecord, name, "Number of mapped application objects in PDO", DataType::kUnsigned8,
                       Access::kRw, 0, kMaxMappedObjects, kRpdoMappingCount[K], mapping_count_binding<K, true>(), kComm),
                   kStride));
    t.add(per_axis(row(index, 1, kRecord, name, kMappingEntryNames[0], DataType::kUnsigned32, Access::kRw, 0, kU32Max,
                       kRpdoMapping[K][0], mapping_entry_binding<K, 0, true>(), kComm),
                   kStride, &mapping_default<K, 0, true>));
    t.add(per_axis(row(index, 2, kRecord, name, kMappingEntryNames[1], DataType::kUnsigned32, Access::kRw, 0, kU32Max,
                       kRpdoMapping[K][1], mapping_entry_binding<K, 1, true>(), kComm),
                   kStride, &mapping_default<K, 1, true>));
    t.add(per_axis(row(index, 3, kRecord, name, kMappingEntryNames[2], DataType::kUnsigned32, Access::kRw, 0, kU32Max,
                       kRpdoMapping[K][2], mapping_entry_binding<K, 2, true>(), kComm),
                   kStride, &mapping_default<K, 2, true>));
  }
  // TPDO communication (1800 + K), table 45.
  {
    const uint16_t index = static_cast<uint16_t>(0x1800 + K);
    const std::string_view name = kTpdoCommunicationNames[K];
    t.add(per_axis(highest_sub(index, kRecord, name, 5), kStride));
    t.add(per_axis(plus_node_id(row(index, 1, kRecord, name, "COB-ID used by TPDO", DataType::kUnsigned32, Access::kRw,
                                    0, kU32Max, kTpdoCobIdBase[K], cob_id_binding<K, false>(), kComm)),
                   kStride, &pdo_cob_id_default<K, false>));
    t.add(per_axis(row(index, 2, kRecord, name, "Transmission type", DataType::kUnsigned8, Access::kRw, 0, kU8Max,
                       kTpdoTransmissionType[K], transmission_type_binding<K, false>(), kComm),
                   kStride));
    t.add(per_axis(row(index, 3, kRecord, name, "Inhibit time", DataType::kUnsigned16, Access::kRw, 0, kU16Max, 0,
                       inhibit_time_binding<K>(), kComm),
                   kStride));
    t.add(per_axis(row(index, 4, kRecord, name, "Compatibility entry", DataType::kUnsigned8, Access::kRo, 0, kU8Max, 0),
                   kStride));
    t.add(per_axis(row(index, 5, kRecord, name, "Event timer", DataType::kUnsigned16, Access::kRw, 0, kU16Max, 0,
                       event_timer_binding<K>(), kComm),
                   kStride));
  }
  // TPDO mapping (1A00 + K), table 47.
  {
    const uint16_t index = static_cast<uint16_t>(0x1A00 + K);
    const std::string_view name = kTpdoMappingNames[K];
    t.add(per_axis(row(index, 0, kRecord, name, "Number of mapped application objects in PDO", DataType::kUnsigned8,
                       Access::kRw, 0, kMaxMappedObjects, kTpdoMappingCount[K], mapping_count_binding<K, false>(),
                       kComm),
                   kStride));
    t.add(per_axis(row(index, 1, kRecord, name, kMappingEntryNames[0], DataType::kUnsigned32, Access::kRw, 0, kU32Max,
                       kTpdoMapping[K][0], mapping_entry_binding<K, 0, false>(), kComm),
                   kStride, &mapping_default<K, 0, false>));
    t.add(per_axis(row(index, 2, kRecord, name, kMappingEntryNames[1], DataType::kUnsigned32, Access::kRw, 0, kU32Max,
                       kTpdoMapping[K][1], mapping_entry_binding<K, 1, false>(), kComm),
                   kStride, &mapping_default<K, 1, false>));
    t.add(per_axis(row(index, 3, kRecord, name, kMappingEntryNames[2], DataType::kUnsigned32, Access::kRw, 0, kU32Max,
                       kTpdoMapping[K][2], mapping_entry_binding<K, 2, false>(), kComm),
                   kStride, &mapping_default<K, 2, false>));
  }
}

constexpr Table build_table() {
  using enum ObjectCode;
  using enum DataType;
  constexpr StorageGroup kComm = StorageGroup::kCommunication;
  constexpr StorageGroup kNode = StorageGroup::kNodeSettings;
  Table t;
  t.add(var(0x1000, "Device type", kUnsigned32, Access::kConst, 0, kU32Max, Tmcm3216::kDeviceType));
  t.add(var(0x1001, "Error register", kUnsigned8, Access::kRo, 0, kU8Max, 0,
            getter([](Tmcm3216& d, uint8_t) { return static_cast<int64_t>(d.error_register()); })));
  t.add(var(0x1005, "COB-ID SYNC", kUnsigned32, Access::kRw, 0, kU32Max, 0x80, sync_cob_id_binding(), kComm));
  t.add(var(0x1006, "Communication cycle period", kUnsigned32, Access::kRw, 0, kU32Max, 0, sync_period_binding(),
            kComm));
  t.add(string_var(0x1008, "Manufacturer device name", [](Tmcm3216&, uint8_t) { return Tmcm3216::kDeviceName; }));
  t.add(string_var(0x1009, "Manufacturer hardware version",
                   [](Tmcm3216&, uint8_t) { return Tmcm3216::kHardwareVersion; }));
  t.add(string_var(0x100A, "Manufacturer software version",
                   [](Tmcm3216&, uint8_t) { return Tmcm3216::kSoftwareVersion; }));
  // 1010 / 1011 (tables 23, 26): reading gives 1 where the group can be saved/restored.
  t.add(highest_sub(0x1010, kArray, "Store parameters", 6));
  t.add(row(0x1010, 1, kArray, "Store parameters", "Save all parameters", kUnsigned32, Access::kRw, 0, kU32Max, 1,
            store_binding<1>()));
  t.add(row(0x1010, 2, kArray, "Store parameters", "Save communication parameters", kUnsigned32, Access::kRw, 0,
            kU32Max, 1, store_binding<2>()));
  t.add(row(0x1010, 3, kArray, "Store parameters", "Save device profile parameters", kUnsigned32, Access::kRw, 0,
            kU32Max, 0, store_binding<3>()));
  t.add(row(0x1010, 4, kArray, "Store parameters", "Save motor 0 parameters", kUnsigned32, Access::kRw, 0, kU32Max, 1,
            store_binding<4>()));
  t.add(row(0x1010, 5, kArray, "Store parameters", "Save motor 1 parameters", kUnsigned32, Access::kRw, 0, kU32Max, 1,
            store_binding<5>()));
  t.add(row(0x1010, 6, kArray, "Store parameters", "Save motor 2 parameters", kUnsigned32, Access::kRw, 0, kU32Max, 1,
            store_binding<6>()));
  t.add(highest_sub(0x1011, kArray, "Restore default parameters", 6));
  t.add(row(0x1011, 1, kArray, "Restore default parameters", "Restore all parameters", kUnsigned32, Access::kRw, 0,
            kU32Max, 1, restore_binding<1>()));
  t.add(row(0x1011, 2, kArray, "Restore default parameters", "Restore communication parameters", kUnsigned32,
            Access::kRw, 0, kU32Max, 1, restore_binding<2>()));
  t.add(row(0x1011, 3, kArray, "Restore default parameters", "Restore device profile parameters", kUnsigned32,
            Access::kRw, 0, kU32Max, 0, restore_binding<3>()));
  t.add(row(0x1011, 4, kArray, "Restore default parameters", "Restore motor 0 parameters", kUnsigned32, Access::kRw, 0,
            kU32Max, 1, restore_binding<4>()));
  t.add(row(0x1011, 5, kArray, "Restore default parameters", "Restore motor 1 parameters", kUnsigned32, Access::kRw, 0,
            kU32Max, 1, restore_binding<5>()));
  t.add(row(0x1011, 6, kArray, "Restore default parameters", "Restore motor 2 parameters", kUnsigned32, Access::kRw, 0,
            kU32Max, 1, restore_binding<6>()));
  t.add(plus_node_id(var(0x1014, "COB-ID EMCY", kUnsigned32, Access::kRw, 0, kU32Max, 0x80, emcy_cob_id_binding(),
                         kComm)));
  t.add(var(0x1015, "Inhibit time EMCY", kUnsigned16, Access::kRw, 0, kU16Max, 0, [] {
              Binding b;
              b.get = [](Tmcm3216& d, uint8_t) { return static_cast<int64_t>(d.communication().emcy_inhibit_100us); };
              b.set = [](Tmcm3216& d, uint8_t, int64_t v) {
                d.communication().emcy_inhibit_100us = static_cast<uint16_t>(v);
                d.emergency().set_inhibit_time_100us(static_cast<uint16_t>(v));
                return SdoAbort::kNone;
              };
              return b;
            }(), kComm));
  t.add(highest_sub(0x1016, kArray, "Consumer heartbeat time", 1, "Number of entries"));
  t.add(row(0x1016, 1, kArray, "Consumer heartbeat time", "Consumer heartbeat time 1", kUnsigned32, Access::kRw, 0,
            kU32Max, 0, consumer_heartbeat_binding(), kComm));
  t.add(var(0x1017, "Producer heartbeat time", kUnsigned16, Access::kRw, 0, kU16Max, 0, producer_heartbeat_binding(),
            kComm));
  // 1018 (table 37): sub 0 is 4, the highest sub-index present (the table prints 3 but lists 4).
  t.add(highest_sub(0x1018, kRecord, "Identity object", 4, "Number of entries"));
  t.add(row(0x1018, 1, kRecord, "Identity object", "Vendor-ID", kUnsigned32, Access::kRo, 0, kU32Max,
            Tmcm3216::kVendorId));
  t.add(row(0x1018, 2, kRecord, "Identity object", "Product code", kUnsigned32, Access::kRo, 0, kU32Max,
            Tmcm3216::kProductCode));
  t.add(row(0x1018, 3, kRecord, "Identity object", "Revision number", kUnsigned32, Access::kRo, 0, kU32Max,
            Tmcm3216::kRevisionNumber));
  t.add(row(0x1018, 4, kRecord, "Identity object", "Serial number", kUnsigned32, Access::kRo, 0, kU32Max, 0,
            getter([](Tmcm3216& d, uint8_t) { return static_cast<int64_t>(d.config().serial_number); })));
  // 1029 (table 39): 0 stopped... as the manual words it; CiA-301 values 0..2.
  t.add(highest_sub(0x1029, kArray, "Error behavior", 2, "Number of error classes"));
  t.add(row(0x1029, 1, kArray, "Error behavior", "Communication error", kUnsigned8, Access::kRw, 0, 2, 0,
            error_behavior_binding<0>(), kComm));
  t.add(row(0x1029, 2, kArray, "Error behavior", "Application error", kUnsigned8, Access::kRw, 0, 2, 1,
            error_behavior_binding<1>(), kComm));
  add_pdo_rows<0>(t);
  add_pdo_rows<1>(t);
  add_pdo_rows<2>(t);
  add_pdo_rows<3>(t);
  // Node ID and bit rate (4.2.62-4.2.66).
  t.add(var(0x2704, "CAN bit rate", kUnsigned16, Access::kRw, 20, 1000, 1000, bit_rate_binding(), kNode));
  t.add(var(0x2705, "Node ID", kUnsigned8, Access::kRw, 1, 255, 1, node_id_binding(), kNode));
  t.add(highest_sub(0x2706, kArray, "Store", 1));
  t.add(with_binding(row(0x2706, 1, kArray, "Store", "Save signature", kUnsigned32, Access::kRw, 0, kU32Max, 1), [] {
    Binding b;
    b.set = [](Tmcm3216& d, uint8_t, int64_t v) { return d.store_node_settings(static_cast<uint32_t>(v)); };
    return b;
  }()));
  // 2707: table 182 says UNSIGNED8 but the values go up to 1000: UNSIGNED16 like 2704.
  t.add(var(0x2707, "CAN bit rate load", kUnsigned16, Access::kRo, 20, 1000, 1000,
            getter([](Tmcm3216& d, uint8_t) { return static_cast<int64_t>(d.bit_rate_kbit()); })));
  // Read-only and live; its default is the node ID itself (EDS "$NODEID+0x0").
  t.add(plus_node_id(var(0x2708, "Node ID load", kUnsigned8, Access::kRo, 0, 255, 0,
                         getter([](Tmcm3216& d, uint8_t) { return static_cast<int64_t>(d.node_id()); }))));
  // The axes: manufacturer area (+ 0x200 per axis), I/O, CiA-402 profile area (+ 0x800).
  add_stepper_rows<Tmcm3216>(t);
  add_ramp_rows<Tmcm3216>(t);
  add_io_rows<Tmcm3216>(t);
  add_profile_rows<Tmcm3216>(t);
  return t;
}

constexpr Table kTable = build_table();

}  // namespace

std::span<const Tmcm3216::Row> Tmcm3216::object_table() { return {kTable.rows.data(), kTable.count}; }

}  // namespace motwin::modules::tmcm3216
