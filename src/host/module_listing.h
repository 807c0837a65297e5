// What `motwin params` lists for a module, as data: the parameters of a TMCL module (axis,
// global, user variables) or the objects of a CANopen module, built from the module's own
// declarative tables (docs/architecture.md). Each module's descriptor builds its listing with
// the helpers below; the text forms (table, CSV, markdown) are tools/parameter_listing.h.
#pragma once

#include <cstddef>
#include <cstdint>
#include <optional>
#include <string>
#include <vector>

#include "core/params/parameter.h"
#include "core/params/parameter_table.h"
#include "core/tmcl/module_storage.h"
#include "host/canopen_dictionary_view.h"

namespace motwin::host {

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

// The objects of one CiA-301 index area ("Communication profile area", 1000..1FFF).
struct ObjectSection {
  std::string title;
  uint16_t first_index;
  uint16_t last_index;
  std::vector<DictionaryObject> objects;  // index order; per-axis objects once per axis
};

struct ModuleParameterListing {
  std::string module_name;
  std::vector<ParameterSection> sections;      // TMCL modules
  std::vector<ObjectSection> object_sections = {};  // CANopen modules
};

// --- Building blocks for the descriptors ---------------------------------------------------

ListedParameter listed_parameter(const params::ParameterInfo& info);

template <class Owner>
ParameterSection section_from_table(std::string title, ParameterKind kind, std::optional<uint8_t> bank,
                                    const params::ParameterTable<Owner>& table) {
  ParameterSection section{std::move(title), kind, bank, {}};
  for (const auto& row : table.rows()) section.parameters.push_back(listed_parameter(row.info));
  return section;
}

// Bank 2 (TMCM-1636 manual 4.2): the first `storable` of `count` variables can be stored with
// STGP and are restored at power-up; the rest live in RAM only.
ParameterSection user_variable_section(size_t count, size_t storable);

// A TMCL module's listing: its axis parameter table, its global parameter table (bank 0) and
// its user variables (bank 2: tmcl::kUserVariableCount, the first ones storable as its NVM
// layout says). Device::axis_parameters() and Device::global_parameters() are its tables.
// A module with firmware generations gives the axis table of one.
template <class Device>
ModuleParameterListing tmcl_parameter_listing(const params::ParameterTable<Device>& axis_parameters) {
  ModuleParameterListing listing{std::string(Device::kName), {}, {}};
  listing.sections.push_back(
      section_from_table("Axis parameters", ParameterKind::kAxis, std::nullopt, axis_parameters));
  listing.sections.push_back(
      section_from_table("Global parameters", ParameterKind::kGlobal, uint8_t{0}, Device::global_parameters()));
  listing.sections.push_back(
      user_variable_section(tmcl::kUserVariableCount, Device::kNvmLayout.storable_user_variables));
  return listing;
}
template <class Device>
ModuleParameterListing tmcl_parameter_listing() {
  return tmcl_parameter_listing<Device>(Device::axis_parameters());
}

// A CANopen module's listing: its objects, split into the CiA-301 index areas that hold any.
ModuleParameterListing canopen_object_listing(std::string module_name, const CanopenDictionaryView& dictionary);

}  // namespace motwin::host
