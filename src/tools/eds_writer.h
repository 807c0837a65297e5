// CiA-306 EDS export of a CANopen module (`motwin eds`), from its descriptor's identity and its
// object dictionary at factory defaults (host/canopen_dictionary_view.h): the same rows the SDO
// server uses give every object, sub-index, data type, access, PDO mapping, limits and default
// (docs/canopen.md "EDS"). Per-axis objects are written once per axis at their own index, with
// their axis' defaults; "$NODEID+" defaults stay symbolic.
#pragma once

#include <cstdint>
#include <optional>
#include <string>

#include "host/canopen_dictionary_view.h"
#include "host/module_descriptor.h"
#include "types/result.h"

namespace motwin::tools {

// `node_id` (1..127) adds a [DeviceComissioning] section naming it.
std::string write_eds(const host::CanopenIdentity& identity, const host::CanopenDictionaryView& dictionary,
                      std::optional<uint8_t> node_id = {});

// The EDS of a module; an error for a module without a CANopen dictionary.
Result<std::string> write_module_eds(const host::ModuleDescriptor& module, std::optional<uint8_t> node_id = {});

}  // namespace motwin::tools
