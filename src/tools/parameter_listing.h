// The text forms of what `motwin params` lists (host/module_listing.h): an aligned table, CSV
// (RFC 4180) or markdown. TMCL parameters and CANopen objects have columns of their own
// (docs/canopen.md, "Object listing").
#pragma once

#include <cstdint>
#include <optional>
#include <string>
#include <string_view>

#include "host/module_listing.h"

namespace motwin::tools {

enum class ListingFormat : uint8_t { kTable, kCsv, kMarkdown };
std::optional<ListingFormat> parse_listing_format(std::string_view name);

std::string format_parameter_listing(const host::ModuleParameterListing& listing, ListingFormat format);

}  // namespace motwin::tools
