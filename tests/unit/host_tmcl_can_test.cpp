// TMCL over CAN: the core link (core/tmcl/can_link.h) on a real TMCM-1636 engine, the module's
// bus node (host/tmcl_can_node.h) with command 138 and GP 69/70/71, the frame bit counts of the
// bus-load accounting (host/can_bit_timing.h) and several modules on one bus (host/module_group.h).
#include <gtest/gtest.h>

#include <functional>
#include <memory>
#include <vector>

#include "core/tmcl/can_link.h"
#include "host/can_bit_timing.h"
#include "host/can_capture.h"
#include "host/can_device_endpoints.h"
#include "host/event_loop.h"
#include "host/can_bus.h"
#include "host/host_runtime.h"
#include "host/module_group.h"
#include "host/module_registry.h"
#include "host/tmcl_can_node.h"
#include "support/host_test_support.h"

#include <fcntl.h>
#include <linux/can.h>
#include <sys/socket.h>
#include <unistd.h>

namespace motwin::host {
namespace {

using tmcl::Instruction;

struct Recorder final : CanBusEndpoint {
  std::vector<can::CanFrame> frames;
  std::vector<uint64_t> stamps;
  void on_frame(const can::CanFrame& frame, uint64_t timestamp_us) override {
    frames.push_back(frame);
    stamps.push_back(timestamp_us);
  }
};

can::CanFrame frame(uint32_t id, std::vector<uint8_t> data) {
  return can::make_frame(id, data.data(), static_cast<uint8_t>(data.size()));
}

std::vector<uint8_t> bytes_of(const can::CanFrame& f) { return std::vector<uint8_t>(f.data, f.data + f.dlc); }

std::unique_ptr<VirtualModule> make_1636() {
  ModuleOptions options;
  options.log = [](const std::string&) {};
  MakeModuleResult made = make_module("tmcm-1636", options);
  EXPECT_TRUE(made) << made.error();
  return std::move(*made);
}

TEST(TmclCanLink, seven_byte_request_gets_a_seven_byte_reply_on_the_send_id) {
  auto module = make_1636();
  // GGP 71 (receive ID) bank 0.
  const tmcl::CanResponse response =
      tmcl::serve_can_frame(module->engine(), frame(1, {10, 71, 0, 0, 0, 0, 0}), 1);
  ASSERT_TRUE(response.addressed);
  ASSERT_TRUE(response.has_reply);
  EXPECT_EQ(response.reply.id, 2u);
  EXPECT_FALSE(response.reply.extended);
  EXPECT_EQ(bytes_of(response.reply), (std::vector<uint8_t>{1, 100, 10, 0, 0, 0, 1}));
}

TEST(TmclCanLink, eight_byte_request_is_answered_with_eight_bytes_and_its_checksum_is_ignored) {
  auto module = make_1636();
  // SGP user variable 0 (bank 2) = 3000, with a wrong "checksum" byte: CAN has its own CRC.
  const tmcl::CanResponse set = tmcl::serve_can_frame(module->engine(), frame(1, {9, 0, 2, 0, 0, 0x0B, 0xB8, 0x55}), 1);
  ASSERT_TRUE(set.has_reply);
  EXPECT_EQ(bytes_of(set.reply), (std::vector<uint8_t>{1, 100, 9, 0, 0, 0x0B, 0xB8, 0}));
  const tmcl::CanResponse get = tmcl::serve_can_frame(module->engine(), frame(1, {10, 0, 2, 0, 0, 0, 0, 0}), 1);
  EXPECT_EQ(bytes_of(get.reply), (std::vector<uint8_t>{1, 100, 10, 0, 0, 0x0B, 0xB8, 0}));
  // encode_can_request builds what PyTrinamic sends.
  const can::CanFrame built = tmcl::encode_can_request(1, Instruction{6, 4, 0, 0}, 8);
  EXPECT_EQ(built.dlc, 8);
  EXPECT_EQ(built.data[7], static_cast<uint8_t>(1 + 6 + 4));
}

TEST(TmclCanLink, status_codes_are_those_of_the_serial_link) {
  auto module = make_1636();
  // Unknown command 99 -> 2; GAP of an unknown parameter -> 3; motor 5 -> 4.
  EXPECT_EQ(tmcl::serve_can_frame(module->engine(), frame(1, {99, 0, 0, 0, 0, 0, 0}), 1).reply.data[1], 2);
  EXPECT_EQ(tmcl::serve_can_frame(module->engine(), frame(1, {6, 250, 0, 0, 0, 0, 0}), 1).reply.data[1], 3);
  EXPECT_EQ(tmcl::serve_can_frame(module->engine(), frame(1, {6, 4, 5, 0, 0, 0, 0}), 1).reply.data[1], 4);
}

TEST(TmclCanLink, short_frames_get_status_2_and_change_nothing) {
  auto module = make_1636();
  int32_t before = 0;
  ASSERT_EQ(module->engine().device().get_axis_parameter(4, 0, before), tmcl::Status::kOk);
  const tmcl::CanResponse response = tmcl::serve_can_frame(module->engine(), frame(1, {5, 4, 0, 0, 1, 0}), 1);
  ASSERT_TRUE(response.has_reply);
  EXPECT_EQ(bytes_of(response.reply), (std::vector<uint8_t>{1, 2, 5, 0, 0, 0, 0}));
  const tmcl::CanResponse empty = tmcl::serve_can_frame(module->engine(), frame(1, {}), 1);
  EXPECT_EQ(bytes_of(empty.reply), (std::vector<uint8_t>{1, 2, 0, 0, 0, 0, 0}));
  int32_t after = 0;
  ASSERT_EQ(module->engine().device().get_axis_parameter(4, 0, after), tmcl::Status::kOk);
  EXPECT_EQ(after, before);
}

TEST(TmclCanLink, other_ids_and_remote_frames_are_not_addressed) {
  auto module = make_1636();
  EXPECT_FALSE(tmcl::serve_can_frame(module->engine(), frame(2, {6, 4, 0, 0, 0, 0, 0}), 1).addressed);
  EXPECT_FALSE(tmcl::serve_can_frame(module->engine(), frame(0x601, {6, 4, 0, 0, 0, 0, 0}), 1).addressed);
  can::CanFrame remote = frame(1, {});
  remote.rtr = true;
  remote.dlc = 7;
  EXPECT_FALSE(tmcl::serve_can_frame(module->engine(), remote, 1).addressed);
}

TEST(TmclCanLink, version_string_fills_eight_data_bytes) {
  auto module = make_1636();
  const tmcl::CanResponse response = tmcl::serve_can_frame(module->engine(), frame(1, {136, 0, 0, 0, 0, 0, 0}), 1);
  ASSERT_TRUE(response.has_reply);
  EXPECT_EQ(response.reply.id, 2u);
  EXPECT_EQ(std::string(response.reply.data, response.reply.data + response.reply.dlc), "1636V109");
  const tmcl::CanResponse binary = tmcl::serve_can_frame(module->engine(), frame(1, {136, 1, 0, 0, 0, 0, 0}), 1);
  EXPECT_EQ(bytes_of(binary.reply), (std::vector<uint8_t>{1, 100, 136, 0x06, 0x64, 0x01, 0x09}));
}

TEST(TmclCanLink, ascii_mode_is_not_available_and_137_has_no_reply) {
  auto module = make_1636();
  EXPECT_EQ(tmcl::serve_can_frame(module->engine(), frame(1, {139, 0, 0, 0, 0, 0, 0}), 1).reply.data[1], 6);
  const tmcl::CanResponse reset = tmcl::serve_can_frame(module->engine(), frame(1, {137, 0, 0, 0, 0, 0x04, 0xD2}), 1);
  EXPECT_TRUE(reset.addressed);
  EXPECT_FALSE(reset.has_reply);
}

TEST(TmclCanLink, new_ids_take_effect_with_the_reply_to_their_own_sgp) {
  auto module = make_1636();
  const tmcl::CanResponse send_id = tmcl::serve_can_frame(module->engine(), frame(1, {9, 70, 0, 0, 0, 0, 0x12}), 1);
  EXPECT_EQ(send_id.reply.id, 0x12u);
  const tmcl::CanResponse receive_id = tmcl::serve_can_frame(module->engine(), frame(1, {9, 71, 0, 0, 0, 0, 0x11}), 1);
  EXPECT_EQ(receive_id.reply.id, 0x12u);
  EXPECT_EQ(receive_id.reply.data[0], 0x11);  // the new receive ID's low byte
  EXPECT_FALSE(tmcl::serve_can_frame(module->engine(), frame(1, {6, 4, 0, 0, 0, 0, 0}), 1).addressed);
  EXPECT_TRUE(tmcl::serve_can_frame(module->engine(), frame(0x11, {6, 4, 0, 0, 0, 0, 0}), 1).addressed);
}

TEST(TmclCanLink, bit_rate_codes) {
  EXPECT_EQ(tmcl::can_bit_rate_from_code(2), 20'000u);
  EXPECT_EQ(tmcl::can_bit_rate_from_code(5), 125'000u);
  EXPECT_EQ(tmcl::can_bit_rate_from_code(8), 1'000'000u);
  EXPECT_EQ(tmcl::can_bit_rate_from_code(1), 0u);
  EXPECT_EQ(tmcl::can_bit_rate_from_code(9), 0u);
}

TEST(TmclCanNode, answers_on_the_bus_and_sends_the_delayed_138_reply) {
  auto module = make_1636();
  CanBus bus([&module] { return module->sim_time_us(); });
  Recorder host;
  const CanBus::EndpointId host_id = bus.attach(host);
  TmclCanNode* node = module->tmcl_can_node();
  ASSERT_NE(node, nullptr);
  ASSERT_EQ(module->can_node(), node);
  node->connect(bus);
  // MVP absolute 1000, then 138 for motor 0 (8-byte requests: the event is 8 bytes too).
  bus.send(host_id, frame(1, {4, 0, 0, 0, 0, 0x03, 0xE8, 0}));
  bus.send(host_id, frame(1, {138, 0, 0, 0, 0, 0, 1, 0}));
  ASSERT_EQ(host.frames.size(), 2u);
  EXPECT_EQ(bytes_of(host.frames[1]), (std::vector<uint8_t>{1, 100, 138, 0, 0, 0, 1, 0}));
  for (int i = 0; i < 200 && host.frames.size() < 3; ++i) {
    module->run_ticks(200);
    node->deliver_events();
  }
  ASSERT_EQ(host.frames.size(), 3u);
  EXPECT_EQ(host.frames[2].id, 2u);
  EXPECT_EQ(bytes_of(host.frames[2]), (std::vector<uint8_t>{1, 128, 138, 0, 0, 0, 1, 0}));
  EXPECT_EQ(node->served_requests(), 2u);
  node->disconnect();
}

TEST(TmclCanNode, routes_138_replies_through_the_tmcl_service_of_the_runtime) {
  auto module = make_1636();
  HostRuntime runtime(*module, Pacing::fast());
  // The service gave the node a channel: without the routing the 138 reply would be dropped.
  TmclCanNode* node = module->tmcl_can_node();
  CanBus bus([&module] { return module->sim_time_us(); });
  Recorder host;
  const CanBus::EndpointId host_id = bus.attach(host);
  node->connect(bus);
  bus.send(host_id, frame(1, {4, 0, 0, 0, 0, 0x01, 0xF4}));
  bus.send(host_id, frame(1, {138, 0, 0, 0, 0, 0, 1}));
  for (int i = 0; i < 400 && host.frames.size() < 3; ++i) runtime.advance_ticks(100);
  ASSERT_EQ(host.frames.size(), 3u);
  EXPECT_EQ(bytes_of(host.frames[2]), (std::vector<uint8_t>{1, 128, 138, 0, 0, 0, 1}));
  node->disconnect();
}

TEST(TmclCanNode, software_reset_replies_first_and_a_new_bit_rate_applies_after_it) {
  auto module = make_1636();
  CanBus bus([&module] { return module->sim_time_us(); });
  bus.set_bit_rate(1'000'000);
  Recorder host;
  const CanBus::EndpointId host_id = bus.attach(host);
  TmclCanNode& node = *module->tmcl_can_node();
  node.connect(bus);
  EXPECT_EQ(node.active_bit_rate(), 1'000'000u);
  bus.send(host_id, frame(1, {9, 69, 0, 0, 0, 0, 7}));  // SGP 69 = 7 (500 kbit/s)
  ASSERT_EQ(host.frames.size(), 1u);
  EXPECT_EQ(host.frames[0].data[1], 100);
  EXPECT_EQ(node.active_bit_rate(), 1'000'000u);  // not before the power-up
  bus.send(host_id, frame(1, {9, 71, 0, 0, 0, 0, 1}));
  EXPECT_EQ(host.frames.size(), 2u);
  bus.send(host_id, frame(1, {255, 0, 0, 0, 0, 0x04, 0xD2}));  // reset: reply, then power-up
  ASSERT_EQ(host.frames.size(), 3u);
  EXPECT_EQ(bytes_of(host.frames[2]), (std::vector<uint8_t>{1, 100, 255, 0, 0, 0x04, 0xD2}));
  EXPECT_EQ(node.active_bit_rate(), 500'000u);
  EXPECT_FALSE(node.on_speed());
  bus.send(host_id, frame(1, {6, 4, 0, 0, 0, 0, 0}));
  EXPECT_EQ(host.frames.size(), 3u) << "a node on another bit rate must not answer";
  bus.set_bit_rate(500'000);
  bus.send(host_id, frame(1, {6, 4, 0, 0, 0, 0, 0}));
  EXPECT_EQ(host.frames.size(), 4u);
  node.disconnect();
}

TEST(CanBitTiming, counts_fields_and_stuff_bits) {
  // A standard frame with 8 bytes: 111 bits before stuffing.
  const can::CanFrame alternating = frame(0x555, {0x55, 0x55, 0x55, 0x55, 0x55, 0x55, 0x55, 0x55});
  EXPECT_EQ(can_frame_bits(alternating), 111u + can_stuff_bits(alternating));
  EXPECT_LE(can_stuff_bits(alternating), 3u);
  // All-zero data: a stuff bit after every five equal bits.
  const can::CanFrame zeros = frame(0x000, {0, 0, 0, 0, 0, 0, 0, 0});
  EXPECT_GE(can_stuff_bits(zeros), 15u);
  EXPECT_LE(can_frame_bits(zeros), 135u);
  // NMT start all: ID 0, 2 bytes 01 00. SOF+ID are 12 zero bits -> at least 2 stuff bits.
  const can::CanFrame nmt = frame(0x000, {0x01, 0x00});
  EXPECT_EQ(can_frame_bits(nmt) - can_stuff_bits(nmt), 1u + 11 + 1 + 2 + 4 + 16 + 15 + 13);
  EXPECT_GE(can_stuff_bits(nmt), 2u);
  // Extended frame without data: 67 bits before stuffing.
  can::CanFrame extended = frame(0x1ABCDEF, {});
  extended.extended = true;
  EXPECT_EQ(can_frame_bits(extended) - can_stuff_bits(extended), 67u);
}

TEST(CanBusLoad, frames_queue_behind_each_other_at_the_bit_rate) {
  uint64_t now_us = 1000;
  CanBus bus([&now_us] { return now_us; });
  bus.set_bit_rate(125'000);  // 8 µs per bit
  Recorder a, b;
  const CanBus::EndpointId ia = bus.attach(a);
  bus.attach(b);
  const can::CanFrame f = frame(0x181, {1, 2, 3, 4, 5, 6, 7, 8});
  const uint64_t bits = can_frame_bits(f);
  bus.send(ia, f);
  bus.send(ia, f);
  ASSERT_EQ(b.stamps.size(), 2u);
  EXPECT_EQ(b.stamps[0], 1000 + bits * 8);
  EXPECT_EQ(b.stamps[1], 1000 + 2 * bits * 8);
  EXPECT_EQ(bus.stats().frames, 2u);
  EXPECT_EQ(bus.stats().bits, 2 * bits);
  EXPECT_EQ(bus.stats().busy_ns, 2 * bits * 8000);
  EXPECT_EQ(bus.stats().max_queue_delay_ns, bits * 8000);
  // Once the bus is idle again, a frame starts at once.
  now_us = 10'000;
  bus.send(ia, f);
  EXPECT_EQ(b.stamps[2], 10'000 + bits * 8);
  EXPECT_EQ(bus.stats().total_queue_delay_ns, bits * 8000);
}

TEST(CanBusLoad, without_a_bit_rate_frames_take_no_time) {
  uint64_t now_us = 5;
  CanBus bus([&now_us] { return now_us; });
  Recorder a, b;
  const CanBus::EndpointId ia = bus.attach(a);
  bus.attach(b);
  bus.send(ia, frame(0x1, {1}));
  bus.send(ia, frame(0x1, {1}));
  EXPECT_EQ(b.stamps, (std::vector<uint64_t>{5, 5}));
  EXPECT_EQ(bus.stats().busy_ns, 0u);
}

TEST(ModuleGroup, parses_node_options) {
  const Result<NodeSpec> plain = parse_node_spec("tmcm-1636", 3);
  ASSERT_TRUE(plain) << plain.error();
  EXPECT_EQ(plain->name, "tmcm-1636-3");
  const Result<NodeSpec> full = parse_node_spec("tmcm-3216:node-id=5,name=left", 1);
  ASSERT_TRUE(full) << full.error();
  EXPECT_EQ(full->node_id, 5);
  EXPECT_EQ(full->name, "left");
  const Result<NodeSpec> ids = parse_node_spec("tmcm-1636:receive-id=3,send-id=4", 1);
  ASSERT_TRUE(ids) << ids.error();
  EXPECT_EQ(ids->receive_id, 3);
  EXPECT_EQ(ids->send_id, 4);
  const Result<NodeSpec> unknown = parse_node_spec("tmcm-9999", 1);
  EXPECT_FALSE(unknown);
  EXPECT_NE(unknown.error().find("unknown module"), std::string::npos);
  EXPECT_FALSE(parse_node_spec("tmcm-3216:node-id=128", 1));
  EXPECT_FALSE(parse_node_spec("tmcm-3216:colour=red", 1));
  EXPECT_FALSE(parse_node_spec("tmcm-3216:name=../x", 1));
  EXPECT_FALSE(parse_node_spec("tmcm-1636:receive-id=256", 1));
  const Result<NodeSpec> later = parse_node_spec("tmcm-1636:firmware=1.13", 1);
  ASSERT_TRUE(later) << later.error();
  EXPECT_EQ(later->firmware, "1.13");
  const Result<NodeSpec> unknown_firmware = parse_node_spec("tmcm-1636:firmware=2.0", 1);
  ASSERT_FALSE(unknown_firmware);
  EXPECT_NE(unknown_firmware.error().find("choices: 1.09, 1.13"), std::string::npos) << unknown_firmware.error();
  EXPECT_FALSE(parse_node_spec("tmcm-3216:firmware=1.13", 1)) << "one firmware only";
}

// firmware=1.13 reaches the member: command 136 over CAN answers the later generation.
TEST(ModuleGroup, a_node_runs_the_firmware_its_spec_names) {
  std::vector<NodeSpec> specs{*parse_node_spec("tmcm-1636:firmware=1.13", 1)};
  Result<std::unique_ptr<ModuleGroup>> made = ModuleGroup::make(specs, std::nullopt, [](const std::string&) {});
  ASSERT_TRUE(made) << made.error();
  EXPECT_EQ((*made)->members()[0].module->firmware_version(), "1636V113");
}

TEST(ModuleGroup, members_share_one_clock_and_answer_only_their_own_ids) {
  std::vector<NodeSpec> specs;
  for (const char* text : {"tmcm-3216:node-id=1", "tmcm-3216:node-id=2", "tmcm-1636"}) {
    specs.push_back(*parse_node_spec(text, specs.size() + 1));
  }
  Result<std::unique_ptr<ModuleGroup>> made = ModuleGroup::make(specs, std::nullopt, [](const std::string&) {});
  ASSERT_TRUE(made) << made.error();
  ModuleGroup& group = **made;
  EXPECT_EQ(group.tick_period_us(), 50u);
  group.run_ticks(40);  // 2 ms
  for (ModuleGroup::Member& member : group.members()) EXPECT_EQ(member.module->sim_time_us(), 2000u) << member.name;
  CanBus bus([&group] { return group.sim_time_us(); });
  Recorder host;
  const CanBus::EndpointId host_id = bus.attach(host);
  for (ModuleGroup::Member& member : group.members()) member.module->can_node()->connect(bus);
  bus.send(host_id, frame(0x602, {0x40, 0x00, 0x10, 0x00, 0, 0, 0, 0}));  // SDO upload 1000 from node 2
  ASSERT_EQ(host.frames.size(), 1u);
  EXPECT_EQ(host.frames[0].id, 0x582u);
  bus.send(host_id, frame(1, {136, 1, 0, 0, 0, 0, 0}));  // TMCL to the TMCM-1636
  ASSERT_EQ(host.frames.size(), 2u);
  EXPECT_EQ(host.frames[1].id, 2u);
  for (ModuleGroup::Member& member : group.members()) member.module->can_node()->disconnect();
}

TEST(ModuleGroup, refuses_two_nodes_with_one_name) {
  std::vector<NodeSpec> specs{*parse_node_spec("tmcm-3216:name=a", 1), *parse_node_spec("tmcm-1636:name=a", 2)};
  Result<std::unique_ptr<ModuleGroup>> made = ModuleGroup::make(specs, std::nullopt, [](const std::string&) {});
  EXPECT_FALSE(made);
  EXPECT_NE(made.error().find("two nodes named \"a\""), std::string::npos) << made.error();
}

}  // namespace
}  // namespace motwin::host

namespace motwin::host {
namespace {

// SLCAN on a pseudo-terminal: a client opens the link like a serial port.
TEST(SlcanPtyEndpoint, a_client_on_the_pty_exchanges_frames_with_the_bus) {
  EventLoop loop;
  CanBus bus;
  Recorder node;
  const CanBus::EndpointId node_id = bus.attach(node);
  const std::string link = ::testing::TempDir() + "motwin-slcan-test-" + std::to_string(::getpid());
  Result<std::unique_ptr<SlcanPtyEndpoint>> opened =
      SlcanPtyEndpoint::open(loop, bus, link, [](const std::string&) {});
  ASSERT_TRUE(opened) << opened.error();
  const int client = ::open(link.c_str(), O_RDWR | O_NOCTTY | O_NONBLOCK | O_CLOEXEC);
  ASSERT_GE(client, 0);
  std::string received;
  auto step = [&] {
    loop.poll_once(1000);
    char buffer[256];
    const ssize_t n = ::read(client, buffer, sizeof(buffer));
    if (n > 0) received.append(buffer, static_cast<size_t>(n));
  };
  auto send_text = [&](const std::string& text) { ASSERT_EQ(::write(client, text.data(), text.size()), static_cast<ssize_t>(text.size())); };
  // Closed: a frame is refused (BEL) and nothing reaches the bus.
  send_text("t1232AABB\r");
  ASSERT_TRUE(testing::pump_until(step, [&] { return received == "\a"; })) << received;
  EXPECT_TRUE(node.frames.empty());
  received.clear();
  send_text("S8\rO\rt1232AABB\r");
  ASSERT_TRUE(testing::pump_until(step, [&] { return received == "\r\rz\r"; })) << received;
  ASSERT_EQ(node.frames.size(), 1u);
  EXPECT_EQ(node.frames[0], frame(0x123, {0xAA, 0xBB}));
  received.clear();
  bus.send(node_id, frame(0x581, {0x43, 0x00, 0x10}));
  ASSERT_TRUE(testing::pump_until(step, [&] { return received == "t5813430010\r"; })) << received;
  ::close(client);
  opened->reset();
  EXPECT_NE(::access(link.c_str(), F_OK), 0) << "the link must go with the endpoint";
}

TEST(CandumpLine, standard_extended_empty_and_remote_frames) {
  EXPECT_EQ(format_candump_line(frame(0x601, {0x40, 0x00, 0x10, 0x00, 0, 0, 0, 0}), 12'000'250),
            "(12.000250) can0 601#4000100000000000");
  can::CanFrame extended = frame(0x1234567, {0xAB});
  extended.extended = true;
  EXPECT_EQ(format_candump_line(extended, 5, "vcan1"), "(0.000005) vcan1 01234567#AB");
  EXPECT_EQ(format_candump_line(frame(0x7FF, {}), 0), "(0.000000) can0 7FF#");
  can::CanFrame remote = frame(0x701, {});
  remote.rtr = true;
  remote.dlc = 1;
  EXPECT_EQ(format_candump_line(remote, 1'000'000), "(1.000000) can0 701#R");
}

TEST(SocketcanEndpoint, fails_with_a_clear_message_where_there_is_no_af_can) {
  EventLoop loop;
  CanBus bus;
  const int probe = ::socket(PF_CAN, SOCK_RAW, CAN_RAW);
  if (probe >= 0) {
    ::close(probe);
    // With kernel CAN, an interface that does not exist is refused by name.
    Result<std::unique_ptr<SocketcanEndpoint>> opened =
        SocketcanEndpoint::open(loop, bus, "motwinnone0", [](const std::string&) {});
    EXPECT_FALSE(opened);
    EXPECT_NE(opened.error().find("no such CAN interface"), std::string::npos) << opened.error();
    return;
  }
  Result<std::unique_ptr<SocketcanEndpoint>> opened =
      SocketcanEndpoint::open(loop, bus, "vcan0", [](const std::string&) {});
  EXPECT_FALSE(opened);
  EXPECT_NE(opened.error().find("no SocketCAN"), std::string::npos) << opened.error();
  EXPECT_EQ(bus.endpoint_count(), 0u);
}

}  // namespace
}  // namespace motwin::host
