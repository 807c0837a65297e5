// One socketcand client's session (host/socketcand_server.h describes the protocol as python-can
// 4.1.0 speaks it), without sockets: the client's bytes go in through push(), the server's
// elements and the frames for the bus go out through Io. SocketcandServer runs one per TCP
// connection; the fuzz target socketcand_session drives it directly.
//
//   start()               `< hi >`
//   < open CHANNEL >      `< ok >`, BCM mode (any channel name: one bus per server); before it,
//                         every element is answered ` < error expected open >`
//   < rawmode >           `< ok >`, raw mode: bus frames reach the client (Io::raw_mode_entered()
//                         when it was not in raw mode yet: the server holds its output back)
//   < bcmmode >           ` < ok >`, BCM mode: no frames, `send` still works
//   < echo >              ` < echo >`
//   < send ID LEN B.. >   the frame to the bus, no answer; a bad one ` < error TEXT >`
//   anything else         ` < error unknown command >`
// Garbage outside `< >` and overlong elements are ignored (SocketcandElementParser). Once
// Io::closing() is true nothing more is handled or written.
#pragma once

#include <cstdint>
#include <string>
#include <string_view>
#include <vector>

#include "host/socketcand_protocol.h"
#include "types/can_frame.h"

namespace motwin::host {

class SocketcandSession {
 public:
  enum class Mode : uint8_t { kAwaitOpen, kBcm, kRaw };

  // The connection and the bus, as the session sees them.
  class Io {
   public:
    // One server element (each in its own write, as python-can expects).
    virtual void write(const std::string& element) = 0;
    // A valid `send` after `open`.
    virtual void send_to_bus(const can::CanFrame& frame) = 0;
    // The session has just entered raw mode.
    virtual void raw_mode_entered() = 0;
    // The connection is going away: the session handles and writes nothing more.
    virtual bool closing() const = 0;

   protected:
    ~Io() = default;
  };

  explicit SocketcandSession(Io& io) : io_(io) {}

  // The greeting, once the client is connected.
  void start();
  // Bytes from the client, cut anywhere.
  void push(std::string_view bytes);
  // A frame another endpoint sent on the bus: written to the client in raw mode only.
  void frame_from_bus(const can::CanFrame& frame, uint64_t timestamp_us);

  Mode mode() const { return mode_; }

 private:
  void handle(const std::string& element);
  void error(const std::string& text);

  Io& io_;
  Mode mode_ = Mode::kAwaitOpen;
  SocketcandElementParser parser_;
  std::vector<std::string> elements_;
};

}  // namespace motwin::host
