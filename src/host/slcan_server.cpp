#include "host/slcan_server.h"

#include <vector>

#include "host/slcan_protocol.h"
#include "host/tcp_connection_server.h"

namespace motwin::host {

// One client: a Lawicel adapter whose channel, while open, carries the bus's frames.
class SlcanTcpServer::Session final : public TcpSession, public CanBusEndpoint {
 public:
  explicit Session(CanBus& bus)
      : bus_(bus), session_([this](const can::CanFrame& frame) { outgoing_.push_back(frame); }) {}

  void on_open() override { bus_id_ = bus_.attach(*this); }
  void on_close() override {
    if (bus_id_ != 0) bus_.detach(bus_id_);
    bus_id_ = 0;
  }

  void on_frame(const can::CanFrame& frame, uint64_t) override {
    if (connection().closing() || !session_.open()) return;
    connection().write(format_slcan_frame(frame));
  }

  void on_data(const uint8_t* bytes, size_t length) override {
    // The adapter acknowledges (`z\r`) before the bus carries the frame: nodes may answer at
    // once, and their answers must follow the acknowledgement, as on a real adapter.
    std::string reply;
    outgoing_.clear();
    session_.push(std::string_view(reinterpret_cast<const char*>(bytes), length), reply);
    connection().write(reply);
    const std::vector<can::CanFrame> frames = std::move(outgoing_);
    outgoing_.clear();
    for (const can::CanFrame& frame : frames) {
      if (connection().closing()) return;
      bus_.send(bus_id_, frame);
    }
  }

 private:
  CanBus& bus_;
  CanBus::EndpointId bus_id_ = 0;
  SlcanSession session_;
  std::vector<can::CanFrame> outgoing_;
};

Result<std::unique_ptr<SlcanTcpServer>> SlcanTcpServer::open(EventLoop& loop, CanBus& bus, const TcpEndpointSpec& spec,
                                                             LogSink log) {
  TcpConnectionServer::Config config{"SLCAN", kMaxClients, kMaxPendingOutputBytes, "it does not read its frames"};
  Result<std::unique_ptr<TcpConnectionServer>> connections = TcpConnectionServer::open(
      loop, spec, std::move(config),
      [&bus](TcpConnection&) -> std::unique_ptr<TcpSession> { return std::make_unique<Session>(bus); }, std::move(log));
  if (!connections) return Error{connections.error()};
  std::unique_ptr<SlcanTcpServer> server(new SlcanTcpServer());
  server->connections_ = std::move(*connections);
  return server;
}

SlcanTcpServer::~SlcanTcpServer() = default;

std::string SlcanTcpServer::local_address() const { return connections_->local_address(); }
uint16_t SlcanTcpServer::local_port() const { return connections_->local_port(); }
size_t SlcanTcpServer::client_count() const { return connections_->client_count(); }

}  // namespace motwin::host
