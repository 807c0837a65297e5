// `motwin serve --web HOST:PORT`: HTTP and WebSocket by libwebsockets on a libuv loop that the
// host's EventLoop polls (libuv's backend descriptor is one more watched descriptor, its timeout
// one more timer), so that the console runs on the simulation's one thread with no lock
// (docs/web-console.md, "The server"). HTTP serves the files built into the binary
// (web_assets.h): `/` is site/index.html, `/vendor/...` the plotting library, anything else of
// site/ by its name, and 404 otherwise. A WebSocket (sub-protocol "motwin", any path) is a
// session whose text messages go to a WebSessionHandler; what it sends back goes out in order,
// except the latest "update" push, which replaces an unsent one (a slow page gets the latest
// snapshot, never a growing queue).
#pragma once

#include <cstddef>
#include <cstdint>
#include <functional>
#include <memory>
#include <string>
#include <string_view>

#include "host/event_loop.h"
#include "types/result.h"

namespace motwin::host::web {

struct WebEndpointSpec {
  std::string host = "127.0.0.1";  // an IPv4 address
  uint16_t port = 8080;            // 0: the system picks a free port
  // Required when `host` is not a loopback address: a WebSocket must then present it as
  // `?token=...` in its URL, or it is refused.
  std::string token;
};

// "HOST:PORT", ":PORT" or "PORT" (host 127.0.0.1); HOST an IPv4 address. Refuses a non-loopback
// host without a token.
Result<WebEndpointSpec> parse_web_endpoint(std::string_view text, std::string token = {});

bool is_loopback_ipv4(std::string_view host);

// What a session sends through.
class WebConnection {
 public:
  // Queued in order (replies). A connection that lets kMaxQueuedBytes pile up is closed.
  virtual void send_text(std::string message) = 0;
  // The newest push replaces one not yet sent: sent after the queued replies.
  virtual void send_latest(std::string message) = 0;
  // Bytes queued by send_text and not yet written (a page that does not keep up).
  virtual size_t queued_bytes() const { return 0; }

 protected:
  ~WebConnection() = default;
};

class WebSessionHandler {
 public:
  virtual ~WebSessionHandler() = default;
  virtual void on_message(std::string_view text) = 0;
};

// Makes the handler of a new WebSocket session; it is destroyed when the socket closes.
using WebSessionFactory = std::function<std::unique_ptr<WebSessionHandler>(WebConnection& connection)>;

class WebServer {
 public:
  static constexpr size_t kMaxSessions = 16;
  static constexpr size_t kMaxQueuedBytes = 4 * 1024 * 1024;
  static constexpr size_t kMaxMessageBytes = 64 * 1024;

  // Fails with "cannot listen on 127.0.0.1:8080" and the like.
  static Result<std::unique_ptr<WebServer>> open(EventLoop& loop, const WebEndpointSpec& spec,
                                                 WebSessionFactory sessions);
  WebServer(const WebServer&) = delete;
  WebServer& operator=(const WebServer&) = delete;
  ~WebServer();

  std::string local_address() const;  // "127.0.0.1:40321"
  uint16_t local_port() const;
  size_t session_count() const;

  class Impl;

 private:
  explicit WebServer(std::unique_ptr<Impl> impl);
  std::unique_ptr<Impl> impl_;
};

}  // namespace motwin::host::web
