// TMCL on the firmware's UART (src/firmware/serial_tmcl_link.h), fed byte by byte as the receive
// interrupt delivers them: framing, telegram pause, ASCII mode and events, against a TMCM-1636.
#include <gtest/gtest.h>

#include <string>
#include <vector>

#include "core/tmcl/serial_link.h"
#include "firmware/serial_tmcl_link.h"
#include "support/tmcm1636_rig.h"

namespace motwin::firmware {
namespace {

using motwin::testing::Tmcm1636Rig;

class CollectedOutput final : public ByteOutput {
 public:
  void write(const uint8_t* bytes, size_t length) override { sent.insert(sent.end(), bytes, bytes + length); }
  std::vector<uint8_t> sent;
};

struct LinkRig {
  Tmcm1636Rig module;
  CollectedOutput output;
  SerialTmclLink link{module.engine, output};

  // Feeds every byte at `now_us`; returns how many the link took.
  size_t feed(const std::vector<uint8_t>& bytes, uint64_t now_us) {
    size_t taken = 0;
    for (uint8_t byte : bytes) {
      if (!link.receive(byte, now_us)) break;
      ++taken;
    }
    return taken;
  }
  static std::vector<uint8_t> frame(uint8_t command, uint8_t type, int32_t value = 0) {
    const tmcl::Frame f = tmcl::encode_request(1, tmcl::Instruction{command, type, 0, value});
    return {f.begin(), f.end()};
  }
  // The value of the 9-byte reply at `offset` of what was sent.
  int32_t reply_value(size_t offset = 0) const {
    const auto& b = output.sent;
    return static_cast<int32_t>((uint32_t{b[offset + 4]} << 24) | (uint32_t{b[offset + 5]} << 16) |
                                (uint32_t{b[offset + 6]} << 8) | b[offset + 7]);
  }
};

TEST(FirmwareSerialTmclLink, AFrameByteByByteIsAnswered) {
  LinkRig rig;
  EXPECT_EQ(rig.feed(LinkRig::frame(136, 1), 0), 9u);
  ASSERT_EQ(rig.output.sent.size(), 9u);
  EXPECT_EQ(rig.output.sent[0], 2);    // host address
  EXPECT_EQ(rig.output.sent[2], 100);  // status OK
  EXPECT_EQ(rig.reply_value(), 1636 * 65536 + 1 * 256 + 9);
}

TEST(FirmwareSerialTmclLink, APauseInsideAFrameDropsItsStart) {
  LinkRig rig;
  const std::vector<uint8_t> frame = LinkRig::frame(136, 1);
  rig.feed({frame.begin(), frame.begin() + 4}, 0);
  rig.feed({frame.begin() + 4, frame.end()}, tmcl::SerialFrameDecoder::kDefaultResyncGapUs + 1);
  EXPECT_TRUE(rig.output.sent.empty());
  rig.feed(frame, 20'000);
  EXPECT_EQ(rig.output.sent.size(), 9u);
}

TEST(FirmwareSerialTmclLink, TelegramPauseHoldsTheReplyAndTheNextRequest) {
  LinkRig rig;
  rig.feed(LinkRig::frame(9, 75, 3), 0);  // SGP 75 = 3 ms
  ASSERT_EQ(rig.output.sent.size(), 9u);
  rig.output.sent.clear();
  const std::vector<uint8_t> two = [] {
    std::vector<uint8_t> bytes = LinkRig::frame(136, 1);
    const std::vector<uint8_t> second = LinkRig::frame(10, 75);
    bytes.insert(bytes.end(), second.begin(), second.end());
    return bytes;
  }();
  EXPECT_EQ(rig.feed(two, 10'000), 9u) << "the second frame waits in the UART while the first reply is held";
  EXPECT_TRUE(rig.link.holding_reply());
  rig.link.poll(12'999);
  EXPECT_TRUE(rig.output.sent.empty());
  rig.link.poll(13'000);
  ASSERT_EQ(rig.output.sent.size(), 9u);
  EXPECT_EQ(rig.reply_value(), 1636 * 65536 + 1 * 256 + 9);
  EXPECT_EQ(rig.feed({two.begin() + 9, two.end()}, 13'050), 9u);
  rig.link.poll(16'050);
  ASSERT_EQ(rig.output.sent.size(), 18u);
  EXPECT_EQ(rig.reply_value(9), 3);
}

TEST(FirmwareSerialTmclLink, Command139SwitchesToAsciiAndBinLeavesIt) {
  LinkRig rig;
  rig.feed(LinkRig::frame(139, 0), 0);
  ASSERT_EQ(rig.output.sent.size(), 9u);
  EXPECT_TRUE(rig.link.ascii_mode());
  rig.output.sent.clear();
  const std::string gap = "AGAP 43, 0\r";
  rig.feed({gap.begin(), gap.end()}, 1000);
  const std::string text(rig.output.sent.begin(), rig.output.sent.end());
  EXPECT_NE(text.find("BA 100 4000\r"), std::string::npos) << text;  // echo, then the reply
  rig.output.sent.clear();
  const std::string bin = "ABIN\r";
  rig.feed({bin.begin(), bin.end()}, 2000);
  EXPECT_FALSE(rig.link.ascii_mode());
  rig.output.sent.clear();
  rig.feed(LinkRig::frame(136, 1), 3000);
  EXPECT_EQ(rig.output.sent.size(), 9u);
}

TEST(FirmwareSerialTmclLink, AnEventOfCommand138IsSentByPoll) {
  LinkRig rig;
  // Command 138 type 0: a reply once the position is reached (docs/tmcl-protocol.md).
  rig.feed(LinkRig::frame(4, 0, 100), 0);
  rig.feed(LinkRig::frame(138, 0, 1), 0);
  rig.output.sent.clear();
  for (int ms = 0; ms < 2000 && rig.output.sent.empty(); ++ms) {
    rig.module.run_ms(1);
    rig.link.poll(static_cast<uint64_t>(ms) * 1000);
  }
  ASSERT_EQ(rig.output.sent.size(), 9u);
  EXPECT_EQ(rig.output.sent[2], 128);  // the event's status
  EXPECT_EQ(rig.output.sent[3], 138);
}

}  // namespace
}  // namespace motwin::firmware
