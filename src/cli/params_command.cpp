// `motwin params`: lists a module's axis parameters, global parameters and user variables
// from its declarative tables.
#include <iostream>
#include <memory>
#include <string>

#include <fmt/format.h>

#include "cli/cli_errors.h"
#include "cli/commands.h"
#include "tools/parameter_listing.h"

namespace motwin::cli {
namespace {

struct ParamsOptions {
  std::string module_name;
  std::string format_name = "table";
};

int run_params(const ParamsOptions& options) {
  if (options.module_name.empty()) {
    print_error(fmt::format("--module is required (known modules: {})", tools::known_module_names()));
    return kExitUsageError;
  }
  const tools::ParameterListingSource* source = tools::find_parameter_listing_source(options.module_name);
  if (source == nullptr) {
    print_error(fmt::format("unknown module '{}' (known modules: {})", options.module_name, tools::known_module_names()));
    return kExitUsageError;
  }
  const std::optional<tools::ListingFormat> format = tools::parse_listing_format(options.format_name);
  if (!format) {
    print_error(fmt::format("unknown format '{}' (expected table, csv or markdown)", options.format_name));
    return kExitUsageError;
  }
  std::cout << tools::format_parameter_listing(source->build(), *format);
  return kExitSuccess;
}

}  // namespace

void add_params_command(CLI::App& app, int& exit_status) {
  auto options = std::make_shared<ParamsOptions>();
  CLI::App* command =
      app.add_subcommand("params", "List a module's axis parameters, global parameters and user variables");
  command->add_option("--module", options->module_name, fmt::format("Module ({})", tools::known_module_names()));
  command->add_option("--format", options->format_name, "table, csv or markdown")->capture_default_str();
  command->footer(
      "Examples:\n"
      "  motwin params --module tmcm-1636\n"
      "  motwin params --module tmcm-1636 --format markdown > docs/tmcm-1636-parameters.md\n");
  command->callback([options, &exit_status] { exit_status = run_params(*options); });
}

}  // namespace motwin::cli
