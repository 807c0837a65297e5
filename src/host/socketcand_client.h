// `--can socketcand-client:HOST:PORT:CHANNEL`: the virtual bus joins a CAN bus that lives elsewhere,
// as a client of a socketcand server (a socketcand daemon on a gateway beside real nodes, or another
// `motwin serve --can socketcand:...`). Frames of the local bus go to the remote one with `send`,
// the remote bus's frames come back in raw mode and reach every other local endpoint (nodes, local
// servers, the capture). docs/canopen.md "A bus across serves and machines" has the decisions:
//
// - Start: serve connects and completes the handshake before it prints its endpoint lines and
//   `ready`; a server that is not reachable, refuses, or answers with an error within
//   kJoinTimeoutUs is a start-up error (exit status 2).
// - Later loss (the server closed, the network failed): one line on the log, then reconnection
//   every kFirstRetryUs doubling up to kMaxRetryUs, and one line when the bus is joined again. The
//   local modules keep running meanwhile; their frames are dropped (counted), as on a cable pulled
//   out of a real node.
// - No echo filter: socketcand (a raw CAN socket without CAN_RAW_RECV_OWN_MSGS) and motwin's own
//   server never send a client its own frames; a filter would also drop a remote node's frame that
//   happens to equal one of ours.
// - Time: the remote bus paces itself; received frames are stamped by the local bus (its clock and,
//   with --can-bitrate, its bit timing); the server's timestamps are checked for form only.
// - RTR frames are not forwarded (socketcand's `send` has no RTR flag); counted as dropped.
#pragma once

#include <cstddef>
#include <cstdint>
#include <memory>
#include <string>
#include <string_view>
#include <vector>

#include <sys/socket.h>

#include "host/can_bus.h"
#include "host/eeprom_file.h"
#include "host/event_loop.h"
#include "host/socket_output.h"
#include "host/socketcand_protocol.h"
#include "host/tcp_server.h"
#include "types/can_frame.h"
#include "types/result.h"

namespace motwin::host {

// The client's half of the protocol, without sockets (the server's is SocketcandSession):
//   server `< hi >`        client `< open CHANNEL >`
//   server `< ok >`        client `< rawmode >`
//   server `< ok >`        joined: Io::handshake_done()
//   server `< frame ID SEC.USEC HEX >`   Io::frame_from_server()
// Before joining, anything else (`< error ... >` above all) fails the session with a reason;
// once joined, elements other than a valid frame are counted and ignored.
class SocketcandClientSession {
 public:
  enum class State : uint8_t { kAwaitHi, kAwaitOpenOk, kAwaitRawModeOk, kJoined, kFailed };

  class Io {
   public:
    virtual void write(const std::string& element) = 0;
    virtual void handshake_done() = 0;
    virtual void failed(const std::string& reason) = 0;
    virtual void frame_from_server(const can::CanFrame& frame) = 0;

   protected:
    ~Io() = default;
  };

  SocketcandClientSession(Io& io, std::string channel) : io_(io), channel_(std::move(channel)) {}

  // Bytes from the server, cut anywhere.
  void push(std::string_view bytes);
  // Writes the frame's `send` when joined and a data frame; false otherwise (nothing written).
  bool send(const can::CanFrame& frame);

  State state() const { return state_; }
  size_t ignored_elements() const { return ignored_; }

 private:
  void handle(const std::string& element);
  void fail(const std::string& reason);

  Io& io_;
  std::string channel_;
  State state_ = State::kAwaitHi;
  SocketcandElementParser parser_;
  std::vector<std::string> elements_;
  size_t ignored_ = 0;
};

struct SocketcandClientSpec {
  TcpEndpointSpec server;
  std::string channel;
};

class SocketcandClientEndpoint final : public CanBusEndpoint, private SocketcandClientSession::Io {
 public:
  static constexpr uint64_t kJoinTimeoutUs = 5'000'000;
  static constexpr uint64_t kFirstRetryUs = 100'000;
  static constexpr uint64_t kMaxRetryUs = 2'000'000;
  // A server that reads slower than the bus sends: beyond this much unsent output, frames are
  // dropped (counted) rather than queued, as a controller's transmit queue overflows.
  static constexpr size_t kMaxPendingOutputBytes = 256 * 1024;

  // Resolves HOST, connects (without blocking the loop: it runs `loop` meanwhile) and completes
  // the handshake, or fails with "cannot join the socketcand bus at HOST:PORT CHANNEL: reason".
  static Result<std::unique_ptr<SocketcandClientEndpoint>> open(EventLoop& loop, CanBus& bus, const SocketcandClientSpec& spec,
                                                        LogSink log = log_to_stderr);
  SocketcandClientEndpoint(const SocketcandClientEndpoint&) = delete;
  SocketcandClientEndpoint& operator=(const SocketcandClientEndpoint&) = delete;
  ~SocketcandClientEndpoint();

  // "127.0.0.1:29536 can0": the server's address and the channel.
  std::string where() const;
  bool joined() const {
    return fd_ >= 0 && session_ && session_->state() == SocketcandClientSession::State::kJoined;
  }
  uint64_t dropped_frames() const { return dropped_frames_; }
  uint64_t connections() const { return connections_; }

  // CanBusEndpoint: a local frame for the remote bus.
  void on_frame(const can::CanFrame& frame, uint64_t timestamp_us) override;

 private:
  SocketcandClientEndpoint(EventLoop& loop, CanBus& bus, sockaddr_storage address, socklen_t address_length,
                   std::string channel, LogSink log);

  void connect_now();
  void on_events(short revents);
  void read_some();
  void flush();
  // The connection ends: closed, then (after the start) a reconnection is scheduled.
  void lose(const std::string& reason);

  // SocketcandClientSession::Io.
  void write(const std::string& element) override;
  void handshake_done() override;
  void failed(const std::string& reason) override;
  void frame_from_server(const can::CanFrame& frame) override;

  EventLoop& loop_;
  CanBus& bus_;
  CanBus::EndpointId bus_id_ = 0;
  sockaddr_storage address_{};
  socklen_t address_length_ = 0;
  std::string channel_;
  LogSink log_;

  int fd_ = -1;
  bool connecting_ = false;
  bool starting_ = true;  // in open(): a failure is returned, not retried
  std::string start_failure_;
  std::unique_ptr<SocketcandClientSession> session_;
  SocketOutput output_;
  uint64_t retry_delay_us_ = kFirstRetryUs;
  EventLoop::TimerId retry_timer_ = 0;
  uint64_t dropped_frames_ = 0;
  uint64_t connections_ = 0;
};

}  // namespace motwin::host
