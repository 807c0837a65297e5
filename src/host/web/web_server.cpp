#include "host/web/web_server.h"

#include <algorithm>
#include <charconv>
#include <cstring>
#include <deque>
#include <optional>
#include <set>
#include <vector>

#include <arpa/inet.h>
#include <libwebsockets.h>
#include <uv.h>

#include "host/web/web_assets.h"

namespace motwin::host::web {

bool is_loopback_ipv4(std::string_view host) {
  in_addr address{};
  const std::string text(host);
  if (::inet_pton(AF_INET, text.c_str(), &address) != 1) return false;
  return (ntohl(address.s_addr) >> 24) == 127;
}

Result<WebEndpointSpec> parse_web_endpoint(std::string_view text, std::string token) {
  WebEndpointSpec spec;
  spec.token = std::move(token);
  std::string_view port_text = text;
  if (const size_t colon = text.rfind(':'); colon != std::string_view::npos) {
    if (colon > 0) spec.host = std::string(text.substr(0, colon));
    port_text = text.substr(colon + 1);
  }
  unsigned port = 0;
  const auto [end, problem] = std::from_chars(port_text.data(), port_text.data() + port_text.size(), port);
  in_addr address{};
  if (port_text.empty() || problem != std::errc{} || end != port_text.data() + port_text.size() || port > 65535 ||
      ::inet_pton(AF_INET, spec.host.c_str(), &address) != 1) {
    return Error{"expected IPV4-ADDRESS:PORT with a port from 0 to 65535, got \"" + std::string(text) + "\""};
  }
  spec.port = static_cast<uint16_t>(port);
  if (!is_loopback_ipv4(spec.host) && spec.token.empty()) {
    return Error{spec.host + " is not a loopback address: the page could be reached from elsewhere, so give "
                             "--web-token TOKEN too (a WebSocket must then present ?token=TOKEN)"};
  }
  return spec;
}

namespace {

// The embedded file an HTTP path names: / is the console, /vendor/... the plotting library,
// /NAME a file of the console's folder.
std::optional<WebAsset> asset_for_path(std::string_view path) {
  if (path == "/" || path.empty()) return find_web_asset("site/index.html");
  if (path.starts_with("/vendor/")) return find_web_asset(path.substr(1));
  if (path.find("..") != std::string_view::npos) return std::nullopt;
  return find_web_asset("site/" + std::string(path.substr(1)));
}

// What one HTTP connection is sending (lws keeps it as the protocol's per-session data).
struct HttpTransfer {
  const char* bytes;
  size_t size;
  size_t sent;
};

bool same_token(std::string_view given, std::string_view expected) {
  // Constant time in the token's length, so the comparison tells nothing by its duration.
  unsigned char difference = given.size() == expected.size() ? 0 : 1;
  for (size_t i = 0; i < expected.size(); ++i) {
    difference |= static_cast<unsigned char>(expected[i] ^ (i < given.size() ? given[i] : 0));
  }
  return difference == 0;
}

}  // namespace

class WebServer::Impl {
 public:
  class Session final : public WebConnection {
   public:
    Session(Impl& server, lws* wsi) : server_(server), wsi_(wsi) {}

    size_t queued_bytes() const override { return queued_bytes_; }

    void send_text(std::string message) override {
      queued_bytes_ += message.size();
      queue_.push_back(std::move(message));
      if (queued_bytes_ > kMaxQueuedBytes) closing_ = true;  // not reading: dropped
      want_write();
    }
    void send_latest(std::string message) override {
      latest_ = std::move(message);
      want_write();
    }

    // LWS_CALLBACK_SERVER_WRITEABLE: one message; false closes the connection.
    bool write_one() {
      if (closing_) return false;
      std::string message;
      if (!queue_.empty()) {
        message = std::move(queue_.front());
        queue_.pop_front();
        queued_bytes_ -= message.size();
      } else if (latest_) {
        message = std::move(*latest_);
        latest_.reset();
      } else {
        return true;
      }
      scratch_.resize(LWS_PRE + message.size());
      std::memcpy(scratch_.data() + LWS_PRE, message.data(), message.size());
      if (lws_write(wsi_, scratch_.data() + LWS_PRE, message.size(), LWS_WRITE_TEXT) <
          static_cast<int>(message.size())) {
        return false;
      }
      if (!queue_.empty() || latest_) lws_callback_on_writable(wsi_);
      return true;
    }

    // LWS_CALLBACK_RECEIVE: a fragment; a whole message goes to the handler.
    bool receive(const char* bytes, size_t length, bool complete) {
      if (incoming_.size() + length > kMaxMessageBytes) return false;
      incoming_.append(bytes, length);
      if (!complete) return true;
      const std::string message = std::move(incoming_);
      incoming_.clear();
      if (handler_) handler_->on_message(message);
      return !closing_;
    }

    void set_handler(std::unique_ptr<WebSessionHandler> handler) { handler_ = std::move(handler); }
    void drop_handler() { handler_.reset(); }

   private:
    void want_write() {
      lws_callback_on_writable(wsi_);
      server_.request_service();
    }

