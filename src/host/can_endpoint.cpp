#include "host/can_endpoint.h"

#include <cerrno>
#include <cstring>

#include <netdb.h>
#include <sys/socket.h>
#include <unistd.h>

namespace motwin::host {

std::optional<CanEndpointSpec> parse_can_endpoint(std::string_view text, std::string& error) {
  CanEndpointSpec spec;
  const size_t colon = text.find(':');
  const std::string_view kind = text.substr(0, colon);
  if (kind == "slcan-tcp") {
    spec.transport = CanTransport::kSlcanTcp;
    if (colon == std::string_view::npos) {
      error = "slcan-tcp needs a port: slcan-tcp:[HOST:]PORT";
      return std::nullopt;
    }
  } else if (kind != "socketcand") {
    error = "expected socketcand[:HOST]:PORT or slcan-tcp:[HOST:]PORT (SLCAN on a pseudo-terminal and SocketCAN "
            "are not implemented yet), got \"" + std::string(text) + "\"";
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

int listen_tcp(const TcpEndpointSpec& spec, std::string& error) {
  const std::string where = (spec.host.find(':') != std::string::npos ? "[" + spec.host + "]" : spec.host) + ":" +
                            std::to_string(spec.port);
  addrinfo hints{};
  hints.ai_family = AF_UNSPEC;
  hints.ai_socktype = SOCK_STREAM;
  hints.ai_flags = AI_PASSIVE | AI_NUMERICSERV;
  addrinfo* addresses = nullptr;
  const std::string port_text = std::to_string(spec.port);
  if (const int status = ::getaddrinfo(spec.host.c_str(), port_text.c_str(), &hints, &addresses); status != 0) {
    error = "cannot listen on " + where + ": " + ::gai_strerror(status);
    return -1;
  }
  int listen_fd = -1;
  int last_errno = 0;
  for (const addrinfo* address = addresses; address != nullptr && listen_fd < 0; address = address->ai_next) {
    const int fd = ::socket(address->ai_family, address->ai_socktype | SOCK_NONBLOCK | SOCK_CLOEXEC, address->ai_protocol);
    if (fd < 0) {
      last_errno = errno;
      continue;
    }
    const int on = 1;
    ::setsockopt(fd, SOL_SOCKET, SO_REUSEADDR, &on, sizeof(on));
    if (::bind(fd, address->ai_addr, address->ai_addrlen) != 0 || ::listen(fd, 16) != 0) {
      last_errno = errno;
      ::close(fd);
      continue;
    }
    listen_fd = fd;
  }
  ::freeaddrinfo(addresses);
  if (listen_fd < 0) error = "cannot listen on " + where + ": " + std::strerror(last_errno);
  return listen_fd;
}

}  // namespace motwin::host
