// A bare TCP server on 127.0.0.1 (a free port) that answers every 9-byte frame with what a
// function returns, in its own thread. The TCP round-trip benchmark uses it as the echo
// baseline (9 bytes in, 9 bytes out); client tests use it to script replies (bad checksum,
// partial reply, silence). One connection is served at a time; the next waits in the backlog.
#pragma once

#include <cstddef>
#include <cstdint>
#include <functional>
#include <memory>
#include <string>
#include <thread>

#include "core/tmcl/serial_link.h"
#include "tools/unique_fd.h"
#include "types/result.h"

namespace motwin::tools {

class LoopbackFrameServer {
 public:
  // Writes the answer to `request` into `reply` and returns how many of its bytes to send
  // (0: no answer). Called on the server thread.
  using Responder = std::function<size_t(const tmcl::Frame& request, tmcl::Frame& reply)>;

  static Result<std::unique_ptr<LoopbackFrameServer>> start(Responder responder);

  LoopbackFrameServer(const LoopbackFrameServer&) = delete;
  LoopbackFrameServer& operator=(const LoopbackFrameServer&) = delete;
  ~LoopbackFrameServer();  // stops the thread and closes every socket

  uint16_t port() const { return port_; }
  std::string address() const;  // "127.0.0.1:PORT"

 private:
  LoopbackFrameServer(UniqueFd listener, uint16_t port, UniqueFd stop_read, UniqueFd stop_write, Responder responder);
  void run();
  // Serves one connection until it closes; false when asked to stop.
  bool serve_connection(int connection_fd);

  UniqueFd listener_;
  uint16_t port_;
  UniqueFd stop_read_;   // readable once the destructor asks the thread to stop
  UniqueFd stop_write_;
  Responder responder_;
  std::thread thread_;
};

}  // namespace motwin::tools
