// ASCII mode through the host transports: each TCP connection switches between binary frames
// and ASCII lines on its own (command 139, BIN), bytes sent right behind the switch are read in
// the new mode, GP 67 bit 0 starts connections in ASCII mode, a power-up returns them to it.
#include <gtest/gtest.h>

#include <memory>
#include <string>
#include <vector>

#include "host/tcp_server.h"
#include "support/host_test_support.h"

namespace motwin::host {
namespace {

using testing::Bytes;
using testing::reply;
using testing::request;
using testing::slice;
using testing::TcpTestClient;

constexpr uint8_t kGap = 6, kSgp = 9, kEnterAscii = 139, kRequestEvent = 138, kSoftwareReset = 255;
constexpr int32_t kDefaultMaxVelocity = 4000;  // AP 43

Bytes text(const std::string& s) { return Bytes(s.begin(), s.end()); }
std::string as_text(const Bytes& b) { return std::string(b.begin(), b.end()); }
Bytes concat(std::initializer_list<Bytes> parts) {
  Bytes out;
  for (const Bytes& part : parts) out.insert(out.end(), part.begin(), part.end());
  return out;
}

class AsciiModeTest : public ::testing::Test {
 protected:
  void SetUp() override {
    Result<std::unique_ptr<TmclTcpServer>> opened = TmclTcpServer::open(
        rig_.runtime->loop(), rig_.runtime->service(), TcpEndpointSpec{"127.0.0.1", 0}, [](const std::string&) {});
    ASSERT_TRUE(opened) << opened.error();
    server_ = std::move(*opened);
  }
  Bytes receive(TcpTestClient& client, size_t count) {
    EXPECT_TRUE(testing::pump_until([this] { rig_.step(); }, [&] { return client.has(count); }))
        << "no reply within the deadline";
    return client.take(count);
  }
  std::string receive_text(TcpTestClient& client, const std::string& expected) {
    return as_text(receive(client, expected.size()));
  }
  void settle() {
    for (int i = 0; i < 20; ++i) rig_.step();
  }

