// The communication objects of a CANopen node (CiA-301 1000h..1FFFh, and the stored node ID and
// bit rate) as rows a module's table adds, bound to its canopen::Node (node.h): one builder,
// add_communication_rows, over a module's CommunicationObjects (which optional objects it has,
// how its documents name them, its PDO defaults); each service's rows carry the checks of that
// service (the SDO write rules live beside the service: check_pdo_*, check_sync_cob_id,
// check_emcy_cob_id, ...). The behaviour behind the objects is the node's.
//
// Templates over the module profile `Owner` and its `Table` (a RowTable or one like it, with
// add()). Owner provides:
//   canopen::Node& node();
//   static constexpr NodeDescription kNode;  (identity, 1010/1011 sub-indices with their names)
//   static constexpr uint32_t kDeviceType;   (1000)
//   static constexpr std::string_view kDeviceName, kHardwareVersion, kSoftwareVersion;  (1008..100A)
#pragma once

#include <array>
#include <cstddef>
#include <cstdint>
#include <string_view>
#include <type_traits>
#include <utility>

#include "core/canopen/node.h"
#include "core/canopen/object_rows.h"

namespace motwin::canopen {

// A module's row table, built at compile time.
template <class Owner, size_t Capacity>
struct RowTable {
  std::array<EntryRow<Owner>, Capacity> rows{};
  size_t count = 0;
  constexpr void add(const EntryRow<Owner>& r) { rows[count++] = r; }
};

namespace communication_rows {

using rows::highest_sub;
using rows::kU16Max;
using rows::kU32Max;
using rows::kU8Max;
using rows::row;
using rows::var;

template <class Owner>
constexpr EntryRow<Owner> plus_node_id(EntryRow<Owner> r) {
  r.info.default_plus_node_id = true;
  return r;
}

template <class Owner>
constexpr EntryRow<Owner> per_axis(EntryRow<Owner> r, uint16_t stride, int64_t (*axis_default)(uint8_t) = nullptr) {
  r.info.axis_stride = stride;
  r.info.axis_default = axis_default;
  return r;
}

// A binding to a field of the node's CommunicationConfig that also tells a service of the value.
template <class Owner, auto Field, auto Apply>
constexpr EntryBinding<Owner> applied_binding() {
  EntryBinding<Owner> b;
  b.get = [](Owner& d, uint8_t) { return static_cast<int64_t>(d.node().communication().*Field); };
  b.set = [](Owner& d, uint8_t, int64_t v) {
    auto& field = d.node().communication().*Field;
    field = static_cast<std::remove_reference_t<decltype(field)>>(v);
    Apply(d.node(), field);
    return SdoAbort::kNone;
  };
  return b;
}

}  // namespace communication_rows

// How a firmware's documents name the communication objects besides the PDOs and 1010/1011's
// sub-indices (those are NodeDescription::storage's).
struct CommunicationNames {
  std::string_view device_type;           // 1000
  std::string_view error_register;        // 1001
  std::string_view sync_cob_id;           // 1005
  std::string_view sync_period;           // 1006
  std::string_view device_name;           // 1008
  std::string_view hardware_version;      // 1009
  std::string_view software_version;      // 100A
  std::string_view guard_time;            // 100C
  std::string_view life_time_factor;      // 100D
  std::string_view store;                 // 1010
  std::string_view restore;               // 1011
  std::string_view emcy_cob_id;           // 1014
  std::string_view emcy_inhibit;          // 1015
  std::string_view consumer_heartbeat;    // 1016
  std::string_view consumer_count;        // 1016 sub 0
  std::string_view consumer_entry;        // 1016 sub 1
  std::string_view producer_heartbeat;    // 1017
  std::string_view identity;              // 1018
  std::string_view identity_count;        // 1018 sub 0
  std::string_view vendor_id;             // 1018 sub 1..4
  std::string_view product_code;
  std::string_view revision_number;
  std::string_view serial_number;
  std::string_view error_behavior;        // 1029
  std::string_view error_behavior_count;  // 1029 sub 0
  std::string_view communication_error;   // 1029 sub 1
  std::string_view application_error;     // 1029 sub 2
};

// CiA-301's words as the TMCM-3216 manual writes them (chapter 3).
inline constexpr CommunicationNames kCommunicationNamesCia301{
    .device_type = "Device type",
    .error_register = "Error register",
    .sync_cob_id = "COB-ID SYNC",
    .sync_period = "Communication cycle period",
    .device_name = "Manufacturer device name",
    .hardware_version = "Manufacturer hardware version",
    .software_version = "Manufacturer software version",
    .guard_time = "Guard time",
    .life_time_factor = "Life time factor",
    .store = "Store parameters",
    .restore = "Restore default parameters",
    .emcy_cob_id = "COB-ID EMCY",
    .emcy_inhibit = "Inhibit time EMCY",
    .consumer_heartbeat = "Consumer heartbeat time",
    .consumer_count = "Number of entries",
    .consumer_entry = "Consumer heartbeat time 1",
    .producer_heartbeat = "Producer heartbeat time",
    .identity = "Identity object",
    .identity_count = "Number of entries",
    .vendor_id = "Vendor-ID",
    .product_code = "Product code",
    .revision_number = "Revision number",
    .serial_number = "Serial number",
    .error_behavior = "Error behavior",
    .error_behavior_count = "Number of error classes",
    .communication_error = "Communication error",
    .application_error = "Application error",
};

// The words of port's CANopen Design Tool, which wrote Trinamic's published EDS files (the
// TMCM-1636's).
inline constexpr CommunicationNames kCommunicationNamesDesignTool{
    .device_type = "Device Type",
    .error_register = "Error Register",
    .sync_cob_id = "COB-ID SYNC",
    .sync_period = "Communication Cycle Period",
    .device_name = "Manufacturer Device Name",
    .hardware_version = "Manufacturer Hardware Version",
    .software_version = "Manufacturer Software Version",
    .guard_time = "Guard Time",
    .life_time_factor = "Life Time Factor",
    .store = "Store Parameter Field",
    .restore = "Restore Default Parameters",
    .emcy_cob_id = "COB-ID EMCY",
    .emcy_inhibit = "Inhibit Time Emergency",
    .consumer_heartbeat = "Heartbeat Consumer Entries",
    .consumer_count = "Highest sub-index supported",
    .consumer_entry = "Consumer Heartbeat Time 1",
    .producer_heartbeat = "Producer Heartbeat Time",
    .identity = "Identity Object",
    .identity_count = "number of entries",
    .vendor_id = "Vendor Id",
    .product_code = "Product Code",
    .revision_number = "Revision number",
    .serial_number = "Serial number",
    .error_behavior = "Error Behaviour",
    .error_behavior_count = "Highest sub-index supported",
    .communication_error = "Communication Error",
    .application_error = "Application Error",
};

namespace communication_rows {

// 1000, 1001, 1008..100A: the module's identity and the node's error register.
template <class Owner, class Table>
constexpr void add_device_rows(Table& t, const CommunicationNames& n) {
  constexpr auto string_binding = [](std::string_view (*get)(Owner&, uint8_t)) {
    EntryBinding<Owner> b;
    b.get_string = get;
    return b;
  };
  t.add(var<Owner>(0x1000, n.device_type, DataType::kUnsigned32, Access::kConst, 0, kU32Max, Owner::kDeviceType));
  t.add(var<Owner>(0x1001, n.error_register, DataType::kUnsigned8, Access::kRo, 0, kU8Max, 0,
                   rows::getter<Owner>([](Owner& d, uint8_t) { return static_cast<int64_t>(d.node().error_register()); })));
  t.add(var<Owner>(0x1008, n.device_name, DataType::kVisibleString, Access::kConst, 0, 0, 0,
                   string_binding([](Owner&, uint8_t) { return Owner::kDeviceName; })));
  t.add(var<Owner>(0x1009, n.hardware_version, DataType::kVisibleString, Access::kConst, 0, 0, 0,
                   string_binding([](Owner&, uint8_t) { return Owner::kHardwareVersion; })));
  t.add(var<Owner>(0x100A, n.software_version, DataType::kVisibleString, Access::kConst, 0, 0, 0,
                   string_binding([](Owner&, uint8_t) { return Owner::kSoftwareVersion; })));
}

// 1005 (and 1006 when `producer`): bit 30 of 1005 makes the node the SYNC producer with the period
// 1006 (a Motwin extension where a manual's module is a consumer only; the factory value keeps
// it one). Without 1006 there is no period to produce with.
template <class Owner, class Table>
constexpr void add_sync_rows(Table& t, const CommunicationNames& n, bool producer) {
  constexpr StorageGroup kComm = StorageGroup::kCommunication;
  auto cob_id = applied_binding<Owner, &CommunicationConfig::sync_cob_id,
                                [](Node& node, uint32_t v) { node.sync().set_cob_id(v); }>();
  cob_id.check = [](Owner& d, uint8_t, int64_t v) { return check_sync_cob_id(d.node().communication().sync_cob_id, v); };
  t.add(var<Owner>(0x1005, n.sync_cob_id, DataType::kUnsigned32, Access::kRw, 0, kU32Max, 0x80, cob_id, kComm));
  if (!producer) return;
  t.add(var<Owner>(0x1006, n.sync_period, DataType::kUnsigned32, Access::kRw, 0, kU32Max, 0,
                   applied_binding<Owner, &CommunicationConfig::sync_period_us,
                                   [](Node& node, uint32_t v) { node.sync().set_cycle_period_us(v); }>(),
                   kComm));
}

// 100C (guard time, ms) and 100D (life time factor): node guarding (node_guarding.h).
template <class Owner, class Table>
constexpr void add_node_guarding_rows(Table& t, const CommunicationNames& n) {
  constexpr StorageGroup kComm = StorageGroup::kCommunication;
  t.add(var<Owner>(0x100C, n.guard_time, DataType::kUnsigned16, Access::kRw, 0, kU16Max, 0,
                   applied_binding<Owner, &CommunicationConfig::guard_time_ms,
                                   [](Node& node, uint16_t v) { node.node_guarding().set_guard_time_ms(v); }>(),
                   kComm));
  t.add(var<Owner>(0x100D, n.life_time_factor, DataType::kUnsigned8, Access::kRw, 0, kU8Max, 0,
                   applied_binding<Owner, &CommunicationConfig::life_time_factor,
                                   [](Node& node, uint8_t v) { node.node_guarding().set_life_time_factor(v); }>(),
                   kComm));
}

// 1010 (Store) or 1011 (Restore): one sub-index per entry of the node's NodeDescription::storage;
// reading gives 1 where the function is supported.
template <class Owner, class Table, bool Store>
constexpr void add_storage_object(Table& t, std::string_view object) {
  constexpr auto& subs = Owner::kNode.storage;
  constexpr uint16_t index = Store ? 0x1010 : 0x1011;
  t.add(highest_sub<Owner>(index, ObjectCode::kArray, object, static_cast<uint8_t>(subs.size())));
  [&]<size_t... I>(std::index_sequence<I...>) {
    (t.add(row<Owner>(index, static_cast<uint8_t>(I + 1), ObjectCode::kArray, object,
                      Store ? subs[I].store_name : subs[I].restore_name, DataType::kUnsigned32, Access::kRw, 0,
                      kU32Max, (Store ? subs[I].store_supported : subs[I].restore_supported) ? 1 : 0, [] {
                        EntryBinding<Owner> b;
                        b.set = [](Owner& d, uint8_t, int64_t v) {
                          const auto signature = static_cast<uint32_t>(v);
                          return Store ? d.node().store_parameters(I + 1, signature)
                                       : d.node().restore_parameters(I + 1, signature);
                        };
                        return b;
                      }())),
     ...);
  }(std::make_index_sequence<subs.size()>{});
}

// 1014 ($NODEID+80h; read-only where a firmware fixes it) and 1015.
template <class Owner, class Table>
constexpr void add_emergency_rows(Table& t, const CommunicationNames& n, Access cob_id_access) {
  constexpr StorageGroup kComm = StorageGroup::kCommunication;
  auto cob_id = applied_binding<Owner, &CommunicationConfig::emcy_cob_id,
                                [](Node& node, uint32_t v) { node.emergency().set_cob_id(v); }>();
  cob_id.check = [](Owner& d, uint8_t, int64_t v) {
    return check_emcy_cob_id(d.node().communication().emcy_cob_id, v, d.node().node_id());
  };
  // A read-only 1014 is always 80h + the node ID: its default, which reset communication loads
  // (and a save skips, as every "$NODEID+" object at its default).
  t.add(plus_node_id(var<Owner>(0x1014, n.emcy_cob_id, DataType::kUnsigned32, cob_id_access, 0, kU32Max, 0x80, cob_id,
                                kComm)));
  t.add(var<Owner>(0x1015, n.emcy_inhibit, DataType::kUnsigned16, Access::kRw, 0, kU16Max, 0,
                   applied_binding<Owner, &CommunicationConfig::emcy_inhibit_100us,
                                   [](Node& node, uint16_t v) { node.emergency().set_inhibit_time_100us(v); }>(),
                   kComm));
}

// 1016 (one consumer entry) and 1017.
template <class Owner, class Table>
constexpr void add_heartbeat_rows(Table& t, const CommunicationNames& n) {
  constexpr StorageGroup kComm = StorageGroup::kCommunication;
  t.add(highest_sub<Owner>(0x1016, ObjectCode::kArray, n.consumer_heartbeat, 1, n.consumer_count));
  EntryBinding<Owner> consumer;
  consumer.get = [](Owner& d, uint8_t) { return static_cast<int64_t>(d.node().communication().consumer_heartbeat[0]); };
  consumer.set = [](Owner& d, uint8_t, int64_t v) {
    d.node().communication().consumer_heartbeat[0] = static_cast<uint32_t>(v);
    d.node().heartbeat_consumer().configure(static_cast<uint32_t>(v));
    return SdoAbort::kNone;
  };
  consumer.check = [](Owner&, uint8_t, int64_t v) { return check_consumer_heartbeat_entry(v); };
  t.add(row<Owner>(0x1016, 1, ObjectCode::kArray, n.consumer_heartbeat, n.consumer_entry, DataType::kUnsigned32,
                   Access::kRw, 0, kU32Max, 0, consumer, kComm));
  t.add(var<Owner>(0x1017, n.producer_heartbeat, DataType::kUnsigned16, Access::kRw, 0, kU16Max, 0,
                   applied_binding<Owner, &CommunicationConfig::producer_heartbeat_ms,
                                   [](Node& node, uint16_t v) { node.nmt().set_heartbeat_period_ms(v); }>(),
                   kComm));
}

// 1018: vendor, product, revision from the node's description, the serial number from its config.
// Sub 0 is 4, the highest sub-index present.
template <class Owner, class Table>
constexpr void add_identity_rows(Table& t, const CommunicationNames& n) {
  constexpr ObjectCode kRecord = ObjectCode::kRecord;
  constexpr NodeIdentity identity = Owner::kNode.identity;
  t.add(highest_sub<Owner>(0x1018, kRecord, n.identity, 4, n.identity_count));
  t.add(row<Owner>(0x1018, 1, kRecord, n.identity, n.vendor_id, DataType::kUnsigned32, Access::kRo, 0, kU32Max,
                   identity.vendor_id));
  t.add(row<Owner>(0x1018, 2, kRecord, n.identity, n.product_code, DataType::kUnsigned32, Access::kRo, 0, kU32Max,
                   identity.product_code));
  t.add(row<Owner>(0x1018, 3, kRecord, n.identity, n.revision_number, DataType::kUnsigned32, Access::kRo, 0, kU32Max,
                   identity.revision_number));
  t.add(row<Owner>(0x1018, 4, kRecord, n.identity, n.serial_number, DataType::kUnsigned32, Access::kRo, 0, kU32Max, 0,
                   rows::getter<Owner>([](Owner& d, uint8_t) {
                     return static_cast<int64_t>(d.node().config().serial_number);
                   })));
}

// 1029 sub 1 (communication error: 0 stopped, 1 remain, 2 stopped as CiA-301 words the values)
// and, where the firmware has it, sub 2 (application error).
template <class Owner, class Table>
constexpr void add_error_behavior_rows(Table& t, const CommunicationNames& n, bool application) {
  constexpr StorageGroup kComm = StorageGroup::kCommunication;
  t.add(highest_sub<Owner>(0x1029, ObjectCode::kArray, n.error_behavior, application ? 2 : 1, n.error_behavior_count));
  t.add(row<Owner>(0x1029, 1, ObjectCode::kArray, n.error_behavior, n.communication_error, DataType::kUnsigned8,
                   Access::kRw, 0, 2, 0,
                   field_binding<Owner, [](Owner& d, uint8_t) -> uint8_t& {
                     return d.node().communication().error_behavior[0];
                   }>(),
                   kComm));
  if (!application) return;
  t.add(row<Owner>(0x1029, 2, ObjectCode::kArray, n.error_behavior, n.application_error, DataType::kUnsigned8,
                   Access::kRw, 0, 2, 1,
                   field_binding<Owner, [](Owner& d, uint8_t) -> uint8_t& {
                     return d.node().communication().error_behavior[1];
                   }>(),
                   kComm));
}

}  // namespace communication_rows

// --- PDOs ---------------------------------------------------------------------------------------

inline constexpr size_t kMaxPdoRowsPerAxis = 4;   // RPDO/TPDO 1..4 of an axis (1400..1403, ...)
inline constexpr size_t kMaxPdoRowEntries = 8;    // mapping sub-indices a table declares

// Axis 0's defaults of one PDO.
struct PdoDefault {
  uint32_t cob_id;  // "$NODEID+" this
  uint8_t transmission_type;
  uint8_t mapping_count;
  uint32_t mapping[kMaxPdoRowEntries];
};

// How a firmware's documents name the PDO objects (PDO K at [K]) and their sub-indices.
struct PdoNames {
  std::string_view rpdo_communication[kMaxPdoRowsPerAxis];
  std::string_view rpdo_mapping[kMaxPdoRowsPerAxis];
  std::string_view tpdo_communication[kMaxPdoRowsPerAxis];
  std::string_view tpdo_mapping[kMaxPdoRowsPerAxis];
  std::string_view communication_count;  // sub 0 of a communication object
  std::string_view rpdo_cob_id;
  std::string_view tpdo_cob_id;
  std::string_view transmission_type;
  std::string_view inhibit_time;
  std::string_view compatibility;
  std::string_view event_timer;
  std::string_view mapping_count;
  std::string_view mapping_entry[kMaxPdoRowEntries];
};

// CiA-301's words as the TMCM-3216 manual writes them.
inline constexpr PdoNames kPdoNamesCia301{
    .rpdo_communication = {"RPDO 1 communication parameter", "RPDO 2 communication parameter",
                           "RPDO 3 communication parameter", "RPDO 4 communication parameter"},
    .rpdo_mapping = {"RPDO 1 mapping parameter", "RPDO 2 mapping parameter", "RPDO 3 mapping parameter",
                     "RPDO 4 mapping parameter"},
    .tpdo_communication = {"TPDO 1 communication parameter", "TPDO 2 communication parameter",
                           "TPDO 3 communication parameter", "TPDO 4 communication parameter"},
    .tpdo_mapping = {"TPDO 1 mapping parameter", "TPDO 2 mapping parameter", "TPDO 3 mapping parameter",
                     "TPDO 4 mapping parameter"},
    .communication_count = "Highest sub-index supported",
    .rpdo_cob_id = "COB-ID used by RPDO",
    .tpdo_cob_id = "COB-ID used by TPDO",
    .transmission_type = "Transmission type",
    .inhibit_time = "Inhibit time",
    .compatibility = "Compatibility entry",
    .event_timer = "Event timer",
    .mapping_count = "Number of mapped application objects in PDO",
    .mapping_entry = {"Mapping entry 1", "Mapping entry 2", "Mapping entry 3", "Mapping entry 4", "Mapping entry 5",
                      "Mapping entry 6", "Mapping entry 7", "Mapping entry 8"},
};

// The words of port's CANopen Design Tool, which wrote Trinamic's published EDS files (the
// TMCM-1636's).
inline constexpr PdoNames kPdoNamesDesignTool{
    .rpdo_communication = {"Receive PDO Communication Parameter 1", "Receive PDO Communication Parameter 2",
                           "Receive PDO Communication Parameter 3", "Receive PDO Communication Parameter 4"},
    .rpdo_mapping = {"Receive PDO Mapping Parameter 1", "Receive PDO Mapping Parameter 2",
                     "Receive PDO Mapping Parameter 3", "Receive PDO Mapping Parameter 4"},
    .tpdo_communication = {"Transmit PDO Communication Parameter 1", "Transmit PDO Communication Parameter 2",
                           "Transmit PDO Communication Parameter 3", "Transmit PDO Communication Parameter 4"},
    .tpdo_mapping = {"Transmit PDO Mapping Parameter 1", "Transmit PDO Mapping Parameter 2",
                     "Transmit PDO Mapping Parameter 3", "Transmit PDO Mapping Parameter 4"},
    .communication_count = "Highest sub-index supported",
    .rpdo_cob_id = "COB-ID",
    .tpdo_cob_id = "COB-ID",
    .transmission_type = "Transmission Type",
    .inhibit_time = "Inhibit Time",
    .compatibility = "Compatibility Entry",
    .event_timer = "Event Timer",
    .mapping_count = "Number of mapped objects",
    .mapping_entry = {"Mapping Entry 1", "Mapping Entry 2", "Mapping Entry 3", "Mapping Entry 4", "Mapping Entry 5",
                      "Mapping Entry 6", "Mapping Entry 7", "Mapping Entry 8"},
};

// Everything a module says about its PDO objects.
struct PdoObjects {
  uint8_t per_axis;         // PDOs per direction and axis; PDO K of axis n is the node's n * per_axis + K
  uint16_t axis_stride;     // index distance of an axis' PDOs (0: one axis)
  // Axes 1.. (modules with axis_stride != 0): their PDOs start not valid (bit 31) with axis 0's
  // identifiers, and their mappings name the same objects of their own axis, `mapping_axis_offset`
  // (index << 16) further per axis.
  uint32_t mapping_axis_offset;
  uint8_t mapping_entries;  // sub-indices 1..n of each mapping object
  bool dummies_mappable;    // the dummy types 0002..0007 may be mapped
  Access compatibility_access;  // TPDO sub 4
  PdoDefault rpdo[kMaxPdoRowsPerAxis];
  PdoDefault tpdo[kMaxPdoRowsPerAxis];
  const PdoNames* names;
};

namespace pdo_rows {

template <const PdoObjects& P, size_t K, bool Receive>
PdoCommunication& pdo_of(Node& node, uint8_t axis) {
  const size_t i = static_cast<size_t>(axis) * P.per_axis + K;
  return Receive ? node.communication().rpdo[i] : node.communication().tpdo[i];
}
template <const PdoObjects& P, size_t K, bool Receive>
PdoMapping& mapping_of(Node& node, uint8_t axis) {
  const size_t i = static_cast<size_t>(axis) * P.per_axis + K;
  return Receive ? node.communication().rpdo_mapping[i] : node.communication().tpdo_mapping[i];
}
template <const PdoObjects& P, size_t K, bool Receive>
constexpr const PdoDefault& default_of() {
  return Receive ? P.rpdo[K] : P.tpdo[K];
}
template <const PdoObjects& P, size_t K, bool Receive>
int64_t cob_id_default(uint8_t axis) {
  const uint32_t base = default_of<P, K, Receive>().cob_id;
  return axis == 0 ? base : (base | kPdoCobIdInvalid);
}
template <const PdoObjects& P, size_t K, size_t E, bool Receive>
int64_t mapping_default(uint8_t axis) {
  const uint32_t entry = default_of<P, K, Receive>().mapping[E];
  return entry == 0 ? 0 : entry + static_cast<uint32_t>(axis) * P.mapping_axis_offset;
}

template <class Owner, const PdoObjects& P, size_t K, bool Receive>
constexpr EntryBinding<Owner> cob_id_binding() {
  auto b = field_binding<Owner, [](Owner& d, uint8_t axis) -> uint32_t& {
    return pdo_of<P, K, Receive>(d.node(), axis).cob_id;
  }>();
  b.check = [](Owner& d, uint8_t axis, int64_t v) {
    return check_pdo_cob_id(pdo_of<P, K, Receive>(d.node(), axis).cob_id, v);
  };
  return b;
}

template <class Owner, const PdoObjects& P, size_t K, bool Receive>
constexpr EntryBinding<Owner> transmission_type_binding() {
  auto b = field_binding<Owner, [](Owner& d, uint8_t axis) -> uint8_t& {
    return pdo_of<P, K, Receive>(d.node(), axis).transmission_type;
  }>();
  b.check = [](Owner&, uint8_t, int64_t v) { return check_pdo_transmission_type(v); };
  return b;
}

template <class Owner, const PdoObjects& P, size_t K>
constexpr EntryBinding<Owner> inhibit_time_binding() {
  auto b = field_binding<Owner, [](Owner& d, uint8_t axis) -> uint16_t& {
    return pdo_of<P, K, false>(d.node(), axis).inhibit_time_100us;
  }>();
  b.check = [](Owner& d, uint8_t axis, int64_t) { return check_pdo_inhibit_time(pdo_of<P, K, false>(d.node(), axis)); };
  return b;
}

template <class Owner, const PdoObjects& P, size_t K>
constexpr EntryBinding<Owner> event_timer_binding() {
  return field_binding<Owner, [](Owner& d, uint8_t axis) -> uint16_t& {
    return pdo_of<P, K, false>(d.node(), axis).event_timer_ms;
  }>();
}

template <class Owner, const PdoObjects& P, size_t K, bool Receive>
constexpr EntryBinding<Owner> mapping_count_binding() {
  auto b = field_binding<Owner, [](Owner& d, uint8_t axis) -> uint8_t& {
    return mapping_of<P, K, Receive>(d.node(), axis).count;
  }>();
  b.check = [](Owner& d, uint8_t axis, int64_t v) {
    Node& node = d.node();
    return check_pdo_mapping_count(node.dictionary(), Receive, pdo_of<P, K, Receive>(node, axis),
                                   mapping_of<P, K, Receive>(node, axis), v, P.dummies_mappable);
  };
  return b;
}

template <class Owner, const PdoObjects& P, size_t K, size_t E, bool Receive>
constexpr EntryBinding<Owner> mapping_entry_binding() {
  auto b = field_binding<Owner, [](Owner& d, uint8_t axis) -> uint32_t& {
    return mapping_of<P, K, Receive>(d.node(), axis).entries[E];
  }>();
  b.check = [](Owner& d, uint8_t axis, int64_t v) {
    Node& node = d.node();
    return check_pdo_mapping_write(node.dictionary(), Receive, pdo_of<P, K, Receive>(node, axis),
                                   mapping_of<P, K, Receive>(node, axis), v, P.dummies_mappable);
  };
  return b;
}

// A row of PDO K that exists once per axis (axis_stride) or once.
template <class Owner>
constexpr EntryRow<Owner> pdo_row(EntryRow<Owner> r, const PdoObjects& p, int64_t (*axis_default)(uint8_t) = nullptr) {
  return p.axis_stride == 0 ? r : communication_rows::per_axis(r, p.axis_stride, axis_default);
}

template <class Owner, class Table, const PdoObjects& P, size_t K, bool Receive, size_t... E>
constexpr void add_mapping_entries(Table& t, uint16_t index, std::string_view name, std::index_sequence<E...>) {
  constexpr const PdoDefault& d = default_of<P, K, Receive>();
  (t.add(pdo_row(rows::row<Owner>(index, static_cast<uint8_t>(E + 1), ObjectCode::kRecord, name, P.names->mapping_entry[E],
                                  DataType::kUnsigned32, Access::kRw, 0, rows::kU32Max, d.mapping[E],
                                  mapping_entry_binding<Owner, P, K, E, Receive>(), StorageGroup::kCommunication),
                 P, &mapping_default<P, K, E, Receive>)),
   ...);
}

template <class Owner, class Table, const PdoObjects& P, size_t K, bool Receive>
constexpr void add_pdo(Table& t) {
  using namespace communication_rows;
  constexpr StorageGroup kComm = StorageGroup::kCommunication;
  constexpr ObjectCode kRecord = ObjectCode::kRecord;
  constexpr const PdoDefault& d = default_of<P, K, Receive>();
  // Communication parameter (1400 + K / 1800 + K).
  const uint16_t communication = static_cast<uint16_t>((Receive ? 0x1400 : 0x1800) + K);
  const std::string_view name = Receive ? P.names->rpdo_communication[K] : P.names->tpdo_communication[K];
  t.add(pdo_row(highest_sub<Owner>(communication, kRecord, name, Receive ? 2 : 5, P.names->communication_count), P));
  t.add(pdo_row(plus_node_id(row<Owner>(communication, 1, kRecord, name, Receive ? P.names->rpdo_cob_id : P.names->tpdo_cob_id,
                                        DataType::kUnsigned32, Access::kRw, 0, kU32Max, d.cob_id,
                                        cob_id_binding<Owner, P, K, Receive>(), kComm)),
                P, &cob_id_default<P, K, Receive>));
  t.add(pdo_row(row<Owner>(communication, 2, kRecord, name, P.names->transmission_type, DataType::kUnsigned8, Access::kRw, 0,
                           kU8Max, d.transmission_type, transmission_type_binding<Owner, P, K, Receive>(), kComm),
                P));
  if constexpr (!Receive) {
    t.add(pdo_row(row<Owner>(communication, 3, kRecord, name, P.names->inhibit_time, DataType::kUnsigned16, Access::kRw, 0,
                             kU16Max, 0, inhibit_time_binding<Owner, P, K>(), kComm),
                  P));
    t.add(pdo_row(row<Owner>(communication, 4, kRecord, name, P.names->compatibility, DataType::kUnsigned8,
                             P.compatibility_access, 0, kU8Max, 0),
                  P));
    t.add(pdo_row(row<Owner>(communication, 5, kRecord, name, P.names->event_timer, DataType::kUnsigned16, Access::kRw, 0,
                             kU16Max, 0, event_timer_binding<Owner, P, K>(), kComm),
                  P));
  }
  // Mapping parameter (1600 + K / 1A00 + K).
  const uint16_t mapping = static_cast<uint16_t>((Receive ? 0x1600 : 0x1A00) + K);
  const std::string_view mapping_name = Receive ? P.names->rpdo_mapping[K] : P.names->tpdo_mapping[K];
  t.add(pdo_row(row<Owner>(mapping, 0, kRecord, mapping_name, P.names->mapping_count, DataType::kUnsigned8, Access::kRw, 0,
                           P.mapping_entries, d.mapping_count, mapping_count_binding<Owner, P, K, Receive>(), kComm),
                P));
  add_mapping_entries<Owner, Table, P, K, Receive>(t, mapping, mapping_name, std::make_index_sequence<P.mapping_entries>{});
}

}  // namespace pdo_rows

// The PDO objects of P, in the order RPDO 1 communication, RPDO 1 mapping, TPDO 1 communication,
// TPDO 1 mapping, RPDO 2 ... (the order of a row table does not change what a lookup finds).
template <class Owner, class Table, const PdoObjects& P>
constexpr void add_pdo_rows(Table& t) {
  static_assert(P.per_axis >= 1 && P.per_axis <= kMaxPdoRowsPerAxis);
  static_assert(P.mapping_entries >= 1 && P.mapping_entries <= kMaxPdoRowEntries);
  [&]<size_t... K>(std::index_sequence<K...>) {
    ((pdo_rows::add_pdo<Owner, Table, P, K, true>(t), pdo_rows::add_pdo<Owner, Table, P, K, false>(t)), ...);
  }(std::make_index_sequence<P.per_axis>{});
}

// Which communication objects a firmware has and how its documents name them.
struct CommunicationObjects {
  const CommunicationNames* names;
  const PdoObjects* pdos;
  bool sync_producer;               // 1006: the node may produce SYNC (1005 bit 30)
  bool node_guarding;               // 100C, 100D
  Access emcy_cob_id_access;        // 1014: rw, or ro where the firmware fixes it
  bool application_error_behavior;  // 1029 sub 2
};

// Every communication object of C, in index order, the PDOs' as add_pdo_rows orders them.
template <class Owner, class Table, const CommunicationObjects& C>
constexpr void add_communication_rows(Table& t) {
  using namespace communication_rows;
  const CommunicationNames& n = *C.names;
  add_device_rows<Owner>(t, n);
  add_sync_rows<Owner>(t, n, C.sync_producer);
  if (C.node_guarding) add_node_guarding_rows<Owner>(t, n);
  add_storage_object<Owner, Table, true>(t, n.store);
  add_storage_object<Owner, Table, false>(t, n.restore);
  add_emergency_rows<Owner>(t, n, C.emcy_cob_id_access);
  add_heartbeat_rows<Owner>(t, n);
  add_identity_rows<Owner>(t, n);
  add_error_behavior_rows<Owner>(t, n, C.application_error_behavior);
  add_pdo_rows<Owner, Table, *C.pdos>(t);
}

// --- The stored node ID and bit rate ---------------------------------------------------------------

// The bit rate (a value the node's description lists) and the node ID (1..127, 255 = LSS
// unconfigured) that apply after the next reset; both stored with the node settings.
template <class Owner>
constexpr EntryBinding<Owner> node_bit_rate_binding() {
  auto b = field_binding<Owner, [](Owner& d, uint8_t) -> uint16_t& { return d.node().node_settings().bit_rate_kbit; }>();
  b.check = [](Owner& d, uint8_t, int64_t v) {
    return v >= 0 && v <= 0xFFFF && d.node().supports_bit_rate(static_cast<uint16_t>(v)) ? SdoAbort::kNone
                                                                                          : SdoAbort::kInvalidValue;
  };
  return b;
}

template <class Owner>
constexpr EntryBinding<Owner> node_id_binding() {
  auto b = field_binding<Owner, [](Owner& d, uint8_t) -> uint8_t& { return d.node().node_settings().node_id; }>();
  b.check = [](Owner&, uint8_t, int64_t v) {
    return (v >= 1 && v <= 127) || v == kLssUnconfiguredNodeId ? SdoAbort::kNone : SdoAbort::kInvalidValue;
  };
  return b;
}

// A write of the "save" signature stores the node settings.
template <class Owner>
constexpr EntryBinding<Owner> node_settings_store_binding() {
  EntryBinding<Owner> b;
  b.set = [](Owner& d, uint8_t, int64_t v) { return d.node().store_node_settings(static_cast<uint32_t>(v)); };
  return b;
}

// The active bit rate and node ID (what the last reset or LSS made of the settings).
template <class Owner>
constexpr EntryBinding<Owner> active_bit_rate_binding() {
  return rows::getter<Owner>([](Owner& d, uint8_t) { return static_cast<int64_t>(d.node().bit_rate_kbit()); });
}
template <class Owner>
constexpr EntryBinding<Owner> active_node_id_binding() {
  return rows::getter<Owner>([](Owner& d, uint8_t) { return static_cast<int64_t>(d.node().node_id()); });
}

}  // namespace motwin::canopen
