// SDO server (src/core/canopen/sdo_server.h): expedited and segmented transfers both ways, every
// abort code the communication area can produce, timeouts and protocol errors. Most tests talk to
// the TMCM-3216 dictionary; a small test dictionary covers write-only and signed objects.
#include <gtest/gtest.h>

#include <array>

#include "core/canopen/object_dictionary.h"
#include "core/canopen/sdo_server.h"
#include "support/canopen_rig.h"

namespace motwin::testing {
namespace {

using canopen::SdoAbort;
using canopen::SdoState;

TEST(SdoServer, expedited_upload_of_device_type_and_identity) {
  Tmcm3216Rig rig;
  const SdoResult device_type = rig.upload(0x1000, 0);
  EXPECT_EQ(device_type.abort, 0u);
  EXPECT_EQ(device_type.response.data[0], 0x43);  // expedited, size indicated, 4 bytes
  EXPECT_EQ(device_type.value, 0xFFFF0192u);
  EXPECT_EQ(rig.read_u32(0x1018, 1), 0x286u);
  EXPECT_EQ(rig.read_u32(0x1018, 2), 3216u);
  EXPECT_EQ(rig.read_u32(0x1018, 3), 0x00010004u);
  const SdoResult count = rig.upload(0x1018, 0);
  EXPECT_EQ(count.response.data[0], 0x4F);  // 1 byte
  EXPECT_EQ(count.value & 0xFF, 4u);
}

TEST(SdoServer, segmented_upload_of_device_name_and_versions) {
  Tmcm3216Rig rig;
  const SdoResult name = rig.upload(0x1008, 0);
  EXPECT_EQ(name.abort, 0u);
  EXPECT_EQ(name.response.data[0], 0x41);  // segmented, size indicated
  EXPECT_EQ(le32(name.response, 4), 9u);
  EXPECT_EQ(name.bytes, "TMCM-3216");
  EXPECT_EQ(rig.upload(0x100A, 0).bytes, "1.04");  // 4 bytes: expedited
  EXPECT_EQ(rig.upload(0x1009, 0).bytes, "1.00");
}

TEST(SdoServer, segmented_upload_segments_carry_toggle_and_length) {
  Tmcm3216Rig rig;
  can::CanFrame r = rig.sdo({0x40, 0x08, 0x10, 0, 0, 0, 0, 0});
  ASSERT_EQ(r.data[0], 0x41);
  r = rig.sdo({0x60, 0, 0, 0, 0, 0, 0, 0});
  EXPECT_EQ(r.data[0], 0x00);  // toggle 0, 7 bytes, more to come
  EXPECT_EQ(std::string(reinterpret_cast<const char*>(r.data + 1), 7), "TMCM-32");
  r = rig.sdo({0x70, 0, 0, 0, 0, 0, 0, 0});
  EXPECT_EQ(r.data[0], 0x10 | (5 << 1) | 1);  // toggle 1, 2 bytes, last
  EXPECT_EQ(r.data[1], '1');
  EXPECT_EQ(r.data[2], '6');
  EXPECT_EQ(rig.device->sdo().state(), SdoState::kIdle);
}

TEST(SdoServer, sdo_server_aborts_toggle_error_in_upload) {
  Tmcm3216Rig rig;
  rig.sdo({0x40, 0x08, 0x10, 0, 0, 0, 0, 0});
  const can::CanFrame r = rig.sdo({0x70, 0, 0, 0, 0, 0, 0, 0});  // toggle 1 first: wrong
  EXPECT_EQ(Tmcm3216Rig::abort_of(r), 0x05030000u);
  EXPECT_EQ(r.data[1], 0x08);
  EXPECT_EQ(r.data[2], 0x10);
  EXPECT_EQ(rig.device->sdo().state(), SdoState::kIdle);
}

TEST(SdoServer, sdo_server_aborts_toggle_error_in_download) {
  Tmcm3216Rig rig;
  EXPECT_EQ(rig.sdo({0x21, 0x16, 0x10, 1, 4, 0, 0, 0}).data[0], 0x60);
  const can::CanFrame r = rig.sdo({0x10 | 0x07, 0x10, 0x27, 0, 0, 0, 0, 0});  // toggle 1 first
  EXPECT_EQ(Tmcm3216Rig::abort_of(r), 0x05030000u);
  EXPECT_EQ(r.data[1], 0x16);
  EXPECT_EQ(r.data[3], 1);
  EXPECT_EQ(rig.read_u32(0x1016, 1), 0u);  // nothing written
}

TEST(SdoServer, segmented_download_writes_the_object) {
  Tmcm3216Rig rig;
  // 1016 sub 1 (UNSIGNED32) = 0x000503E8: node 5, 1000 ms, in one last segment of 4 bytes.
  EXPECT_EQ(rig.sdo({0x21, 0x16, 0x10, 1, 4, 0, 0, 0}).data[0], 0x60);
  const can::CanFrame r = rig.sdo({static_cast<uint8_t>(((7 - 4) << 1) | 1), 0xE8, 0x03, 0x05, 0x00, 0, 0, 0});
  EXPECT_EQ(r.data[0], 0x20);
  EXPECT_EQ(rig.read_u32(0x1016, 1), 0x000503E8u);
}

TEST(SdoServer, segmented_download_over_two_segments_alternates_toggle) {
  Tmcm3216Rig rig;
  // Size not indicated; 2 bytes then 2 bytes.
  EXPECT_EQ(rig.sdo({0x20, 0x16, 0x10, 1, 0, 0, 0, 0}).data[0], 0x60);
  EXPECT_EQ(rig.sdo({static_cast<uint8_t>((7 - 2) << 1), 0x10, 0x00, 0, 0, 0, 0, 0}).data[0], 0x20);
  EXPECT_EQ(rig.sdo({static_cast<uint8_t>(0x10 | ((7 - 2) << 1) | 1), 0x07, 0x00, 0, 0, 0, 0, 0}).data[0], 0x30);
  EXPECT_EQ(rig.read_u32(0x1016, 1), 0x00070010u);
}

TEST(SdoServer, segmented_download_that_differs_from_its_announced_size_aborts_06070010) {
  Tmcm3216Rig rig;
  EXPECT_EQ(rig.sdo({0x21, 0x16, 0x10, 1, 4, 0, 0, 0}).data[0], 0x60);
  const can::CanFrame r = rig.sdo({static_cast<uint8_t>(((7 - 3) << 1) | 1), 1, 2, 3, 0, 0, 0, 0});  // 3 of 4
  EXPECT_EQ(Tmcm3216Rig::abort_of(r), 0x06070010u);
  EXPECT_EQ(rig.read_u32(0x1016, 1), 0u);
}

TEST(SdoServer, segmented_download_announcing_a_wrong_size_aborts_at_once) {
  Tmcm3216Rig rig;
  EXPECT_EQ(Tmcm3216Rig::abort_of(rig.sdo({0x21, 0x16, 0x10, 1, 5, 0, 0, 0})), 0x06070012u);
  EXPECT_EQ(Tmcm3216Rig::abort_of(rig.sdo({0x21, 0x16, 0x10, 1, 2, 0, 0, 0})), 0x06070013u);
  EXPECT_EQ(Tmcm3216Rig::abort_of(rig.sdo({0x21, 0x16, 0x10, 1, 0, 1, 0, 0})), 0x06070012u);  // 256 bytes
}

TEST(SdoServer, expedited_download_with_wrong_sizes_aborts) {
  Tmcm3216Rig rig;
  EXPECT_EQ(rig.download(0x1017, 0, 100, 4), 0x06070012u);  // UNSIGNED16 given 4 bytes
  EXPECT_EQ(rig.download(0x1017, 0, 100, 1), 0x06070013u);  // given 1 byte
  EXPECT_EQ(rig.download(0x1016, 1, 0, 2), 0x06070013u);
  EXPECT_EQ(rig.download(0x1017, 0, 100, 2), 0u);
  EXPECT_EQ(rig.read_u32(0x1017, 0), 100u);
}

TEST(SdoServer, expedited_download_without_size_uses_the_object_size) {
  Tmcm3216Rig rig;
  const can::CanFrame r = rig.sdo({0x22, 0x17, 0x10, 0, 0xF4, 0x01, 0xAA, 0xBB});  // e=1, s=0
  EXPECT_EQ(r.data[0], 0x60);
  EXPECT_EQ(rig.read_u32(0x1017, 0) & 0xFFFF, 500u);
}

TEST(SdoServer, unknown_objects_and_sub_indices_abort) {
  Tmcm3216Rig rig;
  EXPECT_EQ(rig.upload(0x1234, 0).abort, 0x06020000u);
  EXPECT_EQ(rig.upload(0x1018, 5).abort, 0x06090011u);
  EXPECT_EQ(rig.upload(0x1017, 1).abort, 0x06090011u);
  EXPECT_EQ(rig.download(0x6043, 0, 6, 2), 0x06020000u);  // vl mode objects: not supported
  EXPECT_EQ(rig.download(0x7840, 0, 6, 2), 0x06020000u);  // no fourth axis
  EXPECT_EQ(rig.download(0x1010, 7, 0x65766173), 0x06090011u);
  // PDO parameters exist for three axes only.
  EXPECT_EQ(rig.upload(0x1440, 1).abort, 0u);
  EXPECT_EQ(rig.upload(0x1480, 1).abort, 0u);
  EXPECT_EQ(rig.upload(0x14C0, 1).abort, 0x06020000u);
  EXPECT_EQ(rig.upload(0x1404, 1).abort, 0x06020000u);
}

TEST(SdoServer, abort_echoes_the_multiplexer) {
  Tmcm3216Rig rig;
  const can::CanFrame r = rig.upload(0x1234, 0x56).response;
  EXPECT_EQ(r.data[0], 0x80);
  EXPECT_EQ(r.data[1], 0x34);
  EXPECT_EQ(r.data[2], 0x12);
  EXPECT_EQ(r.data[3], 0x56);
}

TEST(SdoServer, writes_to_read_only_and_const_objects_abort_06010002) {
  Tmcm3216Rig rig;
  EXPECT_EQ(rig.download(0x1000, 0, 0), 0x06010002u);
  EXPECT_EQ(rig.download(0x1001, 0, 0, 1), 0x06010002u);
  EXPECT_EQ(rig.download(0x1018, 1, 0x123), 0x06010002u);
  EXPECT_EQ(rig.download(0x1018, 0, 4, 1), 0x06010002u);
  EXPECT_EQ(rig.download(0x2708, 0, 5, 1), 0x06010002u);
  EXPECT_EQ(Tmcm3216Rig::abort_of(rig.sdo({0x21, 0x08, 0x10, 0, 3, 0, 0, 0})), 0x06010002u);  // segmented
  EXPECT_EQ(rig.read_u32(0x1000, 0), 0xFFFF0192u);
}

TEST(SdoServer, values_out_of_range_abort_06090030_31_32) {
  Tmcm3216Rig rig;
  EXPECT_EQ(rig.download(0x1029, 1, 3, 1), 0x06090031u);
  EXPECT_EQ(rig.download(0x2705, 0, 0, 1), 0x06090032u);
  EXPECT_EQ(rig.download(0x2705, 0, 128, 1), 0x06090030u);   // 1..127 and 255 only
  EXPECT_EQ(rig.download(0x2704, 0, 1001, 2), 0x06090031u);
  EXPECT_EQ(rig.download(0x2704, 0, 19, 2), 0x06090032u);
  EXPECT_EQ(rig.download(0x2704, 0, 300, 2), 0x06090030u);   // not one of the listed bit rates
  EXPECT_EQ(rig.download(0x2704, 0, 250, 2), 0u);
  EXPECT_EQ(rig.download(0x1800, 2, 0, 1), 0x06090030u);     // transmission type 0 not supported
  EXPECT_EQ(rig.download(0x1800, 2, 241, 1), 0x06090030u);
  EXPECT_EQ(rig.download(0x1800, 2, 240, 1), 0u);
  EXPECT_EQ(rig.download(0x1005, 0, 0x40000080), 0u);           // SYNC producer: Motwin extension
  EXPECT_EQ(rig.download(0x1005, 0, 0x80000080), 0x06090030u);  // bit 31 is not a 1005 bit
  EXPECT_EQ(rig.download(0x1005, 0, 0x20000080), 0x06090030u);  // 29-bit
}

TEST(SdoServer, store_and_restore_with_wrong_signature_abort_08000020) {
  Tmcm3216Rig rig;
  EXPECT_EQ(rig.download(0x1010, 1, 0x12345678), 0x08000020u);
  EXPECT_EQ(rig.download(0x1011, 1, 0x65766173), 0x08000020u);  // "save" is not "load"
  EXPECT_EQ(rig.download(0x1010, 3, 0x65766173), 0x08000020u);  // device profile: not used
  EXPECT_EQ(rig.download(0x2706, 1, 0), 0x08000020u);
  EXPECT_EQ(rig.nvm->write_count(), 0u);
}

TEST(SdoServer, pdo_mapping_changes_while_valid_abort_08000022) {
  Tmcm3216Rig rig;
  EXPECT_EQ(rig.download(0x1A00, 0, 0, 1), 0x08000022u);
  EXPECT_EQ(rig.download(0x1600, 1, 0, 4), 0x08000022u);
}

TEST(SdoServer, command_specifier_7_aborts_05040001) {
  Tmcm3216Rig rig;
  EXPECT_EQ(Tmcm3216Rig::abort_of(rig.sdo({0xE0, 0, 0, 0, 0, 0, 0, 0})), 0x05040001u);
  EXPECT_EQ(rig.read_u32(0x1000, 0), 0xFFFF0192u);  // still serving
}

TEST(SdoServer, segments_out_of_sequence_abort_05040001) {
  Tmcm3216Rig rig;
  EXPECT_EQ(Tmcm3216Rig::abort_of(rig.sdo({0x60, 0, 0, 0, 0, 0, 0, 0})), 0x05040001u);  // upload segment, idle
  EXPECT_EQ(Tmcm3216Rig::abort_of(rig.sdo({0x01, 0, 0, 0, 0, 0, 0, 0})), 0x05040001u);  // download segment, idle
  rig.sdo({0x40, 0x08, 0x10, 0, 0, 0, 0, 0});
  const can::CanFrame r = rig.sdo({0x01, 0, 0, 0, 0, 0, 0, 0});  // download segment during an upload
  EXPECT_EQ(Tmcm3216Rig::abort_of(r), 0x05040001u);
  EXPECT_EQ(r.data[1], 0x08);
  EXPECT_EQ(rig.device->sdo().state(), SdoState::kIdle);
}

TEST(SdoServer, short_frames_abort_05040001_and_keep_serving) {
  Tmcm3216Rig rig;
  EXPECT_EQ(Tmcm3216Rig::abort_of(rig.sdo({0x40, 0x00, 0x10})), 0x05040001u);
  EXPECT_EQ(Tmcm3216Rig::abort_of(rig.sdo({})), 0x05040001u);
  EXPECT_EQ(rig.read_u32(0x1000, 0), 0xFFFF0192u);
}

TEST(SdoServer, client_abort_ends_a_transfer_silently) {
  Tmcm3216Rig rig;
  rig.sdo({0x40, 0x08, 0x10, 0, 0, 0, 0, 0});
  EXPECT_TRUE(rig.send(frame_of(0x600u + rig.node(), {0x80, 0x08, 0x10, 0, 0, 0, 0x04, 0x05})).empty());
  EXPECT_EQ(rig.device->sdo().state(), SdoState::kIdle);
}

TEST(SdoServer, a_new_initiate_replaces_a_stale_transfer) {
  Tmcm3216Rig rig;
  rig.sdo({0x40, 0x08, 0x10, 0, 0, 0, 0, 0});
  EXPECT_EQ(rig.read_u32(0x1018, 2), 3216u);
}

TEST(SdoServer, segmented_transfer_times_out_with_05040000) {
  Tmcm3216Rig rig;
  rig.sdo({0x40, 0x08, 0x10, 0, 0, 0, 0, 0});
  rig.can.take();
  for (int ms = 0; ms < 999; ++ms) rig.device->process(1000);  // 1 ms of the services
  EXPECT_TRUE(rig.can.take().empty());
  rig.device->process(1000);  // 1 ms of the services
  const std::vector<can::CanFrame> out = rig.can.take();
  ASSERT_EQ(out.size(), 1u);
  EXPECT_EQ(Tmcm3216Rig::abort_of(out[0]), 0x05040000u);
  EXPECT_EQ(out[0].data[1], 0x08);
  EXPECT_EQ(rig.device->sdo().state(), SdoState::kIdle);
}

TEST(SdoServer, requests_to_other_nodes_and_rtr_frames_are_ignored) {
  Tmcm3216Rig rig;
  EXPECT_TRUE(rig.send(frame_of(0x602, {0x40, 0x00, 0x10, 0, 0, 0, 0, 0})).empty());
  can::CanFrame rtr = frame_of(0x601, {});
  rtr.rtr = true;
  rtr.dlc = 8;
  EXPECT_TRUE(rig.send(rtr).empty());
  can::CanFrame extended = frame_of(0x601, {0x40, 0x00, 0x10, 0, 0, 0, 0, 0});
  extended.extended = true;
  EXPECT_TRUE(rig.send(extended).empty());
}

// --- A dictionary with a write-only and a signed object -----------------------------------------

struct TestOwner {
  uint32_t command = 0;
  int16_t offset = 0;
};

using TestRow = canopen::EntryRow<TestOwner>;

constexpr canopen::EntryInfo info(uint16_t index, canopen::DataType type, canopen::Access access, int64_t min,
                                  int64_t max) {
  return canopen::EntryInfo{index, 0,   canopen::ObjectCode::kVar, "test", "test", type, access, false, min, max, 0,
                            false, 0,   canopen::StorageGroup::kNone, nullptr};
}

const std::array<TestRow, 2> kTestRows = {{
    {info(0x2000, canopen::DataType::kUnsigned32, canopen::Access::kWo, 0, 0xFFFFFFFF),
     canopen::field_binding<TestOwner, [](TestOwner& o, uint8_t) -> uint32_t& { return o.command; }>()},
    {info(0x2001, canopen::DataType::kInteger16, canopen::Access::kRw, -100, 100),
     canopen::field_binding<TestOwner, [](TestOwner& o, uint8_t) -> int16_t& { return o.offset; }>()},
}};

struct TestServer {
  TestOwner owner;
  canopen::TableDictionary<TestOwner> dictionary{owner, kTestRows, 1};
  RecordingCanController can;
  canopen::SdoServer server{dictionary, can};

