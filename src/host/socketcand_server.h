// A socketcand-protocol TCP server on the virtual CAN bus: what python-can's
// `interface='socketcand'` (and through it python-canopen) connects to when there is no kernel CAN
// (docs/canopen.md "Reaching a virtual bus without kernel CAN"). Every client is a bus endpoint: it
// sees every frame of the bus except its own, from the moment it is in raw mode.
//
// Session, exactly as python-can 4.1.0 expects it (each server element in its own write; the
// protocol logic is host/socketcand_session.h, without sockets):
//   server `< hi >`; client `< open CHANNEL >`, server `< ok >`; client `< rawmode >`, server
//   `< ok >`; then client `< send ID LEN B0 .. >` and server ` < frame ID SEC.USEC HEX >`
//   (a space before each frame: socketcand_protocol.h).
// - python-can reads `< ok >` with one recv() and compares exactly, so the first frames after
//   rawmode are held back for kRawModeSettleUs (wall time) and then sent: they are delayed,
//   never lost.
// - Any channel name is accepted (there is one bus per server).
// - `< echo >` is answered with `< echo >`; `< bcmmode >` returns to BCM mode (no frames, `send`
//   still works); a bad `send` or an unknown command gets `< error TEXT >` and the session goes
//   on. Garbage outside `< >` and overlong elements are ignored.
// - Timestamps are simulated time (the bus clock), not wall time.
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

class SocketcandServer {
 public:
  static constexpr size_t kMaxClients = 64;
  // A client that lets this much output pile up unread is disconnected.
  static constexpr size_t kMaxPendingOutputBytes = 1024 * 1024;
  static constexpr uint64_t kRawModeSettleUs = 50'000;

  static Result<std::unique_ptr<SocketcandServer>> open(EventLoop& loop, CanBus& bus, const TcpEndpointSpec& spec,
                                                        LogSink log = log_to_stderr);

  SocketcandServer(const SocketcandServer&) = delete;
  SocketcandServer& operator=(const SocketcandServer&) = delete;
  ~SocketcandServer();

  std::string local_address() const;
  uint16_t local_port() const;
  size_t client_count() const;

 private:
  class Session;
  SocketcandServer() = default;

  std::unique_ptr<TcpConnectionServer> connections_;
};

}  // namespace motwin::host
