#include "host/module_listing.h"

#include <limits>
#include <utility>

namespace motwin::host {

ListedParameter listed_parameter(const params::ParameterInfo& info) {
  char access[6];
  params::access_letters(info.access, access);
  return ListedParameter{info.number,        info.number, std::string(info.name),
                         info.min,           info.max,    info.default_value,
                         access,             std::string(params::unit_symbol(info.unit)),
                         std::string(info.description)};
}

ParameterSection user_variable_section(size_t count, size_t storable) {
  constexpr int64_t kMin = std::numeric_limits<int32_t>::min();
  constexpr int64_t kMax = std::numeric_limits<int32_t>::max();
  ParameterSection section{"User variables", ParameterKind::kGlobal, uint8_t{2}, {}};
  section.parameters.push_back(ListedParameter{0, static_cast<uint16_t>(storable - 1), "user variables", kMin, kMax, 0,
                                               "RWE", "", "TMCL user variables; stored by STGP, restored at power-up"});
  if (count > storable) {
    section.parameters.push_back(ListedParameter{static_cast<uint16_t>(storable), static_cast<uint16_t>(count - 1),
                                                 "user variables", kMin, kMax, 0, "RW", "",
                                                 "TMCL user variables; RAM only"});
  }
  return section;
}

ModuleParameterListing canopen_object_listing(std::string module_name, const CanopenDictionaryView& dictionary) {
  // CiA-301 7.4.1: the index areas a device's objects live in.
  struct Area {
    const char* title;
    uint16_t first_index;
    uint16_t last_index;
  };
  static constexpr Area kAreas[] = {
      {"Data types", 0x0001, 0x0FFF},
      {"Communication profile area", 0x1000, 0x1FFF},
      {"Manufacturer-specific profile area", 0x2000, 0x5FFF},
      {"Device profile area", 0x6000, 0x9FFF},
      {"Reserved area", 0xA000, 0xFFFF},
  };
  ModuleParameterListing listing{std::move(module_name), {}, {}};
  for (const Area& area : kAreas) {
    ObjectSection section{area.title, area.first_index, area.last_index, {}};
    for (const DictionaryObject& object : dictionary.objects) {
      if (object.index >= area.first_index && object.index <= area.last_index) section.objects.push_back(object);
    }
    if (!section.objects.empty()) listing.object_sections.push_back(std::move(section));
  }
  return listing;
}

}  // namespace motwin::host
