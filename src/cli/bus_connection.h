// The bus connection of the CAN client commands (`motwin sdo`, `nmt`, `lss`, `candump`): a
// socketcand endpoint given as --can socketcand:HOST:PORT (default 127.0.0.1:29536).
#pragma once

#include <memory>
#include <string>

#include "host/can_endpoint.h"
#include "tools/canopen_client.h"
#include "types/result.h"

namespace motwin::cli {

inline constexpr const char* kDefaultCanEndpoint = "socketcand:127.0.0.1:29536";

// Connects and enters raw mode.
inline Result<std::unique_ptr<tools::SocketcandClient>> connect_can(const std::string& endpoint) {
  const Result<host::CanEndpointSpec> spec = host::parse_can_endpoint(endpoint);
  if (!spec) return spec.error_with_context("--can: ");
  if (spec->transport != host::CanTransport::kSocketcand) {
    return Error{"--can: only socketcand endpoints are supported here"};
  }
  return tools::SocketcandClient::connect(spec->tcp.host, spec->tcp.port);
}

}  // namespace motwin::cli
