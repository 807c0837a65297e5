// The TMCM-1636 CANopen firmware's object table against Trinamic's published EDS of firmware 1.12
// (tests/data/TMCM-1636-CANopen_Hw1.1_Fw1.12.eds): every object and sub-index of the EDS exists
// with the same name, data type, access, PDO mapping and default, except the differences listed
// below, each a decision documented in docs/tmcm-1636-canopen.md "Differences from the published
// EDS"; and the table has no object the EDS lacks.
#include <gtest/gtest.h>

#include <cstdint>
#include <fstream>
#include <map>
#include <optional>
#include <set>
#include <sstream>
#include <string>
#include <tuple>
#include <vector>

#include "core/modules/tmcm1636/tmcm1636_canopen.h"

namespace motwin {
namespace {

using canopen::Access;
using canopen::EntryInfo;
using modules::tmcm1636::Tmcm1636Canopen;

struct EdsEntry {
  std::string name;
  int data_type = 0;
  std::string access;
  bool pdo_mapping = false;
  std::optional<std::string> default_value;  // as written ("$NODEID+0x180", "0x10")
};

using Key = std::pair<uint16_t, uint8_t>;

std::string trim(const std::string& text) {
  const size_t first = text.find_first_not_of(" \t\r");
  if (first == std::string::npos) return "";
  return text.substr(first, text.find_last_not_of(" \t\r") - first + 1);
}

int64_t parse_number(const std::string& text) { return std::stoll(text, nullptr, 0); }

// The VAR entries of an EDS: [XXXX] of ObjectType 7 (sub 0) and [XXXXsubN].
std::map<Key, EdsEntry> read_eds(const std::string& path) {
  std::ifstream file(path);
  EXPECT_TRUE(file) << path;
  std::map<std::string, std::map<std::string, std::string>> sections;
  std::string line;
  std::string section;
  while (std::getline(file, line)) {
    line = trim(line);
    if (line.empty() || line[0] == ';') continue;
    if (line.front() == '[' && line.back() == ']') {
      section = line.substr(1, line.size() - 2);
      continue;
    }
    const size_t equals = line.find('=');
    if (equals != std::string::npos) sections[section][trim(line.substr(0, equals))] = trim(line.substr(equals + 1));
  }
  std::map<Key, EdsEntry> entries;
  for (const auto& [name, keys] : sections) {
    if (name.size() < 4 || !std::isxdigit(static_cast<unsigned char>(name[0]))) continue;
    const auto index = static_cast<uint16_t>(std::stoul(name.substr(0, 4), nullptr, 16));
    uint8_t sub = 0;
    if (name.size() > 4) {
      if (name.compare(4, 3, "sub") != 0) continue;
      sub = static_cast<uint8_t>(std::stoul(name.substr(7), nullptr, 16));
    } else if (keys.count("ObjectType") != 0 && parse_number(keys.at("ObjectType")) != 7) {
      continue;  // an ARRAY or RECORD header: its entries are the sub sections
    }
    EdsEntry entry;
    entry.name = keys.count("ParameterName") ? keys.at("ParameterName") : "";
    entry.data_type = keys.count("DataType") ? static_cast<int>(parse_number(keys.at("DataType"))) : 0;
    entry.access = keys.count("AccessType") ? keys.at("AccessType") : "";
    entry.pdo_mapping = keys.count("PDOMapping") && parse_number(keys.at("PDOMapping")) != 0;
    if (keys.count("DefaultValue") && !keys.at("DefaultValue").empty()) entry.default_value = keys.at("DefaultValue");
    entries[{index, sub}] = entry;
  }
  return entries;
}

const char* access_name(Access access) {
  switch (access) {
    case Access::kRo: return "ro";
    case Access::kWo: return "wo";
    case Access::kRw: return "rw";
    case Access::kConst: return "const";
  }
  return "?";
}

// The EDS's default as Motwin's rows express it: the value, and whether "$NODEID+" adds the node ID.
std::pair<int64_t, bool> eds_default(const std::string& text) {
  const std::string prefix = "$NODEID+";
  if (text.rfind(prefix, 0) == 0) return {parse_number(text.substr(prefix.size())), true};
  return {parse_number(text), false};
}

// What differs from the EDS, and why: the table of docs/tmcm-1636-canopen.md "Differences from the
// published EDS", rows `| object | sub | field | Motwin | EDS | why |`.
struct Decision {
  uint16_t index;
  uint8_t sub;
  std::string field;  // "access" or "default"
  std::string motwin;
  std::string eds;
};

std::vector<Decision> read_decisions() {
  std::ifstream file(MOTWIN_SOURCE_DIR "/../docs/tmcm-1636-canopen.md");
  EXPECT_TRUE(file);
  std::vector<Decision> decisions;
  std::string line;
  bool in_section = false;
  while (std::getline(file, line)) {
    if (line.rfind("## ", 0) == 0) in_section = line == "## Differences from the published EDS";
    if (!in_section || line.rfind("| ", 0) != 0) continue;
    std::vector<std::string> cells;
    std::istringstream row(line.substr(1));
    std::string cell;
    while (std::getline(row, cell, '|')) cells.push_back(trim(cell));
    if (cells.size() < 6 || cells[0].empty() || !std::isxdigit(static_cast<unsigned char>(cells[0][0]))) continue;
    decisions.push_back({static_cast<uint16_t>(std::stoul(cells[0], nullptr, 16)),
                         static_cast<uint8_t>(std::stoul(cells[1])), cells[2], cells[3], cells[4]});
  }
  return decisions;
}

bool decided(const std::vector<Decision>& decisions, Key key, const std::string& field) {
  for (const Decision& d : decisions) {
    if (d.index == key.first && d.sub == key.second && d.field == field) return true;
  }
  return false;
}

std::map<Key, const EntryInfo*> motwin_entries() {
  std::map<Key, const EntryInfo*> rows;
  for (const auto& row : Tmcm1636Canopen::object_table()) rows[{row.info.index, row.info.sub}] = &row.info;
  return rows;
}

std::string where(Key key) {
  std::ostringstream text;
  text << std::hex << std::uppercase << key.first << " sub " << int{key.second};
  return text.str();
}

TEST(Tmcm1636CanopenEds, every_entry_of_the_published_eds_is_in_the_table_as_it_declares_it) {
  const auto eds = read_eds(MOTWIN_TEST_DATA_DIR "/TMCM-1636-CANopen_Hw1.1_Fw1.12.eds");
  ASSERT_GT(eds.size(), 200u);
  const auto rows = motwin_entries();
  const std::vector<Decision> decisions = read_decisions();
  for (const auto& [key, entry] : eds) {
    const auto found = rows.find(key);
    ASSERT_NE(found, rows.end()) << where(key) << " " << entry.name << " is missing";
    const EntryInfo& info = *found->second;
    EXPECT_EQ(info.name, entry.name) << where(key);
    EXPECT_EQ(static_cast<int>(info.type), entry.data_type) << where(key) << " " << entry.name;
    if (!decided(decisions, key, "access")) {
      EXPECT_EQ(access_name(info.access), entry.access) << where(key) << " " << entry.name;
    }
    EXPECT_EQ(info.pdo_mappable, entry.pdo_mapping) << where(key) << " " << entry.name;
    if (entry.default_value && !decided(decisions, key, "default")) {
      auto [value, plus_node_id] = eds_default(*entry.default_value);
      // A hexadecimal default of a signed type is its two's complement ("0x80000000" of an INTEGER32).
      const int bits = 8 * canopen::type_size(info.type);
      if (canopen::is_signed(info.type) && bits < 64 && value >= (int64_t{1} << (bits - 1))) value -= int64_t{1} << bits;
      EXPECT_EQ(info.default_value, value) << where(key) << " " << entry.name;
      EXPECT_EQ(info.default_plus_node_id, plus_node_id) << where(key) << " " << entry.name;
    }
  }
}

TEST(Tmcm1636CanopenEds, the_table_has_no_entry_the_published_eds_lacks) {
  const auto eds = read_eds(MOTWIN_TEST_DATA_DIR "/TMCM-1636-CANopen_Hw1.1_Fw1.12.eds");
  for (const auto& [key, info] : motwin_entries()) {
    EXPECT_TRUE(eds.count(key) != 0) << where(key) << " " << info->name << " is not in the EDS";
  }
}

TEST(Tmcm1636CanopenEds, every_decision_is_a_real_difference_with_the_values_the_docs_give) {
  // A decision that no longer differs from the EDS is stale: drop it from the docs.
  const auto eds = read_eds(MOTWIN_TEST_DATA_DIR "/TMCM-1636-CANopen_Hw1.1_Fw1.12.eds");
  const auto rows = motwin_entries();
  const std::vector<Decision> decisions = read_decisions();
  ASSERT_GE(decisions.size(), 5u) << "the docs' table was not found";
  for (const Decision& d : decisions) {
    const Key key{d.index, d.sub};
    ASSERT_TRUE(eds.count(key) && rows.count(key)) << where(key);
    const EdsEntry& entry = eds.at(key);
    const EntryInfo& info = *rows.at(key);
    if (d.field == "access") {
      EXPECT_EQ(access_name(info.access), d.motwin) << where(key);
      EXPECT_EQ(entry.access, d.eds) << where(key);
      EXPECT_NE(d.motwin, d.eds) << where(key);
    } else {
      ASSERT_EQ(d.field, "default") << where(key);
      ASSERT_TRUE(entry.default_value.has_value()) << where(key);
      EXPECT_EQ(info.default_value, std::stoll(d.motwin, nullptr, 0)) << where(key);
      EXPECT_EQ(eds_default(*entry.default_value).first, std::stoll(d.eds, nullptr, 0)) << where(key);
      EXPECT_NE(info.default_value, eds_default(*entry.default_value).first) << where(key);
    }
  }
}

}  // namespace
}  // namespace motwin
