// JSON field helpers shared by the web console's ops (web_console.cpp and the op files beside it).
#pragma once

#include <cstdint>
#include <limits>
#include <optional>

#include <nlohmann/json.hpp>

namespace motwin::tools::web {

// An integer field of a request (object), or nullopt when it is missing, not an integer or
// beyond int64 (a request's numbers are checked against their own ranges afterwards).
inline std::optional<int64_t> integer_field(const nlohmann::json& request, const char* name) {
  const auto found = request.find(name);
  if (found == request.end() || !found->is_number_integer()) return std::nullopt;
  if (found->is_number_unsigned()) {
    const uint64_t value = found->get<uint64_t>();
    if (value > static_cast<uint64_t>(std::numeric_limits<int64_t>::max())) return std::nullopt;
    return static_cast<int64_t>(value);
  }
  return found->get<int64_t>();
}

}  // namespace motwin::tools::web
