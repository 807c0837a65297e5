// The socketcand client (host/socketcand_client.h): the protocol's client half without sockets,
// the frame element parser and the `send` formatter it shares with the tools, and the endpoint
// joining a SocketcandServer's bus in the same event loop: frames both ways, no echo, a server
// that is not there, and a server that goes away and comes back.
#include <gtest/gtest.h>

#include <memory>
#include <string>
#include <vector>

#include "host/can_bus.h"
#include "host/can_endpoint.h"
#include "host/event_loop.h"
#include "host/socketcand_client.h"
#include "host/socketcand_protocol.h"
#include "host/socketcand_server.h"
#include "support/host_test_support.h"

namespace motwin::host {
namespace {

can::CanFrame frame_on(uint32_t id, std::vector<uint8_t> bytes) {
  return can::make_frame(id, bytes.data(), static_cast<uint8_t>(bytes.size()));
}

Result<can::CanFrame> parse_frame_text(const std::string& element) {
  return parse_socketcand_frame(socketcand_words(element));
}

TEST(SocketcandProtocol, frame_elements_parse_as_socketcand_and_the_server_write_them) {
  const Result<can::CanFrame> standard = parse_frame_text("frame 581 12.000345 4300100092 01FFFF");
  EXPECT_FALSE(standard) << "the data is one word";
  const Result<can::CanFrame> sdo = parse_frame_text("frame 581 12.000345 430010009201FFFF");
  ASSERT_TRUE(sdo) << sdo.error();
  EXPECT_EQ(*sdo, frame_on(0x581, {0x43, 0x00, 0x10, 0x00, 0x92, 0x01, 0xFF, 0xFF}));
  const Result<can::CanFrame> empty = parse_frame_text("frame 000 0.0");
  ASSERT_TRUE(empty) << empty.error();
  EXPECT_EQ(*empty, frame_on(0x000, {}));
  const Result<can::CanFrame> extended = parse_frame_text("frame 00000123 1.5 aBcD");
  ASSERT_TRUE(extended) << extended.error();
  EXPECT_TRUE(extended->extended);
  EXPECT_EQ(extended->id, 0x123u);
  EXPECT_EQ(extended->dlc, 2);
  EXPECT_EQ(extended->data[0], 0xAB);
  EXPECT_TRUE(parse_frame_text("frame 1FFFFFFF 1.5")->extended);
  for (const char* bad : {"frame", "frame 581", "frame 581 12", "frame 581 .5 00", "frame 581 1.x 00",
                          "frame 581 1.5 0", "frame 581 1.5 001122334455667788", "frame 20000000 1.5",
                          "frame xyz 1.5", "frame 581 1.5 zz", "send 581 1.5 00", "frame 581 1.5 00 11"}) {
    EXPECT_FALSE(parse_frame_text(bad)) << bad;
  }
  // What our server writes comes back as the same frame.
  for (const can::CanFrame& frame : {frame_on(0x181, {1, 2, 3}), frame_on(0x7FF, {}),
                                     frame_on(0x080, {0, 0, 0, 0, 0, 0, 0, 0xFF})}) {
    std::vector<std::string> elements;
    SocketcandElementParser parser;
    parser.push(format_socketcand_frame(frame, 1'234'567), elements);
    ASSERT_EQ(elements.size(), 1u);
    const Result<can::CanFrame> parsed = parse_frame_text(elements[0]);
    ASSERT_TRUE(parsed) << elements[0];
    EXPECT_EQ(*parsed, frame) << elements[0];
  }
}

TEST(SocketcandProtocol, send_elements_are_written_as_python_can_writes_them) {
  EXPECT_EQ(format_socketcand_send(frame_on(0x601, {0x40, 0x00, 0x10, 0, 0, 0, 0, 0})),
            "< send 601 8 40 00 10 00 00 00 00 00 >");
  EXPECT_EQ(format_socketcand_send(frame_on(0x000, {})), "< send 000 0 >");
  can::CanFrame extended = frame_on(0x1ABCDEF, {0xFE});
  extended.extended = true;
  EXPECT_EQ(format_socketcand_send(extended), "< send 01ABCDEF 1 FE >");
  // The server's parser reads them back as the same frames.
  for (const can::CanFrame& frame : {frame_on(0x601, {1, 2, 3, 4, 5, 6, 7, 8}), frame_on(0x7FF, {}), extended}) {
    std::vector<std::string> elements;
    SocketcandElementParser parser;
    parser.push(format_socketcand_send(frame), elements);
    ASSERT_EQ(elements.size(), 1u);
    const Result<can::CanFrame> parsed = parse_socketcand_send(socketcand_words(elements[0]));
    ASSERT_TRUE(parsed) << parsed.error();
    EXPECT_EQ(*parsed, frame);
  }
}

struct RecordingClientIo final : SocketcandClientSession::Io {
  std::vector<std::string> writes;
  std::vector<can::CanFrame> frames;
  std::vector<std::string> failures;
  int joins = 0;
  void write(const std::string& element) override { writes.push_back(element); }
  void handshake_done() override { ++joins; }
  void failed(const std::string& reason) override { failures.push_back(reason); }
  void frame_from_server(const can::CanFrame& frame) override { frames.push_back(frame); }
};

TEST(SocketcandClientSession, opens_the_channel_enters_raw_mode_and_then_passes_frames) {
  RecordingClientIo io;
  SocketcandClientSession session(io, "vcan1");
  EXPECT_FALSE(session.send(frame_on(0x181, {1})));
  session.push("< h");
  EXPECT_TRUE(io.writes.empty());
  session.push("i >");
  EXPECT_EQ(io.writes, (std::vector<std::string>{"< open vcan1 >"}));
  session.push("< ok >");
  EXPECT_EQ(io.writes.back(), "< rawmode >");
  EXPECT_EQ(io.joins, 0);
  EXPECT_FALSE(session.send(frame_on(0x181, {1})));
  session.push("< ok > < frame 701 0.100000 05 >garbage< echo >< frame 181 0.1 0102 >< frame 181 >");
  EXPECT_EQ(io.joins, 1);
  EXPECT_EQ(session.state(), SocketcandClientSession::State::kJoined);
  EXPECT_EQ(io.frames, (std::vector<can::CanFrame>{frame_on(0x701, {5}), frame_on(0x181, {1, 2})}));
  EXPECT_EQ(session.ignored_elements(), 2u);
  EXPECT_TRUE(session.send(frame_on(0x201, {7, 8})));
  EXPECT_EQ(io.writes.back(), "< send 201 2 07 08 >");
  can::CanFrame remote = frame_on(0x701, {});
  remote.rtr = true;
  EXPECT_FALSE(session.send(remote)) << "socketcand's send has no RTR flag";
  EXPECT_TRUE(io.failures.empty());
}

TEST(SocketcandClientSession, fails_on_an_error_before_it_joined) {
  RecordingClientIo io;
  SocketcandClientSession session(io, "can9");
  session.push("< hi >< error could not open bus >< ok >< ok >");
  ASSERT_EQ(io.failures.size(), 1u);
  EXPECT_EQ(io.failures[0], "< open can9 > answered with < error could not open bus >");
  EXPECT_EQ(session.state(), SocketcandClientSession::State::kFailed);
  EXPECT_EQ(io.writes, (std::vector<std::string>{"< open can9 >"}));
  EXPECT_EQ(io.joins, 0);

  RecordingClientIo rude;
  SocketcandClientSession no_greeting(rude, "can0");
  no_greeting.push("< ok >");
  ASSERT_EQ(rude.failures.size(), 1u);
  EXPECT_EQ(rude.failures[0], "expected < hi >, got < ok >");
}

struct Recorder final : CanBusEndpoint {
  std::vector<can::CanFrame> frames;
  void on_frame(const can::CanFrame& frame, uint64_t) override { frames.push_back(frame); }
};

// Two buses in one loop: `remote` served by a SocketcandServer, `local` joining it.
struct TwoBuses {
  EventLoop loop;
  CanBus remote;
  CanBus local;
  Recorder remote_node;
  Recorder local_node;
  CanBus::EndpointId remote_id = remote.attach(remote_node);
  CanBus::EndpointId local_id = local.attach(local_node);
  std::vector<std::string> server_log;
  std::vector<std::string> client_log;

