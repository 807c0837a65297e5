// The virtual CAN bus (host/can_bus.h), the socketcand protocol text (host/socketcand_protocol.h)
// and the socketcand server with the TMCM-3216 on an event loop (host/socketcand_server.h).
#include <gtest/gtest.h>

#include <string>
#include <vector>

#include "host/can_bus.h"
#include "host/can_endpoint.h"
#include "host/event_loop.h"
#include "host/module_registry.h"
#include "host/slcan_protocol.h"
#include "host/socketcand_protocol.h"
#include "host/socketcand_server.h"
#include "host/modules/tmcm3216/tmcm3216_virtual_module.h"
#include "support/host_test_support.h"

namespace motwin::host {
namespace {

struct Recorder final : CanBusEndpoint {
  std::vector<can::CanFrame> frames;
  std::vector<uint64_t> stamps;
  std::function<void(const can::CanFrame&)> reaction;
  void on_frame(const can::CanFrame& frame, uint64_t timestamp_us) override {
    frames.push_back(frame);
    stamps.push_back(timestamp_us);
    if (reaction) reaction(frame);
  }
};

can::CanFrame frame(uint32_t id, std::vector<uint8_t> data = {}) {
  return can::make_frame(id, data.data(), static_cast<uint8_t>(data.size()));
}

TEST(CanBus, every_endpoint_but_the_sender_sees_a_frame) {
  uint64_t now = 1234;
  CanBus bus([&now] { return now; });
  Recorder a, b, c;
  const CanBus::EndpointId ia = bus.attach(a);
  bus.attach(b);
  bus.attach(c);
  bus.send(ia, frame(0x123, {1, 2}));
  EXPECT_TRUE(a.frames.empty());
  ASSERT_EQ(b.frames.size(), 1u);
  ASSERT_EQ(c.frames.size(), 1u);
  EXPECT_EQ(b.frames[0], frame(0x123, {1, 2}));
  EXPECT_EQ(b.stamps[0], 1234u);
  EXPECT_EQ(bus.frame_count(), 1u);
}

TEST(CanBus, answers_sent_during_delivery_come_after_the_frame_in_one_order) {
  CanBus bus;
  Recorder client, node, observer;
  const CanBus::EndpointId ic = bus.attach(client);
  const CanBus::EndpointId in = bus.attach(node);
  bus.attach(observer);
  node.reaction = [&](const can::CanFrame& f) {
    if (f.id == 0x601) bus.send(in, frame(0x581, {0x43}));
  };
  bus.send(ic, frame(0x601, {0x40}));
  ASSERT_EQ(observer.frames.size(), 2u);
  EXPECT_EQ(observer.frames[0].id, 0x601u);
  EXPECT_EQ(observer.frames[1].id, 0x581u);
  ASSERT_EQ(client.frames.size(), 1u);
  EXPECT_EQ(client.frames[0].id, 0x581u);
  EXPECT_EQ(node.frames.size(), 1u);  // not its own answer
}

TEST(CanBus, detaching_during_delivery_is_safe) {
  CanBus bus;
  Recorder a, b, c;
  const CanBus::EndpointId ia = bus.attach(a);
  CanBus::EndpointId ib = 0;
  ib = bus.attach(b);
  const CanBus::EndpointId ic = bus.attach(c);
  b.reaction = [&](const can::CanFrame&) { bus.detach(ic); };
  bus.send(ia, frame(1));
  EXPECT_EQ(b.frames.size(), 1u);
  EXPECT_TRUE(c.frames.empty());
  EXPECT_EQ(bus.endpoint_count(), 2u);
  bus.detach(ib);
  bus.send(ia, frame(2));
  EXPECT_EQ(b.frames.size(), 1u);
}

TEST(Socketcand, element_parser_tolerates_garbage) {
  SocketcandElementParser parser;
  std::vector<std::string> out;
  parser.push("junk< hi >xx< open", out);
  parser.push(" can0 ><<< send 1 0 >", out);
  parser.push("<" + std::string(300, 'x') + "> < echo >", out);
  ASSERT_EQ(out.size(), 4u);
  EXPECT_EQ(out[0], " hi ");
  EXPECT_EQ(out[1], " open can0 ");
  EXPECT_EQ(out[2], " send 1 0 ");
  EXPECT_EQ(out[3], " echo ");
  EXPECT_EQ(parser.dropped_elements(), 3u);
}

TEST(Socketcand, parses_python_can_send_elements) {
  // python-can 4.1.0: unpadded lowercase hex data, uppercase ID and length.
  Result<can::CanFrame> f = parse_socketcand_send(socketcand_words(" send 601 8 40 0 10 0 0 0 0 0 "));
  ASSERT_TRUE(f) << f.error();
  EXPECT_EQ(*f, frame(0x601, {0x40, 0, 0x10, 0, 0, 0, 0, 0}));
  EXPECT_FALSE(f->extended);
  f = parse_socketcand_send(socketcand_words(" send 80 0  "));  // empty frame
  ASSERT_TRUE(f) << f.error();
  EXPECT_EQ(f->dlc, 0);
  f = parse_socketcand_send(socketcand_words("send 1FFFFFFF 2 ab CD"));
  ASSERT_TRUE(f) << f.error();
  EXPECT_TRUE(f->extended);
  EXPECT_EQ(f->data[0], 0xAB);
  EXPECT_EQ(f->data[1], 0xCD);
  f = parse_socketcand_send(socketcand_words("send 00000123 0"));  // 8 digits: extended
  ASSERT_TRUE(f) << f.error();
  EXPECT_TRUE(f->extended);
  EXPECT_EQ(f->id, 0x123u);
  EXPECT_FALSE(parse_socketcand_send(socketcand_words("send 601 2 40")));
  EXPECT_FALSE(parse_socketcand_send(socketcand_words("send 601 9 1 2 3 4 5 6 7 8 9")));
  EXPECT_FALSE(parse_socketcand_send(socketcand_words("send 20000000 0")));
  EXPECT_FALSE(parse_socketcand_send(socketcand_words("send xyz 0")));
  EXPECT_FALSE(parse_socketcand_send(socketcand_words("send 601 1 100")));
  EXPECT_FALSE(parse_socketcand_send(socketcand_words("send 601")));
}

TEST(Socketcand, formats_frames_with_a_space_before_each) {
  EXPECT_EQ(format_socketcand_frame(frame(0x585, {0x43, 0x00, 0x10, 0x00, 0x92, 0x01, 0xFC, 0xFF}), 1'500'000),
            " < frame 585 1.500000 430010009201FCFF >");
  EXPECT_EQ(format_socketcand_frame(frame(0x80), 1'000'000), " < frame 080 1.000000  >");
  can::CanFrame extended = frame(0x123, {1});
  extended.extended = true;
  EXPECT_EQ(format_socketcand_frame(extended, 12), " < frame 00000123 0.000012 01 >");
}

TEST(Socketcand, can_endpoint_specs) {
  Result<CanEndpointSpec> spec = parse_can_endpoint("socketcand");
  ASSERT_TRUE(spec);
  EXPECT_EQ(spec->tcp.host, "127.0.0.1");
  EXPECT_EQ(spec->tcp.port, 29536);
  spec = parse_can_endpoint("socketcand:127.0.0.1:0");
  ASSERT_TRUE(spec);
  EXPECT_EQ(spec->tcp.port, 0);
  spec = parse_can_endpoint("socketcand:4000");
  ASSERT_TRUE(spec);
  EXPECT_EQ(spec->tcp.port, 4000);
  spec = parse_can_endpoint("slcan:/tmp/x");
  ASSERT_TRUE(spec) << spec.error();
  EXPECT_EQ(spec->transport, CanTransport::kSlcanPty);
  EXPECT_EQ(spec->device, "/tmp/x");
  spec = parse_can_endpoint("socketcan:vcan0");
  ASSERT_TRUE(spec) << spec.error();
  EXPECT_EQ(spec->transport, CanTransport::kSocketcan);
  EXPECT_EQ(spec->device, "vcan0");
  EXPECT_FALSE(parse_can_endpoint("slcan"));
  EXPECT_FALSE(parse_can_endpoint("socketcan:"));
  EXPECT_FALSE(parse_can_endpoint("kvaser:0"));
  EXPECT_FALSE(parse_can_endpoint("socketcand:1.2.3.4:99999"));
}

TEST(Slcan, frames_round_trip_through_the_text_form) {
  const can::CanFrame sdo = frame(0x605, {0x40, 0x00, 0x10, 0, 0, 0, 0, 0});
  EXPECT_EQ(format_slcan_frame(sdo), "t60584000100000000000\r");
  EXPECT_EQ(parse_slcan_frame("t60584000100000000000"), sdo);
  can::CanFrame extended = frame(0x1ABCDEF0, {0xAA});
  extended.extended = true;
  EXPECT_EQ(format_slcan_frame(extended), "T1ABCDEF01AA\r");
  EXPECT_EQ(parse_slcan_frame("T1ABCDEF01aa"), extended);
  can::CanFrame rtr = frame(0x123);
  rtr.rtr = true;
  rtr.dlc = 2;
  EXPECT_EQ(format_slcan_frame(rtr), "r1232\r");
  EXPECT_EQ(parse_slcan_frame("r1232"), rtr);
  EXPECT_EQ(format_slcan_frame(frame(0x80)), "t0800\r");
  EXPECT_FALSE(parse_slcan_frame("t8000"));          // 11-bit ID above 0x7FF
  EXPECT_FALSE(parse_slcan_frame("t1232AA"));        // one byte short
  EXPECT_FALSE(parse_slcan_frame("t1239"));          // DLC 9
  EXPECT_FALSE(parse_slcan_frame("T200000000"));     // 29-bit ID too large
  EXPECT_FALSE(parse_slcan_frame("t12G0"));
}

TEST(Slcan, session_follows_the_lawicel_command_set) {
  std::vector<can::CanFrame> sent;
  SlcanSession session([&](const can::CanFrame& f) { sent.push_back(f); });
  std::string reply;
  session.push("t1230\r", reply);
  EXPECT_EQ(reply, "\a");  // closed
  reply.clear();
  session.push("S6\rO\r", reply);
  EXPECT_EQ(reply, "\r\r");
  EXPECT_TRUE(session.open());
  EXPECT_EQ(session.bit_rate_code(), 6);
  reply.clear();
  session.push("S8\rt1230\rT00000123111\rV\rN\rF\rZ1\r\n", reply);
  EXPECT_EQ(reply, "\az\rZ\rV1013\rNMOTW\rF00\r\r");
  ASSERT_EQ(sent.size(), 2u);
  EXPECT_EQ(sent[0], frame(0x123));
  EXPECT_TRUE(sent[1].extended);
  reply.clear();
  session.push(std::string(100, 'x') + "\rC\r", reply);  // overlong line
  EXPECT_EQ(reply, "\a\r");
  EXPECT_FALSE(session.open());
  reply.clear();
  session.push("L\rt1230\r", reply);  // listen only: no transmission
  EXPECT_EQ(reply, "\r\a");
  EXPECT_EQ(sent.size(), 2u);
}

// The bus reads the module's clock when the firmware sends: frames sent during one run_ticks()
// batch carry the time of their own tick, not the batch's start (bit-rate accounting and bus-off
// recovery depend on it). A 1 ms heartbeat over one 20 ms batch: 1 ms apart.
TEST(CanBus, frames_sent_within_one_batch_of_ticks_carry_their_own_tick_time) {
  ModuleOptions options;
  options.node_id = 4;
  options.log = [](const std::string&) {};
  MakeModuleResult made = make_module("tmcm-3216", options);
  ASSERT_TRUE(made) << made.error();
  VirtualModule& module = **made;
  CanBus bus([&module] { return module.sim_time_us(); });
  Recorder master;
  const CanBus::EndpointId master_id = bus.attach(master);
  module.can_node()->connect(bus);
  bus.send(master_id, frame(0x604, {0x2B, 0x17, 0x10, 0x00, 0x01, 0x00, 0, 0}));  // 1017 = 1 ms
  module.run_ticks(1);
  master.frames.clear();
  master.stamps.clear();
  module.run_ticks(20'000 / module.tick_period_us());
  std::vector<uint64_t> heartbeats;
  for (size_t n = 0; n < master.frames.size(); ++n) {
    if (master.frames[n].id == 0x704) heartbeats.push_back(master.stamps[n]);
  }
  ASSERT_GE(heartbeats.size(), 19u);
  for (size_t n = 1; n < heartbeats.size(); ++n) EXPECT_EQ(heartbeats[n] - heartbeats[n - 1], 1000u) << n;
  EXPECT_LE(heartbeats.back(), module.sim_time_us());
  module.can_node()->disconnect();
}

// The whole path: a TCP client, the socketcand server, the bus and the TMCM-3216.
TEST(SocketcandServer, serves_an_sdo_exchange_and_never_echoes) {
  ModuleOptions options;
  options.node_id = 3;
  options.log = [](const std::string&) {};
  MakeModuleResult made = make_module("tmcm-3216", options);
  ASSERT_TRUE(made) << made.error();
  VirtualModule& module = **made;
  EXPECT_FALSE(module.has_tmcl());
  ASSERT_NE(module.can_node(), nullptr);
  EventLoop loop;
  CanBus bus([&module] { return module.sim_time_us(); });
  module.can_node()->connect(bus);
  Result<std::unique_ptr<SocketcandServer>> opened =
      SocketcandServer::open(loop, bus, TcpEndpointSpec{"127.0.0.1", 0}, [](const std::string&) {});
  ASSERT_TRUE(opened) << opened.error();
  testing::TcpTestClient client((*opened)->local_port());
  ASSERT_TRUE(client.connected());
  std::string received;
  auto step = [&] {
    loop.poll_once(1000);
    for (uint8_t b : client.receive_available()) received.push_back(static_cast<char>(b));
  };
  auto has = [&](const std::string& text) { return received.find(text) != std::string::npos; };
  ASSERT_TRUE(testing::pump_until(step, [&] { return has("< hi >"); }));
  auto send_text = [&](const std::string& text) { client.send(testing::Bytes(text.begin(), text.end())); };
  send_text("< open can0 >");
  ASSERT_TRUE(testing::pump_until(step, [&] { return has("< ok >"); }));
  received.clear();
  send_text("< rawmode >");
  ASSERT_TRUE(testing::pump_until(step, [&] { return has("< ok >"); }));
  module.run_ticks(2'500'000 / module.tick_period_us());  // 2.5 s of sim time
  send_text("< send 603 8 40 18 10 2 0 0 0 0 >");
  // Held for SocketcandServer::kRawModeSettleUs after rawmode, then delivered.
  ASSERT_TRUE(testing::pump_until(step, [&] { return has(" < frame 583 "); })) << received;
  EXPECT_TRUE(has(" < frame 583 2.500000 43181002900C0000 >")) << received;
  EXPECT_FALSE(has("frame 603")) << "the client's own frame came back: " << received;
  EXPECT_EQ((*opened)->client_count(), 1u);
  module.can_node()->disconnect();
}

}  // namespace
}  // namespace motwin::host
