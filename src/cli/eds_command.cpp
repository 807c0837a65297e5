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

void add_eds_command(CLI::App& app, int& exit_status) {
  struct Options {
    std::string module;
    int node_id = 0;
    std::string output;
  };
  auto options = std::make_shared<Options>();
  if (const host::ModuleDescriptor* first = host::first_module(&host::has_canopen_dictionary)) {
    options->module = std::string(first->name);
  }
  const std::string canopen_modules = host::module_names(&host::has_canopen_dictionary);
  CLI::App* eds =
      app.add_subcommand("eds", "Write the CiA-306 EDS file of a CANopen module (" + canopen_modules + ")");
  eds->add_option("--module", options->module, "CANopen module")->type_name("NAME")->capture_default_str();
  eds->add_option("--node-id", options->node_id, "Add a [DeviceComissioning] section with this node ID")
      ->type_name("N")
      ->check(CLI::Range(1, 127));
  eds->add_option("-o,--output", options->output, "Write to FILE instead of stdout")->type_name("FILE");
  eds->callback([options, canopen_modules, &exit_status] {
    std::optional<uint8_t> node_id;
    if (options->node_id != 0) node_id = static_cast<uint8_t>(options->node_id);
    const host::ModuleDescriptor* module = host::find_module(options->module);
    const Result<std::string> text = module != nullptr
                                         ? tools::write_module_eds(*module, node_id)
                                         : Error{"module \"" + options->module + "\" has no CANopen object dictionary"};
    if (!text) {
      exit_status = usage_error(text.error() + " (available: " + canopen_modules + ")");
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
