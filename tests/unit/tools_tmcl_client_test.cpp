#include "tools/tmcl_client.h"

#include <fcntl.h>
#include <netinet/in.h>
#include <stdlib.h>
#include <sys/socket.h>
#include <unistd.h>

#include <gtest/gtest.h>

#include <atomic>
#include <chrono>
#include <cstring>
#include <mutex>
#include <thread>

#include "support/tmcm1636_rig.h"
#include "tools/fd_io.h"
#include "tools/loopback_frame_server.h"
#include "tools/tmcl_mnemonics.h"
#include "tools/unique_fd.h"

namespace motwin::tools {
namespace {

using namespace std::chrono_literals;

tmcl::Frame frame_from_hex(std::initializer_list<uint8_t> bytes) {
  tmcl::Frame frame{};
  std::copy(bytes.begin(), bytes.end(), frame.begin());
  return frame;
}

tmcl::Instruction instruction(std::string_view text) {
  const Result<tmcl::Instruction> parsed = parse_instruction(text);
  EXPECT_TRUE(parsed) << text;
  return parsed ? parsed.value() : tmcl::Instruction{};
}

std::unique_ptr<LoopbackFrameServer> start_server(LoopbackFrameServer::Responder responder) {
  Result<std::unique_ptr<LoopbackFrameServer>> server = LoopbackFrameServer::start(std::move(responder));
  EXPECT_TRUE(server) << (server ? "" : server.error());
  return server ? std::move(server.value()) : nullptr;
}

TmclClient connect(const LoopbackFrameServer& server) {
  Result<TmclClient> client = TmclClient::connect_tcp(server.address());
  if (!client) ADD_FAILURE() << client.error();
  return std::move(client.value());
}

// A port nobody listens on: bound once to get a free number, then closed.
uint16_t unused_port() {
  UniqueFd socket_fd(::socket(AF_INET, SOCK_STREAM, 0));
  sockaddr_in address{};
  address.sin_family = AF_INET;
  address.sin_addr.s_addr = htonl(INADDR_LOOPBACK);
  ::bind(socket_fd.get(), reinterpret_cast<const sockaddr*>(&address), sizeof address);
  socklen_t length = sizeof address;
  ::getsockname(socket_fd.get(), reinterpret_cast<sockaddr*>(&address), &length);
  return ntohs(address.sin_port);
}

TEST(TmclReplyDecoding, decodes_the_manuals_reply_frames) {
  const Result<TmclReply> calc = decode_reply(frame_from_hex({0x02, 0x01, 0x64, 0x13, 0xFF, 0xFF, 0xEC, 0x78, 0xDC}),
                                              instruction("CALC MUL, -5000"));
  ASSERT_TRUE(calc) << calc.error();
  EXPECT_EQ(calc->host_address, 2);
  EXPECT_EQ(calc->module_address, 1);
  EXPECT_EQ(calc->status, 100);
  EXPECT_EQ(calc->value, -5000);

  const Result<TmclReply> gio = decode_reply(frame_from_hex({0x02, 0x01, 0x64, 0x0F, 0x00, 0x00, 0x01, 0x2E, 0xA5}),
                                             instruction("GIO 0, 1"));
  ASSERT_TRUE(gio) << gio.error();
  EXPECT_EQ(gio->value, 302);

  const Result<TmclReply> version = decode_reply(
      frame_from_hex({0x02, 0x01, 0x64, 0x88, 0x06, 0x64, 0x01, 0x09, 0x63}), instruction("136 1"));
  ASSERT_TRUE(version) << version.error();
  EXPECT_EQ(version->value, 0x06640109);
}

TEST(TmclReplyDecoding, reports_checksum_and_command_mismatches) {
  const Result<TmclReply> bad_checksum = decode_reply(
      frame_from_hex({0x02, 0x01, 0x64, 0x13, 0xFF, 0xFF, 0xEC, 0x78, 0xDD}), instruction("CALC MUL, -5000"));
  ASSERT_FALSE(bad_checksum);
  EXPECT_EQ(bad_checksum.error(),
            "reply checksum error: got 0xDD, expected 0xDC (reply 02 01 64 13 FF FF EC 78 DD)");

  const Result<TmclReply> other_command =
      decode_reply(frame_from_hex({0x02, 0x01, 0x64, 0x0F, 0x00, 0x00, 0x01, 0x2E, 0xA5}), instruction("GAP 1, 0"));
  ASSERT_FALSE(other_command);
  EXPECT_NE(other_command.error().find("reply is for command 15, not for the request's command 6"), std::string::npos);

  // The module's answer to a frame with a bad checksum carries command 0: still a reply.
  const Result<TmclReply> checksum_status =
      decode_reply(frame_from_hex({0x02, 0x01, 0x01, 0x00, 0x00, 0x00, 0x00, 0x00, 0x04}), instruction("GAP 1, 0"));
  ASSERT_TRUE(checksum_status) << checksum_status.error();
  EXPECT_EQ(checksum_status->status, 1);
}

TEST(TmclReplyDecoding, version_string_reply_has_no_checksum) {
  const Result<TmclReply> reply =
      decode_reply(frame_from_hex({0x02, '1', '6', '3', '6', 'V', '1', '0', '9'}), instruction("136 0"));
  ASSERT_TRUE(reply) << reply.error();
  EXPECT_EQ(reply->kind, ReplyKind::kVersionString);
  EXPECT_EQ(reply->version_string, "1636V109");
  EXPECT_FALSE(decode_reply(frame_from_hex({0x02, '1', '6', 0x00, '6', 'V', '1', '0', '9'}), instruction("136 0")));
}

// A real TMCM-1636 core behind the loopback server: the client and the module agree.
TEST(TmclClient, talks_to_a_tmcm1636_over_tcp) {
  testing::Tmcm1636Rig rig;
  std::mutex rig_mutex;
  auto server = start_server([&](const tmcl::Frame& request, tmcl::Frame& reply) -> size_t {
    std::lock_guard lock(rig_mutex);
    const tmcl::SerialResponse response = rig.send(request);
    reply = response.bytes;
    return response.length;
  });
  ASSERT_TRUE(server);
  TmclClient client = connect(*server);

  const Result<TmclReply> move = client.request(instruction("MVP ABS, 0, 90000"));
  ASSERT_TRUE(move) << move.error();
  EXPECT_EQ(move->status, 100);
  const Result<TmclReply> target = client.request(instruction("GAP 50, 0"));
  ASSERT_TRUE(target) << target.error();
  EXPECT_EQ(target->value, 90000);
  const Result<TmclReply> wrong_type = client.request(instruction("GAP 13, 0"));  // no AP 13 in table 11
  ASSERT_TRUE(wrong_type) << wrong_type.error();
  EXPECT_EQ(wrong_type->status, 3);
  const Result<TmclReply> version = client.request(instruction("136 0"));
  ASSERT_TRUE(version) << version.error();
  EXPECT_EQ(version->version_string, "1636V109");
  // Another module address: the module stays silent, as on a shared RS485 bus.
  client.set_reply_timeout(100ms);
  const Result<TmclReply> other_address = client.request(instruction("GAP 50, 0"), 7);
  ASSERT_FALSE(other_address);
  EXPECT_NE(other_address.error().find("no reply from tcp " + server->address() + " within 100 ms"), std::string::npos)
      << other_address.error();
}

TEST(TmclClient, reports_timeout_with_the_bytes_received) {
  // The 4 bytes must arrive within the 100 ms the client waits; a loaded machine may hold the
  // server's thread back longer. Then the whole exchange is made again, with a new server.
  for (int attempt = 1;; ++attempt) {
    auto server = start_server([](const tmcl::Frame& request, tmcl::Frame& reply) -> size_t {
      reply = request;
      return 4;  // a reply cut short
    });
    ASSERT_TRUE(server);
    TmclClient client = connect(*server);
    client.set_reply_timeout(100ms);
    const Result<TmclReply> reply = client.request(instruction("GAP 52, 0"));
    ASSERT_FALSE(reply);
    if (reply.error() == "no reply from tcp " + server->address() + " within 100 ms" && attempt < 10) continue;
    EXPECT_EQ(reply.error(),
              "no reply from tcp " + server->address() + " within 100 ms (got 4 of 9 bytes: 01 06 34 00)");
    break;
  }
}

TEST(TmclClient, drops_a_late_reply_before_the_next_request) {
  std::atomic<int> frames_seen{0};
  auto server = start_server([&](const tmcl::Frame& request, tmcl::Frame& reply) -> size_t {
    // The first reply comes late; every reply echoes the request's value.
    if (frames_seen++ == 0) std::this_thread::sleep_for(150ms);
    reply = tmcl::encode_reply(2, 1, tmcl::Reply{100, request[1], tmcl::decode_instruction(request).value});
    return tmcl::kFrameLength;
  });
  ASSERT_TRUE(server);
  TmclClient client = connect(*server);
  client.set_reply_timeout(50ms);
  ASSERT_FALSE(client.request(instruction("CALC LOAD, 1")));
  std::this_thread::sleep_for(600ms);  // the late reply has long arrived
  client.set_reply_timeout(10s);  // a liveness bound: the reply comes at once
  const Result<TmclReply> second = client.request(instruction("CALC LOAD, 2"));
  ASSERT_TRUE(second) << second.error();
  EXPECT_EQ(second->value, 2);
}

TEST(TmclClient, reports_connection_refused_and_bad_addresses) {
  const std::string address = "127.0.0.1:" + std::to_string(unused_port());
  const Result<TmclClient> refused = TmclClient::connect_tcp(address);
  ASSERT_FALSE(refused);
  EXPECT_EQ(refused.error(), "cannot connect to " + address + ": Connection refused");

  for (const char* bad : {"127.0.0.1", "127.0.0.1:", ":5000", "127.0.0.1:70000", "127.0.0.1:-1", "host:port"}) {
    const Result<TmclClient> client = TmclClient::connect_tcp(bad);
    ASSERT_FALSE(client) << bad;
    EXPECT_NE(client.error().find("expected HOST:PORT"), std::string::npos) << client.error();
  }
}

TEST(TmclClient, command_137_is_sent_without_waiting_for_a_reply) {
  std::atomic<int> frames_seen{0};
  auto server = start_server([&](const tmcl::Frame&, tmcl::Frame&) -> size_t {
    ++frames_seen;
    return 0;
  });
  ASSERT_TRUE(server);
  TmclClient client = connect(*server);
  const Result<TmclReply> reply = client.request(instruction("137 0 0 1234"));
  ASSERT_TRUE(reply) << reply.error();
  EXPECT_EQ(reply->kind, ReplyKind::kNone);
}

// The serial path against a pseudo-terminal, as `motwin serve` offers one.
TEST(TmclClient, talks_over_a_pseudo_terminal) {
  UniqueFd controller(::posix_openpt(O_RDWR | O_NOCTTY | O_CLOEXEC));
  ASSERT_TRUE(controller.valid());
  ASSERT_EQ(::grantpt(controller.get()), 0);
  ASSERT_EQ(::unlockpt(controller.get()), 0);
  const std::string device = ::ptsname(controller.get());

  Result<TmclClient> client = TmclClient::open_serial(device);
  ASSERT_TRUE(client) << client.error();
  std::thread module([&] {
    tmcl::Frame request{};
    if (read_exact(controller.get(), request.data(), request.size(), SteadyClock::now() + 5s).status != IoStatus::kOk) {
      return;
    }
    const tmcl::Frame reply = tmcl::encode_reply(2, 1, tmcl::Reply{100, request[1], 4000});
    write_all(controller.get(), reply.data(), reply.size(), false);
  });
  const Result<TmclReply> reply = client->request(instruction("GAP 43, 0"));
  module.join();
  ASSERT_TRUE(reply) << reply.error();
  EXPECT_EQ(reply->value, 4000);

  const Result<TmclClient> missing = TmclClient::open_serial("/nonexistent/tty");
  ASSERT_FALSE(missing);
  EXPECT_EQ(missing.error(), "cannot open serial device /nonexistent/tty: No such file or directory");
}

}  // namespace
}  // namespace motwin::tools
