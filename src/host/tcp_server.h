// TMCL over TCP, as PyTrinamic's socket interface speaks it: raw 9-byte frames back to back in
// both directions, no extra framing. Any number of clients (up to kMaxClients) share the module
// through TmclHostService; each has its own frame decoder, so a half frame or garbage from one
// client never affects another.
#pragma once

#include <cstddef>
#include <cstdint>
#include <memory>
#include <string>
#include <string_view>

#include <sys/socket.h>

#include "host/eeprom_file.h"
#include "host/event_loop.h"
#include "host/tmcl_host_service.h"
#include "types/result.h"

namespace motwin::host {

inline constexpr std::string_view kDefaultTcpHost = "127.0.0.1";
inline constexpr uint16_t kDefaultTcpPort = 5000;

struct TcpEndpointSpec {
  std::string host = std::string(kDefaultTcpHost);
  uint16_t port = kDefaultTcpPort;  // 0: the system picks a free port
};

// "HOST:PORT", ":PORT", "PORT" (host 127.0.0.1) or "[IPv6]:PORT".
Result<TcpEndpointSpec> parse_tcp_endpoint(std::string_view text);

class TcpConnectionServer;

class TmclTcpServer {
 public:
  // TCP may deliver one frame in two segments; a serial-style 5 ms gap could then split a
  // frame a client sent in one piece. 100 ms keeps "pause to resync" working for a client
  // that lost sync while no real network stalls a frame that long (docs/host-runtime.md).
  static constexpr uint32_t kResyncGapUs = 100'000;
  static constexpr size_t kMaxClients = 64;
  // A client that lets this much reply data pile up is not reading: it is disconnected.
  static constexpr size_t kMaxPendingOutputBytes = 64 * 1024;

  // Fails with "cannot listen on 127.0.0.1:5000: Address already in use" and the like. `echo`:
  // each client's bytes go back to it as they arrive (an RS485 transceiver, LineEcho).
  static Result<std::unique_ptr<TmclTcpServer>> open(EventLoop& loop, TmclHostService& service,
                                                     const TcpEndpointSpec& spec, LogSink log = log_to_stderr,
                                                     LineEcho echo = LineEcho::kNone);

  TmclTcpServer(const TmclTcpServer&) = delete;
  TmclTcpServer& operator=(const TmclTcpServer&) = delete;
  // Closes every connection and the listening socket.
  ~TmclTcpServer();

  std::string local_address() const;  // "127.0.0.1:40321", "[::1]:5000"
  uint16_t local_port() const;
  size_t client_count() const;
  LineEcho echo() const { return echo_; }

 private:
  class Session;
  TmclTcpServer() = default;

  std::unique_ptr<TcpConnectionServer> connections_;
  LineEcho echo_ = LineEcho::kNone;
};

// The descriptor of a non-blocking listening TCP socket (SO_REUSEADDR, backlog 16), or
// "cannot listen on HOST:PORT: reason".
Result<int> listen_tcp(const TcpEndpointSpec& spec);

// "127.0.0.1:5000" or "[::1]:5000" for an IPv4 or IPv6 socket address.
std::string format_socket_address(const sockaddr_storage& address);

}  // namespace motwin::host