  Result<std::unique_ptr<SocketcandServer>> serve(uint16_t port) {
    return SocketcandServer::open(loop, remote, TcpEndpointSpec{"127.0.0.1", port},
                                  [this](const std::string& line) { server_log.push_back(line); });
  }
  Result<std::unique_ptr<SocketcandClientEndpoint>> join(uint16_t port) {
    return SocketcandClientEndpoint::open(loop, local, SocketcandClientSpec{TcpEndpointSpec{"127.0.0.1", port}, "can0"},
                                          [this](const std::string& line) { client_log.push_back(line); });
  }
  bool pump_until(const std::function<bool()>& done) {
    return testing::pump_until([this] { loop.poll_once(1000); }, done);
  }
};

TEST(SocketcandClientEndpoint, joins_a_remote_bus_both_ways_without_echo) {
  TwoBuses buses;
  Result<std::unique_ptr<SocketcandServer>> server = buses.serve(0);
  ASSERT_TRUE(server) << server.error();
  Result<std::unique_ptr<SocketcandClientEndpoint>> client = buses.join((*server)->local_port());
  ASSERT_TRUE(client) << client.error();
  EXPECT_TRUE((*client)->joined());
  EXPECT_EQ((*client)->where(), "127.0.0.1:" + std::to_string((*server)->local_port()) + " can0");
  EXPECT_EQ((*server)->client_count(), 1u);

  buses.local.send(buses.local_id, frame_on(0x601, {0x40, 0x00, 0x10, 0}));
  ASSERT_TRUE(buses.pump_until([&] { return !buses.remote_node.frames.empty(); }));
  // The server holds its output back for a moment after rawmode (SocketcandServer::kRawModeSettleUs).
  buses.remote.send(buses.remote_id, frame_on(0x581, {0x43}));
  buses.remote.send(buses.remote_id, frame_on(0x701, {0x05}));
  ASSERT_TRUE(buses.pump_until([&] { return buses.local_node.frames.size() >= 2; }));
  // A marker both ways proves nothing more is on its way.
  buses.local.send(buses.local_id, frame_on(0x7E5, {0x4C}));
  ASSERT_TRUE(buses.pump_until([&] { return buses.remote_node.frames.size() >= 2; }));
  buses.remote.send(buses.remote_id, frame_on(0x7E4, {0x50}));
  ASSERT_TRUE(buses.pump_until([&] { return buses.local_node.frames.size() >= 3; }));
  EXPECT_EQ(buses.remote_node.frames,
            (std::vector<can::CanFrame>{frame_on(0x601, {0x40, 0x00, 0x10, 0}), frame_on(0x7E5, {0x4C})}));
  EXPECT_EQ(buses.local_node.frames,
            (std::vector<can::CanFrame>{frame_on(0x581, {0x43}), frame_on(0x701, {0x05}), frame_on(0x7E4, {0x50})}))
      << "each remote frame once, none of ours back";
  EXPECT_EQ((*client)->dropped_frames(), 0u);
  EXPECT_TRUE(buses.client_log.empty());
}

TEST(SocketcandClientEndpoint, a_server_that_is_not_there_is_an_error_at_start) {
  TwoBuses buses;
  uint16_t unused_port = 0;
  {
    Result<std::unique_ptr<SocketcandServer>> server = buses.serve(0);
    ASSERT_TRUE(server) << server.error();
    unused_port = (*server)->local_port();
  }
  Result<std::unique_ptr<SocketcandClientEndpoint>> client = buses.join(unused_port);
  ASSERT_FALSE(client);
  EXPECT_EQ(client.error(), "cannot join the socketcand bus at 127.0.0.1:" + std::to_string(unused_port) +
                                " can0: Connection refused");
  EXPECT_EQ(buses.local.endpoint_count(), 1u) << "nothing left on the bus";
  EXPECT_EQ(buses.loop.watch_count(), 0u) << "no socket left open";
}

TEST(SocketcandClientEndpoint, reconnects_when_the_server_comes_back) {
  TwoBuses buses;
  Result<std::unique_ptr<SocketcandServer>> server = buses.serve(0);
  ASSERT_TRUE(server) << server.error();
  const uint16_t port = (*server)->local_port();
  Result<std::unique_ptr<SocketcandClientEndpoint>> client = buses.join(port);
  ASSERT_TRUE(client) << client.error();
  server->reset();  // the gateway goes away
  ASSERT_TRUE(buses.pump_until([&] { return !(*client)->joined(); }));
  ASSERT_EQ(buses.client_log.size(), 1u);
  EXPECT_EQ(buses.client_log[0], "motwin: socketcand-client 127.0.0.1:" + std::to_string(port) +
                                     " can0: connection lost (the server closed the connection); reconnecting, "
                                     "frames are dropped until then");
  buses.local.send(buses.local_id, frame_on(0x181, {1}));
  EXPECT_EQ((*client)->dropped_frames(), 1u) << "a frame while the cable is out";
  // Some failed attempts (refused), then the server is back on the same port.
  const uint64_t until_us = monotonic_now_us() + 3 * SocketcandClientEndpoint::kFirstRetryUs;
  ASSERT_TRUE(buses.pump_until([&] { return monotonic_now_us() >= until_us; }));
  EXPECT_EQ(buses.client_log.size(), 1u) << "failed attempts are not logged";
  Result<std::unique_ptr<SocketcandServer>> again = buses.serve(port);
  ASSERT_TRUE(again) << again.error();
  ASSERT_TRUE(buses.pump_until([&] { return (*client)->joined(); }));
  ASSERT_EQ(buses.client_log.size(), 2u);
  EXPECT_EQ(buses.client_log[1], "motwin: socketcand-client 127.0.0.1:" + std::to_string(port) +
                                     " can0: joined the bus again");
  EXPECT_EQ((*client)->connections(), 2u);
  buses.local.send(buses.local_id, frame_on(0x182, {2}));
  ASSERT_TRUE(buses.pump_until([&] { return !buses.remote_node.frames.empty(); }));
  EXPECT_EQ(buses.remote_node.frames, (std::vector<can::CanFrame>{frame_on(0x182, {2})}));
}

}  // namespace
}  // namespace motwin::host

