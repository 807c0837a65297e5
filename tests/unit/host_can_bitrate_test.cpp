// Bit-rate mismatch on the virtual bus (host/can_bus.h): a node whose controller runs at another
// rate than the bus neither receives nor sends, its error counters follow ISO 11898-1 fault
// confinement, and it takes part again once the rates match. The TMCM-3216 reports its active
// bit rate (2707): LSS activate bit timing and a stored 2704 + reset change it.
#include <gtest/gtest.h>

#include <vector>

#include "host/can_bus.h"
#include "host/module_registry.h"
#include "host/virtual_module.h"
#include "host/modules/tmcm3216/tmcm3216_virtual_module.h"

namespace motwin::host {
namespace {

// A node whose controller rate the test sets.
struct RatedNode final : CanBusEndpoint {
  uint32_t rate = 0;
  std::vector<can::CanFrame> frames;
  void on_frame(const can::CanFrame& frame, uint64_t /*timestamp_us*/) override { frames.push_back(frame); }
  uint32_t controller_bit_rate() override { return rate; }
};

can::CanFrame frame(uint32_t id, std::vector<uint8_t> data = {}) {
  return can::make_frame(id, data.data(), static_cast<uint8_t>(data.size()));
}

TEST(CanBusBitRate, a_node_off_speed_neither_receives_nor_sends) {
  CanBus bus;
  bus.set_bit_rate(1'000'000);
  RatedNode client, node;  // the client follows the bus (rate 0)
  node.rate = 500'000;
  const CanBus::EndpointId client_id = bus.attach(client);
  const CanBus::EndpointId node_id = bus.attach(node);
  EXPECT_FALSE(bus.takes_part(node_id));
  EXPECT_TRUE(bus.takes_part(client_id));
  bus.send(client_id, frame(0x605, {0x40, 0x00, 0x10, 0}));
  bus.send(node_id, frame(0x585, {0x43}));
  EXPECT_TRUE(node.frames.empty());
  EXPECT_TRUE(client.frames.empty());
  EXPECT_EQ(bus.stats().frames, 1u) << "the node's frame never reached the bus";
  const CanNodeBusStats& stats = *bus.node_stats(node_id);
  EXPECT_TRUE(stats.off_speed);
  EXPECT_EQ(stats.bit_rate, 500'000u);
  EXPECT_EQ(stats.frames_missed, 1u);
  EXPECT_EQ(stats.frames_not_sent, 1u);
  EXPECT_EQ(stats.receive_errors, 1u);
  EXPECT_EQ(stats.transmit_errors, 8u);
  EXPECT_EQ(stats.error_state, CanErrorState::kErrorActive);
  EXPECT_TRUE(stats.any_trouble());
  EXPECT_FALSE(bus.node_stats(client_id)->any_trouble());

  // Its controller set up again at the bus's rate: counters start over, it takes part.
  node.rate = 1'000'000;
  bus.send(client_id, frame(0x605, {0x40}));
  ASSERT_EQ(node.frames.size(), 1u);
  bus.send(node_id, frame(0x585, {0x43}));
  ASSERT_EQ(client.frames.size(), 1u);
  EXPECT_FALSE(bus.node_stats(node_id)->off_speed);
  EXPECT_EQ(bus.node_stats(node_id)->transmit_errors, 0u);
  EXPECT_EQ(bus.node_stats(node_id)->frames_missed, 1u) << "the frame counts add up over the run";
}

TEST(CanBusBitRate, a_bus_without_timing_cuts_nobody_off) {
  CanBus bus;  // bit rate 0
  RatedNode client, node;
  node.rate = 20'000;
  const CanBus::EndpointId client_id = bus.attach(client);
  bus.attach(node);
  bus.send(client_id, frame(0x100, {1}));
  EXPECT_EQ(node.frames.size(), 1u);
}

TEST(CanBusBitRate, a_listener_goes_error_passive_and_back_when_the_bus_matches) {
  CanBus bus;
  bus.set_bit_rate(250'000);
  RatedNode client, node;
  node.rate = 125'000;
  const CanBus::EndpointId client_id = bus.attach(client);
  const CanBus::EndpointId node_id = bus.attach(node);
  for (int i = 0; i < 127; ++i) bus.send(client_id, frame(0x80));
  EXPECT_EQ(bus.node_stats(node_id)->error_state, CanErrorState::kErrorActive);
  EXPECT_TRUE(bus.node_stats(node_id)->warning());
  bus.send(client_id, frame(0x80));
  EXPECT_EQ(bus.node_stats(node_id)->receive_errors, 128u);
  EXPECT_EQ(bus.node_stats(node_id)->error_state, CanErrorState::kErrorPassive);
  for (int i = 0; i < 500; ++i) bus.send(client_id, frame(0x80));
  EXPECT_EQ(bus.node_stats(node_id)->receive_errors, 255u) << "a receiver never goes bus-off";
  EXPECT_EQ(bus.node_stats(node_id)->error_state, CanErrorState::kErrorPassive);
  // The master's adapter switched to the node's rate: the first good frame takes REC to 127.
  bus.set_bit_rate(125'000);
  bus.send(client_id, frame(0x80));
  EXPECT_EQ(node.frames.size(), 1u);
  EXPECT_EQ(bus.node_stats(node_id)->receive_errors, 127u);
  EXPECT_EQ(bus.node_stats(node_id)->error_state, CanErrorState::kErrorActive);
}

TEST(CanBusBitRate, a_talker_goes_bus_off_after_32_frames_and_recovers_after_1408_bit_times) {
  uint64_t now_us = 0;
  CanBus bus([&now_us] { return now_us; });
  bus.set_bit_rate(1'000'000);
  RatedNode client, node;
  node.rate = 500'000;
  const CanBus::EndpointId client_id = bus.attach(client);
  const CanBus::EndpointId node_id = bus.attach(node);
  for (int i = 0; i < 16; ++i) bus.send(node_id, frame(0x705, {0x7F}));
  EXPECT_EQ(bus.node_stats(node_id)->transmit_errors, 128u);
  EXPECT_EQ(bus.node_stats(node_id)->error_state, CanErrorState::kErrorPassive);
  for (int i = 0; i < 16; ++i) bus.send(node_id, frame(0x705, {0x7F}));
  EXPECT_EQ(bus.node_stats(node_id)->error_state, CanErrorState::kBusOff);
  EXPECT_EQ(bus.node_stats(node_id)->bus_off_count, 1u);
  bus.send(node_id, frame(0x705, {0x7F}));  // bus-off: not even tried
  EXPECT_EQ(bus.node_stats(node_id)->transmit_errors, 256u);
  EXPECT_EQ(bus.node_stats(node_id)->frames_not_sent, 33u);
  // 128 x 11 bits at the node's 500 kbit/s: 2816 µs.
  now_us = 2815;
  EXPECT_EQ(bus.node_stats(node_id)->error_state, CanErrorState::kBusOff);
  now_us = 2816;
  EXPECT_EQ(bus.node_stats(node_id)->error_state, CanErrorState::kErrorActive);
  EXPECT_EQ(bus.node_stats(node_id)->transmit_errors, 0u);
  // Bus-off is left by recovery only, even when the rates match meanwhile.
  for (int i = 0; i < 32; ++i) bus.send(node_id, frame(0x705, {0x7F}));
  EXPECT_EQ(bus.node_stats(node_id)->bus_off_count, 2u);
  bus.set_bit_rate(500'000);
  bus.send(client_id, frame(0x000, {0x01, 0x00}));
  EXPECT_TRUE(node.frames.empty()) << "bus-off: the controller is off the bus";
  EXPECT_FALSE(bus.takes_part(node_id));
  now_us += 2816;
  bus.send(node_id, frame(0x705, {0x05}));
  EXPECT_EQ(client.frames.size(), 1u);
  EXPECT_EQ(bus.node_stats(node_id)->error_state, CanErrorState::kErrorActive);
}

TEST(CanBusBitRate, node_part_of_a_can_stats_line) {
  CanNodeBusStats stats;
  stats.bit_rate = 500'000;
  stats.off_speed = true;
  stats.error_state = CanErrorState::kErrorPassive;
  stats.receive_errors = 128;
  stats.frames_missed = 128;
  stats.frames_not_sent = 3;
  stats.transmit_errors = 24;
  EXPECT_EQ(format_node_bus_stats("left", stats),
            " node left bitrate 500000 off-speed error-passive rec 128 tec 24 missed 128 not-sent 3 bus-off 0");
}

TEST(CanBusBitRate, a_tmcl_module_reports_gp_69_from_its_last_power_up) {
  ModuleOptions options;
  options.log = [](const std::string&) {};
  MakeModuleResult made = make_module("tmcm-1636", options);
  ASSERT_TRUE(made) << made.error();
  VirtualModule& module = **made;
  CanBus bus([&module] { return module.sim_time_us(); });
  bus.set_bit_rate(1'000'000);
  RatedNode host;
  const CanBus::EndpointId host_id = bus.attach(host);
  CanBusNode& node = *module.can_node();
  node.connect(bus);
  bus.send(host_id, frame(1, {9, 69, 0, 0, 0, 0, 7}));        // SGP 69 = 7: 500 kbit/s at power-up
  bus.send(host_id, frame(1, {255, 0, 0, 0, 0, 0x04, 0xD2}));  // reset: the reply, then the power-up
  ASSERT_EQ(host.frames.size(), 2u);
  EXPECT_EQ(node.controller_bit_rate(), 500'000u);
  bus.send(host_id, frame(1, {136, 1, 0, 0, 0, 0, 0}));
  EXPECT_EQ(host.frames.size(), 2u);
  const CanNodeBusStats& stats = *bus.node_stats(node);
  EXPECT_TRUE(stats.off_speed);
  EXPECT_EQ(stats.frames_missed, 1u);
  EXPECT_EQ(stats.receive_errors, 1u);
  node.disconnect();
}

// The TMCM-3216 on the bus, driven by raw frames as a master would.
class Tmcm3216OnBus : public ::testing::Test {
 protected:
  void SetUp() override {
    ModuleOptions options;
    options.node_id = 5;
    options.log = [](const std::string&) {};
    MakeModuleResult made = make_module("tmcm-3216", options);
    ASSERT_TRUE(made) << made.error();
    module = std::move(*made);
    bus.set_clock([this] { return module->sim_time_us(); });
    bus.set_bit_rate(1'000'000);
    master_id = bus.attach(master);
    module->can_node()->connect(bus);
  }
  void TearDown() override {
    if (module) module->can_node()->disconnect();
  }
  void run_ms(uint32_t ms) { module->run_ticks(uint64_t{ms} * 1000u / module->tick_period_us()); }
  void send(uint32_t id, std::vector<uint8_t> data) { bus.send(master_id, frame(id, std::move(data))); }
  // The SDO answer to one request, or no frame at all.
  std::vector<can::CanFrame> sdo(std::vector<uint8_t> request) {
    master.frames.clear();
    send(0x605, std::move(request));
    return master.frames;
  }
  bool answers() {
    const std::vector<can::CanFrame> reply = sdo({0x40, 0x00, 0x10, 0x00, 0, 0, 0, 0});
    return reply.size() == 1 && reply[0].id == 0x585;
  }
  const CanNodeBusStats& node_stats() { return *bus.node_stats(*module->can_node()); }

  CanBus bus;
  RatedNode master;  // follows the bus
  CanBus::EndpointId master_id = 0;
  std::unique_ptr<VirtualModule> module;
};

// The restart times `motwin serve` gives the module, and a little more (docs/canopen.md).
constexpr uint32_t kRestartMs = modules::tmcm3216::Tmcm3216::kBootDelayUs / 1000 + 10;
constexpr uint32_t kCommunicationRestartMs = modules::tmcm3216::Tmcm3216::kCommunicationBootDelayUs / 1000 + 10;

TEST_F(Tmcm3216OnBus, lss_activated_bit_rate_cuts_the_node_off_until_the_bus_follows) {
  ASSERT_TRUE(answers());
  send(0x7E5, {0x04, 0x01, 0, 0, 0, 0, 0, 0});  // switch state global: configuration
  master.frames.clear();
  send(0x7E5, {0x13, 0x00, 0x02, 0, 0, 0, 0, 0});  // configure bit timing: table 0, index 2 = 500 kbit/s
  ASSERT_EQ(master.frames.size(), 1u);
  EXPECT_EQ(master.frames[0].data[1], 0) << "configure bit timing accepted";
  send(0x7E5, {0x15, 10, 0, 0, 0, 0, 0, 0});  // activate bit timing, switch delay 10 ms
  EXPECT_TRUE(answers()) << "still at 1 Mbit/s during the switch delay";
  run_ms(25);
  EXPECT_EQ(module->can_node()->controller_bit_rate(), 500'000u);
  EXPECT_FALSE(answers());
  EXPECT_TRUE(node_stats().off_speed);
  EXPECT_GE(node_stats().frames_missed, 1u);
  // NMT reset communication: an LSS-activated rate stays until power-up.
  send(0x000, {0x82, 5});
  run_ms(kCommunicationRestartMs);
  EXPECT_FALSE(answers());
  // The master's adapter follows (CiA-305: every node and the master switch): back on the bus.
  bus.set_bit_rate(500'000);
  EXPECT_TRUE(answers());
  EXPECT_FALSE(node_stats().off_speed);
}

TEST_F(Tmcm3216OnBus, stored_2704_applies_at_the_next_reset) {
  // 2704 = 500 (kbit/s), stored with 2706 sub 1 "save".
  auto ok = [](const std::vector<can::CanFrame>& reply) { return reply.size() == 1 && reply[0].data[0] == 0x60; };
  ASSERT_TRUE(ok(sdo({0x2B, 0x04, 0x27, 0x00, 0xF4, 0x01, 0, 0})));
  ASSERT_TRUE(ok(sdo({0x23, 0x06, 0x27, 0x01, 0x73, 0x61, 0x76, 0x65})));
  EXPECT_TRUE(answers()) << "2704 applies at the next reset only";
  master.frames.clear();
  send(0x000, {0x81, 5});  // reset node
  run_ms(kRestartMs);
  EXPECT_TRUE(master.frames.empty()) << "no boot-up at 1 Mbit/s";
  EXPECT_TRUE(node_stats().off_speed);
  EXPECT_GE(node_stats().frames_not_sent, 1u) << "the boot-up was counted";
  EXPECT_FALSE(answers());
  // Master on 500 kbit/s: write 2704 = 1000 back, store, reset: silent again.
  bus.set_bit_rate(500'000);
  ASSERT_TRUE(answers());
  ASSERT_TRUE(ok(sdo({0x2B, 0x04, 0x27, 0x00, 0xE8, 0x03, 0, 0})));
  ASSERT_TRUE(ok(sdo({0x23, 0x06, 0x27, 0x01, 0x73, 0x61, 0x76, 0x65})));
  send(0x000, {0x81, 5});
  run_ms(kRestartMs);
  EXPECT_FALSE(answers());
  bus.set_bit_rate(1'000'000);
  EXPECT_TRUE(answers());
}

}  // namespace
}  // namespace motwin::host
