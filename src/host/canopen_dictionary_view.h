// A CANopen module's object dictionary as plain data, whatever the module: every object at its
// own index with its entries' descriptions and factory defaults, and the identity an EDS names.
// `motwin eds` (tools/eds_writer.h) and `motwin params` (host/module_listing.h) read only this, so
// they know no module's types; each CANopen module's descriptor builds it from its row table
// (view_of) on a device at factory defaults.
//
// Per-axis objects (a row with axis_stride != 0, docs/canopen.md) appear once per axis, at that
// axis' index with that axis' defaults, as the SDO server answers them.
#pragma once

#include <cstdint>
#include <map>
#include <span>
#include <string>
#include <string_view>
#include <vector>

#include "board/can_controller.h"
#include "core/canopen/object_dictionary.h"

namespace motwin::host {

// What an EDS says about the device besides its objects (CiA-306 [FileInfo], [DeviceInfo]).
struct CanopenIdentity {
  std::string_view product_name;  // "TMCM-3216": file name, product name, order code
  std::string_view vendor_name;
  uint32_t vendor_id;             // 1018 sub 1
  uint32_t product_code;          // 1018 sub 2
  uint32_t revision_number;       // 1018 sub 3
  uint8_t rpdo_count;
  uint8_t tpdo_count;
  std::span<const uint16_t> bit_rates_kbit;  // the bit rates the module supports
  bool lss_supported;                        // a CiA-305 LSS slave
  bool dummy_mapping_supported;              // PDOs may map the dummy types 0002..0007
};

// One sub-index of one object.
struct DictionaryEntry {
  canopen::EntryInfo info;
  // Numeric entries: the factory default of this axis, before "$NODEID+" adds the node ID
  // (info.default_plus_node_id).
  int64_t default_value = 0;
  // Visible strings: the value a device at factory defaults answers.
  std::string text;
};

// One object at one index: a device object, or one axis' copy of a per-axis object.
struct DictionaryObject {
  uint16_t index = 0;
  uint8_t axis = 0;        // 0 for device objects
  bool per_axis = false;   // one copy per axis (the axis column of `motwin params`)
  std::vector<DictionaryEntry> entries;  // its sub-indices, in table order
};

struct CanopenDictionaryView {
  std::vector<DictionaryObject> objects;  // in index order
};

// A CAN controller that sends nowhere: for a device made only to read its dictionary.
class NullCanController final : public board::CanController {
 public:
  bool transmit(const can::CanFrame&) override { return true; }
};

// The view of a module's dictionary as the device holding it stands (factory defaults after
// power-up): visible strings are read through the dictionary as an SDO upload reads them.
template <class Owner>
CanopenDictionaryView view_of(canopen::TableDictionary<Owner>& dictionary) {
  const auto rows = dictionary.rows();
  std::map<uint16_t, DictionaryObject> objects;
  for (const auto& row : rows) {
    const canopen::EntryInfo& info = row.info;
    for (uint8_t axis = 0; axis < dictionary.axes_of(info); ++axis) {
      const uint16_t index = static_cast<uint16_t>(info.index + axis * info.axis_stride);
      DictionaryObject& object = objects[index];
      object.index = index;
      object.axis = axis;
      object.per_axis = info.axis_stride != 0;
      DictionaryEntry& entry = object.entries.emplace_back();
      entry.info = info;
      entry.default_value = info.axis_default != nullptr ? info.axis_default(axis) : info.default_value;
      if (canopen::is_numeric(info.type)) continue;
      canopen::ObjectRef ref;
      uint8_t buffer[256];
      size_t length = 0;
      if (dictionary.find(index, info.sub, ref) == canopen::SdoAbort::kNone &&
          dictionary.read(ref, buffer, sizeof(buffer), length) == canopen::SdoAbort::kNone) {
        entry.text.assign(reinterpret_cast<const char*>(buffer), length);
      }
    }
  }
  CanopenDictionaryView view;
  view.objects.reserve(objects.size());
  for (auto& [index, object] : objects) view.objects.push_back(std::move(object));
  return view;
}

}  // namespace motwin::host
