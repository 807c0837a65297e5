// TmclHostService's serving order (docs/host-runtime.md, "Serving order"): each connection's
// requests in their order, connections in turn, so a flooding client cannot hold another
// client's request behind its whole queue.
#include <gtest/gtest.h>

#include <string>
#include <vector>

#include "core/tmcl/serial_link.h"
#include "host/event_loop.h"
#include "host/module_registry.h"
#include "host/tmcl_host_service.h"
#include "support/host_test_support.h"

namespace motwin::host {
namespace {

// A connection that logs which connection got each reply, and its value.
struct LoggingChannel final : ReplyChannel {
  LoggingChannel(char channel_name, std::vector<std::string>& reply_log) : name(channel_name), log(reply_log) {}
  void send_reply(const uint8_t* bytes, size_t length) override {
    ASSERT_EQ(length, tmcl::kFrameLength);
    const int32_t value = static_cast<int32_t>((uint32_t{bytes[4]} << 24) | (uint32_t{bytes[5]} << 16) |
                                               (uint32_t{bytes[6]} << 8) | bytes[7]);
    log.push_back(std::string(1, name) + std::to_string(value));
  }
  char name;
  std::vector<std::string>& log;
};

class TmclServiceOrder : public ::testing::Test {
 protected:
  void SetUp() override {
    ModuleOptions options;
    options.log = [](const std::string&) {};
    MakeModuleResult made = make_module("tmcm-1636", options);
    ASSERT_TRUE(made) << made.error();
    module_ = std::move(*made);
    service_ = std::make_unique<TmclHostService>(module_->engine(), loop_);
  }
  // Rounds of serving until nothing is left, as the host runtime does between its polls.
  void serve_all() {
    for (int rounds = 0; service_->total_queued_requests() > 0 && rounds < 1000; ++rounds) service_->serve_queued();
  }
  // SGP of user variable `n` (bank 2) to `value`: its reply echoes the value.
  void send_sgp(tmcl::ChannelId id, uint8_t n, int32_t value) {
    const testing::Bytes frame = testing::request(9, n, 2, value);
    service_->receive(id, frame.data(), frame.size(), 0);
  }

  EventLoop loop_;
  std::unique_ptr<VirtualModule> module_;
  std::unique_ptr<TmclHostService> service_;
  std::vector<std::string> log_;
};

TEST_F(TmclServiceOrder, connections_take_turns_and_each_keeps_its_own_order) {
  LoggingChannel a('a', log_), b('b', log_), c('c', log_);
  const tmcl::ChannelId ia = service_->open_channel(a);
  const tmcl::ChannelId ib = service_->open_channel(b);
  const tmcl::ChannelId ic = service_->open_channel(c);
  for (int32_t k = 1; k <= 6; ++k) send_sgp(ia, 0, k);  // a floods first
  for (int32_t k = 1; k <= 2; ++k) send_sgp(ib, 1, 10 + k);
  send_sgp(ic, 2, 100);
  EXPECT_EQ(service_->total_queued_requests(), 9u);
  EXPECT_EQ(service_->queued_requests(ia), 6u);
  service_->serve_queued();  // one round: one request of each
  EXPECT_EQ(log_, (std::vector<std::string>{"a1", "b11", "c100"}));
  EXPECT_EQ(service_->total_queued_requests(), 6u);
  // A request that arrives between two rounds joins the next one, not the end of the queue.
  LoggingChannel d('d', log_);
  const tmcl::ChannelId id = service_->open_channel(d);
  send_sgp(id, 3, 1000);
  serve_all();
  const std::vector<std::string> expected{"a1", "b11", "c100", "a2", "b12", "d1000", "a3", "a4", "a5", "a6"};
  EXPECT_EQ(log_, expected);
  EXPECT_EQ(service_->total_queued_requests(), 0u);
  EXPECT_EQ(service_->served_request_count(), 10u);
}

// The web console's channel (ChannelTraffic::kBackground) is served like any other, in its turn;
// only its requests are left out of served_host_request_count(), the host runtime's sign of a
// host talking.
TEST_F(TmclServiceOrder, background_channels_take_their_turns_but_are_not_counted_as_host_requests) {
  LoggingChannel host('h', log_), console('c', log_);
  const tmcl::ChannelId ih = service_->open_channel(host);
  const tmcl::ChannelId ic =
      service_->open_channel(console, tmcl::SerialFrameDecoder::kDefaultResyncGapUs, ChannelTraffic::kBackground);
  for (int32_t k = 1; k <= 3; ++k) send_sgp(ic, 0, k);
  send_sgp(ih, 1, 7);
  serve_all();
  EXPECT_EQ(log_, (std::vector<std::string>{"c1", "h7", "c2", "c3"}));
  EXPECT_EQ(service_->served_request_count(), 4u);
  EXPECT_EQ(service_->served_host_request_count(), 1u);
}

TEST_F(TmclServiceOrder, a_connection_whose_queue_ran_dry_joins_the_end_of_the_round) {
  LoggingChannel a('a', log_), b('b', log_);
  const tmcl::ChannelId ia = service_->open_channel(a);
  const tmcl::ChannelId ib = service_->open_channel(b);
  send_sgp(ib, 1, 1);
  for (int32_t k = 1; k <= 3; ++k) send_sgp(ia, 0, k);
  serve_all();
  send_sgp(ia, 0, 4);
  send_sgp(ib, 1, 2);
  serve_all();
  const std::vector<std::string> expected{"b1", "a1", "a2", "a3", "a4", "b2"};
  EXPECT_EQ(log_, expected);
}

// The requests of a connection that went away still run in their turn; their replies are dropped.
TEST_F(TmclServiceOrder, a_closed_connections_requests_run_in_their_turns_without_replies) {
  LoggingChannel a('a', log_), b('b', log_);
  const tmcl::ChannelId ia = service_->open_channel(a);
  const tmcl::ChannelId ib = service_->open_channel(b);
  for (int32_t k = 1; k <= 3; ++k) send_sgp(ia, 0, k);
  send_sgp(ib, 1, 7);
  service_->close_channel(ia);
  serve_all();
  const std::vector<std::string> expected{"b7"};
  EXPECT_EQ(log_, expected);
  EXPECT_EQ(service_->served_request_count(), 4u);
  // The last SGP of the closed connection executed: user variable 0 holds 3.
  LoggingChannel d('d', log_);
  const tmcl::ChannelId id = service_->open_channel(d);
  const testing::Bytes ggp = testing::request(10, 0, 2, 0);
  service_->receive(id, ggp.data(), ggp.size(), 0);
  serve_all();
  EXPECT_EQ(log_.back(), "d3");
}

}  // namespace
}  // namespace motwin::host
