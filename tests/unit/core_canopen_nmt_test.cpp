// NMT slave and heartbeat producer (src/core/canopen/nmt.h) inside the TMCM-3216: boot-up, state
// transitions, resets, heartbeat period and phase, and SDO refused while stopped.
#include <gtest/gtest.h>

#include "core/canopen/nmt.h"
#include "support/canopen_rig.h"

namespace motwin::testing {
namespace {

using canopen::NmtState;

std::vector<can::CanFrame> with_id(const std::vector<can::CanFrame>& frames, uint32_t id) {
  std::vector<can::CanFrame> out;
  for (const can::CanFrame& f : frames) {
    if (f.id == id) out.push_back(f);
  }
  return out;
}

TEST(Nmt, power_up_sends_boot_up_and_enters_pre_operational) {
  Tmcm3216Rig rig;
  const std::vector<can::CanFrame> out = rig.can.take();
  ASSERT_EQ(out.size(), 1u);
  EXPECT_EQ(out[0].id, 0x701u);
  EXPECT_EQ(out[0].dlc, 1);
  EXPECT_EQ(out[0].data[0], 0x00);
  EXPECT_EQ(rig.device->nmt_state(), NmtState::kPreOperational);
}

TEST(Nmt, start_stop_and_pre_operational_commands) {
  Tmcm3216Rig rig;
  rig.nmt(0x01, 1);
  EXPECT_EQ(rig.device->nmt_state(), NmtState::kOperational);
  rig.nmt(0x02, 0);  // broadcast
  EXPECT_EQ(rig.device->nmt_state(), NmtState::kStopped);
  rig.nmt(0x80, 1);
  EXPECT_EQ(rig.device->nmt_state(), NmtState::kPreOperational);
  rig.nmt(0x01, 2);  // another node
  EXPECT_EQ(rig.device->nmt_state(), NmtState::kPreOperational);
  rig.nmt(0x03, 1);  // unknown command
  EXPECT_EQ(rig.device->nmt_state(), NmtState::kPreOperational);
  rig.send(frame_of(0x000, {0x01}));  // DLC 1: ignored
  EXPECT_EQ(rig.device->nmt_state(), NmtState::kPreOperational);
  rig.send(frame_of(0x000, {0x01, 0x01, 0x00}));  // DLC 3: ignored
  EXPECT_EQ(rig.device->nmt_state(), NmtState::kPreOperational);
}

TEST(Nmt, reset_node_and_reset_communication_send_boot_up) {
  Tmcm3216Rig rig;
  rig.nmt(0x01, 1);
  std::vector<can::CanFrame> out = rig.send(frame_of(0x000, {0x81, 0x01}));
  ASSERT_EQ(out.size(), 1u);
  EXPECT_EQ(out[0].id, 0x701u);
  EXPECT_EQ(out[0].data[0], 0x00);
  EXPECT_EQ(rig.device->nmt_state(), NmtState::kPreOperational);
  rig.nmt(0x01, 1);
  out = rig.send(frame_of(0x000, {0x82, 0x00}));
  ASSERT_EQ(out.size(), 1u);
  EXPECT_EQ(out[0].id, 0x701u);
  EXPECT_EQ(rig.device->nmt_state(), NmtState::kPreOperational);
}

TEST(Nmt, sdo_is_not_answered_while_stopped) {
  Tmcm3216Rig rig;
  rig.nmt(0x02, 1);
  EXPECT_TRUE(rig.send(frame_of(0x601, {0x40, 0x00, 0x10, 0, 0, 0, 0, 0})).empty());
  rig.nmt(0x80, 1);
  EXPECT_EQ(rig.read_u32(0x1000, 0), 0xFFFF0192u);
}

TEST(Nmt, stopping_drops_a_segmented_transfer) {
  Tmcm3216Rig rig;
  rig.sdo({0x40, 0x08, 0x10, 0, 0, 0, 0, 0});
  rig.nmt(0x02, 1);
  EXPECT_EQ(rig.device->sdo().state(), canopen::SdoState::kIdle);
}

TEST(Nmt, heartbeat_follows_1017_period) {
  Tmcm3216Rig rig;
  rig.can.take();  // boot-up
  for (int i = 0; i < 2000; ++i) rig.device->process(1000);  // 1 ms of the services
  EXPECT_TRUE(rig.can.take().empty()) << "no heartbeat while 1017 = 0";
  ASSERT_EQ(rig.download(0x1017, 0, 100, 2), 0u);
  // The first heartbeat goes out in the process call of the write, then one every 100 ms.
  ASSERT_EQ(rig.other.size(), 1u);
  EXPECT_EQ(rig.other[0].id, 0x701u);
  std::vector<int> times_ms;
  for (int ms = 1; ms <= 1000; ++ms) {
    rig.device->process(1000);  // 1 ms of the services
    for (const can::CanFrame& f : rig.can.take()) {
      ASSERT_EQ(f.id, 0x701u);
      ASSERT_EQ(f.dlc, 1);
      EXPECT_EQ(f.data[0], 0x7F);
      times_ms.push_back(ms);
    }
  }
  ASSERT_EQ(times_ms.size(), 10u);
  for (size_t i = 0; i < times_ms.size(); ++i) EXPECT_EQ(times_ms[i], 100 * static_cast<int>(i + 1));
}

TEST(Nmt, heartbeat_reports_the_state_and_goes_out_on_state_change) {
  Tmcm3216Rig rig;
  ASSERT_EQ(rig.download(0x1017, 0, 1000, 2), 0u);
  rig.device->process(1000);  // 1 ms of the services
  rig.can.take();
  rig.other.clear();
  std::vector<can::CanFrame> out = rig.send(frame_of(0x000, {0x01, 0x01}));
  ASSERT_EQ(with_id(out, 0x701).size(), 1u);
  EXPECT_EQ(out[0].data[0], 0x05);
  out = rig.send(frame_of(0x000, {0x02, 0x01}));
  ASSERT_EQ(out.size(), 1u);
  EXPECT_EQ(out[0].data[0], 0x04);
  for (int i = 0; i < 1000; ++i) rig.device->process(1000);  // 1 ms of the services
  out = rig.can.take();
  ASSERT_EQ(out.size(), 1u);
  EXPECT_EQ(out[0].data[0], 0x04);  // heartbeat continues while stopped
}

TEST(Nmt, heartbeat_keeps_its_phase_with_coarse_time_steps) {
  RecordingCanController can;
  canopen::NmtSlave nmt(can);
  nmt.set_node_id(9);
  nmt.initialize();
  nmt.set_heartbeat_period_ms(10);
  nmt.boot();
  can.take();
  // 3 ms steps: heartbeats are due at 10, 20, 30 ... and sent at the first step at or after.
  int sent = 0;
  for (int t = 3; t <= 300; t += 3) {
    nmt.process(3000);
    sent += static_cast<int>(can.take().size());
  }
  EXPECT_EQ(sent, 30);
}

TEST(Nmt, heartbeat_period_survives_reset_communication_from_storage) {
  Tmcm3216Rig rig;
  ASSERT_EQ(rig.download(0x1017, 0, 50, 2), 0u);
  ASSERT_EQ(rig.download(0x1010, 1, 0x65766173), 0u);
  ASSERT_EQ(rig.download(0x1017, 0, 500, 2), 0u);
  rig.nmt(0x82, 1);
  EXPECT_EQ(rig.read_u32(0x1017, 0) & 0xFFFF, 50u);
  rig.can.take();
  for (int i = 0; i < 100; ++i) rig.device->process(1000);  // 1 ms of the services
  // The boot-up restarts the period: heartbeats at 50 and 100 ms.
  EXPECT_EQ(with_id(rig.can.take(), 0x701).size(), 2u);
}

}  // namespace
}  // namespace motwin::testing
