#include <gtest/gtest.h>

#include <memory>
#include <string>
#include <vector>

#include "host/tcp_server.h"
#include "host/tmcl_endpoint_options.h"
#include "support/host_test_support.h"

namespace motwin::host {
namespace {

using testing::Bytes;
using testing::reply;
using testing::request;
using testing::slice;
using testing::TcpTestClient;

constexpr uint8_t kGap = 6, kSap = 5, kSgp = 9, kGgp = 10, kSio = 14, kMvp = 4, kRequestEvent = 138,
                  kSoftwareReset = 255;
constexpr int32_t kDefaultMaxVelocity = 4000;  // AP 43 factory default

class TcpServerTest : public ::testing::Test {
 protected:
  void SetUp() override {
    Result<std::unique_ptr<TmclTcpServer>> opened =
        TmclTcpServer::open(rig_.runtime->loop(), rig_.runtime->service(), TcpEndpointSpec{"127.0.0.1", 0},
                            [this](const std::string& line) { log_.push_back(line); });
    ASSERT_TRUE(opened) << opened.error();
    server_ = std::move(*opened);
  }

  // Pumps the loop until `client` holds `count` bytes, then returns them.
  Bytes receive(TcpTestClient& client, size_t count) {
    EXPECT_TRUE(testing::pump_until([this] { rig_.step(); }, [&] { return client.has(count); }))
        << "no reply within the deadline";
    return client.take(count);
  }
  void pump_until(const std::function<bool()>& done) {
    ASSERT_TRUE(testing::pump_until([this] { rig_.step(); }, done));
  }
  // A few loop iterations, for "nothing happens" checks.
  void settle() {
    for (int i = 0; i < 20; ++i) rig_.step();
  }

