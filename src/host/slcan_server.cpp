#include "host/slcan_server.h"

#include <cerrno>
#include <cstring>
#include <vector>

#include <netinet/in.h>
#include <netinet/tcp.h>
#include <sys/socket.h>
#include <unistd.h>

#include "host/can_endpoint.h"
#include "host/slcan_protocol.h"

namespace motwin::host {
namespace {

constexpr uint64_t kAcceptRetryUs = 100'000;
constexpr size_t kReadChunkBytes = 4096;

}  // namespace

class SlcanTcpServer::Connection final : public CanBusEndpoint {
 public:
  Connection(SlcanTcpServer& server, uint64_t id, int fd, std::string peer)
      : server_(server),
        id_(id),
        fd_(fd),
        peer_(std::move(peer)),
        session_([this](const can::CanFrame& frame) { outgoing_.push_back(frame); }) {}
  Connection(const Connection&) = delete;
  Connection& operator=(const Connection&) = delete;
  ~Connection() { ::close(fd_); }

  uint64_t id() const { return id_; }
  int fd() const { return fd_; }
  const std::string& peer() const { return peer_; }
  bool closing() const { return closing_; }
  void set_bus_id(CanBus::EndpointId id) { bus_id_ = id; }

  void mark_closing() {
    closing_ = true;
    if (bus_id_ != 0) server_.bus_.detach(bus_id_);
    bus_id_ = 0;
  }

  void on_events(short revents) {
    if ((revents & POLLOUT) != 0) flush();
    if (closing_) return;
    if ((revents & (POLLIN | POLLHUP | POLLERR)) != 0) read_some();
  }

  void on_frame(const can::CanFrame& frame, uint64_t) override {
    if (closing_ || !session_.open()) return;
    write(format_slcan_frame(frame));
  }

 private:
  void read_some() {
    char buffer[kReadChunkBytes];
    ssize_t n = 0;
    do {
      n = ::recv(fd_, buffer, sizeof(buffer), 0);
    } while (n < 0 && errno == EINTR);
    if (n < 0) {
      if (errno == EAGAIN || errno == EWOULDBLOCK) return;
      server_.close_connection(*this, std::strerror(errno));
      return;
    }
    if (n == 0) {
      server_.close_connection(*this, "closed by the client");
      return;
    }
    // The adapter acknowledges (`z\r`) before the bus carries the frame: nodes may answer at
    // once, and their answers must follow the acknowledgement, as on a real adapter.
    std::string reply;
    outgoing_.clear();
    session_.push(std::string_view(buffer, static_cast<size_t>(n)), reply);
    write(reply);
    const std::vector<can::CanFrame> frames = std::move(outgoing_);
    outgoing_.clear();
    for (const can::CanFrame& frame : frames) {
      if (closing_) return;
      server_.bus_.send(bus_id_, frame);
    }
  }

  void write(const std::string& text) {
    if (closing_ || text.empty()) return;
    if (output_.size() - output_sent_ + text.size() > kMaxPendingOutputBytes) {
      server_.close_connection(*this, "it does not read its frames");
      return;
    }
    output_ += text;
    flush();
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
    if (closing_) return;
    server_.loop_.set_events(fd_, static_cast<short>(POLLIN | (output_sent_ < output_.size() ? POLLOUT : 0)));
  }

  SlcanTcpServer& server_;
  uint64_t id_;
  int fd_;
  std::string peer_;
  CanBus::EndpointId bus_id_ = 0;
  SlcanSession session_;
  std::vector<can::CanFrame> outgoing_;
  std::string output_;
  size_t output_sent_ = 0;
  bool closing_ = false;
};

SlcanTcpServer::OpenResult SlcanTcpServer::open(EventLoop& loop, CanBus& bus, const TcpEndpointSpec& spec,
                                                LogSink log) {
  OpenResult result;
  const int fd = listen_tcp(spec, result.error);
  if (fd < 0) return result;
  result.server.reset(new SlcanTcpServer(loop, bus, fd, std::move(log)));
  return result;
}

SlcanTcpServer::SlcanTcpServer(EventLoop& loop, CanBus& bus, int listen_fd, LogSink log)
    : loop_(loop), bus_(bus), listen_fd_(listen_fd), log_(std::move(log)) {
  loop_.watch(listen_fd_, POLLIN, [this](short) { accept_clients(); });
}

SlcanTcpServer::~SlcanTcpServer() {
  for (auto& [id, connection] : connections_) {
    loop_.unwatch(connection->fd());
    connection->mark_closing();
  }
  connections_.clear();
  loop_.unwatch(listen_fd_);
  ::close(listen_fd_);
}

std::string SlcanTcpServer::local_address() const {
  sockaddr_storage address{};
  socklen_t length = sizeof(address);
  ::getsockname(listen_fd_, reinterpret_cast<sockaddr*>(&address), &length);
  return format_socket_address(address);
}

uint16_t SlcanTcpServer::local_port() const {
  sockaddr_storage address{};
  socklen_t length = sizeof(address);
  ::getsockname(listen_fd_, reinterpret_cast<sockaddr*>(&address), &length);
  if (address.ss_family == AF_INET) return ntohs(reinterpret_cast<const sockaddr_in&>(address).sin_port);
  return ntohs(reinterpret_cast<const sockaddr_in6&>(address).sin6_port);
}

void SlcanTcpServer::accept_clients() {
  for (;;) {
    sockaddr_storage address{};
    socklen_t length = sizeof(address);
    const int fd = ::accept4(listen_fd_, reinterpret_cast<sockaddr*>(&address), &length, SOCK_NONBLOCK | SOCK_CLOEXEC);
    if (fd < 0) {
      if (errno == EINTR || errno == ECONNABORTED || errno == EPROTO) continue;
      if (errno == EMFILE || errno == ENFILE || errno == ENOBUFS || errno == ENOMEM) {
        log_("motwin: cannot accept an SLCAN client: " + std::string(std::strerror(errno)) + "; retrying shortly");
        loop_.set_events(listen_fd_, 0);
        loop_.add_timer_after(kAcceptRetryUs, [this] { loop_.set_events(listen_fd_, POLLIN); });
      }
      return;
    }
    const std::string peer = format_socket_address(address);
    if (connections_.size() >= kMaxClients) {
      log_("motwin: refusing SLCAN client " + peer + ": already " + std::to_string(kMaxClients) + " clients");
      ::close(fd);
      continue;
    }
    const int on = 1;
    ::setsockopt(fd, IPPROTO_TCP, TCP_NODELAY, &on, sizeof(on));
    const uint64_t id = next_connection_id_++;
    auto connection = std::make_shared<Connection>(*this, id, fd, peer);
    connections_[id] = connection;
    Connection* raw = connection.get();
    loop_.watch(fd, POLLIN, [raw](short revents) { raw->on_events(revents); });
    raw->set_bus_id(bus_.attach(*raw));
    log_("motwin: SLCAN client " + peer + " connected");
  }
}

void SlcanTcpServer::close_connection(Connection& connection, const std::string& reason) {
  if (connection.closing()) return;
  connection.mark_closing();
  loop_.unwatch(connection.fd());
  log_("motwin: SLCAN client " + connection.peer() + " disconnected (" + reason + ")");
  const auto found = connections_.find(connection.id());
  if (found == connections_.end()) return;
  std::shared_ptr<Connection> keep_alive = std::move(found->second);
  connections_.erase(found);
  loop_.defer([keep_alive] {});
}

}  // namespace motwin::host
