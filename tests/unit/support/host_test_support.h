// Helpers for the host runtime tests: TMCL frames, a plain blocking TCP client on 127.0.0.1 and
// a loop pump with a deadline (the deadline only bounds a failing test; no test asserts on it).
#pragma once

#include <gtest/gtest.h>

#include <arpa/inet.h>
#include <netinet/in.h>
#include <netinet/tcp.h>
#include <sys/socket.h>
#include <unistd.h>

#include <chrono>
#include <cstdint>
#include <cstring>
#include <filesystem>
#include <functional>
#include <memory>
#include <optional>
#include <string>
#include <vector>

#include "core/tmcl/serial_link.h"
#include "host/event_loop.h"
#include "host/host_runtime.h"
#include "host/module_registry.h"

namespace motwin::testing {

using Bytes = std::vector<uint8_t>;

inline Bytes request(uint8_t command, uint8_t type, uint8_t motor, int32_t value, uint8_t address = 1) {
  const tmcl::Frame frame = tmcl::encode_request(address, tmcl::Instruction{command, type, motor, value});
  return Bytes(frame.begin(), frame.end());
}

inline Bytes reply(uint8_t status, uint8_t command, int32_t value) {
  const tmcl::Frame frame = tmcl::encode_reply(2, 1, tmcl::Reply{status, command, value});
  return Bytes(frame.begin(), frame.end());
}

inline Bytes slice(const Bytes& bytes, size_t begin, size_t end) {
  return Bytes(bytes.begin() + static_cast<std::ptrdiff_t>(begin), bytes.begin() + static_cast<std::ptrdiff_t>(end));
}

// Runs `step` until `done` or a generous wall-clock deadline; returns whether `done` held.
// `deadline` is a liveness bound (what must happen at all), generous for the ASan build on a
// loaded machine; a test that expects nothing to happen pumps a fixed number of steps instead.
inline bool pump_until(const std::function<void()>& step, const std::function<bool()>& done,
                       std::chrono::milliseconds deadline = std::chrono::milliseconds(30000)) {
  const auto end = std::chrono::steady_clock::now() + deadline;
  while (!done()) {
    if (std::chrono::steady_clock::now() > end) return false;
    step();
  }
  return true;
}

class TcpTestClient {
 public:
  explicit TcpTestClient(uint16_t port) {
    fd_ = ::socket(AF_INET, SOCK_STREAM | SOCK_CLOEXEC, 0);
    sockaddr_in address{};
    address.sin_family = AF_INET;
    address.sin_port = htons(port);
    address.sin_addr.s_addr = htonl(INADDR_LOOPBACK);
    // The listening socket's backlog completes the handshake without the loop running.
    connected_ = ::connect(fd_, reinterpret_cast<sockaddr*>(&address), sizeof(address)) == 0;
    const int on = 1;
    ::setsockopt(fd_, IPPROTO_TCP, TCP_NODELAY, &on, sizeof(on));
  }
  TcpTestClient(const TcpTestClient&) = delete;
  TcpTestClient& operator=(const TcpTestClient&) = delete;
  ~TcpTestClient() { close(); }

  bool connected() const { return connected_; }
  void send(const Bytes& bytes) const { ASSERT_EQ(::send(fd_, bytes.data(), bytes.size(), MSG_NOSIGNAL), static_cast<ssize_t>(bytes.size())); }
  void close() {
    if (fd_ >= 0) ::close(fd_);
    fd_ = -1;
  }
  // Whatever has arrived, without waiting.
  Bytes receive_available() {
    uint8_t buffer[4096];
    for (;;) {
      const ssize_t n = ::recv(fd_, buffer, sizeof(buffer), MSG_DONTWAIT);
      if (n <= 0) break;
      received_.insert(received_.end(), buffer, buffer + n);
    }
    Bytes out;
    out.swap(received_);
    return out;
  }
  // Collects into an internal buffer; true once `count` bytes are there.
  bool has(size_t count) {
    uint8_t buffer[4096];
    const ssize_t n = ::recv(fd_, buffer, sizeof(buffer), MSG_DONTWAIT);
    if (n > 0) received_.insert(received_.end(), buffer, buffer + n);
    return received_.size() >= count;
  }
  Bytes take(size_t count) {
    Bytes out(received_.begin(), received_.begin() + static_cast<std::ptrdiff_t>(std::min(count, received_.size())));
    received_.erase(received_.begin(), received_.begin() + static_cast<std::ptrdiff_t>(out.size()));
    return out;
  }
  // True when the server closed the connection.
  bool closed_by_peer() {
    uint8_t byte = 0;
    const ssize_t n = ::recv(fd_, &byte, 1, MSG_DONTWAIT | MSG_PEEK);
    return n == 0 || (n < 0 && errno != EAGAIN && errno != EWOULDBLOCK);
  }

 private:
  int fd_ = -1;
  bool connected_ = false;
  Bytes received_;
};

// Both ends of a pipe, closed at the end of the test.
struct Pipe {
  int read_fd = -1;
  int write_fd = -1;
  Pipe() {
    int fds[2];
    EXPECT_EQ(::pipe(fds), 0);
    read_fd = fds[0];
    write_fd = fds[1];
  }
  ~Pipe() {
    ::close(read_fd);
    ::close(write_fd);
  }
};

// A fresh directory under the temporary directory, removed afterwards.
class ScratchDirectory {
 public:
  ScratchDirectory() {
    std::string pattern = (std::filesystem::temp_directory_path() / "motwin-unit-XXXXXX").string();
    if (::mkdtemp(pattern.data()) != nullptr) path_ = pattern;
  }
  ScratchDirectory(const ScratchDirectory&) = delete;
  ScratchDirectory& operator=(const ScratchDirectory&) = delete;
  ~ScratchDirectory() {
    std::error_code ignored;
    std::filesystem::permissions(path_, std::filesystem::perms::owner_all, std::filesystem::perm_options::add, ignored);
    std::filesystem::remove_all(path_, ignored);
  }
  const std::filesystem::path& path() const { return path_; }

 private:
  std::filesystem::path path_;
};

// A TMCM-1636 with its image in memory, on a host runtime (real-time pacing unless told).
struct ModuleOnRuntime {
  std::unique_ptr<host::VirtualModule> module;
  std::unique_ptr<host::HostRuntime> runtime;

  explicit ModuleOnRuntime(host::Pacing pacing = host::Pacing::realtime(), host::ModuleOptions options = {}) {
    options.log = [](const std::string&) {};
    host::MakeModuleResult made = host::make_module("tmcm-1636", options);
    EXPECT_TRUE(made) << made.error();
    module = std::move(*made);
    runtime = std::make_unique<host::HostRuntime>(*module, pacing);
    runtime->start();
  }
  // One iteration that never sleeps longer than 5 ms.
  void step() { runtime->step(5000); }
};

}  // namespace motwin::testing
