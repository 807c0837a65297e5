// The socketcand session without sockets (host/socketcand_session.h): the greeting, open, the
// modes, echo, send and the errors, as SocketcandServer runs it per connection.
#include <gtest/gtest.h>

#include <string>
#include <vector>

#include "host/socketcand_protocol.h"
#include "host/socketcand_session.h"

namespace motwin::host {
namespace {

struct RecordingIo final : SocketcandSession::Io {
  std::vector<std::string> writes;
  std::vector<can::CanFrame> sent;
  int raw_mode_entries = 0;
  bool is_closing = false;

  void write(const std::string& element) override { writes.push_back(element); }
  void send_to_bus(const can::CanFrame& frame) override { sent.push_back(frame); }
  void raw_mode_entered() override { ++raw_mode_entries; }
  bool closing() const override { return is_closing; }
};

can::CanFrame frame_on(uint32_t id, std::initializer_list<uint8_t> bytes) {
  can::CanFrame frame;
  frame.id = id;
  for (uint8_t b : bytes) frame.data[frame.dlc++] = b;
  return frame;
}

TEST(SocketcandSession, answers_each_element_by_the_rules) {
  RecordingIo io;
  SocketcandSession session(io);
  session.start();
  session.push("< rawmode >< send 601 1 00 ><open can0");  // before open: errors only, nothing sent
  EXPECT_TRUE(io.sent.empty());
  session.push(" >< echo >< rawmode >< rawmode >< send 601 2 40 >< send 601 2 40 0 >< bcmmode >< frobnicate >");
  EXPECT_EQ(io.writes, (std::vector<std::string>{"< hi >", " < error expected open >", " < error expected open >",
                                                 "< ok >", " < echo >", "< ok >", "< ok >",
                                                 " < error length does not match the data >", " < ok >",
                                                 " < error unknown command >"}));
  ASSERT_EQ(io.sent.size(), 1u);
  EXPECT_EQ(io.sent[0], frame_on(0x601, {0x40, 0x00}));
  EXPECT_EQ(io.raw_mode_entries, 1);  // the second rawmode does not enter it again
  EXPECT_EQ(session.mode(), SocketcandSession::Mode::kBcm);
}

TEST(SocketcandSession, bus_frames_reach_the_client_only_in_raw_mode) {
  RecordingIo io;
  SocketcandSession session(io);
  session.start();
  const can::CanFrame frame = frame_on(0x583, {0x43});
  session.frame_from_bus(frame, 1'000'000);
  session.push("< open can0 >");
  session.frame_from_bus(frame, 1'000'000);
  session.push("< rawmode >");
  session.frame_from_bus(frame, 2'500'000);
  session.push("< bcmmode >");
  session.frame_from_bus(frame, 3'000'000);
  EXPECT_EQ(io.writes, (std::vector<std::string>{"< hi >", "< ok >", "< ok >", format_socketcand_frame(frame, 2'500'000),
                                                 " < ok >"}));
}

TEST(SocketcandSession, a_closing_connection_gets_nothing_more) {
  RecordingIo io;
  SocketcandSession session(io);
  session.start();
  session.push("< open can0 >< rawmode >");
  io.is_closing = true;
  session.push("< echo >< send 601 0 >");
  session.frame_from_bus(frame_on(0x80, {}), 0);
  EXPECT_EQ(io.writes.size(), 3u);
  EXPECT_TRUE(io.sent.empty());
}

}  // namespace
}  // namespace motwin::host
