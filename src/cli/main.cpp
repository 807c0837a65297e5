#include <CLI/CLI.hpp>

#include "cli/commands.h"

int main(int argc, char** argv) {
  CLI::App app{"Motwin: virtual Trinamic motion-control modules (TMCM-1636, TMCM-142, TMCM-3216)"};
  app.require_subcommand(1);
  int exit_status = 0;
  motwin::cli::add_serve_command(app, exit_status);
  motwin::cli::add_tmcl_command(app, exit_status);
  motwin::cli::add_params_command(app, exit_status);
  CLI11_PARSE(app, argc, argv);
  return exit_status;
}
