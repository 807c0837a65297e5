// CiA-306 EDS export from a CANopen module's declarative object table (`motwin eds`): the same
// rows the SDO server uses give every object, sub-index, data type, access, PDO mapping, limits
// and default (notes/canopen.md "EDS"). Per-axis objects are written once per axis at their own
// index, with their axis' defaults; "$NODEID+" defaults stay symbolic.
#pragma once

#include <cstdint>
#include <optional>
#include <string>
#include <string_view>

namespace motwin::tools {

// The EDS of a module ("tmcm-3216"), or nullopt for a module without a CANopen dictionary.
// `node_id` (1..127) adds a [DeviceComissioning] section naming it.
std::optional<std::string> write_module_eds(std::string_view module_name, std::optional<uint8_t> node_id = {});

}  // namespace motwin::tools
