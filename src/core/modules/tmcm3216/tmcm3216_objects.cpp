// The TMCM-3216 object dictionary as data: communication area (manual chapter 3, tables 7-47),
// the node ID / bit rate objects (4.2.62-4.2.66), the manufacturer objects of the stepper axes
// and the I/O (tmcm3216_manufacturer_objects.h), the ramp and unit objects and the CiA-402 profile
// area (tmcm3216_profile_objects.h). One row per sub-index; rows with an axis
// stride exist once per motor (PDO parameters: + 0x40 per axis, manual 3.1.15-3.1.18).
#include <array>

#include "core/canopen/communication_objects.h"
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
constexpr int64_t kU32Max = 0xFFFF'FFFF;

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

// --- The communication objects (manual chapter 3), on the node -----------------------------------

// 1010 / 1011 sub-index names (tables 23, 26); what each selects is Tmcm3216::kNode's.
constexpr std::string_view kStoreNames[] = {"Save all parameters",       "Save communication parameters",
                                            "Save device profile parameters", "Save motor 0 parameters",
                                            "Save motor 1 parameters",   "Save motor 2 parameters"};
constexpr std::string_view kRestoreNames[] = {
    "Restore all parameters",   "Restore communication parameters", "Restore device profile parameters",
    "Restore motor 0 parameters", "Restore motor 1 parameters",     "Restore motor 2 parameters"};
// Tables 41, 43, 45, 47 (axis 0). Axes 1 and 2: the manual gives defaults for axis 0 only. Their
// PDOs start not valid (bit 31) with axis 0's identifiers, so that nothing collides until a
// master configures them, and their mappings name the same objects of their own axis (+ 0x800 per
// axis, manual 2.6.1).
constexpr canopen::PdoObjects kPdoObjects{
    .per_axis = kPdosPerAxis,
    .axis_stride = kPdoAxisStride,
    .mapping_axis_offset = 0x0800'0000,
    .mapping_entries = kMaxMappedObjects,
    .dummies_mappable = true,
    .compatibility_access = Access::kRo,
    .rpdo = {{0x200, 0xFF, 1, {0x6040'0010}},
             {0x300, 0xFF, 2, {0x6040'0010, 0x6060'0008}},
             {0x400, 0xFF, 2, {0x6040'0010, 0x607A'0020}},
             {0x500, 0xFE, 2, {0x6040'0010, 0x60FF'0020}}},
    .tpdo = {{0x180, 0xFF, 1, {0x6041'0010}},
             {0x280, 0xFF, 2, {0x6041'0010, 0x6061'0008}},
             {0x380, 0x01, 2, {0x6041'0010, 0x6064'0020}},
             {0x480, 0x01, 2, {0x6041'0010, 0x606C'0020}}},
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
    .mapping_entry = {"Mapping entry 1", "Mapping entry 2", "Mapping entry 3"},
};

// --- The table ------------------------------------------------------------------------------------

constexpr size_t kCapacity = 360;
using Table = canopen::RowTable<Tmcm3216, kCapacity>;

constexpr Table build_table() {
  using enum ObjectCode;
  using enum DataType;
  constexpr StorageGroup kNode = StorageGroup::kNodeSettings;
  Table t;
  t.add(var(0x1000, "Device type", kUnsigned32, Access::kConst, 0, kU32Max, Tmcm3216::kDeviceType));
  canopen::add_error_register_row<Tmcm3216>(t, "Error register");
  canopen::add_sync_rows<Tmcm3216>(t, "COB-ID SYNC", "Communication cycle period");
  t.add(string_var(0x1008, "Manufacturer device name", [](Tmcm3216&, uint8_t) { return Tmcm3216::kDeviceName; }));
  t.add(string_var(0x1009, "Manufacturer hardware version",
                   [](Tmcm3216&, uint8_t) { return Tmcm3216::kHardwareVersion; }));
  t.add(string_var(0x100A, "Manufacturer software version",
                   [](Tmcm3216&, uint8_t) { return Tmcm3216::kSoftwareVersion; }));
  canopen::add_storage_rows<Tmcm3216>(t, "Store parameters", kStoreNames, "Restore default parameters", kRestoreNames,
                                      kStorageSubIndices);
  canopen::add_emergency_rows<Tmcm3216>(t, "COB-ID EMCY", "Inhibit time EMCY");
  canopen::add_heartbeat_rows<Tmcm3216>(t, "Consumer heartbeat time", "Number of entries", "Consumer heartbeat time 1",
                                        "Producer heartbeat time");
  // 1018 (table 37): sub 0 is 4, the highest sub-index present (the table prints 3 but lists 4).
  canopen::add_identity_rows<Tmcm3216>(t,
                                       {"Identity object", "Number of entries", "Vendor-ID", "Product code",
                                        "Revision number", "Serial number"},
                                       Tmcm3216::kNode.identity);
  // 1029 (table 39): 0 stopped... as the manual words it; CiA-301 values 0..2.
  canopen::add_error_behavior_rows<Tmcm3216>(t, "Error behavior", "Number of error classes", "Communication error",
                                             "Application error");
  canopen::add_pdo_rows<Tmcm3216, Table, kPdoObjects>(t);
  // Node ID and bit rate (4.2.62-4.2.66).
  t.add(var(0x2704, "CAN bit rate", kUnsigned16, Access::kRw, 20, 1000, 1000, canopen::node_bit_rate_binding<Tmcm3216>(),
            kNode));
  t.add(var(0x2705, "Node ID", kUnsigned8, Access::kRw, 1, 255, 1, canopen::node_id_binding<Tmcm3216>(), kNode));
  t.add(canopen::rows::highest_sub<Tmcm3216>(0x2706, kArray, "Store", 1));
  t.add(row(0x2706, 1, kArray, "Store", "Save signature", kUnsigned32, Access::kRw, 0, kU32Max, 1,
            canopen::node_settings_store_binding<Tmcm3216>()));
  // 2707: table 182 says UNSIGNED8 but the values go up to 1000: UNSIGNED16 like 2704.
  t.add(var(0x2707, "CAN bit rate load", kUnsigned16, Access::kRo, 20, 1000, 1000,
            canopen::active_bit_rate_binding<Tmcm3216>()));
  // Read-only and live; its default is the node ID itself (EDS "$NODEID+0x0").
  t.add(canopen::communication_rows::plus_node_id(var(0x2708, "Node ID load", kUnsigned8, Access::kRo, 0, 255, 0,
                                                      canopen::active_node_id_binding<Tmcm3216>())));
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
