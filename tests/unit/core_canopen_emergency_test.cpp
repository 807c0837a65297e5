// EMCY producer (src/core/canopen/emergency.h) and heartbeat consumer (heartbeat_consumer.h) in
// the TMCM-3216: EMCY 8130 on a heartbeat timeout with 1001 bit 4, EMCY 0000 on recovery, the
// 1029 error behaviour, the 1015 inhibit time (producer API and written by SDO) and 1014 bit 31.
#include <gtest/gtest.h>

#include "core/canopen/emergency.h"
#include "core/canopen/heartbeat_consumer.h"
#include "support/canopen_rig.h"

namespace motwin::testing {
namespace {

using canopen::NmtState;

std::vector<can::CanFrame> emcy_frames(const std::vector<can::CanFrame>& frames, uint32_t id = 0x81) {
  std::vector<can::CanFrame> out;
  for (const can::CanFrame& f : frames) {
    if (f.id == id) out.push_back(f);
  }
  return out;
}

void ticks(Tmcm3216Rig& rig, int count, std::vector<can::CanFrame>& out) {
  for (int i = 0; i < count; ++i) {
    rig.device->process(1000);  // 1 ms of the services
    for (const can::CanFrame& f : rig.can.take()) out.push_back(f);
  }
}

TEST(HeartbeatConsumer, monitoring_starts_with_the_first_heartbeat) {
  canopen::HeartbeatConsumer consumer;
  consumer.configure(0x00030064);  // node 3, 100 ms
  EXPECT_EQ(consumer.state(), canopen::HeartbeatConsumer::State::kWaitingForFirst);
  for (int i = 0; i < 1000; ++i) EXPECT_EQ(consumer.process(1000), canopen::HeartbeatEvent::kNone);
  consumer.on_frame(frame_of(0x703, {0x05}));
  consumer.on_frame(frame_of(0x704, {0x05}));  // another node
  int timeout_at = -1;
  for (int ms = 1; ms <= 200 && timeout_at < 0; ++ms) {
    if (consumer.process(1000) == canopen::HeartbeatEvent::kTimeout) timeout_at = ms;
  }
  EXPECT_EQ(timeout_at, 101);  // the first process() after the frame starts the time
  EXPECT_EQ(consumer.process(1000), canopen::HeartbeatEvent::kNone);  // reported once
  consumer.on_frame(frame_of(0x703, {0x05}));
  EXPECT_EQ(consumer.process(1000), canopen::HeartbeatEvent::kRecovered);
  consumer.configure(0);
  EXPECT_EQ(consumer.state(), canopen::HeartbeatConsumer::State::kUnused);
}

TEST(Emergency, heartbeat_timeout_sends_8130_and_recovery_sends_0000) {
  Tmcm3216Rig rig;
  ASSERT_EQ(rig.download(0x1016, 1, 0x00020064), 0u);  // node 2, 100 ms
  rig.send(frame_of(0x702, {0x05}));
  std::vector<can::CanFrame> out;
  ticks(rig, 150, out);
  std::vector<can::CanFrame> emcy = emcy_frames(out);
  ASSERT_EQ(emcy.size(), 1u);
  EXPECT_EQ(emcy[0].dlc, 8);
  const uint8_t expected[8] = {0x30, 0x81, 0x11, 0x00, 0xFF, 0x00, 0x00, 0x00};
  for (int i = 0; i < 8; ++i) EXPECT_EQ(emcy[0].data[i], expected[i]) << i;
  EXPECT_EQ(rig.read_u32(0x1001, 0) & 0xFF, 0x11u);
  EXPECT_EQ(rig.device->nmt_state(), NmtState::kPreOperational) << "1029 acts in operational only";
  out = rig.send(frame_of(0x702, {0x05}));
  ticks(rig, 1, out);
  emcy = emcy_frames(out);
  ASSERT_EQ(emcy.size(), 1u);
  EXPECT_EQ(emcy[0].data[0], 0x00);
  EXPECT_EQ(emcy[0].data[1], 0x00);
  EXPECT_EQ(emcy[0].data[2], 0x00);
  EXPECT_EQ(rig.read_u32(0x1001, 0) & 0xFF, 0u);
}

TEST(Emergency, error_behavior_0_stops_an_operational_node_and_1_keeps_it) {
  Tmcm3216Rig rig;
  ASSERT_EQ(rig.download(0x1016, 1, 0x00020032), 0u);  // node 2, 50 ms
  rig.nmt(0x01, 1);
  rig.send(frame_of(0x702, {0x05}));
  std::vector<can::CanFrame> out;
  ticks(rig, 100, out);
  EXPECT_EQ(emcy_frames(out).size(), 1u) << "the EMCY goes out before the node stops";
  EXPECT_EQ(rig.device->nmt_state(), NmtState::kStopped);

  rig.nmt(0x80, 1);
  ASSERT_EQ(rig.download(0x1029, 1, 1, 1), 0u);
  rig.nmt(0x01, 1);
  rig.send(frame_of(0x702, {0x05}));
  out.clear();
  ticks(rig, 100, out);
  EXPECT_EQ(rig.device->nmt_state(), NmtState::kOperational);
}

TEST(Emergency, inhibit_time_spaces_messages) {
  RecordingCanController can;
  canopen::EmergencyProducer producer(can);
  producer.set_cob_id(0x85);
  producer.set_inhibit_time_100us(100);  // 10 ms
  const uint8_t none[5] = {0, 255, 0, 0, 0};
  EXPECT_TRUE(producer.report(0x8130, 0x11, none));
  EXPECT_TRUE(producer.report(0x0000, 0x00, none));
  producer.process(0);
  EXPECT_EQ(can.take().size(), 1u);
  for (int ms = 1; ms < 10; ++ms) {
    producer.process(1000);
    EXPECT_TRUE(can.take().empty()) << ms;
  }
  producer.process(1000);
  const std::vector<can::CanFrame> out = can.take();
  ASSERT_EQ(out.size(), 1u);
  EXPECT_EQ(out[0].id, 0x85u);
  EXPECT_EQ(out[0].data[0], 0x00);
}

TEST(Emergency, inhibit_time_written_to_1015_spaces_the_rpdo_emcys) {
  // 1015 = 100 (10 ms) by SDO; RPDO 1 (6040, 2 bytes, table 41) with 1 byte raises 8210 at once,
  // the correct RPDO right after it clears the error, and its EMCY 0000 waits out the 10 ms.
  Tmcm3216Rig rig;
  ASSERT_EQ(rig.download(0x1015, 0, 100, 2), 0u);
  EXPECT_EQ(rig.read_u32(0x1015, 0), 100u);
  rig.nmt(0x01, rig.node());
  const uint32_t emcy_id = 0x80u + rig.node();
  const uint32_t rpdo1 = 0x200u + rig.node();

  std::vector<can::CanFrame> emcy = emcy_frames(rig.send(frame_of(rpdo1, {0x06})), emcy_id);
  ASSERT_EQ(emcy.size(), 1u);
  const uint8_t too_short[8] = {0x10, 0x82, 0x11, 0x00, 0xFF, 0x00, 0x00, 0x00};
  for (int i = 0; i < 8; ++i) EXPECT_EQ(emcy[0].data[i], too_short[i]) << i;

  EXPECT_TRUE(emcy_frames(rig.send(frame_of(rpdo1, {0x00, 0x00})), emcy_id).empty()) << "inhibited";
  EXPECT_EQ(rig.read_u32(0x1001, 0) & 0xFF, 0u) << "the error is gone, its EMCY waits";
  int sent_at_ms = -1;
  for (int ms = 1; ms <= 20 && sent_at_ms < 0; ++ms) {
    std::vector<can::CanFrame> out;
    ticks(rig, 1, out);
    emcy = emcy_frames(out, emcy_id);
    if (emcy.empty()) continue;
    sent_at_ms = ms;
    ASSERT_EQ(emcy.size(), 1u);
    const uint8_t reset[8] = {0x00, 0x00, 0x00, 0x00, 0xFF, 0x00, 0x00, 0x00};
    for (int i = 0; i < 8; ++i) EXPECT_EQ(emcy[0].data[i], reset[i]) << i;
  }
  EXPECT_EQ(sent_at_ms, 10) << "10 ms after the 8210";

  // 1015 = 0 again (the running inhibit time of the EMCY 0000 ends first): back-to-back EMCYs
  // go out together.
  ASSERT_EQ(rig.download(0x1015, 0, 0, 2), 0u);
  std::vector<can::CanFrame> out;
  ticks(rig, 10, out);
  EXPECT_TRUE(emcy_frames(out, emcy_id).empty());
  out = rig.send(frame_of(rpdo1, {0x06}));
  for (const can::CanFrame& f : rig.send(frame_of(rpdo1, {0x00, 0x00}))) out.push_back(f);
  emcy = emcy_frames(out, emcy_id);
  ASSERT_EQ(emcy.size(), 2u);
  EXPECT_EQ(emcy[0].data[1], 0x82);
  EXPECT_EQ(emcy[1].data[1], 0x00);
}

// RPDO 1 of axis 0 remapped to 6060 (modes of operation, 1 byte): mode 2 is not supported and
// refused by the object, so the PDO's data "cannot be accepted" (manual table 365): EMCY 6320 once,
// byte 2 = 255, 1001 generic; 0000 when an RPDO is written whole again. Synchronous: at the SYNC.
void map_rpdo1_to_6060(Tmcm3216Rig& rig, uint32_t transmission_type) {
  const uint32_t cob_id = 0x200u + rig.node();
  ASSERT_EQ(rig.download(0x1400, 1, cob_id | 0x8000'0000u, 4), 0u);
  ASSERT_EQ(rig.download(0x1400, 2, transmission_type, 1), 0u);
  ASSERT_EQ(rig.download(0x1600, 0, 0, 1), 0u);
  ASSERT_EQ(rig.download(0x1600, 1, 0x6060'0008u, 4), 0u);
  ASSERT_EQ(rig.download(0x1600, 0, 1, 1), 0u);
  ASSERT_EQ(rig.download(0x1400, 1, cob_id, 4), 0u);
}

TEST(Emergency, rpdo_value_the_object_refuses_sends_6320_once_and_0000_after_a_good_rpdo) {
  Tmcm3216Rig rig;
  map_rpdo1_to_6060(rig, 0xFF);
  rig.nmt(0x01, rig.node());
  const uint32_t emcy_id = 0x80u + rig.node();
  const uint32_t rpdo1 = 0x200u + rig.node();

  std::vector<can::CanFrame> emcy = emcy_frames(rig.send(frame_of(rpdo1, {0x02})), emcy_id);
  ASSERT_EQ(emcy.size(), 1u);
  const uint8_t parameter_error[8] = {0x20, 0x63, 0x01, 0x00, 0xFF, 0x00, 0x00, 0x00};
  for (int i = 0; i < 8; ++i) EXPECT_EQ(emcy[0].data[i], parameter_error[i]) << i;
  EXPECT_EQ(rig.read_u32(0x1001, 0) & 0xFF, 0x01u);
  EXPECT_EQ(rig.read_u32(0x6060, 0) & 0xFF, 0u) << "the refused value is not written";
  EXPECT_TRUE(emcy_frames(rig.send(frame_of(rpdo1, {0x07})), emcy_id).empty()) << "one EMCY per episode";

  emcy = emcy_frames(rig.send(frame_of(rpdo1, {0x01})), emcy_id);
  ASSERT_EQ(emcy.size(), 1u);
  const uint8_t reset[8] = {0x00, 0x00, 0x00, 0x00, 0xFF, 0x00, 0x00, 0x00};
  for (int i = 0; i < 8; ++i) EXPECT_EQ(emcy[0].data[i], reset[i]) << i;
  EXPECT_EQ(rig.read_u32(0x1001, 0) & 0xFF, 0u);
  EXPECT_EQ(rig.read_u32(0x6060, 0) & 0xFF, 1u);
  EXPECT_TRUE(emcy_frames(rig.send(frame_of(rpdo1, {0x03})), emcy_id).empty()) << "nothing to clear";
}

TEST(Emergency, synchronous_rpdo_value_is_judged_at_the_sync) {
  Tmcm3216Rig rig;
  map_rpdo1_to_6060(rig, 1);
  rig.nmt(0x01, rig.node());
  const uint32_t emcy_id = 0x80u + rig.node();
  const uint32_t rpdo1 = 0x200u + rig.node();
  EXPECT_TRUE(emcy_frames(rig.send(frame_of(rpdo1, {0x02})), emcy_id).empty()) << "kept for the SYNC";
  std::vector<can::CanFrame> emcy = emcy_frames(rig.send(frame_of(0x80, {})), emcy_id);
  ASSERT_EQ(emcy.size(), 1u);
  EXPECT_EQ(emcy[0].data[0], 0x20);
  EXPECT_EQ(emcy[0].data[1], 0x63);
  // The same bad value every cycle: no EMCY per SYNC.
  EXPECT_TRUE(emcy_frames(rig.send(frame_of(rpdo1, {0x02})), emcy_id).empty());
  EXPECT_TRUE(emcy_frames(rig.send(frame_of(0x80, {})), emcy_id).empty());
  // A good value: 0000 at its SYNC, not at its reception.
  EXPECT_TRUE(emcy_frames(rig.send(frame_of(rpdo1, {0x03})), emcy_id).empty());
  emcy = emcy_frames(rig.send(frame_of(0x80, {})), emcy_id);
  ASSERT_EQ(emcy.size(), 1u);
  EXPECT_EQ(emcy[0].data[0], 0x00);
  EXPECT_EQ(emcy[0].data[1], 0x00);
  EXPECT_EQ(rig.read_u32(0x6060, 0) & 0xFF, 3u);
}

TEST(Emergency, cob_id_bit_31_switches_the_producer_off) {
  Tmcm3216Rig rig;
  ASSERT_EQ(rig.download(0x1014, 0, 0x80000081), 0u);
  ASSERT_EQ(rig.download(0x1016, 1, 0x00020032), 0u);
  rig.send(frame_of(0x702, {0x05}));
  std::vector<can::CanFrame> out;
  ticks(rig, 100, out);
  EXPECT_TRUE(emcy_frames(out).empty());
  EXPECT_EQ(rig.read_u32(0x1001, 0) & 0xFF, 0x11u);
  ASSERT_EQ(rig.download(0x1014, 0, 0x000000A0), 0u);  // a new ID while not valid
  out = rig.send(frame_of(0x702, {0x05}));  // recovery: EMCY 0000 within this process call
  ticks(rig, 1, out);
  EXPECT_EQ(emcy_frames(out, 0xA0).size(), 1u);
}

TEST(Emergency, queue_overflow_loses_messages_and_counts_them) {
  RecordingCanController can;
  canopen::EmergencyProducer producer(can);
  producer.set_cob_id(0x81);
  const uint8_t none[5] = {};
  for (size_t i = 0; i < canopen::EmergencyProducer::kQueueLength; ++i) EXPECT_TRUE(producer.report(1, 0, none));
  EXPECT_FALSE(producer.report(2, 0, none));
  EXPECT_EQ(producer.lost(), 1u);
  producer.process(0);
  EXPECT_EQ(can.take().size(), canopen::EmergencyProducer::kQueueLength);  // no inhibit time
}

}  // namespace
}  // namespace motwin::testing
