#include "tools/loopback_frame_server.h"

#include <arpa/inet.h>
#include <fcntl.h>
#include <netinet/in.h>
#include <netinet/tcp.h>
#include <poll.h>
#include <sys/socket.h>
#include <unistd.h>

#include <cerrno>
#include <cstring>

#include <fmt/format.h>

#include "tools/fd_io.h"

namespace motwin::tools {

Result<std::unique_ptr<LoopbackFrameServer>> LoopbackFrameServer::start(Responder responder) {
  UniqueFd listener(::socket(AF_INET, SOCK_STREAM | SOCK_CLOEXEC, 0));
  if (!listener.valid()) return Error{fmt::format("socket: {}", std::strerror(errno))};
  sockaddr_in address{};
  address.sin_family = AF_INET;
  address.sin_addr.s_addr = htonl(INADDR_LOOPBACK);
  address.sin_port = 0;  // the kernel picks a free port
  if (::bind(listener.get(), reinterpret_cast<const sockaddr*>(&address), sizeof address) != 0 ||
      ::listen(listener.get(), 4) != 0) {
    return Error{fmt::format("cannot listen on 127.0.0.1: {}", std::strerror(errno))};
  }
  socklen_t length = sizeof address;
  if (::getsockname(listener.get(), reinterpret_cast<sockaddr*>(&address), &length) != 0) {
    return Error{fmt::format("getsockname: {}", std::strerror(errno))};
  }
  int stop_pipe[2];
  if (::pipe2(stop_pipe, O_CLOEXEC) != 0) return Error{fmt::format("pipe: {}", std::strerror(errno))};
  return std::unique_ptr<LoopbackFrameServer>(new LoopbackFrameServer(std::move(listener), ntohs(address.sin_port),
                                                                      UniqueFd(stop_pipe[0]), UniqueFd(stop_pipe[1]),
                                                                      std::move(responder)));
}

LoopbackFrameServer::LoopbackFrameServer(UniqueFd listener, uint16_t port, UniqueFd stop_read, UniqueFd stop_write,
                                         Responder responder)
    : listener_(std::move(listener)),
      port_(port),
      stop_read_(std::move(stop_read)),
      stop_write_(std::move(stop_write)),
      responder_(std::move(responder)),
      thread_([this] { run(); }) {}

LoopbackFrameServer::~LoopbackFrameServer() {
  const uint8_t stop = 1;
  write_all(stop_write_.get(), &stop, 1, false);
  thread_.join();
}

std::string LoopbackFrameServer::address() const { return fmt::format("127.0.0.1:{}", port_); }

void LoopbackFrameServer::run() {
  for (;;) {
    pollfd entries[2] = {{stop_read_.get(), POLLIN, 0}, {listener_.get(), POLLIN, 0}};
    if (::poll(entries, 2, -1) < 0) {
      if (errno == EINTR) continue;
      return;
    }
    if (entries[0].revents != 0) return;
    if (entries[1].revents == 0) continue;
    UniqueFd connection(::accept4(listener_.get(), nullptr, nullptr, SOCK_CLOEXEC));
    if (!connection.valid()) continue;
    const int enable = 1;
    ::setsockopt(connection.get(), IPPROTO_TCP, TCP_NODELAY, &enable, sizeof enable);
    if (!serve_connection(connection.get())) return;
  }
}

bool LoopbackFrameServer::serve_connection(int connection_fd) {
  tmcl::Frame request{};
  size_t fill = 0;
  for (;;) {
    pollfd entries[2] = {{stop_read_.get(), POLLIN, 0}, {connection_fd, POLLIN, 0}};
    if (::poll(entries, 2, -1) < 0) {
      if (errno == EINTR) continue;
      return false;
    }
    if (entries[0].revents != 0) return false;
    if (entries[1].revents == 0) continue;
    const ssize_t n = ::read(connection_fd, request.data() + fill, tmcl::kFrameLength - fill);
    if (n < 0 && errno == EINTR) continue;
    if (n <= 0) return true;  // the client went away: wait for the next one
    fill += static_cast<size_t>(n);
    if (fill < tmcl::kFrameLength) continue;
    fill = 0;
    tmcl::Frame reply{};
    const size_t reply_length = responder_(request, reply);
    if (reply_length > 0 && write_all(connection_fd, reply.data(), reply_length, true).status != IoStatus::kOk) {
      return true;
    }
  }
}

}  // namespace motwin::tools
