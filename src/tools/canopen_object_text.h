// How `motwin eds` and `motwin params` write a CANopen entry's values, so that the EDS and the
// listing read the same: numbers of signed types in decimal, of unsigned types in hexadecimal
// with "0x" (as CiA-306 files write them), defaults that follow the node ID as "$NODEID+0x180".
#pragma once

#include <cstdint>
#include <string>
#include <string_view>

#include "core/canopen/object_dictionary.h"
#include "host/canopen_dictionary_view.h"

namespace motwin::tools {

// "ro", "wo", "rw", "const" (EDS AccessType).
std::string_view access_text(canopen::Access access);
// "UNSIGNED32", "VISIBLE_STRING" (CiA-301 names).
std::string_view data_type_name(canopen::DataType type);
// The full range of a numeric type.
void type_range(canopen::DataType type, int64_t& low, int64_t& high);
// -5, 0x1F.
std::string number_text(canopen::DataType type, int64_t value);
// The factory default as the EDS DefaultValue writes it: a number, "$NODEID+0x180" or a string.
std::string default_text(const host::DictionaryEntry& entry);

}  // namespace motwin::tools
