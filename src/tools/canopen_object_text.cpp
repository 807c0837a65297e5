#include "tools/canopen_object_text.h"

#include <fmt/format.h>

namespace motwin::tools {

using canopen::Access;
using canopen::DataType;

std::string_view access_text(Access access) {
  switch (access) {
    case Access::kRo: return "ro";
    case Access::kWo: return "wo";
    case Access::kRw: return "rw";
    case Access::kConst: return "const";
  }
  return "ro";
}

std::string_view data_type_name(DataType type) {
  switch (type) {
    case DataType::kBoolean: return "BOOLEAN";
    case DataType::kInteger8: return "INTEGER8";
    case DataType::kInteger16: return "INTEGER16";
    case DataType::kInteger32: return "INTEGER32";
    case DataType::kUnsigned8: return "UNSIGNED8";
    case DataType::kUnsigned16: return "UNSIGNED16";
    case DataType::kUnsigned32: return "UNSIGNED32";
    case DataType::kVisibleString: return "VISIBLE_STRING";
  }
  return "?";
}

void type_range(DataType type, int64_t& low, int64_t& high) {
  const uint8_t bits = static_cast<uint8_t>(canopen::type_size(type) * 8);
  if (canopen::is_signed(type)) {
    high = (int64_t{1} << (bits - 1)) - 1;
    low = -high - 1;
  } else {
    low = 0;
    high = bits >= 64 ? INT64_MAX : (int64_t{1} << bits) - 1;
  }
}

std::string number_text(DataType type, int64_t value) {
  if (canopen::is_signed(type)) return fmt::format("{}", value);
  return fmt::format("0x{:X}", static_cast<uint64_t>(value));
}

std::string default_text(const host::DictionaryEntry& entry) {
  const canopen::EntryInfo& info = entry.info;
  if (!canopen::is_numeric(info.type)) return entry.text;
  const std::string number = number_text(info.type, entry.default_value);
  return info.default_plus_node_id ? "$NODEID+" + number : number;
}

}  // namespace motwin::tools
