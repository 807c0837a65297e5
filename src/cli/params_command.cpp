// `motwin params`: lists a module's parameters (TMCL: axis parameters, global parameters, user
// variables) or objects (CANopen) from its declarative tables, as its descriptor builds them.
#include <iostream>
#include <memory>
#include <string>

#include <fmt/format.h>

#include "cli/cli_errors.h"
#include "cli/commands.h"
#include "host/module_registry.h"
#include "tools/parameter_listing.h"

namespace motwin::cli {
namespace {

struct ParamsOptions {
  std::string module_name;
  std::string format_name = "table";
  std::string firmware;  // empty: the module's default generation
};

int run_params(const ParamsOptions& options) {
  if (options.module_name.empty()) {
    return usage_error(fmt::format("--module is required (known modules: {})", host::module_names()));
  }
  const host::ModuleDescriptor* module = host::find_module_ignoring_case(options.module_name);
  if (module == nullptr) {
    return usage_error(
        fmt::format("unknown module '{}' (known modules: {})", options.module_name, host::module_names()));
  }
  const std::optional<tools::ListingFormat> format = tools::parse_listing_format(options.format_name);
  if (!format) {
    return usage_error(fmt::format("unknown format '{}' (expected table, csv or markdown)", options.format_name));
  }
  const Result<host::ModuleParameterListing> listing = host::firmware_listing(*module, options.firmware);
  if (!listing) return usage_error(listing.error());
  std::cout << tools::format_parameter_listing(*listing, *format);
  return kExitSuccess;
}

}  // namespace

void add_params_command(CLI::App& app, int& exit_status) {
  auto options = std::make_shared<ParamsOptions>();
  CLI::App* command = app.add_subcommand(
      "params", "List a module's axis parameters, global parameters and user variables, or its CANopen objects");
  command->add_option("--module", options->module_name, fmt::format("Module ({})", host::module_names()));
  command->add_option("--format", options->format_name, "table, csv or markdown")->capture_default_str();
  command->add_option("--firmware", options->firmware,
                      "The firmware generation whose parameters to list (motwin serve --help lists them); default: "
                      "the module's first")
      ->type_name("VERSION");
  command->footer(
      "Examples:\n"
      "  motwin params --module tmcm-1636\n"
      "  motwin params --module tmcm-1636 --firmware 1.13\n"
      "  motwin params --module tmcm-1636 --format markdown > docs/tmcm-1636-parameters.md\n"
      "  motwin params --module tmcm-3216 --format csv\n"
      "\n"
      "CANopen objects: one row per sub-index, per-axis objects once per axis (docs/canopen.md,\n"
      "\"Object listing\").\n");
  command->callback([options, &exit_status] { exit_status = run_params(*options); });
}

}  // namespace motwin::cli
