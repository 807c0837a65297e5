#include "host/socket_output.h"

#include <string>

#include <sys/socket.h>
#include <unistd.h>

#include <gtest/gtest.h>

namespace motwin::host {
namespace {

struct SocketPair {
  int fds[2] = {-1, -1};
  SocketPair() { EXPECT_EQ(::socketpair(AF_UNIX, SOCK_STREAM, 0, fds), 0); }
  ~SocketPair() {
    for (int fd : fds) if (fd >= 0) ::close(fd);
  }
  std::string read_all_available() {
    std::string out;
    char chunk[65536];
    for (;;) {
      const ssize_t n = ::recv(fds[1], chunk, sizeof(chunk), MSG_DONTWAIT);
      if (n <= 0) return out;
      out.append(chunk, static_cast<size_t>(n));
    }
  }
};

TEST(SocketOutput, sends_everything_a_socket_with_room_takes_and_is_empty_after) {
  SocketPair pair;
  SocketOutput output;
  output.append("< hi >");
  output.append(" < ok >");
  EXPECT_EQ(output.pending(), 13u);
  std::string error;
  EXPECT_EQ(output.send_to(pair.fds[0], &error), SocketOutput::Sent::kAll);
  EXPECT_TRUE(output.empty());
  EXPECT_EQ(pair.read_all_available(), "< hi > < ok >");
}

TEST(SocketOutput, a_full_socket_keeps_the_rest_in_order_until_the_reader_makes_room) {
  SocketPair pair;
  int small = 4096;
  ::setsockopt(pair.fds[0], SOL_SOCKET, SO_SNDBUF, &small, sizeof(small));
  SocketOutput output;
  std::string sent;
  for (int i = 0; i < 20000; ++i) sent += "frame " + std::to_string(i) + ";";  // far more than the socket holds
  output.append(sent);
  std::string received;
  std::string error;
  SocketOutput::Sent result = output.send_to(pair.fds[0], &error);
  EXPECT_EQ(result, SocketOutput::Sent::kSocketFull);
  EXPECT_GT(output.pending(), 0u);
  while (result != SocketOutput::Sent::kAll) {
    received += pair.read_all_available();
    result = output.send_to(pair.fds[0], &error);
    ASSERT_NE(result, SocketOutput::Sent::kFailed) << error;
  }
  received += pair.read_all_available();
  EXPECT_EQ(received, sent);
  EXPECT_TRUE(output.empty());
}

TEST(SocketOutput, a_closed_peer_is_a_failure_with_a_reason_and_no_signal) {
  SocketPair pair;
  ::close(pair.fds[1]);
  pair.fds[1] = -1;
  SocketOutput output;
  output.append("lost");
  std::string error;
  EXPECT_EQ(output.send_to(pair.fds[0], &error), SocketOutput::Sent::kFailed);  // EPIPE, not SIGPIPE
  EXPECT_FALSE(error.empty());
  output.clear();
  EXPECT_TRUE(output.empty());
}

}  // namespace
}  // namespace motwin::host
