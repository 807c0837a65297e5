// A firmware generation may bring its own descriptor (host/module_descriptor.h, with_firmware):
// a firmware of a module that speaks another protocol, as the TMCM-1636's CANopen firmware beside
// its TMCL ones. A test-only module "fake-1636" has two TMCL generations and a CANopen one whose
// descriptor reuses the registered CANopen module's fields; the resolver, make_module() and the
// commands are checked on it and on the registered modules.
#include <gtest/gtest.h>

#include <string>
#include <string_view>
#include <vector>

#include "host/module_descriptor.h"
#include "host/module_group.h"
#include "host/module_registry.h"
#include "support/motwin_cli.h"
#include "tools/eds_writer.h"
#include "tools/parameter_listing.h"

namespace motwin::host {
namespace {

using motwin::testing::run_motwin;

const ModuleDescriptor& tmcl_module() { return *first_module(&has_tmcl); }
const ModuleDescriptor& canopen_module() { return *first_module(&has_canopen_dictionary); }

std::string csv(const ModuleParameterListing& listing) {
  return tools::format_parameter_listing(listing, tools::ListingFormat::kCsv);
}

ModuleParameterListing fake_v2_listing() { return ModuleParameterListing{"fake-1636 2.00", {}}; }

// The CANopen firmware of fake-1636: the registered CANopen module's endpoints, EDS, listing and
// make(), under fake-1636's name.
ModuleDescriptor fake_canopen_descriptor() {
  ModuleDescriptor descriptor = canopen_module();
  descriptor.name = "fake-1636";
  descriptor.product_name = "FAKE-1636";
  descriptor.summary = "FAKE-1636 with its CANopen firmware";
  descriptor.firmware = "FAKE CANopen V1.00";
  descriptor.firmwares = {};  // the descriptor of one firmware
  return descriptor;
}

ModuleDescriptor fake_module() {
  ModuleDescriptor module = tmcl_module();
  module.name = "fake-1636";
  module.firmware = "FAKE V1.00";
  module.firmwares = {
      {"1.00", "FAKE V1.00", "the first TMCL firmware", module.listing},
      {"2.00", "FAKE V2.00", "a later TMCL firmware", &fake_v2_listing},
      {.name = "canopen", .version = "FAKE CANopen V1.00", .help = "the CANopen firmware",
       .descriptor = &fake_canopen_descriptor},
  };
  return module;
}

ModuleOptions quiet_options(std::string firmware) {
  ModuleOptions options;
  options.firmware = std::move(firmware);
  options.log = [](const std::string&) {};
  return options;
}

TEST(FirmwareDescriptors, a_generation_with_its_own_descriptor_resolves_to_that_descriptor) {
  const ModuleDescriptor fake = fake_module();
  const Result<ModuleDescriptor> running = with_firmware(fake, "canopen");
  ASSERT_TRUE(running) << running.error();
  EXPECT_EQ(running->name, "fake-1636") << "--module still finds it";
  EXPECT_EQ(running->product_name, "FAKE-1636");
  EXPECT_EQ(running->summary, "FAKE-1636 with its CANopen firmware");
  EXPECT_EQ(running->firmware, "FAKE CANopen V1.00");
  EXPECT_EQ(running->make, canopen_module().make);
  EXPECT_EQ(running->listing, canopen_module().listing);
  EXPECT_EQ(running->canopen, canopen_module().canopen);
  EXPECT_TRUE(running->endpoints.canopen);
  EXPECT_FALSE(running->endpoints.has_tmcl());
  EXPECT_EQ(running->endpoints.default_endpoint, DefaultEndpoint::kCanSocketcand);
  EXPECT_TRUE(running->trace_parameters.empty());
  EXPECT_TRUE(running->firmwares.empty());
  EXPECT_EQ(running->motors.names(), canopen_module().motors.names());

  const Result<ModuleParameterListing> listing = firmware_listing(fake, "canopen");
  ASSERT_TRUE(listing) << listing.error();
  EXPECT_EQ(csv(*listing), csv(canopen_module().listing()));
  const Result<std::string> eds = tools::write_module_eds(*running);
  ASSERT_TRUE(eds) << eds.error();
  EXPECT_EQ(*eds, *tools::write_module_eds(canopen_module()));

  // Its make() is the CANopen module's, given the generation's name.
  const MakeModuleResult made = running->make(quiet_options("canopen"));
  ASSERT_TRUE(made) << made.error();
  EXPECT_FALSE((*made)->has_tmcl());
  EXPECT_NE((*made)->can_node(), nullptr);
  EXPECT_EQ((*made)->firmware_version(), canopen_module().firmware);
}

TEST(FirmwareDescriptors, a_generation_without_one_resolves_to_the_module_with_its_identity_and_rows) {
  const ModuleDescriptor fake = fake_module();
  const Result<ModuleDescriptor> default_firmware = with_firmware(fake, "");
  ASSERT_TRUE(default_firmware) << default_firmware.error();
  EXPECT_EQ(default_firmware->firmware, "FAKE V1.00");
  EXPECT_EQ(default_firmware->make, tmcl_module().make);
  EXPECT_EQ(default_firmware->listing, tmcl_module().listing);
  EXPECT_TRUE(default_firmware->endpoints.has_tmcl());
  EXPECT_EQ(default_firmware->firmwares.size(), 3u);

  const Result<ModuleDescriptor> later = with_firmware(fake, "2.00");
  ASSERT_TRUE(later) << later.error();
  EXPECT_EQ(later->name, "fake-1636");
  EXPECT_EQ(later->firmware, "FAKE V2.00");
  EXPECT_EQ(later->make, tmcl_module().make) << "make() reads ModuleOptions::firmware";
  EXPECT_EQ(later->listing, &fake_v2_listing);
  EXPECT_EQ(later->endpoints.default_endpoint, DefaultEndpoint::kTmclTcp);
  EXPECT_EQ(firmware_listing(fake, "2.00")->module_name, "fake-1636 2.00");

  // The registered generations: each one's version string and rows, made by the module's make().
  for (const ModuleDescriptor& module : registered_modules()) {
    for (const FirmwareGeneration& generation : module.firmwares) {
      if (generation.descriptor != nullptr) continue;
      SCOPED_TRACE(std::string(module.name) + " --firmware " + std::string(generation.name));
      const Result<ModuleDescriptor> resolved = with_firmware(module, generation.name);
      ASSERT_TRUE(resolved) << resolved.error();
      EXPECT_EQ(resolved->firmware, generation.version);
      EXPECT_EQ(csv(resolved->listing()), csv(generation.listing()));
      EXPECT_EQ(resolved->make, module.make);
      const MakeModuleResult made = make_module(module.name, quiet_options(std::string(generation.name)));
      ASSERT_TRUE(made) << made.error();
      EXPECT_EQ((*made)->firmware_version(), generation.version);
    }
  }
}

TEST(FirmwareDescriptors, unknown_names_give_the_errors_find_firmware_gives) {
  const ModuleDescriptor fake = fake_module();
  const Result<ModuleDescriptor> unknown = with_firmware(fake, "9.9");
  ASSERT_FALSE(unknown);
  EXPECT_EQ(unknown.error(), "unknown firmware \"9.9\" for fake-1636 (choices: 1.00, 2.00, canopen)");
  EXPECT_EQ(unknown.error(), find_firmware(fake, "9.9").error());
  EXPECT_EQ(firmware_listing(fake, "9.9").error(), unknown.error());

  // A module with one firmware takes its version string, and nothing else.
  const ModuleDescriptor& single = *first_module([](const ModuleDescriptor& m) { return m.firmwares.empty(); });
  const Result<ModuleDescriptor> itself = with_firmware(single, single.firmware);
  ASSERT_TRUE(itself) << itself.error();
  EXPECT_EQ(itself->make, single.make);
  const std::string one_firmware =
      "--firmware 9.9: " + std::string(single.name) + " has one firmware, " + std::string(single.firmware);
  EXPECT_EQ(with_firmware(single, "9.9").error(), one_firmware);
  EXPECT_EQ(make_module(single.name, quiet_options("9.9")).error(), one_firmware);
  EXPECT_EQ(find_module_with_firmware(single.name, "9.9").error(), one_firmware);
  EXPECT_EQ(find_module_with_firmware("tmcm-9999", "").error(),
            "unknown module \"tmcm-9999\" (available: " + module_names() + ")");
}

TEST(FirmwareDescriptors, registered_generations_with_a_descriptor_are_their_module_with_that_firmware) {
  const tools::CompletedProcess help = run_motwin({"serve", "--help"});
  ASSERT_EQ(help.exit_status, 0);
  for (const ModuleDescriptor& module : registered_modules()) {
    for (const FirmwareGeneration& generation : module.firmwares) {
      if (generation.descriptor == nullptr) continue;
      SCOPED_TRACE(std::string(module.name) + " --firmware " + std::string(generation.name));
      const ModuleDescriptor own = generation.descriptor();
      EXPECT_EQ(own.name, module.name);
      EXPECT_EQ(own.firmware, generation.version);
      EXPECT_TRUE(own.firmwares.empty());
      EXPECT_EQ(own.canopen != nullptr, own.endpoints.canopen);
      const MakeModuleResult made = make_module(module.name, quiet_options(std::string(generation.name)));
      ASSERT_TRUE(made) << made.error();
      EXPECT_EQ((*made)->name(), module.name);
      EXPECT_EQ((*made)->firmware_version(), generation.version);
      EXPECT_EQ((*made)->has_tmcl(), own.endpoints.has_tmcl());
      const Result<NodeSpec> node = parse_node_spec(std::string(module.name) + ":firmware=" + std::string(generation.name), 1);
      ASSERT_TRUE(node) << node.error();
      EXPECT_EQ(node_module(*node)->make, own.make);
      // `serve --help` lists it under its module with where it is served.
      EXPECT_NE(help.output.find("    " + std::string(generation.name) + " (" + std::string(generation.version) +
                                 "): " + std::string(generation.help) + "\n      Endpoints: "),
                std::string::npos);
      const tools::CompletedProcess eds =
          run_motwin({"eds", "--module", std::string(module.name), "--firmware", std::string(generation.name)});
      EXPECT_EQ(eds.exit_status, own.canopen != nullptr ? 0 : 2) << eds.output;
    }
  }
}

TEST(FirmwareDescriptors, eds_takes_a_firmware_and_refuses_one_that_speaks_tmcl) {
  const std::string canopen_modules = module_names(&has_canopen_dictionary);
  for (const ModuleDescriptor& module : registered_modules()) {
    for (const FirmwareGeneration& generation : module.firmwares) {
      const Result<ModuleDescriptor> running = with_firmware(module, generation.name);
      ASSERT_TRUE(running) << running.error();
      if (running->canopen != nullptr) continue;
      SCOPED_TRACE(std::string(module.name) + " --firmware " + std::string(generation.name));
      const tools::CompletedProcess eds =
          run_motwin({"eds", "--module", std::string(module.name), "--firmware", std::string(generation.name)});
      EXPECT_EQ(eds.exit_status, 2);
      EXPECT_EQ(eds.output, "motwin: error: firmware " + std::string(generation.name) + " of " +
                                std::string(module.name) + " speaks no CANopen: it has no CANopen object dictionary "
                                "(available: " + canopen_modules + ")\n");
    }
  }
  const ModuleDescriptor& canopen = canopen_module();
  const tools::CompletedProcess plain = run_motwin({"eds", "--module", std::string(canopen.name)});
  const tools::CompletedProcess named =
      run_motwin({"eds", "--module", std::string(canopen.name), "--firmware", std::string(canopen.firmware)});
  EXPECT_EQ(named.exit_status, 0) << named.output;
  EXPECT_EQ(named.output, plain.output);
  const tools::CompletedProcess unknown =
      run_motwin({"eds", "--module", std::string(tmcl_module().name), "--firmware", "9.9"});
  EXPECT_EQ(unknown.exit_status, 2);
  EXPECT_EQ(unknown.output, "motwin: error: " + find_firmware(tmcl_module(), "9.9").error() + "\n");
}

}  // namespace
}  // namespace motwin::host
