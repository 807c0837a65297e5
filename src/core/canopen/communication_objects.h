// The communication objects of a CANopen node (CiA-301 1000h..1FFFh, and the stored node ID and
// bit rate) as rows a module's table adds, bound to its canopen::Node (node.h): each builder adds
// the rows of one service's objects with the checks of that service (the SDO write rules live
// beside the service: check_pdo_*, check_sync_cob_id, check_emcy_cob_id, ...). The module
// chooses which objects it has, their names (each firmware's manual or EDS spells them its own
// way) and the PDO defaults; the behaviour behind them is the node's.
//
// Templates over the module profile `Owner` and its `Table` (a RowTable or one like it, with
// add()). Owner provides:
//   canopen::Node& node();
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

// 1001, read-only and live.
template <class Owner, class Table>
constexpr void add_error_register_row(Table& t, std::string_view name) {
  t.add(rows::var<Owner>(0x1001, name, DataType::kUnsigned8, Access::kRo, 0, rows::kU8Max, 0,
                         rows::getter<Owner>([](Owner& d, uint8_t) { return static_cast<int64_t>(d.node().error_register()); })));
}

// 1005 (and 1006 when `period_name` is not empty): bit 30 of 1005 makes the node the SYNC
// producer with the period 1006 (a Motwin extension where a manual's module is a consumer only;
// the factory value keeps it one).
template <class Owner, class Table>
constexpr void add_sync_rows(Table& t, std::string_view cob_id_name, std::string_view period_name) {
  using namespace communication_rows;
  constexpr StorageGroup kComm = StorageGroup::kCommunication;
  auto cob_id = applied_binding<Owner, &CommunicationConfig::sync_cob_id,
                                [](Node& n, uint32_t v) { n.sync().set_cob_id(v); }>();
  cob_id.check = [](Owner& d, uint8_t, int64_t v) { return check_sync_cob_id(d.node().communication().sync_cob_id, v); };
  t.add(var<Owner>(0x1005, cob_id_name, DataType::kUnsigned32, Access::kRw, 0, kU32Max, 0x80, cob_id, kComm));
  if (period_name.empty()) return;
  t.add(var<Owner>(0x1006, period_name, DataType::kUnsigned32, Access::kRw, 0, kU32Max, 0,
                   applied_binding<Owner, &CommunicationConfig::sync_period_us,
                                   [](Node& n, uint32_t v) { n.sync().set_cycle_period_us(v); }>(),
                   kComm));
}

// 1010 / 1011: one sub-index per entry of the node's NodeDescription::storage; reading gives 1
// where the function is supported. `store_names` / `restore_names` name subs 1..n.
template <class Owner, class Table, size_t N>
constexpr void add_storage_rows(Table& t, std::string_view store_object, const std::string_view (&store_names)[N],
                                std::string_view restore_object, const std::string_view (&restore_names)[N],
                                const StorageSubIndex (&subs)[N]) {
  using namespace communication_rows;
  static_assert(N >= 1 && N <= 8);
  t.add(highest_sub<Owner>(0x1010, ObjectCode::kArray, store_object, static_cast<uint8_t>(N)));
  [&]<size_t... I>(std::index_sequence<I...>) {
    (t.add(row<Owner>(0x1010, static_cast<uint8_t>(I + 1), ObjectCode::kArray, store_object, store_names[I],
                      DataType::kUnsigned32, Access::kRw, 0, kU32Max, subs[I].store_supported ? 1 : 0, [] {
                        EntryBinding<Owner> b;
                        b.set = [](Owner& d, uint8_t, int64_t v) {
                          return d.node().store_parameters(I + 1, static_cast<uint32_t>(v));
                        };
                        return b;
                      }())),
     ...);
  }(std::make_index_sequence<N>{});
  t.add(highest_sub<Owner>(0x1011, ObjectCode::kArray, restore_object, static_cast<uint8_t>(N)));
  [&]<size_t... I>(std::index_sequence<I...>) {
    (t.add(row<Owner>(0x1011, static_cast<uint8_t>(I + 1), ObjectCode::kArray, restore_object, restore_names[I],
                      DataType::kUnsigned32, Access::kRw, 0, kU32Max, subs[I].restore_supported ? 1 : 0, [] {
                        EntryBinding<Owner> b;
                        b.set = [](Owner& d, uint8_t, int64_t v) {
                          return d.node().restore_parameters(I + 1, static_cast<uint32_t>(v));
                        };
                        return b;
                      }())),
     ...);
  }(std::make_index_sequence<N>{});
}

