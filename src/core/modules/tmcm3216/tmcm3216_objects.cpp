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
using canopen::StorageGroup;
using Row = Tmcm3216::Row;
using Binding = EntryBinding<Tmcm3216>;

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

// --- The communication objects (manual chapter 3), on the node -----------------------------------

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
    .names = &canopen::kPdoNamesCia301,
};

// --- The table ------------------------------------------------------------------------------------

// Chapter 3: SYNC producer as a Motwin extension (1006), no node guarding (manual 1.1: RTR frames
// are not answered).
constexpr canopen::CommunicationObjects kCommunication{
    .names = &canopen::kCommunicationNamesCia301,
    .pdos = &kPdoObjects,
    .sync_producer = true,
    .node_guarding = false,
    .emcy_cob_id_access = Access::kRw,
    .application_error_behavior = true,
};

constexpr size_t kCapacity = 360;
using Table = canopen::RowTable<Tmcm3216, kCapacity>;

constexpr Table build_table() {
  using enum ObjectCode;
  using enum DataType;
  constexpr StorageGroup kNode = StorageGroup::kNodeSettings;
  Table t;
  // Chapter 3. 1018 (table 37): sub 0 is 4, the highest sub-index present (the table prints 3 but
  // lists 4). 1029 (table 39): 0 stopped... as the manual words it; CiA-301 values 0..2.
  canopen::add_communication_rows<Tmcm3216, Table, kCommunication>(t);
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
