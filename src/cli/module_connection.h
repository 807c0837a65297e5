// The options with which the commands that talk TMCL to a module (`motwin tmcl|download|disasm|
// start|stop|step|status`) reach it: --tcp HOST:PORT or --serial DEVICE, --module-address,
// --timeout-ms.
#pragma once

#include <chrono>
#include <string>

#include <CLI/CLI.hpp>

#include "tools/tmcl_client.h"
#include "types/result.h"

namespace motwin::cli {

struct ModuleConnection {
  std::string tcp_address;
  std::string serial_device;
  int module_address = tools::kDefaultModuleAddress;
  int timeout_ms = static_cast<int>(tools::kDefaultReplyTimeout.count());

  uint8_t address() const { return static_cast<uint8_t>(module_address); }
};

// The help of the options, as a command words them.
struct ConnectionHelp {
  std::string tcp = "The module's TMCL-over-TCP endpoint (motwin serve), HOST:PORT";
  std::string serial = "The module's serial device or pseudo-terminal (115200 bit/s)";
  std::string module_address = "Module address of the requests";
  std::string timeout = "How long to wait for each reply (and to connect)";
};

inline void add_connection_options(CLI::App& command, ModuleConnection& connection, const ConnectionHelp& help = {}) {
  CLI::Option* tcp = command.add_option("--tcp", connection.tcp_address, help.tcp);
  CLI::Option* serial = command.add_option("--serial", connection.serial_device, help.serial);
  tcp->excludes(serial);
  command.add_option("--module-address", connection.module_address, help.module_address)
      ->capture_default_str()
      ->check(CLI::Range(0, 255));
  command.add_option("--timeout-ms", connection.timeout_ms, help.timeout)
      ->capture_default_str()
      ->check(CLI::Range(1, 3600 * 1000));
}

// Exactly one of --tcp and --serial must be given.
inline Result<tools::TmclClient> connect(const ModuleConnection& connection) {
  if (connection.tcp_address.empty() == connection.serial_device.empty()) {
    return Error{"give exactly one of --tcp HOST:PORT or --serial DEVICE"};
  }
  Result<tools::TmclClient> client =
      connection.tcp_address.empty()
          ? tools::TmclClient::open_serial(connection.serial_device)
          : tools::TmclClient::connect_tcp(connection.tcp_address, std::chrono::milliseconds(connection.timeout_ms));
  if (client) client->set_reply_timeout(std::chrono::milliseconds(connection.timeout_ms));
  return client;
}

}  // namespace motwin::cli