// 1014 ($NODEID+80h; `cob_id_access` ro where a firmware fixes it) and 1015.
template <class Owner, class Table>
constexpr void add_emergency_rows(Table& t, std::string_view cob_id_name, std::string_view inhibit_name,
                                  Access cob_id_access = Access::kRw) {
  using namespace communication_rows;
  constexpr StorageGroup kComm = StorageGroup::kCommunication;
  auto cob_id = applied_binding<Owner, &CommunicationConfig::emcy_cob_id,
                                [](Node& n, uint32_t v) { n.emergency().set_cob_id(v); }>();
  cob_id.check = [](Owner& d, uint8_t, int64_t v) {
    return check_emcy_cob_id(d.node().communication().emcy_cob_id, v, d.node().node_id());
  };
  // A read-only 1014 is not stored: it is always 80h + the node ID.
  t.add(plus_node_id(var<Owner>(0x1014, cob_id_name, DataType::kUnsigned32, cob_id_access, 0, kU32Max, 0x80, cob_id,
                                cob_id_access == Access::kRw ? kComm : StorageGroup::kNone)));
  t.add(var<Owner>(0x1015, inhibit_name, DataType::kUnsigned16, Access::kRw, 0, kU16Max, 0,
                   applied_binding<Owner, &CommunicationConfig::emcy_inhibit_100us,
                                   [](Node& n, uint16_t v) { n.emergency().set_inhibit_time_100us(v); }>(),
                   kComm));
}

// 1016 (one consumer entry) and 1017.
template <class Owner, class Table>
constexpr void add_heartbeat_rows(Table& t, std::string_view consumer_object, std::string_view consumer_count,
                                  std::string_view consumer_entry, std::string_view producer_name) {
  using namespace communication_rows;
  constexpr StorageGroup kComm = StorageGroup::kCommunication;
  t.add(highest_sub<Owner>(0x1016, ObjectCode::kArray, consumer_object, 1, consumer_count));
  EntryBinding<Owner> consumer;
  consumer.get = [](Owner& d, uint8_t) { return static_cast<int64_t>(d.node().communication().consumer_heartbeat[0]); };
  consumer.set = [](Owner& d, uint8_t, int64_t v) {
    d.node().communication().consumer_heartbeat[0] = static_cast<uint32_t>(v);
    d.node().heartbeat_consumer().configure(static_cast<uint32_t>(v));
    return SdoAbort::kNone;
  };
  consumer.check = [](Owner&, uint8_t, int64_t v) { return check_consumer_heartbeat_entry(v); };
  t.add(row<Owner>(0x1016, 1, ObjectCode::kArray, consumer_object, consumer_entry, DataType::kUnsigned32, Access::kRw, 0,
                   kU32Max, 0, consumer, kComm));
  t.add(var<Owner>(0x1017, producer_name, DataType::kUnsigned16, Access::kRw, 0, kU16Max, 0,
                   applied_binding<Owner, &CommunicationConfig::producer_heartbeat_ms,
                                   [](Node& n, uint16_t v) { n.nmt().set_heartbeat_period_ms(v); }>(),
                   kComm));
}

// 1018: vendor, product, revision from the node's description, the serial number from its config.
struct IdentityNames {
  std::string_view object;
  std::string_view count;
  std::string_view vendor_id;
  std::string_view product_code;
  std::string_view revision_number;
  std::string_view serial_number;
};

template <class Owner, class Table>
constexpr void add_identity_rows(Table& t, const IdentityNames& names, const NodeIdentity& identity) {
  using namespace communication_rows;
  constexpr ObjectCode kRecord = ObjectCode::kRecord;
  t.add(highest_sub<Owner>(0x1018, kRecord, names.object, 4, names.count));
  t.add(row<Owner>(0x1018, 1, kRecord, names.object, names.vendor_id, DataType::kUnsigned32, Access::kRo, 0, kU32Max,
                   identity.vendor_id));
  t.add(row<Owner>(0x1018, 2, kRecord, names.object, names.product_code, DataType::kUnsigned32, Access::kRo, 0, kU32Max,
                   identity.product_code));
  t.add(row<Owner>(0x1018, 3, kRecord, names.object, names.revision_number, DataType::kUnsigned32, Access::kRo, 0,
                   kU32Max, identity.revision_number));
  t.add(row<Owner>(0x1018, 4, kRecord, names.object, names.serial_number, DataType::kUnsigned32, Access::kRo, 0, kU32Max,
                   0, rows::getter<Owner>([](Owner& d, uint8_t) {
                     return static_cast<int64_t>(d.node().config().serial_number);
                   })));
}