    Impl& server_;
    lws* wsi_;
    std::unique_ptr<WebSessionHandler> handler_;
    std::deque<std::string> queue_;
    size_t queued_bytes_ = 0;
    std::optional<std::string> latest_;
    std::string incoming_;
    std::vector<unsigned char> scratch_;
    bool closing_ = false;
  };

  Impl(EventLoop& loop, WebEndpointSpec spec, WebSessionFactory sessions)
      : loop_(loop), spec_(std::move(spec)), sessions_(std::move(sessions)) {}

  ~Impl() {
    *alive_ = false;
    if (timer_) loop_.cancel_timer(*timer_);
    if (watching_) loop_.unwatch(uv_backend_fd(&uv_));
    // On a foreign loop lws finishes destroying its context once libuv has closed its handles,
    // and then clears context_ (info.pcontext). Only lws has handles on this loop, so running it
    // until none is left ends; a context still there then is destroyed once more.
    for (int pass = 0; pass < 2 && context_ != nullptr; ++pass) {
      lws_context_destroy(context_);
      if (uv_initialised_) uv_run(&uv_, UV_RUN_DEFAULT);
    }
    if (uv_initialised_) {
      for (int pass = 0; pass < 100 && uv_loop_close(&uv_) == UV_EBUSY; ++pass) uv_run(&uv_, UV_RUN_NOWAIT);
    }
  }

  Result<void> start() {
    lws_set_log_level(LLL_ERR, nullptr);
    if (uv_loop_init(&uv_) != 0) return Error{"cannot start the web server's event loop"};
    uv_initialised_ = true;
    protocols_[0] = {"http", &Impl::on_http, sizeof(HttpTransfer), 0, 0, nullptr, 0};
    protocols_[1] = {"motwin", &Impl::on_websocket, sizeof(Session*), 4096, 0, nullptr, 0};
    protocols_[2] = {nullptr, nullptr, 0, 0, 0, nullptr, 0};
    foreign_loops_[0] = &uv_;
    lws_context_creation_info info{};
    info.port = spec_.port;
    // With IPv6 off, lws binds the address itself; with it on it would listen on every interface.
    info.iface = spec_.host.c_str();
    info.protocols = protocols_;
    info.options = LWS_SERVER_OPTION_LIBUV | LWS_SERVER_OPTION_DISABLE_IPV6 |
                   LWS_SERVER_OPTION_HTTP_HEADERS_SECURITY_BEST_PRACTICES_ENFORCE;
    info.foreign_loops = foreign_loops_;
    info.user = this;
    info.pcontext = &context_;
    context_ = lws_create_context(&info);
    const std::string where = spec_.host + ":" + std::to_string(spec_.port);
    if (context_ == nullptr) return Error{"cannot listen on " + where};
    const int port = lws_get_vhost_listen_port(lws_get_vhost_by_name(context_, "default"));
    if (port <= 0) return Error{"cannot listen on " + where};
    port_ = static_cast<uint16_t>(port);
    loop_.watch(uv_backend_fd(&uv_), POLLIN, [this](short) { run_uv(); });
    watching_ = true;
    run_uv();
    return {};
  }

  // A change made outside libuv's turn (a write wanted) takes effect on its next turn.
  void request_service() {
    if (service_requested_ || in_uv_run_) return;
    service_requested_ = true;
    loop_.defer([this, alive = alive_] {
      if (!*alive) return;
      service_requested_ = false;
      run_uv();
    });
  }

  void run_uv() {
    in_uv_run_ = true;
    uv_run(&uv_, UV_RUN_NOWAIT);
    in_uv_run_ = false;
    if (timer_) loop_.cancel_timer(*timer_);
    timer_.reset();
    uv_update_time(&uv_);
    const int timeout_ms = uv_backend_timeout(&uv_);
    if (timeout_ms >= 0) {
      timer_ = loop_.add_timer_after(static_cast<uint64_t>(timeout_ms) * 1000u, [this] {
        timer_.reset();
        run_uv();
      });
    }
  }

  std::string local_address() const { return spec_.host + ":" + std::to_string(port_); }
  uint16_t port() const { return port_; }
  size_t session_count() const { return open_sessions_.size(); }

 private:
  static Impl& of(lws* wsi) { return *static_cast<Impl*>(lws_context_user(lws_get_context(wsi))); }

