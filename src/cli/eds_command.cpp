// `motwin eds`: writes the CiA-306 EDS of a CANopen module from its object table.
#include <fstream>
#include <iostream>
#include <memory>
#include <optional>
#include <string>

#include "cli/cli_errors.h"
#include "cli/commands.h"
#include "host/module_registry.h"
#include "tools/eds_writer.h"

namespace motwin::cli {
namespace {

struct EdsOptions {
  std::string module;
  std::string firmware;  // empty: the module's default
  int node_id = 0;
  std::string output;
};

// "tmcm-NNNN --firmware NAME, ...": the firmware generations of registered modules that speak
// CANopen while their module's default firmware does not; empty when there are none.
std::string canopen_generations() {
  std::string names;
  for (const host::ModuleDescriptor& module : host::registered_modules()) {
    for (const host::FirmwareGeneration& generation : module.firmwares) {
      if (generation.descriptor == nullptr || generation.descriptor().canopen == nullptr) continue;
      names += (names.empty() ? "" : ", ") + std::string(module.name) + " --firmware " + std::string(generation.name);
    }
  }
  return names;
}

// The EDS of the module running the firmware, or why there is none.
Result<std::string> module_eds(const EdsOptions& options, const std::string& canopen_modules) {
  std::optional<uint8_t> node_id;
  if (options.node_id != 0) node_id = static_cast<uint8_t>(options.node_id);
  const host::ModuleDescriptor* module = host::find_module(options.module);
  if (module == nullptr) {
    return Error{"module \"" + options.module + "\" has no CANopen object dictionary (available: " + canopen_modules + ")"};
  }
  const Result<host::ModuleDescriptor> running = host::with_firmware(*module, options.firmware);
  if (!running) return Error{running.error()};
  if (running->canopen == nullptr && !options.firmware.empty()) {
    return Error{"firmware " + options.firmware + " of " + options.module +
                 " speaks no CANopen: it has no CANopen object dictionary (available: " + canopen_modules + ")"};
  }
  const Result<std::string> text = tools::write_module_eds(*running, node_id);
  if (!text) return Error{text.error() + " (available: " + canopen_modules + ")"};
  return text;
}

}  // namespace

void add_eds_command(CLI::App& app, int& exit_status) {
  auto options = std::make_shared<EdsOptions>();
  if (const host::ModuleDescriptor* first = host::first_module(&host::has_canopen_dictionary)) {
    options->module = std::string(first->name);
  }
  const std::string canopen_modules = host::module_names(&host::has_canopen_dictionary);
  const std::string generations = canopen_generations();
  CLI::App* eds = app.add_subcommand("eds", "Write the CiA-306 EDS file of a CANopen module (" + canopen_modules +
                                                (generations.empty() ? "" : "; " + generations) + ")");
  eds->add_option("--module", options->module, "CANopen module")->type_name("NAME")->capture_default_str();
  eds->add_option("--firmware", options->firmware,
                  "The module's firmware generation, for a module whose CANopen firmware is one of several (motwin "
                  "serve --help lists them); default: the module's first")
      ->type_name("VERSION");
  eds->add_option("--node-id", options->node_id, "Add a [DeviceComissioning] section with this node ID")
      ->type_name("N")
      ->check(CLI::Range(1, 127));
  eds->add_option("-o,--output", options->output, "Write to FILE instead of stdout")->type_name("FILE");
  eds->callback([options, canopen_modules, &exit_status] {
    const Result<std::string> text = module_eds(*options, canopen_modules);
    if (!text) {
      exit_status = usage_error(text.error());
      return;
    }
    if (options->output.empty()) {
      std::cout << *text;
      exit_status = kExitSuccess;
      return;
    }
    std::ofstream file(options->output, std::ios::binary | std::ios::trunc);
    file << *text;
    file.close();
    exit_status = file ? kExitSuccess : usage_error("cannot write " + options->output);
  });
}

}  // namespace motwin::cli
