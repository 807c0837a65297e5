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
  if (kind == "slcan-tcp") {
    spec.transport = CanTransport::kSlcanTcp;
    if (colon == std::string_view::npos) {
      return Error{"slcan-tcp needs a port: slcan-tcp:[HOST:]PORT"};
    }
  } else if (kind != "socketcand") {
    return Error{"expected socketcand[:HOST]:PORT, slcan-tcp:[HOST:]PORT, slcan:LINK or socketcan:IFACE, got \"" +
                 std::string(text) + "\""};
  }
  if (colon == std::string_view::npos) return spec;
  const Result<TcpEndpointSpec> tcp = parse_tcp_endpoint(text.substr(colon + 1));
  if (!tcp) return tcp.error_with_context(std::string(kind) + ": ");
  spec.tcp = *tcp;
  return spec;
}

}  // namespace motwin::host