  static int on_http(lws* wsi, lws_callback_reasons reason, void* user, void* in, size_t length) {
    auto* transfer = static_cast<HttpTransfer*>(user);
    switch (reason) {
      case LWS_CALLBACK_HTTP: {
        const std::string_view path(static_cast<const char*>(in), in == nullptr ? 0 : std::strlen(static_cast<const char*>(in)));
        unsigned char buffer[LWS_PRE + 1024];
        unsigned char* start = buffer + LWS_PRE;
        unsigned char* p = start;
        unsigned char* end = buffer + sizeof(buffer) - 1;
        if (path == "/favicon.ico") {
          // The page names no icon; a browser asking anyway gets an empty answer, not a 404 in its log.
          if (lws_add_http_common_headers(wsi, HTTP_STATUS_NO_CONTENT, "image/x-icon", 0, &p, end) ||
              lws_finalize_write_http_header(wsi, start, &p, end)) {
            return 1;
          }
          return lws_http_transaction_completed(wsi) ? -1 : 0;
        }
        const std::optional<WebAsset> asset = asset_for_path(path);
        if (!asset) {
          lws_return_http_status(wsi, HTTP_STATUS_NOT_FOUND, nullptr);
          return lws_http_transaction_completed(wsi) ? -1 : 0;
        }
        const std::string content_type(asset->content_type);
        if (lws_add_http_common_headers(wsi, HTTP_STATUS_OK, content_type.c_str(), asset->bytes.size(), &p, end) ||
            lws_add_http_header_by_token(wsi, WSI_TOKEN_HTTP_CACHE_CONTROL,
                                         reinterpret_cast<const unsigned char*>("no-store"), 8, &p, end) ||
            lws_finalize_write_http_header(wsi, start, &p, end)) {
          return 1;
        }
        *transfer = HttpTransfer{asset->bytes.data(), asset->bytes.size(), 0};
        lws_callback_on_writable(wsi);
        return 0;
      }
      case LWS_CALLBACK_HTTP_WRITEABLE: {
        if (transfer->bytes == nullptr) break;
        constexpr size_t kChunk = 16 * 1024;
        unsigned char buffer[LWS_PRE + kChunk];
        const size_t count = std::min(kChunk, transfer->size - transfer->sent);
        std::memcpy(buffer + LWS_PRE, transfer->bytes + transfer->sent, count);
        transfer->sent += count;
        const bool last = transfer->sent == transfer->size;
        if (lws_write(wsi, buffer + LWS_PRE, count, last ? LWS_WRITE_HTTP_FINAL : LWS_WRITE_HTTP) <
            static_cast<int>(count)) {
          return 1;
        }
        if (last) {
          transfer->bytes = nullptr;
          return lws_http_transaction_completed(wsi) ? -1 : 0;
        }
        lws_callback_on_writable(wsi);
        return 0;
      }
      default:
        break;
    }
    return lws_callback_http_dummy(wsi, reason, user, in, length);
  }

  static int on_websocket(lws* wsi, lws_callback_reasons reason, void* user, void* in, size_t length) {
    auto** session = static_cast<Session**>(user);
    switch (reason) {
      case LWS_CALLBACK_FILTER_PROTOCOL_CONNECTION: {
        Impl& server = of(wsi);
        if (server.open_sessions_.size() >= kMaxSessions) return 1;
        if (!server.spec_.token.empty()) {
          char buffer[256];
          const char* token = lws_get_urlarg_by_name(wsi, "token=", buffer, sizeof(buffer));
          if (token == nullptr || !same_token(token, server.spec_.token)) return 1;
        }
        return 0;
      }
      case LWS_CALLBACK_ESTABLISHED: {
        Impl& server = of(wsi);
        *session = new Session(server, wsi);
        server.open_sessions_.insert(*session);
        (*session)->set_handler(server.sessions_(**session));
        return 0;
      }
      case LWS_CALLBACK_CLOSED: {
        if (*session == nullptr) return 0;
        of(wsi).open_sessions_.erase(*session);
        (*session)->drop_handler();
        delete *session;
        *session = nullptr;
        return 0;
      }
      case LWS_CALLBACK_RECEIVE: {
        if (*session == nullptr) return -1;
        const bool complete = lws_is_final_fragment(wsi) && lws_remaining_packet_payload(wsi) == 0;
        return (*session)->receive(static_cast<const char*>(in), length, complete) ? 0 : -1;
      }
      case LWS_CALLBACK_SERVER_WRITEABLE:
        if (*session == nullptr) return 0;
        return (*session)->write_one() ? 0 : -1;
      default:
        return 0;
    }
  }

  EventLoop& loop_;
  WebEndpointSpec spec_;
  WebSessionFactory sessions_;
  uv_loop_t uv_{};
  bool uv_initialised_ = false;
  lws_protocols protocols_[3]{};
  void* foreign_loops_[1]{};
  lws_context* context_ = nullptr;
  uint16_t port_ = 0;
  bool watching_ = false;
  std::optional<EventLoop::TimerId> timer_;
  bool service_requested_ = false;
  bool in_uv_run_ = false;
  std::shared_ptr<bool> alive_ = std::make_shared<bool>(true);
  std::set<Session*> open_sessions_;
};

Result<std::unique_ptr<WebServer>> WebServer::open(EventLoop& loop, const WebEndpointSpec& spec,
                                                   WebSessionFactory sessions) {
  auto impl = std::make_unique<Impl>(loop, spec, std::move(sessions));
  if (Result<void> started = impl->start(); !started) return Error{started.error()};
  return std::unique_ptr<WebServer>(new WebServer(std::move(impl)));
}

WebServer::WebServer(std::unique_ptr<Impl> impl) : impl_(std::move(impl)) {}
WebServer::~WebServer() = default;
std::string WebServer::local_address() const { return impl_->local_address(); }
uint16_t WebServer::local_port() const { return impl_->port(); }
size_t WebServer::session_count() const { return impl_->session_count(); }

}  // namespace motwin::host::web