// 100C (guard time, ms) and 100D (life time factor): node guarding (node_guarding.h).
template <class Owner, class Table>
constexpr void add_node_guarding_rows(Table& t, std::string_view guard_time_name, std::string_view life_time_name) {
  using namespace communication_rows;
  constexpr StorageGroup kComm = StorageGroup::kCommunication;
  t.add(var<Owner>(0x100C, guard_time_name, DataType::kUnsigned16, Access::kRw, 0, kU16Max, 0,
                   applied_binding<Owner, &CommunicationConfig::guard_time_ms,
                                   [](Node& n, uint16_t v) { n.node_guarding().set_guard_time_ms(v); }>(),
                   kComm));
  t.add(var<Owner>(0x100D, life_time_name, DataType::kUnsigned8, Access::kRw, 0, kU8Max, 0,
                   applied_binding<Owner, &CommunicationConfig::life_time_factor,
                                   [](Node& n, uint8_t v) { n.node_guarding().set_life_time_factor(v); }>(),
                   kComm));
}

// 1029 sub 1 (communication error: 0 stopped, 1 remain, 2 stopped as CiA-301 words the values)
// and sub 2 (application error; an empty name: the firmware has sub 1 only).
template <class Owner, class Table>
constexpr void add_error_behavior_rows(Table& t, std::string_view object, std::string_view count,
                                       std::string_view communication, std::string_view application) {
  using namespace communication_rows;
  constexpr StorageGroup kComm = StorageGroup::kCommunication;
  t.add(highest_sub<Owner>(0x1029, ObjectCode::kArray, object, application.empty() ? 1 : 2, count));
  t.add(row<Owner>(0x1029, 1, ObjectCode::kArray, object, communication, DataType::kUnsigned8, Access::kRw, 0, 2, 0,
                   field_binding<Owner, [](Owner& d, uint8_t) -> uint8_t& {
                     return d.node().communication().error_behavior[0];
                   }>(),
                   kComm));
  if (application.empty()) return;
  t.add(row<Owner>(0x1029, 2, ObjectCode::kArray, object, application, DataType::kUnsigned8, Access::kRw, 0, 2, 1,
                   field_binding<Owner, [](Owner& d, uint8_t) -> uint8_t& {
                     return d.node().communication().error_behavior[1];
                   }>(),
                   kComm));
}

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
  // Names: of the objects, PDO K at [K]; of their sub-indices.
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
  (t.add(pdo_row(rows::row<Owner>(index, static_cast<uint8_t>(E + 1), ObjectCode::kRecord, name, P.mapping_entry[E],
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
  const std::string_view name = Receive ? P.rpdo_communication[K] : P.tpdo_communication[K];
  t.add(pdo_row(highest_sub<Owner>(communication, kRecord, name, Receive ? 2 : 5, P.communication_count), P));
  t.add(pdo_row(plus_node_id(row<Owner>(communication, 1, kRecord, name, Receive ? P.rpdo_cob_id : P.tpdo_cob_id,
                                        DataType::kUnsigned32, Access::kRw, 0, kU32Max, d.cob_id,
                                        cob_id_binding<Owner, P, K, Receive>(), kComm)),
                P, &cob_id_default<P, K, Receive>));
  t.add(pdo_row(row<Owner>(communication, 2, kRecord, name, P.transmission_type, DataType::kUnsigned8, Access::kRw, 0,
                           kU8Max, d.transmission_type, transmission_type_binding<Owner, P, K, Receive>(), kComm),
                P));
  if constexpr (!Receive) {
    t.add(pdo_row(row<Owner>(communication, 3, kRecord, name, P.inhibit_time, DataType::kUnsigned16, Access::kRw, 0,
                             kU16Max, 0, inhibit_time_binding<Owner, P, K>(), kComm),
                  P));
    t.add(pdo_row(row<Owner>(communication, 4, kRecord, name, P.compatibility, DataType::kUnsigned8,
                             P.compatibility_access, 0, kU8Max, 0),
                  P));
    t.add(pdo_row(row<Owner>(communication, 5, kRecord, name, P.event_timer, DataType::kUnsigned16, Access::kRw, 0,
                             kU16Max, 0, event_timer_binding<Owner, P, K>(), kComm),
                  P));
  }
  // Mapping parameter (1600 + K / 1A00 + K).
  const uint16_t mapping = static_cast<uint16_t>((Receive ? 0x1600 : 0x1A00) + K);
  const std::string_view mapping_name = Receive ? P.rpdo_mapping[K] : P.tpdo_mapping[K];
  t.add(pdo_row(row<Owner>(mapping, 0, kRecord, mapping_name, P.mapping_count, DataType::kUnsigned8, Access::kRw, 0,
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
