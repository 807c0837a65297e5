#include "host/socketcand_server.h"

#include <string>
#include <string_view>

#include "host/socketcand_session.h"
#include "host/tcp_connection_server.h"

namespace motwin::host {

// One client: a bus endpoint from the moment it is connected, seeing frames in raw mode. The
// protocol is SocketcandSession's; this class ties it to the connection and the bus.
class SocketcandServer::Session final : public TcpSession, public CanBusEndpoint, private SocketcandSession::Io {
 public:
  Session(CanBus& bus, std::weak_ptr<bool> server_alive, TcpConnectionServer& server)
      : bus_(bus), server_alive_(std::move(server_alive)), server_(server) {}

  void on_open() override {
    bus_id_ = bus_.attach(*this);
    session_.start();
  }

  void on_close() override {
    if (bus_id_ != 0) bus_.detach(bus_id_);
    bus_id_ = 0;
  }

  void on_data(const uint8_t* bytes, size_t length) override {
    session_.push(std::string_view(reinterpret_cast<const char*>(bytes), length));
  }

  // CanBusEndpoint.
  void on_frame(const can::CanFrame& frame, uint64_t timestamp_us) override {
    session_.frame_from_bus(frame, timestamp_us);
  }

 private:
  // SocketcandSession::Io.
  void write(const std::string& element) override { connection().write(element); }
  void send_to_bus(const can::CanFrame& frame) override { bus_.send(bus_id_, frame); }
  bool closing() const override { return connection().closing(); }

  // python-can compares the `< ok >` of rawmode with one recv(): nothing may follow it closely.
  void raw_mode_entered() override {
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
  SocketcandSession session_{*this};
};

Result<std::unique_ptr<SocketcandServer>> SocketcandServer::open(EventLoop& loop, CanBus& bus,
                                                                 const TcpEndpointSpec& spec, LogSink log) {
  std::unique_ptr<SocketcandServer> server(new SocketcandServer());
  SocketcandServer* raw = server.get();
  TcpConnectionServer::Config config{"socketcand", kMaxClients, kMaxPendingOutputBytes, "it does not read its frames"};
  Result<std::unique_ptr<TcpConnectionServer>> connections = TcpConnectionServer::open(
      loop, spec, std::move(config),
      [&bus, raw](TcpConnection&) -> std::unique_ptr<TcpSession> {
        return std::make_unique<Session>(bus, raw->connections_->lifetime(), *raw->connections_);
      },
      std::move(log));
  if (!connections) return Error{connections.error()};
  server->connections_ = std::move(*connections);
  return server;
}

SocketcandServer::~SocketcandServer() = default;

std::string SocketcandServer::local_address() const { return connections_->local_address(); }
uint16_t SocketcandServer::local_port() const { return connections_->local_port(); }
size_t SocketcandServer::client_count() const { return connections_->client_count(); }

}  // namespace motwin::host
