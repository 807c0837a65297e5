// Adding a module is its own folders plus one row of the registry (docs/host-runtime.md, "Adding
// a module"). These tests hold that up: every registered module is known to `params`, `eds`,
// `serve` and `run` through its descriptor alone, a fake module gets an EDS and an object listing
// from its table alone, and no file outside a module's own folders names the module.
#include <gtest/gtest.h>

#include <algorithm>
#include <cctype>
#include <chrono>
#include <filesystem>
#include <fstream>
#include <sstream>
#include <string>
#include <string_view>
#include <vector>

#include "core/canopen/object_dictionary.h"
#include "host/canopen_dictionary_view.h"
#include "host/module_descriptor.h"
#include "host/module_listing.h"
#include "host/module_registry.h"
#include "support/motwin_cli.h"
#include "tools/child_process.h"
#include "tools/eds_writer.h"
#include "tools/parameter_listing.h"
#include "tools/serve_process.h"

namespace motwin::host {
namespace {

using motwin::testing::run_motwin;

using namespace std::chrono_literals;

bool contains(const std::string& text, std::string_view part) { return text.find(part) != std::string::npos; }

std::string name_of(const ModuleDescriptor& module) { return std::string(module.name); }

// Each line of a help paragraph after `indent`, as `serve --help` shows it.
std::string indented(std::string_view paragraph, std::string_view indent) {
  std::string text;
  size_t begin = 0;
  while (begin < paragraph.size()) {
    const size_t end = std::min(paragraph.find('\n', begin), paragraph.size());
    text += std::string(indent) + std::string(paragraph.substr(begin, end - begin)) + "\n";
    begin = end + 1;
  }
  return text;
}

TEST(ModuleDescriptors, the_registry_lists_each_module_once_with_every_field_filled) {
  ASSERT_GE(registered_modules().size(), 3u);
  for (const ModuleDescriptor& module : registered_modules()) {
    SCOPED_TRACE(name_of(module));
    EXPECT_EQ(find_module(module.name), &module);
    EXPECT_FALSE(module.product_name.empty());
    EXPECT_FALSE(module.summary.empty());
    EXPECT_FALSE(module.firmware.empty());
    EXPECT_FALSE(module.help.empty());
    EXPECT_FALSE(module.input_signals().empty());
    EXPECT_TRUE(module.endpoints.has_tmcl() || module.endpoints.has_can());
    // `run` traces something on every TMCL module; a CANopen dictionary is behind the CANopen endpoint.
    EXPECT_EQ(module.trace_parameters.empty(), !module.endpoints.has_tmcl());
    EXPECT_EQ(module.canopen != nullptr, module.endpoints.canopen);
    const std::vector<std::string_view> motors = module.motors.names();
    ASSERT_FALSE(motors.empty());
    EXPECT_EQ(motors.front(), "ideal");
    const ModuleParameterListing listing = module.listing();
    EXPECT_EQ(listing.module_name, module.name);
    EXPECT_FALSE(listing.sections.empty() && listing.object_sections.empty());
  }
  EXPECT_EQ(find_module("tmcm-9999"), nullptr);
}

TEST(ModuleDescriptors, each_motor_choice_makes_the_module_the_descriptor_describes) {
  for (const ModuleDescriptor& descriptor : registered_modules()) {
    for (const std::string_view motor : descriptor.motors.names()) {
      SCOPED_TRACE(name_of(descriptor) + " --motor " + std::string(motor));
      ModuleOptions options;
      options.motor = std::string(motor);
      const MakeModuleResult made = descriptor.make(options);
      ASSERT_TRUE(made) << made.error();
      const VirtualModule& module = **made;
      EXPECT_EQ(module.name(), descriptor.name);
      EXPECT_EQ(module.firmware_version(), descriptor.firmware);
      EXPECT_EQ(module.has_tmcl(), descriptor.endpoints.has_tmcl());
      EXPECT_EQ((*made)->can_node() != nullptr, descriptor.endpoints.has_can());
    }
  }
}

TEST(ModuleDescriptors, params_lists_each_module_in_each_format) {
  for (const ModuleDescriptor& module : registered_modules()) {
    for (const auto& [name, format] : {std::pair{"table", tools::ListingFormat::kTable},
                                       std::pair{"csv", tools::ListingFormat::kCsv},
                                       std::pair{"markdown", tools::ListingFormat::kMarkdown}}) {
      SCOPED_TRACE(name_of(module) + " " + name);
      const tools::CompletedProcess listed = run_motwin({"params", "--module", name_of(module), "--format", name});
      EXPECT_EQ(listed.exit_status, 0) << listed.output;
      EXPECT_EQ(listed.output, tools::format_parameter_listing(module.listing(), format));
      EXPECT_GT(std::count(listed.output.begin(), listed.output.end(), '\n'), 20);
    }
  }
}

TEST(ModuleDescriptors, eds_writes_canopen_modules_and_names_them_for_the_others) {
  const std::string canopen_modules = module_names(&has_canopen_dictionary);
  ASSERT_FALSE(canopen_modules.empty());
  for (const ModuleDescriptor& module : registered_modules()) {
    SCOPED_TRACE(name_of(module));
    const tools::CompletedProcess eds = run_motwin({"eds", "--module", name_of(module)});
    if (module.canopen != nullptr) {
      EXPECT_EQ(eds.exit_status, 0) << eds.output;
      EXPECT_TRUE(eds.output.starts_with("[FileInfo]\n"));
      EXPECT_TRUE(contains(eds.output, "\nProductName=" + std::string(module.canopen->identity.product_name) + "\n"));
      const Result<std::string> written = tools::write_module_eds(module);
      ASSERT_TRUE(written) << written.error();
      EXPECT_EQ(eds.output, *written);
    } else {
      EXPECT_EQ(eds.exit_status, 2);
      EXPECT_EQ(eds.output, "motwin: error: module \"" + name_of(module) +
                                "\" has no CANopen object dictionary (available: " + canopen_modules + ")\n");
    }
  }
}

TEST(ModuleDescriptors, serve_help_shows_each_module_its_motors_and_its_signals) {
  const tools::CompletedProcess help = run_motwin({"serve", "--help"});
  ASSERT_EQ(help.exit_status, 0);
  for (const ModuleDescriptor& module : registered_modules()) {
    SCOPED_TRACE(name_of(module));
    // "  tmcm-142   TMCM-142 1-axis ...": the name, padding, the summary.
    const size_t row = help.output.find("\n  " + name_of(module) + " ");
    ASSERT_NE(row, std::string::npos);
    const size_t summary = help.output.find_first_not_of(' ', row + 3 + module.name.size());
    EXPECT_EQ(help.output.substr(summary, module.summary.size() + 1), std::string(module.summary) + "\n");
    const size_t block = help.output.find("\n" + name_of(module) + " (firmware " + std::string(module.firmware) + "):\n");
    ASSERT_NE(block, std::string::npos);
    EXPECT_TRUE(help.output.substr(block).starts_with("\n" + name_of(module) + " (firmware " +
                                                      std::string(module.firmware) + "):\n" + indented(module.help, "  ")));
    std::string motors = "  Motors (--motor ";
    for (const std::string_view motor : module.motors.names()) motors += std::string(motor) + "|";
    EXPECT_NE(help.output.find(motors + "FILE):\n" + indented(module.motors.help, "    "), block), std::string::npos);
    const size_t signals = help.output.find("Signals of " + name_of(module) + " (--set, --scenario):\n");
    ASSERT_NE(signals, std::string::npos);
    for (const sim::SignalInfo& signal : module.input_signals()) {
      EXPECT_NE(help.output.find("\n  " + std::string(signal.name) + " ", signals), std::string::npos) << signal.name;
    }
  }
}

TEST(ModuleDescriptors, serve_starts_each_module_and_prints_its_firmware) {
  for (const ModuleDescriptor& module : registered_modules()) {
    SCOPED_TRACE(name_of(module));
    const bool on_tcp = module.endpoints.default_endpoint == DefaultEndpoint::kTmclTcp;
    Result<tools::ChildProcess> serve = tools::ChildProcess::spawn(
        {MOTWIN_BINARY, "serve", "--module", name_of(module), "--state-dir", "none", "--speed", "fast",
         on_tcp ? "--tmcl-tcp" : "--can", on_tcp ? "127.0.0.1:0" : "socketcand:127.0.0.1:0"});
    ASSERT_TRUE(serve) << serve.error();
    const auto deadline = tools::SteadyClock::now() + 20s;
    EXPECT_EQ(serve->read_line(deadline),
              "motwin: " + name_of(module) + " (" + std::string(module.firmware) + ") eeprom none");
    const std::optional<std::string> endpoint = serve->read_line(deadline);
    ASSERT_TRUE(endpoint);
    EXPECT_TRUE(endpoint->starts_with(on_tcp ? "endpoint tmcl-tcp 127.0.0.1:" : "endpoint can-socketcand 127.0.0.1:"))
        << *endpoint;
    EXPECT_EQ(serve->read_line(deadline), "ready");
    EXPECT_EQ(serve->stop(), 0);
  }
}

TEST(ModuleDescriptors, run_traces_the_default_columns_of_tmcl_modules_and_refuses_the_others) {
  Result<tools::TemporaryDirectory> directory = tools::TemporaryDirectory::create("motwin-descriptor");
  ASSERT_TRUE(directory) << directory.error();
  const std::string program = (directory->path() / "stop.tmc").string();
  std::ofstream(program) << "STOP\n";
  for (const ModuleDescriptor& module : registered_modules()) {
    SCOPED_TRACE(name_of(module));
    const std::string trace = (directory->path() / (name_of(module) + ".csv")).string();
    const tools::CompletedProcess run =
        run_motwin({"run", program, "--module", name_of(module), "--for", "3ms", "--trace", trace});
    if (module.endpoints.has_tmcl()) {
      EXPECT_EQ(run.exit_status, 0) << run.output;
      std::string header = "time_s";
      for (const uint8_t number : module.trace_parameters) header += ",AP" + std::to_string(number);
      std::ifstream file(trace);
      std::string first_line;
      std::getline(file, first_line);
      EXPECT_EQ(first_line, header);
      EXPECT_TRUE(contains(run.output, "program: stopped by")) << run.output;
    } else {
      EXPECT_EQ(run.exit_status, 2);
      EXPECT_EQ(run.output, "motwin: error: " + name_of(module) + " has no TMCL interpreter (motwin run takes a TMCL "
                                "module: " + module_names(&has_tmcl) + ")\n");
    }
  }
}

// --- A new CANopen module needs no code outside its own files -----------------------------------

// A two-axis device with three objects: enough to show every path of the EDS and the listing.
struct FakeDevice {
  int64_t velocity[2] = {0, 0};
};

constexpr int64_t fake_axis_default(uint8_t axis) { return 100 + axis; }

constexpr canopen::EntryRow<FakeDevice> kFakeRows[] = {
    {{0x1000, 0, canopen::ObjectCode::kVar, "Device type", "Device type", canopen::DataType::kUnsigned32,
      canopen::Access::kConst, false, 0, 0xFFFFFFFF, 0x00020192, false, 0, canopen::StorageGroup::kNone, nullptr},
     {}},
    {{0x1008, 0, canopen::ObjectCode::kVar, "Manufacturer device name", "Manufacturer device name",
      canopen::DataType::kVisibleString, canopen::Access::kConst, false, 0, 0, 0, false, 0,
      canopen::StorageGroup::kNone, nullptr},
     {.get_string = [](FakeDevice&, uint8_t) { return std::string_view("FAKE-2"); }}},
    {{0x1014, 0, canopen::ObjectCode::kVar, "COB-ID EMCY", "COB-ID EMCY", canopen::DataType::kUnsigned32,
      canopen::Access::kRw, false, 0, 0xFFFFFFFF, 0x80, true, 0, canopen::StorageGroup::kCommunication, nullptr},
     {}},
    {{0x6080, 0, canopen::ObjectCode::kVar, "Max motor speed", "Max motor speed", canopen::DataType::kInteger32,
      canopen::Access::kRw, true, -5, 5000, 0, false, 0x800, canopen::StorageGroup::kAxis, &fake_axis_default},
     canopen::field_binding<FakeDevice, [](FakeDevice& device, uint8_t axis) -> int64_t& {
       return device.velocity[axis];
     }>()},
};

CanopenDictionaryView fake_dictionary() {
  FakeDevice device;
  canopen::TableDictionary<FakeDevice> dictionary(device, kFakeRows, 2);
  return view_of(dictionary);
}

ModuleParameterListing fake_listing() { return canopen_object_listing("fake-2", fake_dictionary()); }

constexpr uint16_t kFakeBitRates[] = {125, 1000};
const CanopenDescription kFakeCanopen{{"FAKE-2", "Nobody", 0x1234, 2, 0x10000, 1, 2, kFakeBitRates, false, true},
                                      &fake_dictionary};

ModuleDescriptor fake_descriptor() {
  ModuleDescriptor descriptor = registered_modules().back();  // what a new row would fill in
  descriptor.name = "fake-2";
  descriptor.product_name = "FAKE-2";
  descriptor.listing = &fake_listing;
  descriptor.canopen = &kFakeCanopen;
  return descriptor;
}

TEST(ModuleDescriptors, a_new_canopen_row_gets_an_object_listing_and_an_eds_from_its_table_alone) {
  const ModuleDescriptor fake = fake_descriptor();
  EXPECT_EQ(tools::format_parameter_listing(fake.listing(), tools::ListingFormat::kCsv),
            "index,sub,axis,name,type,access,pdo,min,max,default\n"
            "1000,0,,Device type,UNSIGNED32,const,no,0x0,0xFFFFFFFF,0x20192\n"
            "1008,0,,Manufacturer device name,VISIBLE_STRING,const,no,,,FAKE-2\n"
            "1014,0,,COB-ID EMCY,UNSIGNED32,rw,no,0x0,0xFFFFFFFF,$NODEID+0x80\n"
            "6080,0,0,Max motor speed,INTEGER32,rw,yes,-5,5000,100\n"
            "6880,0,1,Max motor speed,INTEGER32,rw,yes,-5,5000,101\n");
  const std::string table = tools::format_parameter_listing(fake.listing(), tools::ListingFormat::kTable);
  EXPECT_TRUE(table.starts_with("fake-2 objects\n\nCommunication profile area (1000..1FFF)\n")) << table;
  EXPECT_TRUE(contains(table, "\n\nDevice profile area (6000..9FFF)\n")) << table;

  const Result<std::string> eds = tools::write_module_eds(fake, 3);
  ASSERT_TRUE(eds) << eds.error();
  for (const char* line : {"FileName=FAKE-2.eds", "VendorNumber=0x1234", "ProductNumber=2", "RevisionNumber=0x00010000",
                           "BaudRate_10=0", "BaudRate_125=1", "BaudRate_500=0", "BaudRate_1000=1", "NrOfRXPDO=1",
                           "NrOfTXPDO=2", "LSS_Supported=0", "NodeID=3", "[MandatoryObjects]\nSupportedObjects=1\n1=0x1000",
                           "[OptionalObjects]\nSupportedObjects=4\n1=0x1008\n2=0x1014\n3=0x6080\n4=0x6880",
                           "[1008]\nParameterName=Manufacturer device name\nObjectType=0x7\nDataType=0x0009\n"
                           "AccessType=const\nDefaultValue=FAKE-2\nPDOMapping=0\n",
                           "[1014]\nParameterName=COB-ID EMCY\nObjectType=0x7\nDataType=0x0007\nAccessType=rw\n"
                           "DefaultValue=$NODEID+0x80\nPDOMapping=0\n",
                           "[6880]\nParameterName=Max motor speed (motor 1)\nObjectType=0x7\nDataType=0x0004\n"
                           "AccessType=rw\nLowLimit=-5\nHighLimit=5000\nDefaultValue=101\nPDOMapping=1\n"}) {
    EXPECT_TRUE(contains(*eds, std::string(line) + "\n")) << line;
  }
}

// --- No module-specific code outside the module's own files ------------------------------------

// The code of a C++ file without its comments; string and character literals stay.
std::string without_comments(std::string_view source) {
  std::string code;
  size_t i = 0;
  const auto copy_literal = [&](char quote) {
    code += source[i++];
    while (i < source.size() && source[i] != quote) {
      if (source[i] == '\\' && i + 1 < source.size()) code += source[i++];
      code += source[i++];
    }
    if (i < source.size()) code += source[i++];
  };
  while (i < source.size()) {
    if (source.substr(i, 2) == "//") {
      while (i < source.size() && source[i] != '\n') ++i;
    } else if (source.substr(i, 2) == "/*") {
      const size_t end = source.find("*/", i + 2);
      i = end == std::string_view::npos ? source.size() : end + 2;
      code += ' ';
    } else if (source.substr(i, 2) == "R\"") {  // raw string: R"delimiter( ... )delimiter"
      const size_t open = source.find('(', i);
      const std::string close = ")" + std::string(source.substr(i + 2, open - i - 2)) + "\"";
      const size_t end = source.find(close, open);
      const size_t stop = end == std::string_view::npos ? source.size() : end + close.size();
      code += source.substr(i, stop - i);
      i = stop;
    } else if (source[i] == '"' || source[i] == '\'') {
      copy_literal(source[i]);
    } else {
      code += source[i++];
    }
  }
  return code;
}

struct ModuleSpelling {
  std::string name;        // "tmcm-1636": as a whole string literal
  std::string folder;      // "tmcm1636": src/*/modules/tmcm1636/, the namespace tmcm1636::
  std::string identifier;  // "Tmcm1636": in class and type names
};

ModuleSpelling spelling_of(std::string_view name) {
  ModuleSpelling spelling{std::string(name), {}, {}};
  for (const char c : name) {
    if (c != '-') spelling.folder += c;
  }
  spelling.identifier = spelling.folder;
  spelling.identifier[0] = static_cast<char>(std::toupper(static_cast<unsigned char>(spelling.identifier[0])));
  return spelling;
}

// What in `code` (comments removed) is specific to the module: a string literal that is exactly its
// name (a name comparison, a default), an identifier or namespace of its own, an include of one
// of its folders. Help text naming the module inside a longer literal (an example) is not.
std::vector<std::string> module_specific_code(const std::string& code, const ModuleSpelling& module) {
  std::vector<std::string> found;
  for (const std::string& needle : {"\"" + module.name + "\"", module.identifier, module.folder + "::",
                                    "/modules/" + module.folder + "/"}) {
    if (code.find(needle) != std::string::npos) found.push_back(needle);
  }
  return found;
}

TEST(ModuleSourceCheck, finds_names_identifiers_and_includes_but_not_comments_or_examples) {
  const ModuleSpelling module = spelling_of("tmcm-142");
  EXPECT_EQ(module.folder, "tmcm142");
  EXPECT_EQ(module.identifier, "Tmcm142");
  const auto check = [&module](std::string_view source) { return module_specific_code(without_comments(source), module); };
  EXPECT_EQ(check("if (options.module == \"tmcm-142\") {}"), std::vector<std::string>{"\"tmcm-142\""});
  EXPECT_EQ(check("using modules::tmcm142::Tmcm142;").size(), 2u);
  EXPECT_EQ(check("#include \"core/modules/tmcm142/tmcm142.h\""), std::vector<std::string>{"/modules/tmcm142/"});
  EXPECT_TRUE(check("// Tmcm142 and \"tmcm-142\" in a comment\n/* modules::tmcm142:: */ int x;").empty());
  EXPECT_TRUE(check("footer(\"  motwin params --module tmcm-142\\n\"); char c = '\"'; // Tmcm142").empty());
  EXPECT_TRUE(check("auto help = R\"(// not a comment: Tmcm142)\";").size() == 1u);
}

TEST(ModuleSourceCheck, no_file_outside_a_modules_folders_and_the_registry_row_file_names_the_module) {
  const std::filesystem::path source_root = MOTWIN_SOURCE_DIR;
  ASSERT_TRUE(std::filesystem::is_directory(source_root / "host" / "modules"));
  size_t files = 0;
  for (const auto& entry : std::filesystem::recursive_directory_iterator(source_root)) {
    const std::string extension = entry.path().extension().string();
    if (!entry.is_regular_file() || (extension != ".h" && extension != ".cpp")) continue;
    const std::string relative = entry.path().lexically_relative(source_root).generic_string();
    if (relative == "host/module_registry.cpp") continue;
    std::ifstream file(entry.path());
    std::stringstream text;
    text << file.rdbuf();
    const std::string code = without_comments(text.str());
    ++files;
    for (const ModuleDescriptor& descriptor : registered_modules()) {
      const ModuleSpelling module = spelling_of(descriptor.name);
      // Its own folders in every layer: src/core/modules/tmcm1636/, src/host/modules/tmcm1636/ ...
      const size_t slash = relative.find('/');
      if (slash != std::string::npos && relative.substr(slash).starts_with("/modules/" + module.folder + "/")) continue;
      for (const std::string& found : module_specific_code(code, module)) {
        ADD_FAILURE() << "src/" << relative << " names " << module.name << ": " << found;
      }
    }
  }
  EXPECT_GT(files, 100u);
}

}  // namespace
}  // namespace motwin::host
