#include "host/tcp_connection_server.h"

#include <algorithm>
#include <cerrno>
#include <cstring>

#include <netinet/in.h>
#include <netinet/tcp.h>
#include <sys/socket.h>
#include <unistd.h>


namespace motwin::host {
namespace {

// While the process is out of descriptors, accepting is retried this much later instead of
// spinning on a listening socket that stays readable.
constexpr uint64_t kAcceptRetryUs = 100'000;
// How long a full server keeps new clients waiting in the backlog for a slot before it refuses them.
constexpr uint64_t kRefuseAfterUs = 100'000;

}  // namespace

void TcpSession::on_input_closed() { connection().close("closed by the client"); }

TcpConnection::TcpConnection(TcpConnectionServer& server, uint64_t id, int fd, std::string peer)
    : server_(server), id_(id), fd_(fd), peer_(std::move(peer)) {}

TcpConnection::~TcpConnection() { ::close(fd_); }

uint64_t TcpConnection::quiet_seen_us() const { return server_.loop_.quiet_seen_us(fd_); }

void TcpConnection::on_events(short revents) {
  if ((revents & POLLOUT) != 0) flush();
  if (closing_) return;
  if ((revents & (POLLIN | POLLHUP | POLLERR)) == 0) return;
  if (session_->read_budget() == 0) {
    // Not reading (back-pressure or input closed) yet the socket failed: nothing left to wait for.
    if ((revents & (POLLHUP | POLLERR)) != 0) close("connection lost");
    return;
  }
  read_some();
}

void TcpConnection::read_some() {
  uint8_t buffer[TcpSession::kReadChunkBytes];
  const size_t budget = std::min(sizeof(buffer), session_->read_budget());
  if (budget == 0) return;
  ssize_t n = 0;
  do {
    n = ::recv(fd_, buffer, budget, 0);
  } while (n < 0 && errno == EINTR);
  if (n < 0) {
    if (errno == EAGAIN || errno == EWOULDBLOCK) return;
    close(std::strerror(errno));
    return;
  }
  if (n == 0) {
    session_->on_input_closed();
    return;
  }
  session_->on_data(buffer, static_cast<size_t>(n));
  update_events();
}

void TcpConnection::write(const void* bytes, size_t length) {
  if (closing_ || length == 0) return;
  if (pending_output() + length > server_.config_.max_pending_output_bytes) {
    close(server_.config_.overflow_reason);
    return;
  }
  output_.append(bytes, length);
  flush();
}

void TcpConnection::hold_output(bool held) {
  held_ = held;
  if (!held_) flush();
}

void TcpConnection::flush() {
  if (!held_) {
    std::string error;
    if (output_.send_to(fd_, &error) == SocketOutput::Sent::kFailed) {
      close(error);
      return;
    }
  }
  update_events();
  if (!closing_ && output_.empty()) session_->on_output_drained();
}

void TcpConnection::update_events() {
  if (closing_) return;
  short events = 0;
  if (session_->read_budget() > 0) events |= POLLIN;
  if (!held_ && !output_.empty()) events |= POLLOUT;
  server_.loop_.set_events(fd_, events);
}

void TcpConnection::close(const std::string& reason) {
  if (closing_) return;
  closing_ = true;
  server_.remove(*this, reason);
}

Result<std::unique_ptr<TcpConnectionServer>> TcpConnectionServer::open(EventLoop& loop, const TcpEndpointSpec& spec,
                                                                       Config config, SessionFactory factory,
                                                                       LogSink log) {
  const Result<int> fd = listen_tcp(spec);
  if (!fd) return Error{fd.error()};
  return std::unique_ptr<TcpConnectionServer>(
      new TcpConnectionServer(loop, *fd, std::move(config), std::move(factory), std::move(log)));
}

TcpConnectionServer::TcpConnectionServer(EventLoop& loop, int listen_fd, Config config, SessionFactory factory,
                                         LogSink log)
    : loop_(loop), listen_fd_(listen_fd), config_(std::move(config)), factory_(std::move(factory)), log_(std::move(log)) {
  loop_.watch(listen_fd_, POLLIN, [this](short) { accept_clients(); });
}

TcpConnectionServer::~TcpConnectionServer() {
  for (auto& [id, connection] : connections_) {
    connection->closing_ = true;
    loop_.unwatch(connection->fd_);
    connection->session_->on_close();
  }
  connections_.clear();
  loop_.unwatch(listen_fd_);
  ::close(listen_fd_);
}

std::string TcpConnectionServer::local_address() const {
  sockaddr_storage address{};
  socklen_t length = sizeof(address);
  ::getsockname(listen_fd_, reinterpret_cast<sockaddr*>(&address), &length);
  return format_socket_address(address);
}

uint16_t TcpConnectionServer::local_port() const {
  sockaddr_storage address{};
  socklen_t length = sizeof(address);
  ::getsockname(listen_fd_, reinterpret_cast<sockaddr*>(&address), &length);
  if (address.ss_family == AF_INET) return ntohs(reinterpret_cast<const sockaddr_in&>(address).sin_port);
  return ntohs(reinterpret_cast<const sockaddr_in6&>(address).sin6_port);
}

TcpConnection* TcpConnectionServer::find(uint64_t id) {
  const auto found = connections_.find(id);
  return found == connections_.end() ? nullptr : found->second.get();
}

void TcpConnectionServer::accept_clients(WhenFull when_full) {
  for (;;) {
    if (connections_.size() >= config_.max_clients && when_full == WhenFull::kLookAgainAfterThisIteration) {
      std::weak_ptr<bool> alive = lifetime_;
      loop_.defer([this, alive] {
        if (!alive.expired()) accept_clients(WhenFull::kPauseUntilASlotFrees);
      });
      return;
    }
    if (connections_.size() >= config_.max_clients && when_full == WhenFull::kPauseUntilASlotFrees) {
      pause_accepting_until_a_slot_frees();
      return;
    }
    sockaddr_storage address{};
    socklen_t length = sizeof(address);
    const int fd = ::accept4(listen_fd_, reinterpret_cast<sockaddr*>(&address), &length, SOCK_NONBLOCK | SOCK_CLOEXEC);
    if (fd < 0) {
      if (errno == EINTR || errno == ECONNABORTED || errno == EPROTO) continue;
      if (errno == EMFILE || errno == ENFILE || errno == ENOBUFS || errno == ENOMEM) {
        log_("motwin: cannot accept a " + config_.kind + " client: " + std::string(std::strerror(errno)) +
             "; retrying shortly");
        loop_.set_events(listen_fd_, 0);
        std::weak_ptr<bool> alive = lifetime_;
        loop_.add_timer_after(kAcceptRetryUs, [this, alive] {
          if (!alive.expired()) loop_.set_events(listen_fd_, POLLIN);
        });
      }
      return;  // EAGAIN: all accepted
    }
    const std::string peer = format_socket_address(address);
    if (connections_.size() >= config_.max_clients) {
      log_("motwin: refusing " + config_.kind + " client " + peer + ": already " + std::to_string(config_.max_clients) +
           " clients");
      ::close(fd);
      continue;
    }
    const int on = 1;
    ::setsockopt(fd, IPPROTO_TCP, TCP_NODELAY, &on, sizeof(on));  // small request/reply exchanges: no Nagle delay
    const uint64_t id = next_connection_id_++;
    auto connection = std::make_shared<TcpConnection>(*this, id, fd, peer);
    TcpConnection* raw = connection.get();
    connections_[id] = std::move(connection);
    raw->session_ = factory_(*raw);
    raw->session_->connection_ = raw;
    loop_.watch(fd, POLLIN, [raw](short revents) { raw->on_events(revents); });
    log_("motwin: " + config_.kind + " client " + peer + " connected");
    raw->session_->on_open();
    raw->update_events();
  }
}

void TcpConnectionServer::pause_accepting_until_a_slot_frees() {
  // New clients wait in the listen backlog meanwhile.
  paused_while_full_ = true;
  loop_.set_events(listen_fd_, 0);
  std::weak_ptr<bool> alive = lifetime_;
  loop_.add_timer_after(kRefuseAfterUs, [this, alive] {
    if (alive.expired() || !paused_while_full_) return;
    resume_accepting();
    accept_clients(WhenFull::kRefuse);  // still full: the waiting clients are refused
  });
}

void TcpConnectionServer::resume_accepting() {
  paused_while_full_ = false;
  loop_.set_events(listen_fd_, POLLIN);
}

void TcpConnectionServer::remove(TcpConnection& connection, const std::string& reason) {
  if (paused_while_full_) resume_accepting();  // the next poll takes a waiting client
  loop_.unwatch(connection.fd_);
  connection.session_->on_close();
  log_("motwin: " + config_.kind + " client " + connection.peer_ + " disconnected (" + reason + ")");
  const auto found = connections_.find(connection.id_);
  if (found == connections_.end()) return;
  // Its member functions may be on the stack right now: destroy it after this dispatch.
  std::shared_ptr<TcpConnection> keep_alive = std::move(found->second);
  connections_.erase(found);
  loop_.defer([keep_alive] {});
}

}  // namespace motwin::host