  can::CanFrame request(std::initializer_list<uint8_t> bytes) {
    server.on_request(frame_of(0x601, bytes));
    server.process(0);
    EXPECT_EQ(can.frames.size(), 1u);
    return can.take().at(0);
  }
};

TEST(SdoServer, reading_a_write_only_object_aborts_06010001) {
  TestServer t;
  EXPECT_EQ(Tmcm3216Rig::abort_of(t.request({0x23, 0x00, 0x20, 0, 0x78, 0x56, 0x34, 0x12})), 0u);
  EXPECT_EQ(t.owner.command, 0x12345678u);
  EXPECT_EQ(Tmcm3216Rig::abort_of(t.request({0x40, 0x00, 0x20, 0, 0, 0, 0, 0})), 0x06010001u);
}

TEST(SdoServer, signed_objects_are_sign_extended_and_range_checked) {
  TestServer t;
  EXPECT_EQ(Tmcm3216Rig::abort_of(t.request({0x2B, 0x01, 0x20, 0, 0x9C, 0xFF, 0, 0})), 0u);  // -100
  EXPECT_EQ(t.owner.offset, -100);
  const can::CanFrame r = t.request({0x40, 0x01, 0x20, 0, 0, 0, 0, 0});
  EXPECT_EQ(r.data[0], 0x4B);
  EXPECT_EQ(r.data[4], 0x9C);
  EXPECT_EQ(r.data[5], 0xFF);
  EXPECT_EQ(Tmcm3216Rig::abort_of(t.request({0x2B, 0x01, 0x20, 0, 0x9B, 0xFF, 0, 0})), 0x06090032u);  // -101
  EXPECT_EQ(Tmcm3216Rig::abort_of(t.request({0x2B, 0x01, 0x20, 0, 101, 0, 0, 0})), 0x06090031u);
  EXPECT_EQ(t.owner.offset, -100);
}

TEST(ObjectDictionary, codec_round_trips_every_numeric_type) {
  uint8_t bytes[4] = {};
  canopen::encode_value(canopen::DataType::kInteger8, -1, bytes);
  EXPECT_EQ(bytes[0], 0xFF);
  EXPECT_EQ(canopen::decode_value(canopen::DataType::kInteger8, bytes), -1);
  EXPECT_EQ(canopen::decode_value(canopen::DataType::kUnsigned8, bytes), 255);
  canopen::encode_value(canopen::DataType::kInteger32, INT32_MIN, bytes);
  EXPECT_EQ(canopen::decode_value(canopen::DataType::kInteger32, bytes), INT32_MIN);
  EXPECT_EQ(canopen::decode_value(canopen::DataType::kUnsigned32, bytes), 0x80000000);
}

}  // namespace
}  // namespace motwin::testing
