#include <CLI/CLI.hpp>

#include <exception>
#include <string>

#include "cli/cli_errors.h"
#include "cli/commands.h"
#include "cli/usage_hints.h"
#include "host/module_registry.h"

namespace {

// "TMCM-1636, TMCM-142, ...": every registered module.
std::string product_names() {
  std::string names;
  for (const motwin::host::ModuleDescriptor& module : motwin::host::registered_modules()) {
    if (!names.empty()) names += ", ";
    names += module.product_name;
  }
  return names;
}

}  // namespace

int main(int argc, char** argv) {
  CLI::App app{"Motwin: virtual Trinamic motion-control modules (" + product_names() + ")"};
  app.require_subcommand(1);
  int exit_status = 0;
  motwin::cli::add_serve_command(app, exit_status);
  motwin::cli::add_tmcl_command(app, exit_status);
  motwin::cli::add_params_command(app, exit_status);
  motwin::cli::add_asm_command(app, exit_status);
  motwin::cli::add_disasm_command(app, exit_status);
  motwin::cli::add_download_command(app, exit_status);
  motwin::cli::add_program_control_commands(app, exit_status);
  motwin::cli::add_run_command(app, exit_status);
  motwin::cli::add_eds_command(app, exit_status);
  motwin::cli::add_canopen_commands(app, exit_status);
  motwin::cli::add_candump_command(app, exit_status);
  motwin::cli::add_lss_command(app, exit_status);
  // Usage errors look like every other error and exit with status 2 (CLI11's own codes are
  // 100 and up); --help still exits 0.
  app.failure_message([](const CLI::App* failed, const CLI::Error& error) {
    return "motwin: error: " + motwin::cli::explain_parse_error(*failed, error) + " (see --help)\n";
  });
  if (const std::string unknown = motwin::cli::unknown_command_message(app, argc, argv); !unknown.empty()) {
    return motwin::cli::usage_error(unknown + " (see --help)");
  }
  // The only exceptions: CLI11 reports bad arguments with one, and anything the commands did not
  // foresee (out of memory, say) ends here as an error line rather than an abort.
  try {
    app.parse(argc, argv);
  } catch (const CLI::ParseError& error) {
    return app.exit(error) == 0 ? motwin::cli::kExitSuccess : motwin::cli::kExitUsageError;
  } catch (const std::exception& unexpected) {
    motwin::cli::print_error(unexpected.what());
    return motwin::cli::kExitUsageError;
  }
  return exit_status;
}
