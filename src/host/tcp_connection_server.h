// The TCP connection handling every Motwin TCP server shares (TMCL over TCP, socketcand, SLCAN
// over TCP): a listening socket, accepting up to a limit of clients, one bounded output buffer
// per connection flushed as the socket takes it, back-pressure on input, closing with a logged
// reason and destruction deferred until no callback of the connection is on the stack.
// The protocol lives in a TcpSession the server creates for each connection.
#pragma once

#include <cstddef>
#include <cstdint>
#include <functional>
#include <map>
#include <memory>
#include <string>
#include <vector>

#include "host/eeprom_file.h"
#include "host/event_loop.h"
#include "host/socket_output.h"
#include "host/tcp_server.h"
#include "types/result.h"

namespace motwin::host {

class TcpConnection;

// One connection's protocol.
class TcpSession {
 public:
  static constexpr size_t kReadChunkBytes = 4096;

  virtual ~TcpSession() = default;
  // The connection is set up (the place for a greeting such as socketcand's `< hi >`).
  virtual void on_open() {}
  // Bytes the client sent (at most read_budget() of them).
  virtual void on_data(const uint8_t* bytes, size_t length) = 0;
  // How many bytes to read now; 0 stops reading until TcpConnection::update_events().
  virtual size_t read_budget() const { return kReadChunkBytes; }
  // The client shut down its sending side. Default: close the connection.
  virtual void on_input_closed();
  // Everything queued has been sent.
  virtual void on_output_drained() {}
  // The connection is closing, for whatever reason: the last call the session gets.
  virtual void on_close() {}

  TcpConnection& connection() const { return *connection_; }

 private:
  friend class TcpConnectionServer;
  TcpConnection* connection_ = nullptr;
};

class TcpConnectionServer;

class TcpConnection {
 public:
  TcpConnection(TcpConnectionServer& server, uint64_t id, int fd, std::string peer);
  TcpConnection(const TcpConnection&) = delete;
  TcpConnection& operator=(const TcpConnection&) = delete;
  ~TcpConnection();

  uint64_t id() const { return id_; }
  const std::string& peer() const { return peer_; }
  bool closing() const { return closing_; }
  size_t pending_output() const { return output_.pending(); }
  // When the loop last saw the socket without input (EventLoop::quiet_seen_us).
  uint64_t quiet_seen_us() const;
  TcpSession& session() { return *session_; }

  // Queues bytes and sends what the socket takes now. A client with more than the server's
  // output limit unread is closed (the server's overflow reason).
  void write(const void* bytes, size_t length);
  void write(const std::string& text) { write(text.data(), text.size()); }
  // While held, output is queued but not sent (socketcand's settle time after rawmode).
  void hold_output(bool held);
  void close(const std::string& reason);
  // Re-reads the session's read budget and the output state into the poll events.
  void update_events();

 private:
  friend class TcpConnectionServer;
  void on_events(short revents);
  void read_some();
  void flush();

  TcpConnectionServer& server_;
  uint64_t id_;
  int fd_;
  std::string peer_;
  std::unique_ptr<TcpSession> session_;
  SocketOutput output_;
  bool held_ = false;
  bool closing_ = false;
};

class TcpConnectionServer {
 public:
  struct Config {
    std::string kind;                // "TCP", "socketcand", "SLCAN": in log lines
    size_t max_clients = 64;
    size_t max_pending_output_bytes = 64 * 1024;
    std::string overflow_reason = "it does not read its replies";
  };
  using SessionFactory = std::function<std::unique_ptr<TcpSession>(TcpConnection& connection)>;

  // Fails with "cannot listen on 127.0.0.1:5000: Address already in use" and the like.
  static Result<std::unique_ptr<TcpConnectionServer>> open(EventLoop& loop, const TcpEndpointSpec& spec, Config config,
                                                           SessionFactory factory, LogSink log = log_to_stderr);

  TcpConnectionServer(const TcpConnectionServer&) = delete;
  TcpConnectionServer& operator=(const TcpConnectionServer&) = delete;
  // Closes every connection (their sessions get on_close()) and the listening socket.
  ~TcpConnectionServer();

  std::string local_address() const;
  uint16_t local_port() const;
  size_t client_count() const { return connections_.size(); }
  EventLoop& loop() { return loop_; }
  // nullptr once the connection is gone (for deferred work holding an id).
  TcpConnection* find(uint64_t id);
  // Deferred work holds a weak reference: it must not touch a server destroyed meanwhile.
  std::weak_ptr<bool> lifetime() const { return lifetime_; }

 private:
  friend class TcpConnection;
  TcpConnectionServer(EventLoop& loop, int listen_fd, Config config, SessionFactory factory, LogSink log);
  // What a full server does with the next client. A client is refused only when the server is
  // still full after two more looks: once the connections that closed in the same loop iteration
  // are removed, then once those it has just accepted were polled (a burst of clients that
  // connect and hang up at once, accepted together on a loaded machine, holds slots until then).
  enum class WhenFull {
    kLookAgainAfterThisIteration,
    kPauseUntilASlotFrees,  // stop accepting until a client goes, at most kRefuseAfterUs
    kRefuse,
  };
  void accept_clients(WhenFull when_full = WhenFull::kLookAgainAfterThisIteration);
  void pause_accepting_until_a_slot_frees();
  void resume_accepting();
  void remove(TcpConnection& connection, const std::string& reason);

  EventLoop& loop_;
  int listen_fd_;
  Config config_;
  SessionFactory factory_;
  LogSink log_;
  uint64_t next_connection_id_ = 1;
  bool paused_while_full_ = false;
  std::map<uint64_t, std::shared_ptr<TcpConnection>> connections_;
  std::shared_ptr<bool> lifetime_ = std::make_shared<bool>(true);
};

}  // namespace motwin::host
