#include "host/tcp_server.h"

#include <cerrno>
#include <charconv>
#include <cstring>
#include <vector>

#include <arpa/inet.h>
#include <fcntl.h>
#include <netdb.h>
#include <netinet/in.h>
#include <netinet/tcp.h>
#include <unistd.h>

#include "core/tmcl/serial_link.h"
#include "host/tcp_connection_server.h"

namespace motwin::host {
namespace {

std::optional<uint16_t> parse_port(std::string_view text) {
  unsigned value = 0;
  const auto result = std::from_chars(text.data(), text.data() + text.size(), value);
  if (text.empty() || result.ec != std::errc{} || result.ptr != text.data() + text.size() || value > 65535) {
    return std::nullopt;
  }
  return static_cast<uint16_t>(value);
}

}  // namespace

Result<TcpEndpointSpec> parse_tcp_endpoint(std::string_view text) {
  TcpEndpointSpec spec;
  std::string_view port_text = text;
  if (!text.empty() && text.front() == '[') {
    const size_t close = text.find("]:");
    if (close == std::string_view::npos) {
      return Error{"expected [IPV6]:PORT, got \"" + std::string(text) + "\""};
    }
    spec.host = std::string(text.substr(1, close - 1));
    port_text = text.substr(close + 2);
  } else if (const size_t colon = text.rfind(':'); colon != std::string_view::npos) {
    if (colon > 0) spec.host = std::string(text.substr(0, colon));
    port_text = text.substr(colon + 1);
  }
  const std::optional<uint16_t> port = parse_port(port_text);
  if (spec.host.empty() || !port) {
    return Error{"expected HOST:PORT with a port from 0 to 65535, got \"" + std::string(text) + "\""};
  }
  spec.port = *port;
  return spec;
}

Result<int> listen_tcp(const TcpEndpointSpec& spec) {
  const std::string where = (spec.host.find(':') != std::string::npos ? "[" + spec.host + "]" : spec.host) + ":" +
                            std::to_string(spec.port);
  addrinfo hints{};
  hints.ai_family = AF_UNSPEC;
  hints.ai_socktype = SOCK_STREAM;
  hints.ai_flags = AI_PASSIVE | AI_NUMERICSERV;
  addrinfo* addresses = nullptr;
  const std::string port_text = std::to_string(spec.port);
  if (const int status = ::getaddrinfo(spec.host.c_str(), port_text.c_str(), &hints, &addresses); status != 0) {
    return Error{"cannot listen on " + where + ": " + ::gai_strerror(status)};
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
  if (listen_fd < 0) return Error{"cannot listen on " + where + ": " + std::strerror(last_errno)};
  return listen_fd;
}

std::string format_socket_address(const sockaddr_storage& address) {
  char host[INET6_ADDRSTRLEN] = "?";
  uint16_t port = 0;
  if (address.ss_family == AF_INET) {
    const auto& ipv4 = reinterpret_cast<const sockaddr_in&>(address);
    ::inet_ntop(AF_INET, &ipv4.sin_addr, host, sizeof(host));
    port = ntohs(ipv4.sin_port);
    return std::string(host) + ":" + std::to_string(port);
  }
  if (address.ss_family == AF_INET6) {
    const auto& ipv6 = reinterpret_cast<const sockaddr_in6&>(address);
    ::inet_ntop(AF_INET6, &ipv6.sin6_addr, host, sizeof(host));
    port = ntohs(ipv6.sin6_port);
  }
  return "[" + std::string(host) + "]:" + std::to_string(port);
}

// One client: a TMCL channel of the service (frame decoder or ASCII lines) on the way in, the
// connection's bounded buffer on the way out.
class TmclTcpServer::Session final : public TcpSession, public ReplyChannel {
 public:
  Session(TmclHostService& service, LineEcho echo) : service_(service), echo_(echo) {}

  void on_open() override { channel_ = service_.open_channel(*this, kResyncGapUs, ChannelTraffic::kHost, echo_); }

  // Read no more than the service takes, so the rest waits in the kernel (back-pressure).
  size_t read_budget() const override { return input_closed_ ? 0 : service_.input_room(channel_); }

  void on_data(const uint8_t* bytes, size_t length) override {
    // Frames or ASCII lines, whichever mode this connection is in; the echo of ASCII mode may
    // come back through send_reply() (and close us if we cannot take it).
    service_.receive(channel_, bytes, length, monotonic_now_us(), connection().quiet_seen_us());
  }

  void on_input_closed() override {
    // The client is done sending; replies to what it sent still go out before we close.
    input_closed_ = true;
    connection().update_events();
    close_if_finished();
  }

  void on_output_drained() override { close_if_finished(); }
  void on_close() override { service_.close_channel(channel_); }

  // ReplyChannel.
  void send_reply(const uint8_t* bytes, size_t length) override { connection().write(bytes, length); }
  void on_request_served() override {
    if (connection().closing()) return;
    connection().update_events();
    close_if_finished();
  }

 private:
  void close_if_finished() {
    if (connection().closing() || !input_closed_ || connection().pending_output() > 0) return;
    if (service_.queued_requests(channel_) != 0 || service_.reply_held_for(channel_)) return;
    connection().close("closed by the client");
  }

  TmclHostService& service_;
  LineEcho echo_;
  tmcl::ChannelId channel_ = 0;
  bool input_closed_ = false;
};

Result<std::unique_ptr<TmclTcpServer>> TmclTcpServer::open(EventLoop& loop, TmclHostService& service,
                                                           const TcpEndpointSpec& spec, LogSink log, LineEcho echo) {
  TcpConnectionServer::Config config{"TCP", kMaxClients, kMaxPendingOutputBytes, "it does not read its replies"};
  Result<std::unique_ptr<TcpConnectionServer>> connections = TcpConnectionServer::open(
      loop, spec, std::move(config),
      [&service, echo](TcpConnection&) -> std::unique_ptr<TcpSession> {
        return std::make_unique<Session>(service, echo);
      },
      std::move(log));
  if (!connections) return Error{connections.error()};
  std::unique_ptr<TmclTcpServer> server(new TmclTcpServer());
  server->connections_ = std::move(*connections);
  server->echo_ = echo;
  return server;
}

TmclTcpServer::~TmclTcpServer() = default;

std::string TmclTcpServer::local_address() const { return connections_->local_address(); }
uint16_t TmclTcpServer::local_port() const { return connections_->local_port(); }
size_t TmclTcpServer::client_count() const { return connections_->client_count(); }

}  // namespace motwin::host