  testing::ModuleOnRuntime rig_;
  std::unique_ptr<TmclTcpServer> server_;
};

TEST_F(AsciiModeTest, command_139_then_lines_then_bin_then_frames_all_in_one_burst) {
  TcpTestClient client(server_->local_port());
  // Everything at once: the bytes behind each switch must be read in the mode that follows it.
  client.send(concat({request(kEnterAscii, 0, 0, 0), text("AGAP 43, 0\rABIN\r"), request(kGap, 43, 0, 0)}));
  EXPECT_EQ(receive(client, 9), reply(100, kEnterAscii, 0)) << "the reply to 139 is binary";
  const std::string lines = "AGAP 43, 0\rBA 100 4000\rABIN\rBA 100 0\r";
  EXPECT_EQ(receive_text(client, lines), lines);
  EXPECT_EQ(receive(client, 9), reply(100, kGap, kDefaultMaxVelocity)) << "binary again after BIN";
  settle();
  EXPECT_EQ(client.receive_available(), Bytes{});
}

TEST_F(AsciiModeTest, each_connection_has_its_own_mode) {
  TcpTestClient terminal(server_->local_port());
  TcpTestClient binary(server_->local_port());
  terminal.send(request(kEnterAscii, 0, 0, 0));
  EXPECT_EQ(receive(terminal, 9), reply(100, kEnterAscii, 0));
  binary.send(request(kGap, 43, 0, 0));
  EXPECT_EQ(receive(binary, 9), reply(100, kGap, kDefaultMaxVelocity));
  terminal.send(text("ASAP 43, 0, 3000\r"));
  const std::string expected = "ASAP 43, 0, 3000\rBA 100 3000\r";
  EXPECT_EQ(receive_text(terminal, expected), expected);
  binary.send(request(kGap, 43, 0, 0));
  EXPECT_EQ(receive(binary, 9), reply(100, kGap, 3000));
  // Binary frames on the ASCII connection are just garbage lines there: never a binary reply.
  terminal.send(request(kGap, 43, 0, 0));
  settle();
  EXPECT_EQ(terminal.receive_available(), Bytes{});
}

TEST_F(AsciiModeTest, characters_are_echoed_as_they_arrive_and_a_line_is_answered_at_cr) {
  TcpTestClient terminal(server_->local_port());
  terminal.send(request(kEnterAscii, 0, 0, 0));
  EXPECT_EQ(receive(terminal, 9), reply(100, kEnterAscii, 0));
  terminal.send(text("AGAP"));
  EXPECT_EQ(receive_text(terminal, "AGAP"), "AGAP");
  terminal.send(text(" 43, 0"));
  EXPECT_EQ(receive_text(terminal, " 43, 0"), " 43, 0");
  terminal.send(text("\r"));
  EXPECT_EQ(receive_text(terminal, "\rBA 100 4000\r"), "\rBA 100 4000\r");
}

TEST_F(AsciiModeTest, gp67_bit_0_starts_new_connections_in_ascii_mode_and_a_reset_returns_to_it) {
  TcpTestClient setup(server_->local_port());
  setup.send(request(kSgp, 67, 0, 0x21));  // start in ASCII, no echo
  EXPECT_EQ(receive(setup, 9), reply(100, kSgp, 0x21));
  TcpTestClient terminal(server_->local_port());
  terminal.send(text("AGAP 43, 0\r"));
  EXPECT_EQ(receive_text(terminal, "BA 100 4000\r"), "BA 100 4000\r");
  terminal.send(text("ABIN\r"));
  EXPECT_EQ(receive_text(terminal, "BA 100 0\r"), "BA 100 0\r");
  // A software reset (from the other connection) powers the module up: every link returns to
  // the start mode, this one to ASCII.
  setup.send(request(kSoftwareReset, 0, 0, 1234));
  EXPECT_EQ(receive(setup, 9), reply(100, kSoftwareReset, 1234));
  terminal.send(text("AGGP 67, 0\r"));
  EXPECT_EQ(receive_text(terminal, "BA 100 33\r"), "BA 100 33\r");
  // ... including the connection that sent the reset.
  setup.send(text("AGAP 43, 0\r"));
  EXPECT_EQ(receive_text(setup, "BA 100 4000\r"), "BA 100 4000\r");
}

TEST_F(AsciiModeTest, the_telegram_pause_applies_to_ascii_replies_too) {
  TcpTestClient terminal(server_->local_port());
  terminal.send(request(kSgp, 67, 0, 0x20));
  EXPECT_EQ(receive(terminal, 9), reply(100, kSgp, 0x20));
  terminal.send(request(kEnterAscii, 0, 0, 0));
  EXPECT_EQ(receive(terminal, 9), reply(100, kEnterAscii, 0));
  terminal.send(text("ASGP 75, 0, 30\r"));
  EXPECT_EQ(receive_text(terminal, "BA 100 30\r"), "BA 100 30\r");
  const uint64_t sent_us = monotonic_now_us();
  terminal.send(text("AGAP 43, 0\r"));
  EXPECT_EQ(receive_text(terminal, "BA 100 4000\r"), "BA 100 4000\r");
  EXPECT_GE(monotonic_now_us() - sent_us, 25'000u);
}

TEST_F(AsciiModeTest, a_position_event_asked_in_binary_arrives_as_a_line_in_ascii_mode) {
  TcpTestClient client(server_->local_port());
  client.send(request(kSgp, 67, 0, 0x20));
  EXPECT_EQ(receive(client, 9), reply(100, kSgp, 0x20));
  // Standing at its target, the axis counts as reached: the event follows the next tick batch.
  // The two requests are served one loop iteration apart (docs/host-runtime.md, serving order);
  // should a tick batch fall in between (this process stalled on a loaded machine), the event
  // comes before the switch, in binary: back to binary mode, and once more.
  for (int attempt = 1;; ++attempt) {
    client.send(concat({request(kRequestEvent, 0, 0, 1), request(kEnterAscii, 0, 0, 0)}));
    const Bytes replies = receive(client, 18);
    if (replies == concat({reply(100, kRequestEvent, 1), reply(128, kRequestEvent, 1)})) {
      ASSERT_LT(attempt, 10) << "a tick batch came between the two requests at every attempt";
      EXPECT_EQ(receive(client, 9), reply(100, kEnterAscii, 0));
      client.send(text("ABIN\r"));
      EXPECT_EQ(receive_text(client, "BA 100 0\r"), "BA 100 0\r");
      continue;
    }
    EXPECT_EQ(replies, concat({reply(100, kRequestEvent, 1), reply(100, kEnterAscii, 0)}));
    EXPECT_EQ(receive_text(client, "BA 128 1\r"), "BA 128 1\r");
    break;
  }
}

TEST_F(AsciiModeTest, a_flood_of_lines_is_answered_in_order_without_unbounded_buffering) {
  TcpTestClient terminal(server_->local_port());
  terminal.send(request(kSgp, 67, 0, 0x20));
  EXPECT_EQ(receive(terminal, 9), reply(100, kSgp, 0x20));
  terminal.send(request(kEnterAscii, 0, 0, 0));
  EXPECT_EQ(receive(terminal, 9), reply(100, kEnterAscii, 0));
  std::string burst;
  std::string expected;
  for (int i = 0; i < 2000; ++i) {
    burst += "ASGP 7, 2, " + std::to_string(i) + "\r";
    expected += "BA 100 " + std::to_string(i) + "\r";
  }
  terminal.send(text(burst));
  rig_.runtime->loop().poll_once(100'000);
  EXPECT_LE(rig_.runtime->service().total_queued_requests(), 1u) << "one line at a time";
  EXPECT_EQ(as_text(receive(terminal, expected.size())), expected);
}

TEST_F(AsciiModeTest, an_endless_line_is_answered_and_does_not_grow_the_server) {
  TcpTestClient terminal(server_->local_port());
  terminal.send(request(kSgp, 67, 0, 0x20));
  EXPECT_EQ(receive(terminal, 9), reply(100, kSgp, 0x20));
  terminal.send(request(kEnterAscii, 0, 0, 0));
  EXPECT_EQ(receive(terminal, 9), reply(100, kEnterAscii, 0));
  terminal.send(text("A" + std::string(200'000, 'Z') + "\rAGAP 43, 0\r"));
  EXPECT_EQ(receive_text(terminal, "BA 2 0\rBA 100 4000\r"), "BA 2 0\rBA 100 4000\r");
}

}  // namespace
}  // namespace motwin::host
