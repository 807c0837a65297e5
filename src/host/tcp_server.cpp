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

namespace motwin::host {
namespace {

// While the process is out of descriptors, accepting is retried this much later instead of
// spinning on a listening socket that stays readable.
constexpr uint64_t kAcceptRetryUs = 100'000;
constexpr size_t kReadChunkBytes = 4096;

std::optional<uint16_t> parse_port(std::string_view text) {
  unsigned value = 0;
  const auto result = std::from_chars(text.data(), text.data() + text.size(), value);
  if (text.empty() || result.ec != std::errc{} || result.ptr != text.data() + text.size() || value > 65535) {
    return std::nullopt;
  }
  return static_cast<uint16_t>(value);
}

}  // namespace

std::optional<TcpEndpointSpec> parse_tcp_endpoint(std::string_view text, std::string& error) {
  TcpEndpointSpec spec;
  std::string_view port_text = text;
  if (!text.empty() && text.front() == '[') {
    const size_t close = text.find("]:");
    if (close == std::string_view::npos) {
      error = "expected [IPV6]:PORT, got \"" + std::string(text) + "\"";
      return std::nullopt;
    }
    spec.host = std::string(text.substr(1, close - 1));
    port_text = text.substr(close + 2);
  } else if (const size_t colon = text.rfind(':'); colon != std::string_view::npos) {
    if (colon > 0) spec.host = std::string(text.substr(0, colon));
    port_text = text.substr(colon + 1);
  }
  const std::optional<uint16_t> port = parse_port(port_text);
  if (spec.host.empty() || !port) {
    error = "expected HOST:PORT with a port from 0 to 65535, got \"" + std::string(text) + "\"";
    return std::nullopt;
  }
  spec.port = *port;
  return spec;
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

// One client connection: a frame decoder on the way in, a bounded buffer on the way out.
class TmclTcpServer::Connection final : public ReplyChannel {
 public:
  Connection(TmclTcpServer& server, int fd, std::string peer) : server_(server), fd_(fd), peer_(std::move(peer)) {}
  Connection(const Connection&) = delete;
  Connection& operator=(const Connection&) = delete;
  ~Connection() { ::close(fd_); }

  int fd() const { return fd_; }
  const std::string& peer() const { return peer_; }
  tmcl::ChannelId channel() const { return channel_; }
  void set_channel(tmcl::ChannelId channel) { channel_ = channel; }
  bool closing() const { return closing_; }
  void mark_closing() { closing_ = true; }

  void on_events(short revents) {
    if ((revents & POLLOUT) != 0) flush();
    if (closing_) return;
    if ((revents & (POLLIN | POLLHUP | POLLERR)) == 0) return;
    if (!wants_input()) {
      // Not reading (queue full or input closed) yet the socket failed: nothing left to wait for.
      if ((revents & (POLLHUP | POLLERR)) != 0) server_.close_connection(*this, "connection lost");
      return;
    }
    read_some();
  }

  void send_reply(const uint8_t* bytes, size_t length) override {
    if (closing_) return;
    if (output_.size() - output_sent_ + length > kMaxPendingOutputBytes) {
      server_.close_connection(*this, "it does not read its replies");
      return;
    }
    output_.insert(output_.end(), bytes, bytes + length);
    flush();
  }

  void on_request_served() override {
    if (closing_) return;
    update_poll_events();
    close_if_finished();
  }

 private:
  bool wants_input() const { return !input_closed_ && server_.service_.has_room(channel_); }

  void read_some() {
    // Read no more than the service takes, so the rest waits in the kernel (back-pressure).
    uint8_t buffer[kReadChunkBytes];
    const size_t budget = std::min(sizeof(buffer), server_.service_.input_room(channel_));
    if (budget == 0) return;
    ssize_t n = 0;
    do {
      n = ::recv(fd_, buffer, budget, 0);
    } while (n < 0 && errno == EINTR);
    if (n < 0) {
      if (errno == EAGAIN || errno == EWOULDBLOCK) return;
      server_.close_connection(*this, std::strerror(errno));
      return;
    }
    if (n == 0) {
      // The client is done sending; replies to what it sent still go out before we close.
      input_closed_ = true;
      update_poll_events();
      close_if_finished();
      return;
    }
    // Frames or ASCII lines, whichever mode this connection is in; the echo of ASCII mode may
    // come back through send_reply() (and close us if we cannot take it).
    server_.service_.receive(channel_, buffer, static_cast<size_t>(n), monotonic_now_us());
    update_poll_events();
  }

  void flush() {
    while (output_sent_ < output_.size()) {
      const ssize_t n = ::send(fd_, output_.data() + output_sent_, output_.size() - output_sent_,
                               MSG_NOSIGNAL | MSG_DONTWAIT);
      if (n > 0) {
        output_sent_ += static_cast<size_t>(n);
      } else if (n < 0 && errno == EINTR) {
        continue;
      } else if (n < 0 && (errno == EAGAIN || errno == EWOULDBLOCK)) {
        break;
      } else {
        server_.close_connection(*this, n < 0 ? std::strerror(errno) : "send failed");
        return;
      }
    }
    if (output_sent_ == output_.size()) {
      output_.clear();
      output_sent_ = 0;
    }
    update_poll_events();
    close_if_finished();
  }

  void update_poll_events() {
    if (closing_) return;
    short events = 0;
    if (wants_input()) events |= POLLIN;
    if (output_sent_ < output_.size()) events |= POLLOUT;
    server_.loop_.set_events(fd_, events);
  }

  void close_if_finished() {
    if (closing_ || !input_closed_ || output_sent_ < output_.size()) return;
    if (server_.service_.queued_requests(channel_) != 0 || server_.service_.reply_held_for(channel_)) return;
    server_.close_connection(*this, "closed by the client");
  }

  TmclTcpServer& server_;
  int fd_;
  std::string peer_;
  tmcl::ChannelId channel_ = 0;
  std::vector<uint8_t> output_;
  size_t output_sent_ = 0;
  bool input_closed_ = false;
  bool closing_ = false;
};

TmclTcpServer::OpenResult TmclTcpServer::open(EventLoop& loop, TmclHostService& service, const TcpEndpointSpec& spec,
                                              LogSink log) {
  OpenResult result;
  const std::string where = (spec.host.find(':') != std::string::npos ? "[" + spec.host + "]" : spec.host) + ":" +
                            std::to_string(spec.port);
  addrinfo hints{};
  hints.ai_family = AF_UNSPEC;
  hints.ai_socktype = SOCK_STREAM;
  hints.ai_flags = AI_PASSIVE | AI_NUMERICSERV;
  addrinfo* addresses = nullptr;
  const std::string port_text = std::to_string(spec.port);
  if (const int status = ::getaddrinfo(spec.host.c_str(), port_text.c_str(), &hints, &addresses); status != 0) {
    result.error = "cannot listen on " + where + ": " + ::gai_strerror(status);
    return result;
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
  if (listen_fd < 0) {
    result.error = "cannot listen on " + where + ": " + std::strerror(last_errno);
    return result;
  }
  result.server.reset(new TmclTcpServer(loop, service, listen_fd, std::move(log)));
  return result;
}

TmclTcpServer::TmclTcpServer(EventLoop& loop, TmclHostService& service, int listen_fd, LogSink log)
    : loop_(loop), service_(service), listen_fd_(listen_fd), log_(std::move(log)) {
  loop_.watch(listen_fd_, POLLIN, [this](short) { accept_clients(); });
}

TmclTcpServer::~TmclTcpServer() {
  for (auto& [channel, connection] : connections_) {
    loop_.unwatch(connection->fd());
    service_.close_channel(channel);
    connection->mark_closing();
  }
  connections_.clear();
  loop_.unwatch(listen_fd_);
  ::close(listen_fd_);
}

std::string TmclTcpServer::local_address() const {
  sockaddr_storage address{};
  socklen_t length = sizeof(address);
  ::getsockname(listen_fd_, reinterpret_cast<sockaddr*>(&address), &length);
  return format_socket_address(address);
}

uint16_t TmclTcpServer::local_port() const {
  sockaddr_storage address{};
  socklen_t length = sizeof(address);
  ::getsockname(listen_fd_, reinterpret_cast<sockaddr*>(&address), &length);
  if (address.ss_family == AF_INET) return ntohs(reinterpret_cast<const sockaddr_in&>(address).sin_port);
  return ntohs(reinterpret_cast<const sockaddr_in6&>(address).sin6_port);
}

void TmclTcpServer::accept_clients(bool after_other_callbacks) {
  for (;;) {
    if (connections_.size() >= kMaxClients && !after_other_callbacks) {
      std::weak_ptr<bool> alive = lifetime_;
      loop_.defer([this, alive] {
        if (!alive.expired()) accept_clients(true);
      });
      return;
    }
    sockaddr_storage address{};
    socklen_t length = sizeof(address);
    const int fd = ::accept4(listen_fd_, reinterpret_cast<sockaddr*>(&address), &length, SOCK_NONBLOCK | SOCK_CLOEXEC);
    if (fd < 0) {
      if (errno == EINTR || errno == ECONNABORTED || errno == EPROTO) continue;
      if (errno == EMFILE || errno == ENFILE || errno == ENOBUFS || errno == ENOMEM) {
        log_("motwin: cannot accept a TCP client: " + std::string(std::strerror(errno)) + "; retrying shortly");
        loop_.set_events(listen_fd_, 0);
        loop_.add_timer_after(kAcceptRetryUs, [this] { loop_.set_events(listen_fd_, POLLIN); });
      }
      return;  // EAGAIN: all accepted
    }
    const std::string peer = format_socket_address(address);
    if (connections_.size() >= kMaxClients) {
      log_("motwin: refusing TCP client " + peer + ": already " + std::to_string(kMaxClients) + " clients");
      ::close(fd);
      continue;
    }
    const int on = 1;
    ::setsockopt(fd, IPPROTO_TCP, TCP_NODELAY, &on, sizeof(on));  // replies are 9 bytes: no Nagle delay
    auto connection = std::make_shared<Connection>(*this, fd, peer);
    const tmcl::ChannelId channel = service_.open_channel(*connection, kResyncGapUs);
    connection->set_channel(channel);
    connections_[channel] = connection;
    Connection* raw = connection.get();
    loop_.watch(fd, POLLIN, [raw](short revents) { raw->on_events(revents); });
    log_("motwin: TCP client " + peer + " connected");
  }
}

void TmclTcpServer::close_connection(Connection& connection, const std::string& reason) {
  if (connection.closing()) return;
  connection.mark_closing();
  loop_.unwatch(connection.fd());
  service_.close_channel(connection.channel());
  log_("motwin: TCP client " + connection.peer() + " disconnected (" + reason + ")");
  const auto found = connections_.find(connection.channel());
  if (found == connections_.end()) return;
  // Its member functions may be on the stack right now: destroy it after this dispatch.
  std::shared_ptr<Connection> keep_alive = std::move(found->second);
  connections_.erase(found);
  loop_.defer([keep_alive] {});
}

}  // namespace motwin::host
