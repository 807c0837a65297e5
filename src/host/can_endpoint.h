// `--can` endpoint specifications of `motwin serve`.
//   socketcand                 127.0.0.1:29536 (socketcand's default port)
//   socketcand:PORT            127.0.0.1:PORT (0: a free port)
//   socketcand:HOST:PORT       HOST as for --tmcl-tcp ([::1]:PORT for IPv6)
//   slcan-tcp:[HOST:]PORT      SLCAN (Lawicel) over TCP, python-can channel socket://HOST:PORT
//   slcan:LINK                 SLCAN on a pseudo-terminal, LINK a symbolic link to it
//   socketcan:IFACE            a Linux CAN interface (vcan0, can0), where the kernel has AF_CAN
//   socketcand-client:HOST:PORT:CHANNEL
//                              joins the bus of a socketcand server elsewhere (host/socketcand_client.h)
// (host/can_device_endpoints.h, docs/canopen.md).
#pragma once

#include <cstdint>
#include <string>
#include <string_view>

#include "host/tcp_server.h"
#include "types/result.h"

namespace motwin::host {

inline constexpr uint16_t kDefaultSocketcandPort = 29536;

enum class CanTransport : uint8_t { kSocketcand, kSlcanTcp, kSlcanPty, kSocketcan, kSocketcandClient };

struct CanEndpointSpec {
  CanTransport transport = CanTransport::kSocketcand;
  TcpEndpointSpec tcp{std::string(kDefaultTcpHost), kDefaultSocketcandPort};  // kSocketcandClient: the server
  std::string device;  // kSlcanPty: the link path; kSocketcan: the interface name; kSocketcandClient: the channel
};

Result<CanEndpointSpec> parse_can_endpoint(std::string_view text);

}  // namespace motwin::host
