// SDO block transfer (src/core/canopen/sdo_block.cpp): block download and upload with sub-blocks,
// CRC, sequence errors, block size errors, the protocol switch threshold and timeouts. A test
// dictionary holds a large byte string (the TMCM-3216 has no object longer than 9 bytes); the
// TMCM-3216 rig covers its own objects.
#include <gtest/gtest.h>

#include <string>
#include <vector>

#include "core/canopen/sdo_server.h"
#include "support/canopen_rig.h"

namespace motwin::testing {
namespace {

using canopen::DataType;
using canopen::EntryInfo;
using canopen::ObjectRef;
using canopen::SdoAbort;
using canopen::SdoServer;
using canopen::SdoState;

// 2000: a writable byte string of up to 1024 bytes; 2001: UNSIGNED32.
class BlobDictionary final : public canopen::ObjectDictionary {
 public:
  std::string blob;
  uint32_t number = 0;

  SdoAbort find(uint16_t index, uint8_t sub, ObjectRef& out) const override {
    if (index != 0x2000 && index != 0x2001) return SdoAbort::kNoObject;
    if (sub != 0) return SdoAbort::kNoSubIndex;
    out = ObjectRef{index == 0x2000 ? &kBlob : &kNumber, 0, index, 0};
    return SdoAbort::kNone;
  }
  size_t size(const ObjectRef& ref) override { return ref.index == 0x2000 ? blob.size() : 4; }
  SdoAbort read(const ObjectRef& ref, uint8_t* out, size_t capacity, size_t& length) override {
    if (ref.index == 0x2001) {
      canopen::encode_value(DataType::kUnsigned32, number, out);
      length = 4;
      return SdoAbort::kNone;
    }
    if (blob.size() > capacity) return SdoAbort::kOutOfMemory;
    for (size_t i = 0; i < blob.size(); ++i) out[i] = static_cast<uint8_t>(blob[i]);
    length = blob.size();
    return SdoAbort::kNone;
  }
  SdoAbort write(const ObjectRef& ref, const uint8_t* data, size_t length) override {
    if (ref.index == 0x2001) {
      if (length != 4) return length > 4 ? SdoAbort::kDataTooLong : SdoAbort::kDataTooShort;
      number = static_cast<uint32_t>(canopen::decode_value(DataType::kUnsigned32, data));
      return SdoAbort::kNone;
    }
    blob.assign(reinterpret_cast<const char*>(data), length);
    return SdoAbort::kNone;
  }

 private:
  static constexpr EntryInfo kBlob{0x2000, 0, canopen::ObjectCode::kVar, "Blob", "Blob", DataType::kVisibleString,
                                   canopen::Access::kRw, false, 0, 0, 0, false, 0, canopen::StorageGroup::kNone,
                                   nullptr};
  static constexpr EntryInfo kNumber{0x2001, 0, canopen::ObjectCode::kVar, "Number", "Number",
                                     DataType::kUnsigned32, canopen::Access::kRw, false, 0, 0xFFFF'FFFF, 0, false,
                                     0, canopen::StorageGroup::kNone, nullptr};
};

struct BlockRig {
  BlobDictionary dictionary;
  RecordingCanController can;
  SdoServer server{dictionary, can};

  BlockRig() { server.set_node_id(5); }

