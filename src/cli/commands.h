// Each `motwin` subcommand registers itself on the CLI11 app; main.cpp only wires them.
#pragma once

#include <CLI/CLI.hpp>

namespace motwin::cli {

// Every add_* function registers its subcommand and its callback. The callback sets the
// process exit status through `exit_status`.
void add_serve_command(CLI::App& app, int& exit_status);
void add_tmcl_command(CLI::App& app, int& exit_status);
void add_params_command(CLI::App& app, int& exit_status);
void add_asm_command(CLI::App& app, int& exit_status);
void add_disasm_command(CLI::App& app, int& exit_status);
void add_download_command(CLI::App& app, int& exit_status);
// start, stop, step, status
void add_program_control_commands(CLI::App& app, int& exit_status);
void add_run_command(CLI::App& app, int& exit_status);
// CANopen: `motwin eds` (docs/canopen.md)
void add_eds_command(CLI::App& app, int& exit_status);
// `motwin sdo read|write`, `motwin nmt`
void add_canopen_commands(CLI::App& app, int& exit_status);
// `motwin candump`, `motwin lss` (src/cli/bus_commands.cpp)
void add_candump_command(CLI::App& app, int& exit_status);
void add_lss_command(CLI::App& app, int& exit_status);

}  // namespace motwin::cli
