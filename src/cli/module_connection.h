// The options with which the program commands (`motwin download|start|stop|step|status`) reach
// a module: --tcp HOST:PORT or --serial DEVICE, --module-address, --timeout-ms.
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

inline void add_connection_options(CLI::App& command, ModuleConnection& connection) {
  CLI::Option* tcp =
      command.add_option("--tcp", connection.tcp_address, "The module's TMCL-over-TCP endpoint (motwin serve), HOST:PORT");
  CLI::Option* serial = command.add_option("--serial", connection.serial_device,
                                           "The module's serial device or pseudo-terminal (115200 bit/s)");
  tcp->excludes(serial);
  command.add_option("--module-address", connection.module_address, "Module address of the requests")
      ->capture_default_str()
      ->check(CLI::Range(0, 255));
  command.add_option("--timeout-ms", connection.timeout_ms, "How long to wait for each reply (and to connect)")
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
