#include "host/can_endpoint.h"

namespace motwin::host {

Result<CanEndpointSpec> parse_can_endpoint(std::string_view text) {
  CanEndpointSpec spec;
  const size_t colon = text.find(':');
  const std::string_view kind = text.substr(0, colon);
  if (kind == "slcan" || kind == "socketcan") {
    spec.transport = kind == "slcan" ? CanTransport::kSlcanPty : CanTransport::kSocketcan;
    spec.device = colon == std::string_view::npos ? std::string() : std::string(text.substr(colon + 1));
    if (spec.device.empty()) {
      return Error{kind == "slcan" ? "slcan needs a link path: slcan:/tmp/motwin-slcan"
                                   : "socketcan needs an interface: socketcan:vcan0"};
    }
    return spec;
  }
  if (kind == "socketcand-client") {
    // HOST:PORT:CHANNEL, the channel after the last colon (an IPv6 host goes in brackets).
    const Error usage{"socketcand-client needs HOST:PORT:CHANNEL (socketcand-client:gateway:29536:can0), got \"" +
                      std::string(text) + "\""};
    if (colon == std::string_view::npos) return usage;
    const std::string_view rest = text.substr(colon + 1);
    const size_t last = rest.rfind(':');
    if (last == std::string_view::npos || last == 0) return usage;
    const std::string_view channel = rest.substr(last + 1);
    if (channel.empty() || channel.find_first_of(" \t<>]") != std::string_view::npos) return usage;
    const Result<TcpEndpointSpec> tcp = parse_tcp_endpoint(rest.substr(0, last));
    if (!tcp || tcp->port == 0 || rest.substr(0, last).find(':') == std::string_view::npos) return usage;
    spec.transport = CanTransport::kSocketcandClient;
    spec.tcp = *tcp;
    spec.device = std::string(channel);
    return spec;
  }
  if (kind == "slcan-tcp") {
    spec.transport = CanTransport::kSlcanTcp;
    if (colon == std::string_view::npos) {
      return Error{"slcan-tcp needs a port: slcan-tcp:[HOST:]PORT"};
    }
  } else if (kind != "socketcand") {
    return Error{"expected socketcand[:HOST]:PORT, slcan-tcp:[HOST:]PORT, slcan:LINK, socketcan:IFACE or "
                 "socketcand-client:HOST:PORT:CHANNEL, got \"" +
                 std::string(text) + "\""};
  }
  if (colon == std::string_view::npos) return spec;
  const Result<TcpEndpointSpec> tcp = parse_tcp_endpoint(text.substr(colon + 1));
  if (!tcp) return tcp.error_with_context(std::string(kind) + ": ");
  spec.tcp = *tcp;
  return spec;
}

}  // namespace motwin::host
