// The parameters a module exposes, as `motwin params` lists them, built from the module's
// declarative tables (DESIGN.md "One declarative source per module"), and their text forms.
#pragma once

#include <cstdint>
#include <optional>
#include <span>
#include <string>
#include <string_view>
#include <vector>

namespace motwin::tools {

struct ListedParameter {
  // One parameter, or a run of identical ones (user variables 0..55): first == last otherwise.
  uint16_t first_number;
  uint16_t last_number;
  std::string name;
  int64_t min;
  int64_t max;
  int64_t default_value;
  std::string access;  // manual letters: "RWEX"
  std::string unit;    // "rpm", "" when dimensionless
  std::string description;
};

// Which TMCL commands reach a section: SAP/GAP/STAP/RSAP or SGP/GGP/STGP/RSGP.
enum class ParameterKind : uint8_t { kAxis, kGlobal };

struct ParameterSection {
  std::string title;  // "Axis parameters"
  ParameterKind kind;
  std::optional<uint8_t> bank;  // global parameters only
  std::vector<ListedParameter> parameters;
};

struct ModuleParameterListing {
  std::string module_name;
  std::vector<ParameterSection> sections;
};

// A module whose parameters can be listed. Each entry builds its listing from the module's
// own tables; adding a module is adding an entry (parameter_listing.cpp).
struct ParameterListingSource {
  std::string_view module_name;  // as `--module` takes it: "tmcm-1636"
  ModuleParameterListing (*build)();
};

std::span<const ParameterListingSource> parameter_listing_sources();
// Case-insensitive; nullptr when the module is unknown.
const ParameterListingSource* find_parameter_listing_source(std::string_view module_name);
// "tmcm-1636, tmcm-142": for "unknown module" messages.
std::string known_module_names();

enum class ListingFormat : uint8_t { kTable, kCsv, kMarkdown };
std::optional<ListingFormat> parse_listing_format(std::string_view name);

std::string format_parameter_listing(const ModuleParameterListing& listing, ListingFormat format);

}  // namespace motwin::tools
