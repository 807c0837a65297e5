// `--can` endpoint specifications of `motwin serve` and the TCP listening socket the CAN
// transports share.
//   socketcand                 127.0.0.1:29536 (socketcand's default port)
//   socketcand:PORT            127.0.0.1:PORT (0: a free port)
//   socketcand:HOST:PORT       HOST as for --tmcl-tcp ([::1]:PORT for IPv6)
//   slcan-tcp:[HOST:]PORT      SLCAN (Lawicel) over TCP, python-can channel socket://HOST:PORT
// SLCAN over a pseudo-terminal and SocketCAN are not implemented yet (docs/canopen.md).
#pragma once

#include <cstdint>
#include <optional>
#include <string>
#include <string_view>

#include "host/tcp_server.h"

namespace motwin::host {

inline constexpr uint16_t kDefaultSocketcandPort = 29536;

enum class CanTransport : uint8_t { kSocketcand, kSlcanTcp };

struct CanEndpointSpec {
  CanTransport transport = CanTransport::kSocketcand;
  TcpEndpointSpec tcp{std::string(kDefaultTcpHost), kDefaultSocketcandPort};
};

std::optional<CanEndpointSpec> parse_can_endpoint(std::string_view text, std::string& error);

// A non-blocking listening TCP socket (SO_REUSEADDR, backlog 16), or -1 with `error` set to
// "cannot listen on HOST:PORT: reason".
int listen_tcp(const TcpEndpointSpec& spec, std::string& error);

}  // namespace motwin::host