  testing::ModuleOnRuntime rig_;
  std::vector<std::string> log_;
  std::unique_ptr<TmclTcpServer> server_;  // destroyed before rig_
};

// --tmcl-tcp and --tmcl-pty take the same options after their address.
TEST(TmclEndpointArgument, the_first_comma_ends_the_address_and_echo_is_the_one_option) {
  EXPECT_EQ(parse_tmcl_endpoint_argument("127.0.0.1:0")->address, "127.0.0.1:0");
  EXPECT_EQ(parse_tmcl_endpoint_argument("127.0.0.1:0")->echo, LineEcho::kNone);
  EXPECT_EQ(parse_tmcl_endpoint_argument("127.0.0.1:0,echo")->address, "127.0.0.1:0");
  EXPECT_EQ(parse_tmcl_endpoint_argument("127.0.0.1:0,echo")->echo, LineEcho::kTransceiver);
  EXPECT_EQ(parse_tmcl_endpoint_argument("[::1]:5000,echo")->address, "[::1]:5000");
  EXPECT_EQ(parse_tmcl_endpoint_argument("/tmp/tmcm3216,echo")->address, "/tmp/tmcm3216");
  EXPECT_EQ(parse_tmcl_endpoint_argument("/tmp/tmcm3216,echo,echo")->echo, LineEcho::kTransceiver);
  EXPECT_EQ(parse_tmcl_endpoint_argument("/tmp/a,b").error(),
            "unknown option \"b\" in \"/tmp/a,b\": the options after the address are echo (and the address has "
            "no comma)");
  EXPECT_FALSE(parse_tmcl_endpoint_argument("/tmp/tmcm3216,"));
  EXPECT_FALSE(parse_tmcl_endpoint_argument("/tmp/tmcm3216,Echo"));
  EXPECT_EQ(parse_tmcl_endpoint_argument(",echo").error(),
            "expected an address before the options (ADDRESS[,echo]), got \",echo\"");
  EXPECT_EQ(describe_line_echo(LineEcho::kTransceiver), " echo");
  EXPECT_EQ(describe_line_echo(LineEcho::kNone), "");
}

TEST(TcpEndpointSpec, parses_host_and_port) {
  EXPECT_EQ(parse_tcp_endpoint("127.0.0.1:5000")->host, "127.0.0.1");
  EXPECT_EQ(parse_tcp_endpoint("127.0.0.1:5000")->port, 5000);
  EXPECT_EQ(parse_tcp_endpoint("0.0.0.0:0")->port, 0);
  EXPECT_EQ(parse_tcp_endpoint(":6000")->host, "127.0.0.1");
  EXPECT_EQ(parse_tcp_endpoint("6000")->port, 6000);
  EXPECT_EQ(parse_tcp_endpoint("localhost:1")->host, "localhost");
  EXPECT_EQ(parse_tcp_endpoint("[::1]:7000")->host, "::1");
  EXPECT_EQ(parse_tcp_endpoint("[::1]:7000")->port, 7000);
  for (const char* bad : {"127.0.0.1:65536", "127.0.0.1:", "127.0.0.1:x", "", "[::1]"}) {
    SCOPED_TRACE(bad);
    EXPECT_FALSE(parse_tcp_endpoint(bad));
  }
}

TEST_F(TcpServerTest, port_zero_picks_a_free_port_on_the_loopback_address) {
  EXPECT_NE(server_->local_port(), 0);
  EXPECT_EQ(server_->local_address(), "127.0.0.1:" + std::to_string(server_->local_port()));
}

TEST_F(TcpServerTest, a_port_in_use_is_a_clear_error) {
  Result<std::unique_ptr<TmclTcpServer>> second = TmclTcpServer::open(
      rig_.runtime->loop(), rig_.runtime->service(), TcpEndpointSpec{"127.0.0.1", server_->local_port()});
  EXPECT_FALSE(second);
  EXPECT_EQ(second.error(), "cannot listen on " + server_->local_address() + ": Address already in use");
}

TEST_F(TcpServerTest, answers_a_gap_frame_with_the_exact_reply_bytes) {
  TcpTestClient client(server_->local_port());
  ASSERT_TRUE(client.connected());
  client.send(request(kGap, 43, 0, 0));
  // 02 01 64 06 00 00 0F A0 1C: host 2, module 1, status 100, GAP, 4000.
  EXPECT_EQ(receive(client, 9), (Bytes{0x02, 0x01, 0x64, 0x06, 0x00, 0x00, 0x0F, 0xA0, 0x1C}));
  EXPECT_EQ(server_->client_count(), 1u);
}

TEST_F(TcpServerTest, frames_sent_back_to_back_are_answered_in_order) {
  TcpTestClient client(server_->local_port());
  Bytes burst = request(kSap, 43, 0, 3000);
  for (const Bytes& frame : {request(kGap, 43, 0, 0), request(kSgp, 5, 2, -7), request(kGgp, 5, 2, 0)}) {
    burst.insert(burst.end(), frame.begin(), frame.end());
  }
  client.send(burst);
  const Bytes replies = receive(client, 36);
  EXPECT_EQ(slice(replies, 0, 9), reply(100, kSap, 3000));
  EXPECT_EQ(slice(replies, 9, 18), reply(100, kGap, 3000));
  EXPECT_EQ(slice(replies, 18, 27), reply(100, kSgp, -7));
  EXPECT_EQ(slice(replies, 27, 36), reply(100, kGgp, -7));
}

// The half frames below must be completed within the resync gap. A loaded machine may stall this
// process for that long between the two halves: then the server rightly drops the first half, and
// the attempt is made again with a new client.
constexpr uint64_t kWithinResyncGapUs = TmclTcpServer::kResyncGapUs * 8 / 10;
constexpr int kAttempts = 10;

TEST_F(TcpServerTest, a_half_frame_from_one_client_does_not_disturb_another) {
  TcpTestClient quick(server_->local_port());
  for (int attempt = 1;; ++attempt) {
    TcpTestClient slow(server_->local_port());
    const Bytes slow_frame = request(kGap, 43, 0, 0);
    const uint64_t first_half_us = monotonic_now_us();
    slow.send(slice(slow_frame, 0, 4));
    settle();
    quick.send(request(kSgp, 7, 2, 1234));
    EXPECT_EQ(receive(quick, 9), reply(100, kSgp, 1234));
    EXPECT_EQ(slow.receive_available(), Bytes{});
    if (monotonic_now_us() - first_half_us >= kWithinResyncGapUs) {
      ASSERT_LT(attempt, kAttempts) << "this process stalled for most of the resync gap at every attempt";
      continue;
    }
    slow.send(slice(slow_frame, 4, 9));
    EXPECT_EQ(receive(slow, 9), reply(100, kGap, kDefaultMaxVelocity));
    quick.send(request(kGgp, 7, 2, 0));
    EXPECT_EQ(receive(quick, 9), reply(100, kGgp, 1234));
    EXPECT_EQ(slow.receive_available(), Bytes{});
    break;
  }
}

TEST_F(TcpServerTest, a_stall_of_the_server_is_no_pause_of_the_line) {
  for (int attempt = 1;; ++attempt) {
    TcpTestClient client(server_->local_port());
    const Bytes frame = request(kGap, 43, 0, 0);
    const uint64_t first_half_us = monotonic_now_us();
    client.send(slice(frame, 0, 4));
    settle();  // the first half is read
    if (monotonic_now_us() - first_half_us >= kWithinResyncGapUs) {
      ASSERT_LT(attempt, kAttempts) << "this process stalled for most of the resync gap at every attempt";
      continue;
    }
    // The rest follows at once, but the server does not run for 150 ms (a loaded machine; the
    // TCP resync gap is 100 ms): the bytes wait in the kernel, the client never paused.
    client.send(slice(frame, 4, 9));
    ::usleep(150'000);
    EXPECT_EQ(receive(client, 9), reply(100, kGap, kDefaultMaxVelocity));
    break;
  }
}

TEST_F(TcpServerTest, garbage_from_one_client_is_answered_to_it_alone) {
  TcpTestClient noisy(server_->local_port());
  TcpTestClient good(server_->local_port());
  Bytes bad_checksum = request(kGap, 43, 0, 0);
  bad_checksum[8] ^= 0x55;
  noisy.send(bad_checksum);
  EXPECT_EQ(receive(noisy, 9), reply(1, 0, 0));  // status 1, command 0, value 0
  noisy.send(request(kGap, 43, 0, 0, /*address=*/5));  // another module's frame: no reply
  good.send(request(kGap, 43, 0, 0));
  EXPECT_EQ(receive(good, 9), reply(100, kGap, kDefaultMaxVelocity));
  settle();
  EXPECT_EQ(noisy.receive_available(), Bytes{});
}

TEST_F(TcpServerTest, a_client_leaving_mid_frame_disturbs_nobody) {
  TcpTestClient stays(server_->local_port());
  {
    TcpTestClient leaves(server_->local_port());
    pump_until([this] { return server_->client_count() == 2; });
    leaves.send(slice(request(kSap, 43, 0, 1), 0, 5));
    settle();
  }
  pump_until([this] { return server_->client_count() == 1; });
  stays.send(request(kGap, 43, 0, 0));
  EXPECT_EQ(receive(stays, 9), reply(100, kGap, kDefaultMaxVelocity));  // the half SAP never ran
  EXPECT_EQ(log_.back().find("disconnected (closed by the client)") != std::string::npos, true) << log_.back();
}

TEST_F(TcpServerTest, a_client_that_closes_after_sending_still_gets_its_command_executed) {
  {
    TcpTestClient fire_and_forget(server_->local_port());
    fire_and_forget.send(request(kSap, 43, 0, 2500));
  }
  TcpTestClient checker(server_->local_port());
  pump_until([this] { return server_->client_count() == 1 && rig_.runtime->service().served_request_count() == 1; });
  checker.send(request(kGap, 43, 0, 0));
  EXPECT_EQ(receive(checker, 9), reply(100, kGap, 2500));
}

TEST_F(TcpServerTest, the_telegram_pause_delays_the_reply_without_blocking_others) {
  TcpTestClient client(server_->local_port());
  client.send(request(kSgp, 75, 0, 40));  // GP 75: 40 ms telegram pause from the next request on
  EXPECT_EQ(receive(client, 9), reply(100, kSgp, 40));
  client.send(request(kGap, 43, 0, 0));
  // From the start of the loop iteration that executed it: no later than the execution, however
  // long this process is stalled before it looks.
  uint64_t held_from_us = 0;
  pump_until([&] {
    if (rig_.runtime->service().reply_held()) return true;
    held_from_us = monotonic_now_us();
    return false;
  });
  EXPECT_EQ(client.receive_available(), Bytes{});  // executed, reply held back
  const uint64_t sim_before_us = rig_.runtime->sim_time_us();
  EXPECT_EQ(receive(client, 9), reply(100, kGap, kDefaultMaxVelocity));
  EXPECT_GE(monotonic_now_us() - held_from_us, 30'000u);  // 40 ms from execution, minus our pumping
  EXPECT_GT(rig_.runtime->sim_time_us(), sim_before_us);  // the simulation ran meanwhile
}

TEST_F(TcpServerTest, the_position_reached_event_goes_to_the_client_that_asked) {
  TcpTestClient asker(server_->local_port());
  TcpTestClient other(server_->local_port());
  asker.send(request(kRequestEvent, 0, 0, 1));
  EXPECT_EQ(receive(asker, 9), reply(100, kRequestEvent, 1));
  // Standing at its target the axis is already "reached": the event follows after a tick batch.
  EXPECT_EQ(receive(asker, 9), reply(128, kRequestEvent, 1));
  settle();
  EXPECT_EQ(other.receive_available(), Bytes{});
  EXPECT_EQ(rig_.module->engine().pending_event_count(), 0u);
}

TEST_F(TcpServerTest, a_departed_clients_event_request_is_forgotten) {
  {
    TcpTestClient asker(server_->local_port());
    asker.send(request(kMvp, 0, 0, 1'000'000));  // a long move: not reached for a while
    asker.send(request(kRequestEvent, 0, 0, 1));
    EXPECT_EQ(receive(asker, 18).size(), 18u);
    EXPECT_EQ(rig_.module->engine().pending_event_count(), 1u);
  }
  pump_until([this] { return server_->client_count() == 0; });
  EXPECT_EQ(rig_.module->engine().pending_event_count(), 0u);
}

TEST_F(TcpServerTest, software_reset_replies_first_then_restarts_the_firmware) {
  TcpTestClient client(server_->local_port());
  client.send(request(kSap, 43, 0, 1111));  // not stored: lost by the reset
  EXPECT_EQ(receive(client, 9), reply(100, kSap, 1111));
  client.send(request(kSoftwareReset, 0, 0, 1234));
  EXPECT_EQ(receive(client, 9), reply(100, kSoftwareReset, 1234));
  client.send(request(kGap, 43, 0, 0));
  EXPECT_EQ(receive(client, 9), reply(100, kGap, kDefaultMaxVelocity));
}

TEST_F(TcpServerTest, output_changes_reach_the_runtime_listener_with_their_sim_time) {
  std::vector<sim::OutputChange> changes;
  rig_.runtime->set_output_listener([&](const sim::OutputChange& change) { changes.push_back(change); });
  TcpTestClient client(server_->local_port());
  client.send(request(kSio, 1, 2, 1));  // GPO1 on
  EXPECT_EQ(receive(client, 9), reply(100, kSio, 1));
  ASSERT_EQ(changes.size(), 1u);
  EXPECT_EQ(changes[0].signal, "GPO1");
  EXPECT_EQ(changes[0].level, 1);
  EXPECT_LE(changes[0].sim_time_us, rig_.runtime->sim_time_us());
  EXPECT_EQ(changes[0].sim_time_us % 50, 0u);
}

TEST_F(TcpServerTest, a_flooding_client_is_throttled_not_buffered_without_bound) {
  TcpTestClient flood(server_->local_port());
  Bytes burst;
  for (int i = 0; i < 500; ++i) {
    const Bytes frame = request(kGap, 43, 0, 0);
    burst.insert(burst.end(), frame.begin(), frame.end());
  }
  flood.send(burst);
  rig_.runtime->loop().poll_once(100'000);  // one read: at most one queue's worth of frames
  EXPECT_LE(rig_.runtime->service().total_queued_requests(), TmclHostService::kMaxQueuedRequestsPerChannel);
  const Bytes replies = receive(flood, 500 * 9);
  EXPECT_EQ(slice(replies, 499 * 9, 500 * 9), reply(100, kGap, kDefaultMaxVelocity));
}

TEST_F(TcpServerTest, clients_beyond_the_limit_are_refused_and_a_freed_slot_is_taken_at_once) {
  std::vector<std::unique_ptr<TcpTestClient>> clients;
  for (size_t i = 0; i < TmclTcpServer::kMaxClients; ++i) {
    clients.push_back(std::make_unique<TcpTestClient>(server_->local_port()));
    pump_until([&] { return server_->client_count() == i + 1; });
  }
  TcpTestClient extra(server_->local_port());
  pump_until([&] { return extra.closed_by_peer(); });
  EXPECT_EQ(server_->client_count(), TmclTcpServer::kMaxClients);
  EXPECT_NE(log_.back().find("refusing TCP client"), std::string::npos) << log_.back();
  // A client leaves and another arrives before the loop runs: the newcomer gets the slot.
  clients.front().reset();
  TcpTestClient next(server_->local_port());
  next.send(request(kGap, 43, 0, 0));
  EXPECT_EQ(receive(next, 9), reply(100, kGap, kDefaultMaxVelocity));
  clients.back()->send(request(kGap, 43, 0, 0));
  EXPECT_EQ(receive(*clients.back(), 9), reply(100, kGap, kDefaultMaxVelocity));
}

// Clients that connect and hang up at once, all accepted in one loop iteration on a loaded
// machine, fill the last slots before their hang-ups are polled; a client behind them waits in
// the backlog until they are gone instead of being refused.
TEST_F(TcpServerTest, a_newcomer_behind_clients_that_hung_up_waits_for_their_slots) {
  std::vector<std::unique_ptr<TcpTestClient>> clients;
  constexpr size_t kHangingUp = 4;
  for (size_t i = 0; i < TmclTcpServer::kMaxClients - kHangingUp; ++i) {
    clients.push_back(std::make_unique<TcpTestClient>(server_->local_port()));
    pump_until([&] { return server_->client_count() == i + 1; });
  }
  for (size_t i = 0; i < kHangingUp; ++i) {
    TcpTestClient gone(server_->local_port());  // in the backlog, closed before the loop runs
  }
  TcpTestClient newcomer(server_->local_port());
  newcomer.send(request(kGap, 43, 0, 0));
  EXPECT_EQ(receive(newcomer, 9), reply(100, kGap, kDefaultMaxVelocity));
  EXPECT_EQ(server_->client_count(), TmclTcpServer::kMaxClients - kHangingUp + 1);
  for (const std::string& line : log_) EXPECT_EQ(line.find("refusing"), std::string::npos) << line;
}

TEST_F(TcpServerTest, shutting_the_server_down_closes_its_clients) {
  TcpTestClient client(server_->local_port());
  pump_until([this] { return server_->client_count() == 1; });
  server_.reset();
  EXPECT_TRUE(client.closed_by_peer());
}

// The RS485 transceiver's echo on TCP (`--tmcl-tcp HOST:PORT,echo`): a client writing a byte at a
// time gets each back before it writes the next, then the reply; a client of a server without
// it gets only the reply.
TEST_F(TcpServerTest, with_the_echo_each_byte_comes_back_as_it_arrives_then_the_reply) {
  Result<std::unique_ptr<TmclTcpServer>> opened =
      TmclTcpServer::open(rig_.runtime->loop(), rig_.runtime->service(), TcpEndpointSpec{"127.0.0.1", 0},
                          [](const std::string&) {}, LineEcho::kTransceiver);
  ASSERT_TRUE(opened) << opened.error();
  const std::unique_ptr<TmclTcpServer> echoing = std::move(*opened);
  EXPECT_EQ(echoing->echo(), LineEcho::kTransceiver);
  EXPECT_EQ(server_->echo(), LineEcho::kNone);
  TcpTestClient client(echoing->local_port());
  const Bytes frame = request(kSap, 43, 0, 1234);
  for (size_t i = 0; i < frame.size(); ++i) {
    client.send(Bytes{frame[i]});
    EXPECT_EQ(receive(client, 1), Bytes{frame[i]}) << "byte " << i;
  }
  EXPECT_EQ(receive(client, 9), reply(100, kSap, 1234));
  TcpTestClient plain(server_->local_port());
  plain.send(request(kGap, 43, 0, 0));
  EXPECT_EQ(receive(plain, 9), reply(100, kGap, 1234)) << "no echo on the other server";
  settle();
  EXPECT_EQ(client.receive_available(), Bytes{});
  EXPECT_EQ(plain.receive_available(), Bytes{});
}

}  // namespace
}  // namespace motwin::host
