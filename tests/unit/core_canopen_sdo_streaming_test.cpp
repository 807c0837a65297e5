// Uploads longer than the SDO server's buffer (SdoServer::kBufferSize): the value streams through
// the buffer in windows read by ObjectDictionary::read_part, by block and by segmented upload,
// with partial acknowledgements, CRC over the whole value and read errors mid-transfer.
#include <gtest/gtest.h>

#include "core/canopen/sdo_server.h"
#include "support/sdo_frames.h"

namespace motwin::testing {
namespace {

using canopen::SdoAbort;
using canopen::SdoServer;
using canopen::SdoState;

struct StreamingRig {
  StreamingDictionary dictionary;
  RecordingCanController can;
  SdoServer server{dictionary, can};
};

std::vector<uint8_t> expected_domain(size_t size) {
  std::vector<uint8_t> bytes(size);
  for (size_t i = 0; i < size; ++i) bytes[i] = domain_byte(i);
  return bytes;
}

TEST(SdoStreaming, block_upload_of_100_kb_arrives_whole_with_the_crc_of_the_whole_value) {
  StreamingRig rig;
  const BlockUploadResult result = block_upload(rig.server, rig.can, 0x2100, 127);
  ASSERT_EQ(result.abort_code, 0u);
  EXPECT_EQ(result.announced_size, 100'000u);
  const std::vector<uint8_t> expected = expected_domain(100'000);
  ASSERT_EQ(result.data.size(), expected.size());
  EXPECT_EQ(result.data, expected);
  EXPECT_EQ(result.server_crc, canopen::crc16_ccitt(expected.data(), expected.size()));
  // 14286 segments + one initiate response and one end frame per transfer.
  EXPECT_EQ(result.frames_from_server, (100'000u + 6) / 7 + 2);
  // Never more than the buffer at once; one window per sub-block of 889 bytes at most.
  EXPECT_LE(rig.dictionary.largest_part, SdoServer::kBufferSize);
  EXPECT_GE(rig.dictionary.part_reads, 100'000u / SdoServer::kBufferSize);
  EXPECT_LE(rig.dictionary.part_reads, 100'000u / 889 + 2);
  EXPECT_EQ(rig.server.state(), SdoState::kIdle);
}

TEST(SdoStreaming, partial_acknowledgements_resend_from_the_window_and_keep_the_crc_right) {
  StreamingRig rig;
  rig.dictionary.domain_size = 20'000;
  // The client keeps only 100 of each 127 segments: every sub-block resends 27 segments,
  // partly from the old window and partly after a new read.
  const BlockUploadResult result = block_upload(rig.server, rig.can, 0x2100, 127, 100);
  ASSERT_EQ(result.abort_code, 0u);
  const std::vector<uint8_t> expected = expected_domain(20'000);
  EXPECT_EQ(result.data, expected);
  EXPECT_EQ(result.server_crc, canopen::crc16_ccitt(expected.data(), expected.size()));
}

TEST(SdoStreaming, small_sub_blocks_stream_too) {
  StreamingRig rig;
  rig.dictionary.domain_size = 5'001;
  const BlockUploadResult result = block_upload(rig.server, rig.can, 0x2100, 3, 2);
  ASSERT_EQ(result.abort_code, 0u);
  EXPECT_EQ(result.data, expected_domain(5'001));
}

TEST(SdoStreaming, segmented_upload_of_a_value_longer_than_the_buffer) {
  StreamingRig rig;
  rig.dictionary.domain_size = 3'000;
  rig.server.on_request(frame_of(0x601, {0x40, 0x00, 0x21, 0x00, 0, 0, 0, 0}));
  rig.server.process(0);
  std::vector<can::CanFrame> r = rig.can.take();
  ASSERT_EQ(r.size(), 1u);
  EXPECT_EQ(r[0].data[0], 0x41);  // segmented, size indicated
  EXPECT_EQ(r[0].data[4] | r[0].data[5] << 8, 3'000);
  std::vector<uint8_t> received;
  uint8_t toggle = 0;
  for (int guard = 0; guard < 1000; ++guard) {
    rig.server.on_request(frame_of(0x601, {static_cast<uint8_t>(0x60 | toggle), 0, 0, 0, 0, 0, 0, 0}));
    rig.server.process(0);
    r = rig.can.take();
    ASSERT_EQ(r.size(), 1u);
    ASSERT_EQ(r[0].data[0] & 0x10, toggle);
    const size_t length = 7 - ((r[0].data[0] >> 1) & 0x07);
    received.insert(received.end(), r[0].data + 1, r[0].data + 1 + length);
    toggle ^= 0x10;
    if ((r[0].data[0] & 0x01) != 0) break;
  }
  EXPECT_EQ(received, expected_domain(3'000));
  EXPECT_EQ(rig.server.state(), SdoState::kIdle);
}

TEST(SdoStreaming, a_long_value_the_dictionary_cannot_stream_aborts_05040005_at_initiate) {
  StreamingRig rig;
  EXPECT_EQ(block_upload(rig.server, rig.can, 0x2101, 127).abort_code, 0x05040005u);
  rig.can.take();
  rig.server.on_request(frame_of(0x601, {0x40, 0x01, 0x21, 0x00, 0, 0, 0, 0}));
  rig.server.process(0);
  const std::vector<can::CanFrame> r = rig.can.take();
  ASSERT_EQ(r.size(), 1u);
  EXPECT_EQ(r[0].data[0], 0x80);
  EXPECT_EQ(r[0].data[4] | r[0].data[5] << 8 | r[0].data[6] << 16 | r[0].data[7] << 24, 0x05040005);
  EXPECT_EQ(rig.server.state(), SdoState::kIdle);
}

TEST(SdoStreaming, a_read_error_in_the_middle_aborts_with_the_dictionary_code_and_the_server_recovers) {
  StreamingRig rig;
  rig.dictionary.fail_from = 10'000;
  const BlockUploadResult failed = block_upload(rig.server, rig.can, 0x2100, 127);
  EXPECT_EQ(failed.abort_code, 0x06060000u);
  EXPECT_GE(failed.data.size(), 8'000u);  // what came before the error was delivered
  EXPECT_EQ(rig.server.state(), SdoState::kIdle);
  rig.dictionary.fail_from = SIZE_MAX;
  const BlockUploadResult again = block_upload(rig.server, rig.can, 0x2100, 127);
  EXPECT_EQ(again.abort_code, 0u);
  EXPECT_EQ(again.data, expected_domain(100'000));
}

}  // namespace
}  // namespace motwin::testing
