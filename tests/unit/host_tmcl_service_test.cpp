// TmclHostService's serving order (docs/host-runtime.md, "Serving order"): each connection's
// requests in their order, connections in turn, so a flooding client cannot hold another
// client's request behind its whole queue. And the RS485 transceiver's echo (LineEcho): each
// byte back as it arrives, ahead of the reply, whatever the bytes are.
#include <gtest/gtest.h>

#include <functional>
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

// A connection that keeps every byte it is sent, in order.
struct RecordingChannel final : ReplyChannel {
  void send_reply(const uint8_t* bytes, size_t length) override { heard.insert(heard.end(), bytes, bytes + length); }
  testing::Bytes heard;
};

testing::Bytes joined(const testing::Bytes& first, const testing::Bytes& second) {
  testing::Bytes both = first;
  both.insert(both.end(), second.begin(), second.end());
  return both;
}

class TmclServiceEcho : public TmclServiceOrder {
 protected:
  // Hands the bytes to the service one at a time, `spacing_us` apart on the line, serving after
  // each as the host runtime does between its polls; `after_each` sees the channel after each.
  void send_bytewise(tmcl::ChannelId id, const testing::Bytes& bytes, uint64_t spacing_us,
                     const std::function<void(size_t sent)>& after_each) {
    for (size_t i = 0; i < bytes.size(); ++i) {
      now_us_ += spacing_us;
      service_->receive(id, &bytes[i], 1, now_us_);
      after_each(i + 1);
      serve_all();
    }
  }
  uint64_t now_us_ = 0;
};

// What Zephyr's TMCM RS485 bus driver does: a byte, its echo, the next byte ... and after the
// ninth echo the reply. A channel without the echo beside it hears only its reply. The bytes are
// 200 ms apart, as a host waiting for each echo on a loaded machine may send them: far more than
// a serial line's resync gap, less than an echoing link's (kEchoResyncGapUs).
TEST_F(TmclServiceEcho, each_byte_comes_back_as_it_arrives_and_the_reply_follows_the_ninth) {
  RecordingChannel rs485, plain;
  const tmcl::ChannelId echoing = service_->open_channel(rs485, tmcl::SerialFrameDecoder::kDefaultResyncGapUs,
                                                         ChannelTraffic::kHost, LineEcho::kTransceiver);
  const tmcl::ChannelId quiet = service_->open_channel(plain);
  const testing::Bytes sap = testing::request(5, 43, 0, 2000);  // SAP 43 (max velocity), 0, 2000
  send_bytewise(echoing, sap, 200'000, [&](size_t sent) {
    EXPECT_EQ(rs485.heard, testing::slice(sap, 0, sent)) << "after byte " << sent;
  });
  EXPECT_EQ(rs485.heard, joined(sap, testing::reply(100, 5, 2000)));
  const testing::Bytes gap = testing::request(6, 43, 0, 0);
  service_->receive(quiet, gap.data(), gap.size(), now_us_);
  serve_all();
  EXPECT_EQ(plain.heard, testing::reply(100, 6, 2000));
  EXPECT_EQ(rs485.heard.size(), 18u) << "another connection's traffic is not echoed here";
}

// The transceiver knows nothing of TMCL: a bad checksum, a frame for another module on the bus
// and a burst of several frames come back whole, and every reply still after its frame's echo.
TEST_F(TmclServiceEcho, garbage_and_other_modules_frames_are_echoed_too) {
  RecordingChannel rs485;
  const tmcl::ChannelId id = service_->open_channel(rs485, tmcl::SerialFrameDecoder::kDefaultResyncGapUs,
                                                    ChannelTraffic::kHost, LineEcho::kTransceiver);
  testing::Bytes bad_checksum = testing::request(9, 0, 2, 7);
  bad_checksum.back() ^= 0x55;
  send_bytewise(id, bad_checksum, 1000, [&](size_t sent) {
    EXPECT_EQ(rs485.heard, testing::slice(bad_checksum, 0, sent));
  });
  EXPECT_EQ(rs485.heard, joined(bad_checksum, testing::reply(1, 0, 0))) << "status 1 after the echo";
  rs485.heard.clear();
  const testing::Bytes other_module = testing::request(9, 0, 2, 7, /*address=*/2);
  service_->receive(id, other_module.data(), other_module.size(), now_us_ += 10'000);
  serve_all();
  EXPECT_EQ(rs485.heard, other_module) << "echoed, and not answered";
  rs485.heard.clear();
  // A host that gives up on a frame and pauses for the gap starts afresh; the echo is of all.
  const testing::Bytes abandoned = testing::slice(testing::request(9, 0, 2, 99), 0, 4);
  service_->receive(id, abandoned.data(), abandoned.size(), now_us_ += 10'000);
  const testing::Bytes fresh = testing::request(9, 0, 2, 8);
  service_->receive(id, fresh.data(), fresh.size(), now_us_ += TmclHostService::kEchoResyncGapUs + 1000);
  serve_all();
  EXPECT_EQ(rs485.heard, joined(joined(abandoned, fresh), testing::reply(100, 9, 8)));
  rs485.heard.clear();
  const testing::Bytes burst = joined(testing::request(9, 1, 2, 11), testing::request(10, 1, 2, 0));
  service_->receive(id, burst.data(), burst.size(), now_us_ += 10'000);
  EXPECT_EQ(rs485.heard, burst) << "the echo of a burst precedes every reply";
  serve_all();
  EXPECT_EQ(rs485.heard, joined(burst, joined(testing::reply(100, 9, 11), testing::reply(100, 10, 11))));
}

// The transceiver sits below the protocol: in ASCII mode (command 139) each character comes
// back from it, then the firmware's own echo of the character, then the reply line.
TEST_F(TmclServiceEcho, ascii_mode_gets_the_transceivers_echo_before_the_firmwares) {
  RecordingChannel rs485;
  const tmcl::ChannelId id = service_->open_channel(rs485, tmcl::SerialFrameDecoder::kDefaultResyncGapUs,
                                                    ChannelTraffic::kHost, LineEcho::kTransceiver);
  const testing::Bytes enter_ascii = testing::request(139, 0, 0, 0);
  service_->receive(id, enter_ascii.data(), enter_ascii.size(), now_us_);
  serve_all();
  EXPECT_EQ(rs485.heard, joined(enter_ascii, testing::reply(100, 139, 0)));
  ASSERT_EQ(service_->link_mode(id), LinkMode::kAscii);
  rs485.heard.clear();
  const std::string line = "AGAP 43, 0\r";  // AP 43: max velocity, 4000 at factory
  std::string expected;
  for (const char c : line) expected += std::string(2, c);  // the transceiver's, then the firmware's
  send_bytewise(id, testing::Bytes(line.begin(), line.end()), 1000, [&](size_t sent) {
    EXPECT_EQ(std::string(rs485.heard.begin(), rs485.heard.end()), expected.substr(0, 2 * sent));
  });
  EXPECT_EQ(std::string(rs485.heard.begin(), rs485.heard.end()), expected + "BA 100 4000\r");
}

}  // namespace
}  // namespace motwin::host
