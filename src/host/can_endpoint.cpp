#include "host/can_endpoint.h"

namespace motwin::host {

std::optional<CanEndpointSpec> parse_can_endpoint(std::string_view text, std::string& error) {
  CanEndpointSpec spec;
  const size_t colon = text.find(':');
  const std::string_view kind = text.substr(0, colon);
  if (kind == "slcan" || kind == "socketcan") {
    spec.transport = kind == "slcan" ? CanTransport::kSlcanPty : CanTransport::kSocketcan;
    spec.device = colon == std::string_view::npos ? std::string() : std::string(text.substr(colon + 1));
    if (spec.device.empty()) {
      error = kind == "slcan" ? "slcan needs a link path: slcan:/tmp/motwin-slcan" : "socketcan needs an interface: socketcan:vcan0";
      return std::nullopt;
    }
    return spec;
  }
  if (kind == "slcan-tcp") {
    spec.transport = CanTransport::kSlcanTcp;
    if (colon == std::string_view::npos) {
      error = "slcan-tcp needs a port: slcan-tcp:[HOST:]PORT";
      return std::nullopt;
    }
  } else if (kind != "socketcand") {
    error = "expected socketcand[:HOST]:PORT, slcan-tcp:[HOST:]PORT, slcan:LINK or socketcan:IFACE, got \"" +
            std::string(text) + "\"";
    return std::nullopt;
  }
  if (colon == std::string_view::npos) return spec;
  std::string tcp_error;
  const std::optional<TcpEndpointSpec> tcp = parse_tcp_endpoint(text.substr(colon + 1), tcp_error);
  if (!tcp) {
    error = std::string(kind) + ": " + tcp_error;
    return std::nullopt;
  }
  spec.tcp = *tcp;
  return spec;
}

}  // namespace motwin::host
