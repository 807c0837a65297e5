// The busy-poll window of the host runtime (HostRuntime::kBusyPollAfterRequestUs): input from a
// host on any descriptor opens it, whatever the protocol, so a CAN-only `serve --node ...` (no
// TMCL service) answers socketcand round trips without a wake-up from sleep each time
// (docs/benchmarks.md, "CAN round trip"). Values only: no timing is asserted.
#include <gtest/gtest.h>

#include <unistd.h>

#include <memory>
#include <string>
#include <vector>

#include "host/can_bus.h"
#include "host/event_loop.h"
#include "host/host_runtime.h"
#include "host/module_group.h"
#include "host/module_registry.h"
#include "host/socketcand_server.h"
#include "support/host_test_support.h"

namespace motwin::host {
namespace {

using testing::Pipe;

void quiet(const std::string&) {}

TEST(EventLoop, counts_callbacks_with_input_but_not_writable_ones) {
  EventLoop loop;
  Pipe pipe;
  size_t reads = 0, writables = 0;
  loop.watch(pipe.read_fd, POLLIN, [&](short) {
    char byte = 0;
    EXPECT_EQ(::read(pipe.read_fd, &byte, 1), 1);
    ++reads;
  });
  loop.poll_once(0);
  EXPECT_EQ(loop.input_event_count(), 0u);
  ASSERT_EQ(::write(pipe.write_fd, "a", 1), 1);
  loop.poll_once(1'000'000);
  EXPECT_EQ(reads, 1u);
  EXPECT_EQ(loop.input_event_count(), 1u);
  // An empty pipe's write end is always writable: its callback runs, yet nobody talked.
  loop.watch(pipe.write_fd, POLLOUT, [&](short) { ++writables; });
  loop.poll_once(0);
  EXPECT_EQ(writables, 1u);
  EXPECT_EQ(loop.input_event_count(), 1u);
  ASSERT_EQ(::write(pipe.write_fd, "bc", 2), 2);
  loop.poll_once(1'000'000);  // one readable event, however many bytes
  EXPECT_EQ(loop.input_event_count(), 2u);
}

TEST(HostRuntimeBusyPoll, input_on_any_descriptor_opens_the_window_and_output_alone_does_not) {
  ModuleOptions options;
  options.node_id = 1;
  options.log = quiet;
  MakeModuleResult made = make_module("tmcm-3216", options);
  ASSERT_TRUE(made) << made.error();
  HostRuntime runtime(**made, Pacing::realtime());
  ASSERT_FALSE(runtime.has_tmcl_service());
  runtime.start();
  Pipe pipe;
  runtime.loop().watch(pipe.write_fd, POLLOUT, [](short) {});
  runtime.step(0);
  runtime.step(0);
  EXPECT_EQ(runtime.busy_poll_until_us(), 0u);
  runtime.loop().unwatch(pipe.write_fd);

  runtime.loop().watch(pipe.read_fd, POLLIN, [&](short) {
    char byte = 0;
    EXPECT_EQ(::read(pipe.read_fd, &byte, 1), 1);
  });
  const uint64_t before_us = monotonic_now_us();
  ASSERT_EQ(::write(pipe.write_fd, "x", 1), 1);
  runtime.step(1'000'000);
  const uint64_t after_us = monotonic_now_us();
  EXPECT_GE(runtime.busy_poll_until_us(), before_us + HostRuntime::kBusyPollAfterRequestUs);
  EXPECT_LE(runtime.busy_poll_until_us(), after_us + HostRuntime::kBusyPollAfterRequestUs);
  // A step without input leaves the window where it was.
  const uint64_t window_us = runtime.busy_poll_until_us();
  runtime.step(0);
  EXPECT_EQ(runtime.busy_poll_until_us(), window_us);
}

// The web console's reads of subscribed values go through the TMCL service on a background
// channel: served, they leave the window closed (an idle serve with pages open still sleeps
// between its tick batches); a host's request on an ordinary channel opens it.
TEST(HostRuntimeBusyPoll, requests_of_a_background_channel_do_not_open_the_window) {
  ModuleOptions options;
  options.log = quiet;
  MakeModuleResult made = make_module("tmcm-1636", options);
  ASSERT_TRUE(made) << made.error();
  HostRuntime runtime(**made, Pacing::realtime());
  ASSERT_TRUE(runtime.has_tmcl_service());
  runtime.start();
  struct Replies final : ReplyChannel {
    void send_reply(const uint8_t*, size_t length) override { bytes += length; }
    size_t bytes = 0;
  } console, host;
  TmclHostService& service = runtime.service();
  const tmcl::ChannelId console_channel =
      service.open_channel(console, tmcl::SerialFrameDecoder::kDefaultResyncGapUs, ChannelTraffic::kBackground);
  const tmcl::ChannelId host_channel = service.open_channel(host);
  const testing::Bytes gap = testing::request(6, 1, 0, 0);
  for (int i = 0; i < 3; ++i) service.receive(console_channel, gap.data(), gap.size(), monotonic_now_us());
  for (int step = 0; step < 100 && console.bytes < 3 * tmcl::kFrameLength; ++step) runtime.step(0);
  EXPECT_EQ(console.bytes, 3 * tmcl::kFrameLength);
  EXPECT_EQ(runtime.busy_poll_until_us(), 0u);

  const uint64_t before_us = monotonic_now_us();
  service.receive(host_channel, gap.data(), gap.size(), before_us);
  for (int step = 0; step < 100 && host.bytes < tmcl::kFrameLength; ++step) runtime.step(0);
  EXPECT_EQ(host.bytes, tmcl::kFrameLength);
  EXPECT_GE(runtime.busy_poll_until_us(), before_us + HostRuntime::kBusyPollAfterRequestUs);
  service.close_channel(console_channel);
  service.close_channel(host_channel);
}

// The benchmark's set-up (bench/bench_can_roundtrip.cpp): a TMCM-3216 and a TMCM-1636 on one bus
// in one runtime, a socketcand client. Each request opens the window; the sim time stays on the
// tick grid and never runs ahead of the wall clock while the loop spins.
TEST(HostRuntimeBusyPoll, can_frames_from_a_socketcand_client_open_the_window_of_a_can_only_group) {
  std::vector<NodeSpec> specs;
  for (const char* text : {"tmcm-3216:node-id=1", "tmcm-1636"}) {
    const Result<NodeSpec> spec = parse_node_spec(text, specs.size() + 1);
    ASSERT_TRUE(spec) << spec.error();
    specs.push_back(*spec);
  }
  Result<std::unique_ptr<ModuleGroup>> made = ModuleGroup::make(specs, std::nullopt, quiet);
  ASSERT_TRUE(made) << made.error();
  ModuleGroup& group = **made;
  HostRuntime runtime(group, Pacing::realtime());
  ASSERT_FALSE(runtime.has_tmcl_service());
  CanBus bus([&group] { return group.sim_time_us(); });
  for (ModuleGroup::Member& member : group.members()) member.module->can_node()->connect(bus);
  Result<std::unique_ptr<SocketcandServer>> opened =
      SocketcandServer::open(runtime.loop(), bus, TcpEndpointSpec{"127.0.0.1", 0}, quiet);
  ASSERT_TRUE(opened) << opened.error();
  runtime.start();

  testing::TcpTestClient client((*opened)->local_port());
  ASSERT_TRUE(client.connected());
  std::string received;
  const auto step = [&] {
    runtime.step(1000);
    for (uint8_t b : client.receive_available()) received.push_back(static_cast<char>(b));
  };
  const auto has = [&](const std::string& text) { return received.find(text) != std::string::npos; };
  const auto send_text = [&](const std::string& text) { client.send(testing::Bytes(text.begin(), text.end())); };
  ASSERT_TRUE(testing::pump_until(step, [&] { return has("< hi >"); }));
  send_text("< open can0 >");
  ASSERT_TRUE(testing::pump_until(step, [&] { return has("< ok >"); }));
  received.clear();
  send_text("< rawmode >");
  ASSERT_TRUE(testing::pump_until(step, [&] { return has("< ok >"); }));

  struct Exchange {
    const char* request;
    const char* reply;
  };
  // An SDO upload of 1000 sub 0 from node 1 (reply on 0x581), and TMCL GAP 4 over CAN to the
  // TMCM-1636 (request on ID 1, reply on ID 2 with status 100).
  for (const Exchange& exchange : {Exchange{"< send 601 8 40 00 10 00 00 00 00 00 >", " < frame 581 "},
                                   Exchange{"< send 1 7 06 04 00 00 00 00 00 >", " < frame 002 "}}) {
    received.clear();
    const uint64_t before_us = monotonic_now_us();
    send_text(exchange.request);
    ASSERT_TRUE(testing::pump_until(step, [&] { return has(exchange.reply); })) << received;
    EXPECT_GE(runtime.busy_poll_until_us(), before_us + HostRuntime::kBusyPollAfterRequestUs) << exchange.request;
    EXPECT_LE(runtime.busy_poll_until_us(), monotonic_now_us() + HostRuntime::kBusyPollAfterRequestUs);
    // Whole ticks, not ahead of the wall clock, every member within one of its ticks of the group.
    EXPECT_EQ(runtime.sim_time_us(), group.tick_count() * group.tick_period_us());
    EXPECT_LE(runtime.sim_time_us(), runtime.pacer().target_sim_us(monotonic_now_us()));
    for (ModuleGroup::Member& member : group.members()) {
      EXPECT_LE(member.module->sim_time_us(), runtime.sim_time_us()) << member.name;
      EXPECT_GT(member.module->sim_time_us() + member.module->tick_period_us(), runtime.sim_time_us()) << member.name;
    }
  }
  for (ModuleGroup::Member& member : group.members()) member.module->can_node()->disconnect();
}

}  // namespace
}  // namespace motwin::host
