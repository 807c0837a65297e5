// The bus connection of the CAN client commands (`motwin sdo`, `nmt`, `lss`, `candump`): a
// socketcand endpoint given as --can socketcand:HOST:PORT (default 127.0.0.1:29536).
#pragma once

#include <memory>
#include <string>

#include "cli/cli_errors.h"
#include "host/can_endpoint.h"
#include "tools/canopen_client.h"

namespace motwin::cli {

inline constexpr const char* kDefaultCanEndpoint = "socketcand:127.0.0.1:29536";

// Connects and enters raw mode; nullptr after printing the error (exit_status = 2).
inline std::unique_ptr<tools::SocketcandClient> connect_can(const std::string& endpoint, int& exit_status) {
  const Result<host::CanEndpointSpec> spec = host::parse_can_endpoint(endpoint);
  if (!spec || spec->transport != host::CanTransport::kSocketcand) {
    print_error("--can: " + (spec ? std::string("only socketcand endpoints are supported here") : spec.error()));
    exit_status = kExitUsageError;
    return nullptr;
  }
  Result<std::unique_ptr<tools::SocketcandClient>> opened =
      tools::SocketcandClient::connect(spec->tcp.host, spec->tcp.port);
  if (!opened) {
    print_error(opened.error());
    exit_status = kExitUsageError;
    return nullptr;
  }
  return std::move(*opened);
}

}  // namespace motwin::cli
