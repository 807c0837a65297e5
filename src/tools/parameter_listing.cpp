#include "tools/parameter_listing.h"

#include <algorithm>
#include <array>
#include <cstdint>
#include <limits>

#include <fmt/format.h>

#include "core/modules/tmcm142/tmcm142.h"
#include "core/modules/tmcm1636/tmcm1636.h"
#include "core/params/parameter.h"
#include "core/params/parameter_table.h"
#include "tools/text.h"

namespace motwin::tools {
namespace {

// --- Building listings from the module tables ------------------------------------------------

ListedParameter listed(const params::ParameterInfo& info) {
  char access[6];
  params::access_letters(info.access, access);
  return ListedParameter{info.number, info.number,  std::string(info.name), info.min,
                         info.max,    info.default_value, access,        std::string(params::unit_symbol(info.unit)),
                         std::string(info.description)};
}

template <class Owner>
ParameterSection section_from_table(std::string title, ParameterKind kind, std::optional<uint8_t> bank,
                                    const params::ParameterTable<Owner>& table) {
  ParameterSection section{std::move(title), kind, bank, {}};
  for (const auto& row : table.rows()) section.parameters.push_back(listed(row.info));
  return section;
}

// Bank 2 (TMCM-1636 manual 4.2): the first `storable` variables can be stored with STGP and
// are restored at power-up; the rest live in RAM only.
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

ModuleParameterListing tmcm1636_listing() {
  using modules::tmcm1636::Tmcm1636;
  ModuleParameterListing listing{std::string(Tmcm1636::kName), {}};
  listing.sections.push_back(section_from_table("Axis parameters", ParameterKind::kAxis, std::nullopt, Tmcm1636::axis_parameters()));
  listing.sections.push_back(section_from_table("Global parameters", ParameterKind::kGlobal, uint8_t{0}, Tmcm1636::global_parameters()));
  listing.sections.push_back(
      user_variable_section(modules::tmcm1636::kUserVariableCount, modules::tmcm1636::kStorableUserVariables));
  return listing;
}

// Descriptions tagged params::kMotwinDecisionTag mark the parameters Motwin numbered itself.
ModuleParameterListing tmcm142_listing() {
  using modules::tmcm142::Tmcm142;
  ModuleParameterListing listing{std::string(Tmcm142::kName), {}};
  listing.sections.push_back(section_from_table("Axis parameters", ParameterKind::kAxis, std::nullopt, Tmcm142::axis_parameters()));
  listing.sections.push_back(section_from_table("Global parameters", ParameterKind::kGlobal, uint8_t{0}, Tmcm142::global_parameters()));
  listing.sections.push_back(user_variable_section(tmcl::kUserVariableCount, modules::tmcm142::kStorableUserVariables));
  return listing;
}

constexpr ParameterListingSource kSources[] = {
    {modules::tmcm1636::Tmcm1636::kName, &tmcm1636_listing},
    {modules::tmcm142::Tmcm142::kName, &tmcm142_listing},
};

// --- Text forms --------------------------------------------------------------------------------

std::string number_text(const ListedParameter& parameter) {
  if (parameter.first_number == parameter.last_number) return std::to_string(parameter.first_number);
  return fmt::format("{}..{}", parameter.first_number, parameter.last_number);
}

std::string_view kind_name(ParameterKind kind) { return kind == ParameterKind::kAxis ? "axis" : "global"; }

std::string section_heading(const ListingFormat format, const ParameterSection& section) {
  const std::string_view commands =
      section.kind == ParameterKind::kAxis ? "SAP, GAP, STAP, RSAP" : "SGP, GGP, STGP, RSGP";
  const std::string bank = section.bank ? fmt::format(", bank {}", *section.bank) : "";
  if (format == ListingFormat::kMarkdown) return fmt::format("## {} ({}{})\n\n", section.title, commands, bank);
  return fmt::format("{} ({}{})\n", section.title, commands, bank);
}

// The columns of the table and markdown forms, in order.
struct Column {
  std::string_view header;
  bool right_aligned;
  std::string (*text)(const ListedParameter&);
};
constexpr Column kColumns[] = {
    {"number", true, &number_text},
    {"name", false, [](const ListedParameter& p) { return p.name; }},
    {"range", false, [](const ListedParameter& p) { return fmt::format("{}..{}", p.min, p.max); }},
    {"default", true, [](const ListedParameter& p) { return std::to_string(p.default_value); }},
    {"access", false, [](const ListedParameter& p) { return p.access; }},
    {"unit", false, [](const ListedParameter& p) { return p.unit; }},
    {"description", false, [](const ListedParameter& p) { return p.description; }},
};
constexpr size_t kColumnCount = std::size(kColumns);

void append_table_section(std::string& out, const ParameterSection& section) {
  std::array<size_t, kColumnCount> widths{};
  for (size_t c = 0; c < kColumnCount; ++c) widths[c] = kColumns[c].header.size();
  std::vector<std::array<std::string, kColumnCount>> cells;
  for (const ListedParameter& parameter : section.parameters) {
    auto& row = cells.emplace_back();
    for (size_t c = 0; c < kColumnCount; ++c) {
      row[c] = kColumns[c].text(parameter);
      widths[c] = std::max(widths[c], row[c].size());
    }
  }
  const auto append_line = [&](const auto& texts) {
    std::string line;
    for (size_t c = 0; c < kColumnCount; ++c) {
      const bool last = c + 1 == kColumnCount;
      if (c > 0) line += "  ";
      if (last) {
        line += texts[c];  // no padding after the last column
      } else if (kColumns[c].right_aligned) {
        line += fmt::format("{:>{}}", texts[c], widths[c]);
      } else {
        line += fmt::format("{:<{}}", texts[c], widths[c]);
      }
    }
    while (!line.empty() && line.back() == ' ') line.pop_back();
    out += line;
    out += '\n';
  };
  std::array<std::string_view, kColumnCount> headers{};
  for (size_t c = 0; c < kColumnCount; ++c) headers[c] = kColumns[c].header;
  append_line(headers);
  for (const auto& row : cells) append_line(row);
}

std::string markdown_cell(const std::string& text) {
  std::string out;
  for (const char c : text) {
    if (c == '|') out += '\\';
    out += c;
  }
  return out;
}

void append_markdown_section(std::string& out, const ParameterSection& section) {
  std::string header = "|";
  std::string rule = "|";
  for (const Column& column : kColumns) {
    header += fmt::format(" {} |", column.header);
    rule += column.right_aligned ? "---:|" : "---|";
  }
  out += header + "\n" + rule + "\n";
  for (const ListedParameter& parameter : section.parameters) {
    out += "|";
    for (const Column& column : kColumns) out += fmt::format(" {} |", markdown_cell(column.text(parameter)));
    out += "\n";
  }
}

// RFC 4180: quote a field that holds a comma, a quote or a line break; double the quotes.
std::string csv_field(const std::string& text) {
  if (text.find_first_of(",\"\r\n") == std::string::npos) return text;
  std::string out = "\"";
  for (const char c : text) {
    if (c == '"') out += '"';
    out += c;
  }
  return out + "\"";
}

std::string format_csv(const ModuleParameterListing& listing) {
  std::string out = "kind,bank,number,name,min,max,default,access,unit,description\n";
  for (const ParameterSection& section : listing.sections) {
    for (const ListedParameter& p : section.parameters) {
      out += fmt::format("{},{},{},{},{},{},{},{},{},{}\n", kind_name(section.kind),
                         section.bank ? std::to_string(*section.bank) : "", number_text(p), csv_field(p.name), p.min,
                         p.max, p.default_value, p.access, csv_field(p.unit), csv_field(p.description));
    }
  }
  return out;
}

}  // namespace

std::span<const ParameterListingSource> parameter_listing_sources() { return kSources; }

const ParameterListingSource* find_parameter_listing_source(std::string_view module_name) {
  for (const ParameterListingSource& source : kSources) {
    if (equals_ignore_case(source.module_name, module_name)) return &source;
  }
  return nullptr;
}

std::string known_module_names() {
  std::string out;
  for (const ParameterListingSource& source : kSources) {
    if (!out.empty()) out += ", ";
    out += source.module_name;
  }
  return out;
}

std::optional<ListingFormat> parse_listing_format(std::string_view name) {
  if (equals_ignore_case(name, "table")) return ListingFormat::kTable;
  if (equals_ignore_case(name, "csv")) return ListingFormat::kCsv;
  if (equals_ignore_case(name, "markdown")) return ListingFormat::kMarkdown;
  return std::nullopt;
}

std::string format_parameter_listing(const ModuleParameterListing& listing, ListingFormat format) {
  if (format == ListingFormat::kCsv) return format_csv(listing);
  std::string out = format == ListingFormat::kMarkdown ? fmt::format("# {} parameters\n\n", listing.module_name)
                                                       : fmt::format("{} parameters\n\n", listing.module_name);
  for (size_t i = 0; i < listing.sections.size(); ++i) {
    const ParameterSection& section = listing.sections[i];
    if (i > 0) out += '\n';
    out += section_heading(format, section);
    if (format == ListingFormat::kMarkdown) {
      append_markdown_section(out, section);
    } else {
      append_table_section(out, section);
    }
  }
  return out;
}

}  // namespace motwin::tools
