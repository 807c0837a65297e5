#include "tools/parameter_listing.h"

#include <algorithm>
#include <span>
#include <vector>

#include <fmt/format.h>

#include "tools/canopen_object_text.h"
#include "tools/text.h"

namespace motwin::tools {
namespace {

using host::DictionaryEntry;
using host::DictionaryObject;
using host::ListedParameter;
using host::ModuleParameterListing;
using host::ObjectSection;
using host::ParameterKind;
using host::ParameterSection;

// --- Columns of the table and markdown forms, for any kind of row ----------------------------

template <class Row>
struct Column {
  std::string_view header;
  bool right_aligned;
  std::string (*text)(const Row&);
};

template <class Row>
void append_table(std::string& out, std::span<const Column<Row>> columns, const std::vector<Row>& rows) {
  const size_t count = columns.size();
  std::vector<size_t> widths(count);
  for (size_t c = 0; c < count; ++c) widths[c] = columns[c].header.size();
  std::vector<std::vector<std::string>> cells;
  for (const Row& row : rows) {
    std::vector<std::string>& texts = cells.emplace_back(count);
    for (size_t c = 0; c < count; ++c) {
      texts[c] = columns[c].text(row);
      widths[c] = std::max(widths[c], texts[c].size());
    }
  }
  const auto append_line = [&](const auto& texts) {
    std::string line;
    for (size_t c = 0; c < count; ++c) {
      const bool last = c + 1 == count;
      if (c > 0) line += "  ";
      if (last) {
        line += texts[c];  // no padding after the last column
      } else if (columns[c].right_aligned) {
        line += fmt::format("{:>{}}", texts[c], widths[c]);
      } else {
        line += fmt::format("{:<{}}", texts[c], widths[c]);
      }
    }
    while (!line.empty() && line.back() == ' ') line.pop_back();
    out += line;
    out += '\n';
  };
  std::vector<std::string_view> headers(count);
  for (size_t c = 0; c < count; ++c) headers[c] = columns[c].header;
  append_line(headers);
  for (const auto& texts : cells) append_line(texts);
}

std::string markdown_cell(const std::string& text) {
  std::string out;
  for (const char c : text) {
    if (c == '|') out += '\\';
    out += c;
  }
  return out;
}

template <class Row>
void append_markdown(std::string& out, std::span<const Column<Row>> columns, const std::vector<Row>& rows) {
  std::string header = "|";
  std::string rule = "|";
  for (const Column<Row>& column : columns) {
    header += fmt::format(" {} |", column.header);
    rule += column.right_aligned ? "---:|" : "---|";
  }
  out += header + "\n" + rule + "\n";
  for (const Row& row : rows) {
    out += "|";
    for (const Column<Row>& column : columns) out += fmt::format(" {} |", markdown_cell(column.text(row)));
    out += "\n";
  }
}

template <class Row>
void append_section(std::string& out, ListingFormat format, std::span<const Column<Row>> columns,
                    const std::vector<Row>& rows) {
  if (format == ListingFormat::kMarkdown) {
    append_markdown(out, columns, rows);
  } else {
    append_table(out, columns, rows);
  }
}

std::string section_heading(ListingFormat format, const std::string& text) {
  return format == ListingFormat::kMarkdown ? fmt::format("## {}\n\n", text) : fmt::format("{}\n", text);
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

// --- TMCL parameters -----------------------------------------------------------------------------

std::string parameter_number_text(const ListedParameter& parameter) {
  if (parameter.first_number == parameter.last_number) return std::to_string(parameter.first_number);
  return fmt::format("{}..{}", parameter.first_number, parameter.last_number);
}

constexpr Column<ListedParameter> kParameterColumns[] = {
    {"number", true, &parameter_number_text},
    {"name", false, [](const ListedParameter& p) { return p.name; }},
    {"range", false, [](const ListedParameter& p) { return fmt::format("{}..{}", p.min, p.max); }},
    {"default", true, [](const ListedParameter& p) { return std::to_string(p.default_value); }},
    {"access", false, [](const ListedParameter& p) { return p.access; }},
    {"unit", false, [](const ListedParameter& p) { return p.unit; }},
    {"description", false, [](const ListedParameter& p) { return p.description; }},
};

std::string parameter_section_title(const ParameterSection& section) {
  const std::string_view commands =
      section.kind == ParameterKind::kAxis ? "SAP, GAP, STAP, RSAP" : "SGP, GGP, STGP, RSGP";
  const std::string bank = section.bank ? fmt::format(", bank {}", *section.bank) : "";
  return fmt::format("{} ({}{})", section.title, commands, bank);
}

void append_parameter_csv(std::string& out, const std::vector<ParameterSection>& sections) {
  out += "kind,bank,number,name,min,max,default,access,unit,description\n";
  for (const ParameterSection& section : sections) {
    const std::string_view kind = section.kind == ParameterKind::kAxis ? "axis" : "global";
    for (const ListedParameter& p : section.parameters) {
      out += fmt::format("{},{},{},{},{},{},{},{},{},{}\n", kind, section.bank ? std::to_string(*section.bank) : "",
                         parameter_number_text(p), csv_field(p.name), p.min, p.max, p.default_value, p.access,
                         csv_field(p.unit), csv_field(p.description));
    }
  }
}

// --- CANopen objects -----------------------------------------------------------------------------

// One sub-index of one object (an axis copy of a per-axis object).
struct ObjectEntryRow {
  const DictionaryObject* object;
  const DictionaryEntry* entry;
};

std::vector<ObjectEntryRow> entry_rows(const ObjectSection& section) {
  std::vector<ObjectEntryRow> rows;
  for (const DictionaryObject& object : section.objects) {
    for (const DictionaryEntry& entry : object.entries) rows.push_back(ObjectEntryRow{&object, &entry});
  }
  return rows;
}

// A VAR by its object's name; a sub-index of an ARRAY or RECORD as "object: sub-index".
std::string entry_name(const ObjectEntryRow& row) {
  const canopen::EntryInfo& info = row.entry->info;
  if (info.code == canopen::ObjectCode::kVar) return std::string(info.object_name);
  return fmt::format("{}: {}", info.object_name, info.name);
}

std::string axis_text(const ObjectEntryRow& row) { return row.object->per_axis ? std::to_string(row.object->axis) : ""; }

std::string range_text(const ObjectEntryRow& row) {
  const canopen::EntryInfo& info = row.entry->info;
  if (!canopen::is_numeric(info.type)) return "";
  return number_text(info.type, info.min) + ".." + number_text(info.type, info.max);
}

constexpr Column<ObjectEntryRow> kObjectColumns[] = {
    {"index", false, [](const ObjectEntryRow& row) { return fmt::format("{:04X}", row.object->index); }},
    {"sub", true, [](const ObjectEntryRow& row) { return std::to_string(row.entry->info.sub); }},
    {"axis", true, &axis_text},
    {"name", false, &entry_name},
    {"type", false, [](const ObjectEntryRow& row) { return std::string(data_type_name(row.entry->info.type)); }},
    {"access", false, [](const ObjectEntryRow& row) { return std::string(access_text(row.entry->info.access)); }},
    {"pdo", false, [](const ObjectEntryRow& row) { return std::string(row.entry->info.pdo_mappable ? "yes" : "no"); }},
    {"range", false, &range_text},
    {"default", false, [](const ObjectEntryRow& row) { return default_text(*row.entry); }},
};

std::string object_section_title(const ObjectSection& section) {
  return fmt::format("{} ({:04X}..{:04X})", section.title, section.first_index, section.last_index);
}

void append_object_csv(std::string& out, const std::vector<ObjectSection>& sections) {
  out += "index,sub,axis,name,type,access,pdo,min,max,default\n";
  for (const ObjectSection& section : sections) {
    for (const ObjectEntryRow& row : entry_rows(section)) {
      const canopen::EntryInfo& info = row.entry->info;
      const bool numeric = canopen::is_numeric(info.type);
      out += fmt::format("{:04X},{},{},{},{},{},{},{},{},{}\n", row.object->index, info.sub, axis_text(row),
                         csv_field(entry_name(row)), data_type_name(info.type), access_text(info.access),
                         info.pdo_mappable ? "yes" : "no", numeric ? number_text(info.type, info.min) : "",
                         numeric ? number_text(info.type, info.max) : "", csv_field(default_text(*row.entry)));
    }
  }
}

}  // namespace

std::optional<ListingFormat> parse_listing_format(std::string_view name) {
  if (equals_ignore_case(name, "table")) return ListingFormat::kTable;
  if (equals_ignore_case(name, "csv")) return ListingFormat::kCsv;
  if (equals_ignore_case(name, "markdown")) return ListingFormat::kMarkdown;
  return std::nullopt;
}

std::string format_parameter_listing(const ModuleParameterListing& listing, ListingFormat format) {
  std::string out;
  if (format == ListingFormat::kCsv) {
    if (!listing.sections.empty() || listing.object_sections.empty()) append_parameter_csv(out, listing.sections);
    if (!listing.object_sections.empty()) append_object_csv(out, listing.object_sections);
    return out;
  }
  // A CANopen module lists objects, a TMCL module parameters.
  const std::string_view what = listing.sections.empty() && !listing.object_sections.empty() ? "objects" : "parameters";
  out = format == ListingFormat::kMarkdown ? fmt::format("# {} {}\n\n", listing.module_name, what)
                                           : fmt::format("{} {}\n\n", listing.module_name, what);
  bool first = true;
  for (const ParameterSection& section : listing.sections) {
    if (!first) out += '\n';
    first = false;
    out += section_heading(format, parameter_section_title(section));
    append_section<ListedParameter>(out, format, kParameterColumns, section.parameters);
  }
  for (const ObjectSection& section : listing.object_sections) {
    if (!first) out += '\n';
    first = false;
    out += section_heading(format, object_section_title(section));
    append_section<ObjectEntryRow>(out, format, kObjectColumns, entry_rows(section));
  }
  return out;
}

}  // namespace motwin::tools