namespace motwin::host {
namespace {

TEST(CanEndpointSpec, socketcand_client_takes_host_port_and_channel) {
  Result<CanEndpointSpec> spec = parse_can_endpoint("socketcand-client:gateway.local:29536:can1");
  ASSERT_TRUE(spec) << spec.error();
  EXPECT_EQ(spec->transport, CanTransport::kSocketcandClient);
  EXPECT_EQ(spec->tcp.host, "gateway.local");
  EXPECT_EQ(spec->tcp.port, 29536);
  EXPECT_EQ(spec->device, "can1");
  spec = parse_can_endpoint("socketcand-client:[::1]:4000:vcan0");
  ASSERT_TRUE(spec) << spec.error();
  EXPECT_EQ(spec->tcp.host, "::1");
  EXPECT_EQ(spec->tcp.port, 4000);
  EXPECT_EQ(spec->device, "vcan0");
  for (const char* bad : {"socketcand-client", "socketcand-client:127.0.0.1:29536", "socketcand-client:29536:can0",
                          "socketcand-client:127.0.0.1:0:can0", "socketcand-client:127.0.0.1:29536:",
                          "socketcand-client:127.0.0.1:x:can0", "socketcand-client:127.0.0.1:1:c<0"}) {
    const Result<CanEndpointSpec> refused = parse_can_endpoint(bad);
    ASSERT_FALSE(refused) << bad;
    EXPECT_NE(refused.error().find("socketcand-client needs HOST:PORT:CHANNEL"), std::string::npos) << bad;
  }
}

}  // namespace
}  // namespace motwin::host
