// SLCAN over TCP on the virtual CAN bus: each TCP client is a Lawicel adapter of its own
// (host/slcan_protocol.h), as python-can reaches it with `interface='slcan',
// channel='socket://127.0.0.1:PORT'` (a pyserial URL). A client sees the bus's frames while its
// channel is open (`O`), never its own.
#pragma once

#include <cstddef>
#include <cstdint>
#include <memory>
#include <string>

#include "host/can_bus.h"
#include "host/eeprom_file.h"
#include "host/event_loop.h"
#include "host/tcp_server.h"
#include "types/result.h"

namespace motwin::host {

class TcpConnectionServer;

class SlcanTcpServer {
 public:
  static constexpr size_t kMaxClients = 64;
  static constexpr size_t kMaxPendingOutputBytes = 1024 * 1024;

  static Result<std::unique_ptr<SlcanTcpServer>> open(EventLoop& loop, CanBus& bus, const TcpEndpointSpec& spec,
                                                      LogSink log = log_to_stderr);

  SlcanTcpServer(const SlcanTcpServer&) = delete;
  SlcanTcpServer& operator=(const SlcanTcpServer&) = delete;
  ~SlcanTcpServer();

  std::string local_address() const;
  uint16_t local_port() const;
  size_t client_count() const;

 private:
  class Session;
  SlcanTcpServer() = default;

  std::unique_ptr<TcpConnectionServer> connections_;
};

}  // namespace motwin::host
