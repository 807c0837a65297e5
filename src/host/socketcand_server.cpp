#include "host/socketcand_server.h"

#include <vector>

#include "host/socketcand_protocol.h"
#include "host/tcp_connection_server.h"

namespace motwin::host {

// One client: a bus endpoint from the moment it is connected, seeing frames in raw mode.
class SocketcandServer::Session final : public TcpSession, public CanBusEndpoint {
 public:
  enum class Mode : uint8_t { kAwaitOpen, kBcm, kRaw };

  Session(CanBus& bus, std::weak_ptr<bool> server_alive, TcpConnectionServer& server)
      : bus_(bus), server_alive_(std::move(server_alive)), server_(server) {}

  void on_open() override {
    bus_id_ = bus_.attach(*this);
    connection().write("< hi >");
  }

  void on_close() override {
    if (bus_id_ != 0) bus_.detach(bus_id_);
    bus_id_ = 0;
  }

  void on_data(const uint8_t* bytes, size_t length) override {
    elements_.clear();
    parser_.push(std::string_view(reinterpret_cast<const char*>(bytes), length), elements_);
    for (const std::string& element : elements_) {
      if (connection().closing()) return;
      handle(element);
    }
  }

  // CanBusEndpoint.
  void on_frame(const can::CanFrame& frame, uint64_t timestamp_us) override {
    if (connection().closing() || mode_ != Mode::kRaw) return;
    connection().write(format_socketcand_frame(frame, timestamp_us));
  }

 private:
  void handle(const std::string& element) {
    const std::vector<std::string_view> words = socketcand_words(element);
    const std::string_view command = words.empty() ? std::string_view{} : words[0];
    switch (mode_) {
      case Mode::kAwaitOpen:
        if (command == "open" && words.size() == 2) {
          mode_ = Mode::kBcm;
          connection().write("< ok >");
        } else {
          error("expected open");
        }
        return;
      case Mode::kBcm:
      case Mode::kRaw:
        if (command == "send") {
          std::string problem;
          const std::optional<can::CanFrame> frame = parse_socketcand_send(words, problem);
          if (!frame) {
            error(problem);
            return;
          }
          bus_.send(bus_id_, *frame);
        } else if (command == "rawmode" && words.size() == 1) {
          const bool entering = mode_ != Mode::kRaw;
          mode_ = Mode::kRaw;
          connection().write("< ok >");
          if (entering) hold_output();
        } else if (command == "bcmmode" && words.size() == 1) {
          mode_ = Mode::kBcm;
          connection().write(" < ok >");
        } else if (command == "echo" && words.size() == 1) {
          connection().write(" < echo >");
        } else {
          error("unknown command");
        }
        return;
    }
  }

  void error(const std::string& text) { connection().write(" < error " + text + " >"); }

  // python-can compares the `< ok >` of rawmode with one recv(): nothing may follow it closely.
  void hold_output() {
    connection().hold_output(true);
    std::weak_ptr<bool> alive = server_alive_;
    TcpConnectionServer* server = &server_;
    const uint64_t id = connection().id();
    server_.loop().add_timer_after(kRawModeSettleUs, [alive, server, id] {
      if (alive.expired()) return;
      if (TcpConnection* connection = server->find(id)) connection->hold_output(false);
    });
  }

  CanBus& bus_;
  std::weak_ptr<bool> server_alive_;
  TcpConnectionServer& server_;
  CanBus::EndpointId bus_id_ = 0;
  Mode mode_ = Mode::kAwaitOpen;
  SocketcandElementParser parser_;
  std::vector<std::string> elements_;
};

SocketcandServer::OpenResult SocketcandServer::open(EventLoop& loop, CanBus& bus, const TcpEndpointSpec& spec,
                                                    LogSink log) {
  OpenResult result;
  std::unique_ptr<SocketcandServer> server(new SocketcandServer());
  SocketcandServer* raw = server.get();
  TcpConnectionServer::Config config{"socketcand", kMaxClients, kMaxPendingOutputBytes, "it does not read its frames"};
  TcpConnectionServer::OpenResult opened = TcpConnectionServer::open(
      loop, spec, std::move(config),
      [&bus, raw](TcpConnection&) -> std::unique_ptr<TcpSession> {
        return std::make_unique<Session>(bus, raw->connections_->lifetime(), *raw->connections_);
      },
      std::move(log));
  if (!opened.server) {
    result.error = opened.error;
    return result;
  }
  server->connections_ = std::move(opened.server);
  result.server = std::move(server);
  return result;
}

SocketcandServer::~SocketcandServer() = default;

std::string SocketcandServer::local_address() const { return connections_->local_address(); }
uint16_t SocketcandServer::local_port() const { return connections_->local_port(); }
size_t SocketcandServer::client_count() const { return connections_->client_count(); }

}  // namespace motwin::host
