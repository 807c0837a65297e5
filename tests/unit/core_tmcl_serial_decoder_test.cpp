#include <gtest/gtest.h>

#include "core/tmcl/serial_link.h"

namespace motwin::tmcl {
namespace {

TEST(SerialFrameDecoder, assembles_frames_split_anywhere) {
  SerialFrameDecoder decoder;
  const Frame frame = encode_request(1, Instruction{6, 52, 0, 0});
  uint64_t t = 1000;
  for (size_t i = 0; i < 8; ++i) EXPECT_FALSE(decoder.push(frame[i], t += 100));
  EXPECT_TRUE(decoder.push(frame[8], t += 100));
  EXPECT_EQ(decoder.frame(), frame);
  EXPECT_EQ(decoder.pending_bytes(), 0u);
}

TEST(SerialFrameDecoder, a_pause_longer_than_the_gap_discards_a_partial_frame) {
  SerialFrameDecoder decoder(5000);
  const Frame frame = encode_request(1, Instruction{6, 52, 0, 0});
  decoder.push(0xAA, 0);
  decoder.push(0xBB, 1000);
  uint64_t t = 1000 + 5001;  // pause: the garbage is dropped
  for (size_t i = 0; i < 8; ++i) EXPECT_FALSE(decoder.push(frame[i], t++));
  EXPECT_TRUE(decoder.push(frame[8], t));
  EXPECT_EQ(decoder.frame(), frame);
}

TEST(SerialFrameDecoder, without_a_pause_garbage_shifts_the_frame) {
  SerialFrameDecoder decoder(5000);
  const Frame frame = encode_request(1, Instruction{6, 52, 0, 0});
  decoder.push(0xAA, 0);
  bool complete = false;
  for (size_t i = 0; i < 9; ++i) complete = decoder.push(frame[i], 10 + i);
  EXPECT_FALSE(complete);
  EXPECT_EQ(decoder.pending_bytes(), 1u);
}

TEST(SerialLink, checksum_matches_the_notes_test_vectors) {
  const Frame ror = encode_request(1, Instruction{1, 0, 0, 350});
  EXPECT_EQ(ror, (Frame{0x01, 0x01, 0x00, 0x00, 0x00, 0x00, 0x01, 0x5E, 0x61}));
  const Frame rfs = encode_request(1, Instruction{13, 0, 0, 0});
  EXPECT_EQ(rfs[8], 0x0E);
  EXPECT_EQ(encode_request(1, Instruction{0, 0, 0, 0})[8], 0x01);
  EXPECT_EQ(decode_instruction(encode_request(1, Instruction{4, 1, 0, -10000})).value, -10000);
}

}  // namespace
}  // namespace motwin::tmcl
