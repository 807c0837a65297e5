#include "tools/parameter_listing.h"

#include <gtest/gtest.h>

#include <string>

#include "core/modules/tmcm1636/tmcm1636.h"
#include "host/module_registry.h"

namespace motwin::tools {
namespace {

using host::ListedParameter;
using host::ModuleParameterListing;
using host::ParameterKind;
using host::ParameterSection;

const ListedParameter* find_parameter(const ModuleParameterListing& listing, ParameterKind kind,
                                      std::optional<uint8_t> bank, uint16_t number) {
  for (const ParameterSection& section : listing.sections) {
    if (section.kind != kind || section.bank != bank) continue;
    for (const ListedParameter& parameter : section.parameters) {
      if (parameter.first_number <= number && number <= parameter.last_number) return &parameter;
    }
  }
  return nullptr;
}

ModuleParameterListing tmcm1636_listing() {
  const host::ModuleDescriptor* source = host::find_module_ignoring_case("tmcm-1636");
  EXPECT_NE(source, nullptr);
  return source != nullptr ? source->listing() : ModuleParameterListing{};
}

TEST(ParameterListing, tmcm1636_max_velocity_row_comes_from_the_module_table) {
  const ModuleParameterListing listing = tmcm1636_listing();
  const ListedParameter* max_velocity = find_parameter(listing, ParameterKind::kAxis, std::nullopt, 43);
  ASSERT_NE(max_velocity, nullptr);
  EXPECT_EQ(max_velocity->min, 0);
  EXPECT_EQ(max_velocity->max, 200000);
  EXPECT_EQ(max_velocity->default_value, 4000);
  EXPECT_EQ(max_velocity->access, "RWEX");
  EXPECT_EQ(max_velocity->unit, "rpm");

  const std::string table = format_parameter_listing(listing, ListingFormat::kTable);
  EXPECT_NE(table.find("max velocity"), std::string::npos);
  EXPECT_NE(table.find("0..200000"), std::string::npos);
  const std::string csv = format_parameter_listing(listing, ListingFormat::kCsv);
  EXPECT_NE(csv.find("\naxis,,43,max velocity,0,200000,4000,RWEX,rpm,"), std::string::npos) << csv;
  const std::string markdown = format_parameter_listing(listing, ListingFormat::kMarkdown);
  EXPECT_NE(markdown.find("| 43 | max velocity | 0..200000 | 4000 | RWEX | rpm |"), std::string::npos);
}

TEST(ParameterListing, tmcm1636_lists_every_table_row_and_the_user_variables) {
  using modules::tmcm1636::Tmcm1636;
  const ModuleParameterListing listing = tmcm1636_listing();
  ASSERT_EQ(listing.sections.size(), 3u);
  EXPECT_EQ(listing.sections[0].parameters.size(), Tmcm1636::axis_parameters().rows().size());
  EXPECT_EQ(listing.sections[1].parameters.size(), Tmcm1636::global_parameters().rows().size());

  const ListedParameter* serial_address = find_parameter(listing, ParameterKind::kGlobal, 0, 66);
  ASSERT_NE(serial_address, nullptr);
  EXPECT_EQ(serial_address->default_value, 1);  // docs/decisions.md "Errata in the manuals"

  const ListedParameter* storable = find_parameter(listing, ParameterKind::kGlobal, 2, 55);
  ASSERT_NE(storable, nullptr);
  EXPECT_EQ(storable->first_number, 0);
  EXPECT_EQ(storable->access, "RWE");
  const ListedParameter* ram_only = find_parameter(listing, ParameterKind::kGlobal, 2, 56);
  ASSERT_NE(ram_only, nullptr);
  EXPECT_EQ(ram_only->last_number, 255);
  EXPECT_EQ(ram_only->access, "RW");
  EXPECT_EQ(ram_only->min, -2147483648);
}

TEST(ParameterListing, csv_quotes_fields_with_commas_and_markdown_escapes_pipes) {
  ModuleParameterListing listing{"test", {}};
  listing.sections.push_back(ParameterSection{"Axis parameters", ParameterKind::kAxis, std::nullopt, {}});
  listing.sections[0].parameters.push_back(
      ListedParameter{7, 7, "a, \"b\"", 0, 1, 0, "RW", "", "x | y"});
  EXPECT_EQ(format_parameter_listing(listing, ListingFormat::kCsv),
            "kind,bank,number,name,min,max,default,access,unit,description\n"
            "axis,,7,\"a, \"\"b\"\"\",0,1,0,RW,,x | y\n");
  EXPECT_NE(format_parameter_listing(listing, ListingFormat::kMarkdown).find("| x \\| y |"), std::string::npos);
}

TEST(ParameterListing, module_names_and_formats_are_looked_up_case_insensitively) {
  EXPECT_NE(host::find_module_ignoring_case("TMCM-1636"), nullptr);
  EXPECT_EQ(host::find_module_ignoring_case("tmcm-9999"), nullptr);
  EXPECT_EQ(parse_listing_format("CSV"), ListingFormat::kCsv);
  EXPECT_EQ(parse_listing_format("markdown"), ListingFormat::kMarkdown);
  EXPECT_FALSE(parse_listing_format("json"));
  // `motwin params` now also lists the TMCM-3216's objects.
  EXPECT_EQ(host::module_names(), "tmcm-1636, tmcm-142, tmcm-3216");
}

}  // namespace
}  // namespace motwin::tools