  // One request frame; returns every frame the server sent.
  std::vector<can::CanFrame> send(std::initializer_list<uint8_t> bytes) { return send(frame_of(0x605, bytes)); }
  std::vector<can::CanFrame> send(const can::CanFrame& frame) {
    server.on_request(frame);
    server.process(0);
    return can.take();
  }
  // A download segment: seqno (| 0x80 when last) and 7 bytes of `data` from `offset`.
  std::vector<can::CanFrame> segment(uint8_t seqno, bool last, const std::string& data, size_t offset) {
    can::CanFrame f;
    f.id = 0x605;
    f.dlc = 8;
    f.data[0] = static_cast<uint8_t>(seqno | (last ? 0x80 : 0));
    for (size_t i = 0; i < 7; ++i) {
      f.data[1 + i] = offset + i < data.size() ? static_cast<uint8_t>(data[offset + i]) : 0;
    }
    return send(f);
  }
};

std::string pattern(size_t size) {
  std::string s;
  for (size_t i = 0; i < size; ++i) s.push_back(static_cast<char>((i * 37 + 11) & 0xFF));
  return s;
}

uint16_t crc_of(const std::string& s) {
  return canopen::crc16_ccitt(reinterpret_cast<const uint8_t*>(s.data()), s.size());
}

uint32_t abort_of(const can::CanFrame& f) { return f.data[0] == 0x80 ? le32(f, 4) : 0; }

TEST(SdoBlock, crc16_ccitt_matches_the_standard_check_value) {
  const std::string check = "123456789";
  EXPECT_EQ(crc_of(check), 0x31C3);  // CRC-16/XMODEM: poly 0x1021, init 0
  EXPECT_EQ(crc_of(""), 0x0000);
}

// Sends `data` as block download segments from `offset`, `count` of them (the last flagged when it
// is the end of the data); returns the frames of the final segment.
std::vector<can::CanFrame> send_sub_block(BlockRig& rig, const std::string& data, size_t offset, uint8_t count) {
  std::vector<can::CanFrame> out;
  for (uint8_t seq = 1; seq <= count; ++seq) {
    const size_t at = offset + (seq - 1) * 7u;
    const bool last = at + 7 >= data.size();
    out = rig.segment(seq, last, data, at);
    if (seq < count) {
      EXPECT_TRUE(out.empty()) << "segment " << int(seq) << " answered";
    }
    if (last) break;
  }
  return out;
}

TEST(SdoBlock, download_of_1000_bytes_in_two_sub_blocks_with_crc) {
  BlockRig rig;
  const std::string data = pattern(1000);  // 143 segments: 127 + 16, the last with 6 bytes
  auto r = rig.send({0xC6, 0x00, 0x20, 0x00, 0xE8, 0x03, 0, 0});  // CRC, size 1000
  ASSERT_EQ(r.size(), 1u);
  EXPECT_EQ(r[0].id, 0x585u);
  const uint8_t initiate[8] = {0xA4, 0x00, 0x20, 0x00, 127, 0, 0, 0};  // server CRC, blksize 127
  for (int i = 0; i < 8; ++i) EXPECT_EQ(r[0].data[i], initiate[i]) << i;
  EXPECT_EQ(rig.server.state(), SdoState::kDownloadBlock);

  r = send_sub_block(rig, data, 0, 127);
  ASSERT_EQ(r.size(), 1u);
  EXPECT_EQ(r[0].data[0], 0xA2);
  EXPECT_EQ(r[0].data[1], 127);  // ackseq
  EXPECT_EQ(r[0].data[2], 127);  // next blksize
  r = send_sub_block(rig, data, 127 * 7, 16);
  ASSERT_EQ(r.size(), 1u);
  EXPECT_EQ(r[0].data[0], 0xA2);
  EXPECT_EQ(r[0].data[1], 16);
  EXPECT_EQ(rig.server.state(), SdoState::kDownloadBlockEnd);
  EXPECT_TRUE(rig.dictionary.blob.empty());  // written only at the end

  const uint16_t crc = crc_of(data);
  r = rig.send({static_cast<uint8_t>(0xC1 | (1 << 2)), static_cast<uint8_t>(crc), static_cast<uint8_t>(crc >> 8), 0,
                0, 0, 0, 0});  // 1 unused byte in the last segment
  ASSERT_EQ(r.size(), 1u);
  EXPECT_EQ(r[0].data[0], 0xA1);
  EXPECT_EQ(rig.dictionary.blob, data);
  EXPECT_EQ(rig.server.state(), SdoState::kIdle);
}

TEST(SdoBlock, download_with_wrong_crc_aborts_05040004_and_writes_nothing) {
  BlockRig rig;
  rig.dictionary.blob = "old";
  const std::string data = pattern(20);
  rig.send({0xC6, 0x00, 0x20, 0x00, 20, 0, 0, 0});
  const auto r = send_sub_block(rig, data, 0, 3);
  ASSERT_EQ(r.size(), 1u);
  EXPECT_EQ(r[0].data[1], 3);
  const uint16_t wrong = static_cast<uint16_t>(crc_of(data) ^ 0x0100);
  const auto end = rig.send({0xC1 | (1 << 2), static_cast<uint8_t>(wrong), static_cast<uint8_t>(wrong >> 8), 0, 0,
                             0, 0, 0});
  ASSERT_EQ(end.size(), 1u);
  EXPECT_EQ(abort_of(end[0]), 0x05040004u);
  EXPECT_EQ(end[0].data[1], 0x00);
  EXPECT_EQ(end[0].data[2], 0x20);
  EXPECT_EQ(rig.dictionary.blob, "old");
}

TEST(SdoBlock, download_without_client_crc_ignores_the_crc_field) {
  BlockRig rig;
  const std::string data = pattern(10);
  rig.send({0xC2, 0x00, 0x20, 0x00, 10, 0, 0, 0});  // size indicated, no CRC
  send_sub_block(rig, data, 0, 2);
  const auto end = rig.send({0xC1 | (4 << 2), 0xDE, 0xAD, 0, 0, 0, 0, 0});  // 3 bytes in the last segment
  ASSERT_EQ(end.size(), 1u);
  EXPECT_EQ(end[0].data[0], 0xA1);
  EXPECT_EQ(rig.dictionary.blob, data);
}

TEST(SdoBlock, download_end_with_a_size_other_than_announced_aborts_06070010) {
  BlockRig rig;
  const std::string data = pattern(14);
  rig.send({0xC2, 0x00, 0x20, 0x00, 14, 0, 0, 0});
  send_sub_block(rig, data, 0, 2);
  const auto end = rig.send({0xC1 | (2 << 2), 0, 0, 0, 0, 0, 0, 0});  // says 12 bytes
  ASSERT_EQ(end.size(), 1u);
  EXPECT_EQ(abort_of(end[0]), 0x06070010u);
  EXPECT_TRUE(rig.dictionary.blob.empty());
}

TEST(SdoBlock, download_segment_out_of_order_is_acknowledged_with_the_last_good_one) {
  BlockRig rig;
  const std::string data = pattern(35);  // 5 segments
  auto r = rig.send({0xC6, 0x00, 0x20, 0x00, 35, 0, 0, 0});
  EXPECT_TRUE(rig.segment(1, false, data, 0).empty());
  EXPECT_TRUE(rig.segment(2, false, data, 7).empty());
  EXPECT_TRUE(rig.segment(4, false, data, 21).empty());  // 3 lost: ignored from here on
  r = rig.segment(5, true, data, 28);
  ASSERT_EQ(r.size(), 1u);
  EXPECT_EQ(r[0].data[0], 0xA2);
  EXPECT_EQ(r[0].data[1], 2);  // resume after segment 2
  EXPECT_EQ(rig.server.state(), SdoState::kDownloadBlock);
  // The client sends the rest again as a new sub-block starting at 1.
  EXPECT_TRUE(rig.segment(1, false, data, 14).empty());
  EXPECT_TRUE(rig.segment(2, false, data, 21).empty());
  r = rig.segment(3, true, data, 28);
  ASSERT_EQ(r.size(), 1u);
  EXPECT_EQ(r[0].data[1], 3);
  const uint16_t crc = crc_of(data);
  r = rig.send({0xC1, static_cast<uint8_t>(crc), static_cast<uint8_t>(crc >> 8), 0, 0, 0, 0, 0});
  ASSERT_EQ(r.size(), 1u);
  EXPECT_EQ(r[0].data[0], 0xA1);
  EXPECT_EQ(rig.dictionary.blob, data);
}

TEST(SdoBlock, download_sequence_number_0_or_above_block_size_aborts_05040003) {
  BlockRig rig;
  const std::string data = pattern(30);
  rig.send({0xC6, 0x00, 0x20, 0x00, 30, 0, 0, 0});
  auto r = rig.send({0x7F, 1, 2, 3, 4, 5, 6, 7});  // seqno 127 is fine as a number...
  ASSERT_EQ(r.size(), 1u);                          // ...but out of order: acknowledged with 0
  EXPECT_EQ(r[0].data[0], 0xA2);
  EXPECT_EQ(r[0].data[1], 0);
  // 0x80 would be seqno 0 with the last bit: that byte is the client's abort, not a segment.
  r = rig.send({0x80, 0x00, 0x20, 0x00, 0, 0, 0, 0});
  EXPECT_TRUE(r.empty());
  EXPECT_EQ(rig.server.state(), SdoState::kIdle);
  // Sequence number 0 (without the last bit) is no segment number.
  rig.send({0xC6, 0x00, 0x20, 0x00, 30, 0, 0, 0});
  r = rig.send({0x00, 1, 2, 3, 4, 5, 6, 7});
  ASSERT_EQ(r.size(), 1u);
  EXPECT_EQ(abort_of(r[0]), 0x05040003u);
}

TEST(SdoBlock, download_larger_than_the_buffer_aborts_06070012) {
  BlockRig rig;
  const auto r = rig.send({0xC6, 0x00, 0x20, 0x00, 0x01, 0x08, 0, 0});  // 2049 bytes
  ASSERT_EQ(r.size(), 1u);
  EXPECT_EQ(abort_of(r[0]), 0x06070012u);
  EXPECT_EQ(abort_of(rig.send({0xC6, 0x00, 0x30, 0x00, 1, 0, 0, 0})[0]), 0x06020000u);  // absent object
  EXPECT_EQ(abort_of(rig.send({0xC6, 0x01, 0x20, 0x00, 5, 0, 0, 0})[0]), 0x06070012u);  // 5 bytes into U32
}

TEST(SdoBlock, download_stalls_abort_05040000_after_the_timeout) {
  BlockRig rig;
  rig.send({0xC6, 0x00, 0x20, 0x00, 30, 0, 0, 0});
  rig.segment(1, false, pattern(30), 0);
  rig.server.process(SdoServer::kTimeoutUs - 1);
  EXPECT_TRUE(rig.can.take().empty());
  rig.server.process(1);
  const auto r = rig.can.take();
  ASSERT_EQ(r.size(), 1u);
  EXPECT_EQ(abort_of(r[0]), 0x05040000u);
  EXPECT_EQ(rig.server.state(), SdoState::kIdle);
}

TEST(SdoBlock, upload_waiting_for_an_acknowledgement_aborts_05040000_after_the_timeout) {
  BlockRig rig;
  rig.dictionary.blob = pattern(30);
  rig.send({0xA4, 0x00, 0x20, 0x00, 2, 0, 0, 0});
  EXPECT_EQ(rig.send({0xA3, 0, 0, 0, 0, 0, 0, 0}).size(), 2u);
  EXPECT_EQ(rig.server.state(), SdoState::kUploadBlockAck);
  rig.server.process(SdoServer::kTimeoutUs - 1);
  EXPECT_TRUE(rig.can.take().empty());
  rig.server.process(1);
  const auto r = rig.can.take();
  ASSERT_EQ(r.size(), 1u);
  EXPECT_EQ(abort_of(r[0]), 0x05040000u);
  EXPECT_EQ(r[0].data[1], 0x00);
  EXPECT_EQ(r[0].data[2], 0x20);
  EXPECT_EQ(rig.server.state(), SdoState::kIdle);
}

TEST(SdoBlock, client_abort_in_any_block_state_ends_the_transfer_silently) {
  BlockRig rig;
  rig.dictionary.blob = pattern(30);
  rig.send({0xA4, 0x00, 0x20, 0x00, 2, 0, 0, 0});
  rig.send({0xA3, 0, 0, 0, 0, 0, 0, 0});
  EXPECT_TRUE(rig.send({0x80, 0x00, 0x20, 0x00, 0, 0, 0, 0x08}).empty());
  EXPECT_EQ(rig.server.state(), SdoState::kIdle);
  rig.send({0xC6, 0x00, 0x20, 0x00, 30, 0, 0, 0});
  EXPECT_TRUE(rig.send({0x80, 0x00, 0x20, 0x00, 0, 0, 0, 0x08}).empty());
  EXPECT_EQ(rig.server.state(), SdoState::kIdle);
  EXPECT_EQ(rig.dictionary.blob, pattern(30));
}

// Reads every segment frame of an upload sub-block.
std::string collect(const std::vector<can::CanFrame>& frames, uint8_t first_seq, size_t& last_seen) {
  std::string out;
  uint8_t expected = first_seq;
  for (const can::CanFrame& f : frames) {
    EXPECT_EQ(f.data[0] & 0x7F, expected);
    ++expected;
    for (int i = 1; i < 8; ++i) out.push_back(static_cast<char>(f.data[i]));
    last_seen = f.data[0] & 0x80;
  }
  return out;
}

TEST(SdoBlock, upload_of_100_bytes_in_sub_blocks_of_10_with_crc) {
  BlockRig rig;
  rig.dictionary.blob = pattern(100);  // 15 segments, the last with 2 bytes
  auto r = rig.send({0xA4, 0x00, 0x20, 0x00, 10, 0, 0, 0});
  ASSERT_EQ(r.size(), 1u);
  const uint8_t initiate[8] = {0xC6, 0x00, 0x20, 0x00, 100, 0, 0, 0};  // CRC, size indicated
  for (int i = 0; i < 8; ++i) EXPECT_EQ(r[0].data[i], initiate[i]) << i;
  size_t last = 0;
  r = rig.send({0xA3, 0, 0, 0, 0, 0, 0, 0});  // start
  ASSERT_EQ(r.size(), 10u);
  std::string received = collect(r, 1, last);
  EXPECT_EQ(last, 0u);
  r = rig.send({0xA2, 10, 10, 0, 0, 0, 0, 0});
  ASSERT_EQ(r.size(), 5u);
  received += collect(r, 1, last);
  EXPECT_EQ(last, 0x80u);  // c bit on segment 5
  EXPECT_EQ(received.substr(0, 100), rig.dictionary.blob);
  r = rig.send({0xA2, 5, 10, 0, 0, 0, 0, 0});
  ASSERT_EQ(r.size(), 1u);
  EXPECT_EQ(r[0].data[0], 0xC1 | (5 << 2));  // 5 unused bytes in the last segment
  const uint16_t crc = crc_of(rig.dictionary.blob);
  EXPECT_EQ(r[0].data[1], crc & 0xFF);
  EXPECT_EQ(r[0].data[2], crc >> 8);
  EXPECT_EQ(rig.server.state(), SdoState::kUploadBlockEnd);
  EXPECT_TRUE(rig.send({0xA1, 0, 0, 0, 0, 0, 0, 0}).empty());
  EXPECT_EQ(rig.server.state(), SdoState::kIdle);
}

TEST(SdoBlock, upload_resends_after_a_partial_acknowledgement) {
  BlockRig rig;
  rig.dictionary.blob = pattern(28);  // 4 segments
  rig.send({0xA0, 0x00, 0x20, 0x00, 4, 0, 0, 0});  // no CRC
  auto r = rig.send({0xA3, 0, 0, 0, 0, 0, 0, 0});
  ASSERT_EQ(r.size(), 4u);
  r = rig.send({0xA2, 2, 4, 0, 0, 0, 0, 0});  // segments 3 and 4 lost
  ASSERT_EQ(r.size(), 2u);
  size_t last = 0;
  EXPECT_EQ(collect(r, 1, last), rig.dictionary.blob.substr(14));
  EXPECT_EQ(last, 0x80u);
  r = rig.send({0xA2, 2, 4, 0, 0, 0, 0, 0});
  ASSERT_EQ(r.size(), 1u);
  EXPECT_EQ(r[0].data[0], 0xC1);  // no unused bytes; CRC field 0 without client CRC
  EXPECT_EQ(r[0].data[1], 0);
  EXPECT_EQ(r[0].data[2], 0);
}

TEST(SdoBlock, upload_block_size_errors_abort_05040002_and_ackseq_errors_05040003) {
  BlockRig rig;
  rig.dictionary.blob = pattern(50);
  auto r = rig.send({0xA4, 0x00, 0x20, 0x00, 0, 0, 0, 0});
  EXPECT_EQ(abort_of(r[0]), 0x05040002u);
  r = rig.send({0xA4, 0x00, 0x20, 0x00, 128, 0, 0, 0});
  EXPECT_EQ(abort_of(r[0]), 0x05040002u);
  rig.send({0xA4, 0x00, 0x20, 0x00, 3, 0, 0, 0});
  EXPECT_EQ(rig.send({0xA3, 0, 0, 0, 0, 0, 0, 0}).size(), 3u);
  r = rig.send({0xA2, 3, 0, 0, 0, 0, 0, 0});
  EXPECT_EQ(abort_of(r[0]), 0x05040002u);
  EXPECT_EQ(r[0].data[1], 0x00);
  EXPECT_EQ(r[0].data[2], 0x20);
  rig.send({0xA4, 0x00, 0x20, 0x00, 3, 0, 0, 0});
  rig.send({0xA3, 0, 0, 0, 0, 0, 0, 0});
  r = rig.send({0xA2, 4, 3, 0, 0, 0, 0, 0});  // 4 of 3 sent
  EXPECT_EQ(abort_of(r[0]), 0x05040003u);
  EXPECT_EQ(rig.server.state(), SdoState::kIdle);
}

TEST(SdoBlock, upload_request_out_of_state_aborts_05040001) {
  BlockRig rig;
  rig.dictionary.blob = pattern(50);
  rig.send({0xA4, 0x00, 0x20, 0x00, 3, 0, 0, 0});
  const auto r = rig.send({0xA2, 0, 3, 0, 0, 0, 0, 0});  // ack before start
  ASSERT_EQ(r.size(), 1u);
  EXPECT_EQ(abort_of(r[0]), 0x05040001u);
  EXPECT_EQ(abort_of(rig.send({0xA3, 0, 0, 0, 0, 0, 0, 0})[0]), 0x05040001u);  // start while idle
}

TEST(SdoBlock, upload_of_an_empty_value_is_one_empty_last_segment) {
  BlockRig rig;
  rig.send({0xA4, 0x00, 0x20, 0x00, 127, 0, 0, 0});
  auto r = rig.send({0xA3, 0, 0, 0, 0, 0, 0, 0});
  ASSERT_EQ(r.size(), 1u);
  EXPECT_EQ(r[0].data[0], 0x81);
  r = rig.send({0xA2, 1, 127, 0, 0, 0, 0, 0});
  ASSERT_EQ(r.size(), 1u);
  EXPECT_EQ(r[0].data[0], 0xC1 | (7 << 2));
}

TEST(SdoBlock, protocol_switch_threshold_answers_small_objects_with_a_normal_upload) {
  Tmcm3216Rig rig;
  // pst 21, 1008 has 9 bytes: segmented initiate response (CiA-301 7.2.4.3.13).
  can::CanFrame r = rig.sdo({0xA4, 0x08, 0x10, 0x00, 127, 21, 0, 0});
  EXPECT_EQ(r.data[0], 0x41);
  EXPECT_EQ(le32(r, 4), 9u);
  EXPECT_EQ(rig.device->sdo().state(), SdoState::kUploadSegments);
  r = rig.sdo({0x60, 0, 0, 0, 0, 0, 0, 0});
  EXPECT_EQ(std::string(reinterpret_cast<const char*>(r.data + 1), 7), "TMCM-32");
  // pst 21, 1000 (4 bytes): expedited.
  r = rig.sdo({0xA4, 0x00, 0x10, 0x00, 127, 21, 0, 0});
  EXPECT_EQ(r.data[0], 0x43);
  EXPECT_EQ(le32(r, 4), 0xFFFF0192u);
  // pst 0 (python-canopen): block transfer even for 4 bytes.
  r = rig.sdo({0xA4, 0x00, 0x10, 0x00, 127, 0, 0, 0});
  EXPECT_EQ(r.data[0], 0xC6);
  EXPECT_EQ(le32(r, 4), 4u);
}

TEST(SdoBlock, tmcm3216_block_upload_of_device_name_and_block_download_of_1017) {
  Tmcm3216Rig rig;
  rig.sdo({0xA4, 0x08, 0x10, 0x00, 127, 0, 0, 0});
  const std::vector<can::CanFrame> segments = rig.send(frame_of(0x601, {0xA3, 0, 0, 0, 0, 0, 0, 0}));
  ASSERT_EQ(segments.size(), 2u);
  EXPECT_EQ(segments[0].data[0], 0x01);
  EXPECT_EQ(segments[1].data[0], 0x82);
  EXPECT_EQ(std::string(reinterpret_cast<const char*>(segments[0].data + 1), 7), "TMCM-32");
  can::CanFrame end = rig.sdo({0xA2, 2, 127, 0, 0, 0, 0, 0});
  EXPECT_EQ(end.data[0], 0xC1 | (5 << 2));
  const uint16_t crc = crc_of("TMCM-3216");
  EXPECT_EQ(end.data[1] | end.data[2] << 8, crc);
  EXPECT_TRUE(rig.send(frame_of(0x601, {0xA1, 0, 0, 0, 0, 0, 0, 0})).empty());

  // 1017 = 500 ms (2 bytes) by block download with CRC.
  can::CanFrame r = rig.sdo({0xC6, 0x17, 0x10, 0x00, 2, 0, 0, 0});
  EXPECT_EQ(r.data[0], 0xA4);
  r = rig.sdo({0x81, 0xF4, 0x01, 0, 0, 0, 0, 0});
  EXPECT_EQ(r.data[0], 0xA2);
  EXPECT_EQ(r.data[1], 1);
  const uint8_t value[2] = {0xF4, 0x01};
  const uint16_t value_crc = canopen::crc16_ccitt(value, 2);
  r = rig.sdo({0xC1 | (5 << 2), static_cast<uint8_t>(value_crc), static_cast<uint8_t>(value_crc >> 8), 0, 0, 0, 0, 0});
  EXPECT_EQ(r.data[0], 0xA1);
  EXPECT_EQ(rig.read_u32(0x1017, 0) & 0xFFFF, 500u);
  // A block download into a read-only object aborts at once.
  EXPECT_EQ(Tmcm3216Rig::abort_of(rig.sdo({0xC6, 0x00, 0x10, 0x00, 4, 0, 0, 0})), 0x06010002u);
}

}  // namespace
}  // namespace motwin::testing
