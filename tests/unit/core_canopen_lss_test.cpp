// LSS slave (src/core/canopen/lss_slave.h) in the TMCM-3216: switch state global and selective,
// inquire identity and node ID, configure node ID and bit timing with their error codes, activate
// bit timing, store configuration, fastscan as python-canopen runs it, and the unconfigured node
// (2705 = 255) that only LSS reaches until it has a node ID.
#include <gtest/gtest.h>

#include <vector>

#include "core/canopen/lss_slave.h"
#include "support/canopen_rig.h"

namespace motwin::testing {
namespace {

using canopen::LssState;
using canopen::NmtState;
using modules::tmcm3216::Tmcm3216Config;

constexpr uint32_t kSerial = 0x1234'5678;

Tmcm3216Config with_serial() {
  Tmcm3216Config config;
  config.serial_number = kSerial;
  return config;
}

can::CanFrame lss(std::initializer_list<uint8_t> bytes) {
  can::CanFrame f = frame_of(0x7E5, bytes);
  while (f.dlc < 8) f.data[f.dlc++] = 0;
  return f;
}

can::CanFrame lss_value(uint8_t command, uint32_t value) {
  return lss({command, static_cast<uint8_t>(value), static_cast<uint8_t>(value >> 8), static_cast<uint8_t>(value >> 16),
              static_cast<uint8_t>(value >> 24)});
}

std::vector<can::CanFrame> slave_answers(const std::vector<can::CanFrame>& frames) {
  std::vector<can::CanFrame> out;
  for (const can::CanFrame& f : frames) {
    if (f.id == 0x7E4) out.push_back(f);
  }
  return out;
}

// Sends one LSS frame; returns the 0x7E4 answers.
std::vector<can::CanFrame> ask(Tmcm3216Rig& rig, const can::CanFrame& frame) { return slave_answers(rig.send(frame)); }

void switch_selective(Tmcm3216Rig& rig, bool expect_answer = true) {
  EXPECT_TRUE(ask(rig, lss_value(0x40, 0x286)).empty());
  EXPECT_TRUE(ask(rig, lss_value(0x41, 3216)).empty());
  EXPECT_TRUE(ask(rig, lss_value(0x42, 0x0001'0004)).empty());
  const auto answer = ask(rig, lss_value(0x43, kSerial));
  ASSERT_EQ(answer.size(), expect_answer ? 1u : 0u);
  if (expect_answer) {
    EXPECT_EQ(answer[0].dlc, 8);
    EXPECT_EQ(answer[0].data[0], 0x44);
  }
}

TEST(Lss, inquire_needs_the_configuration_state) {
  Tmcm3216Rig rig(with_serial());
  EXPECT_TRUE(ask(rig, lss({0x5A})).empty());  // waiting: ignored
  ask(rig, lss({0x04, 0x01}));                  // switch state global: configuration
  EXPECT_EQ(rig.device->lss().state(), LssState::kConfiguration);
  const uint32_t expected[4] = {0x286, 3216, 0x0001'0004, kSerial};
  for (uint8_t i = 0; i < 4; ++i) {
    const auto answer = ask(rig, lss({static_cast<uint8_t>(0x5A + i)}));
    ASSERT_EQ(answer.size(), 1u);
    EXPECT_EQ(answer[0].data[0], 0x5A + i);
    EXPECT_EQ(le32(answer[0], 1), expected[i]);
  }
  const auto node = ask(rig, lss({0x5E}));
  ASSERT_EQ(node.size(), 1u);
  EXPECT_EQ(node[0].data[1], 1);
  ask(rig, lss({0x04, 0x00}));
  EXPECT_TRUE(ask(rig, lss({0x5E})).empty());
}

TEST(Lss, switch_state_selective_needs_the_whole_identity_in_order) {
  Tmcm3216Rig rig(with_serial());
  EXPECT_TRUE(ask(rig, lss_value(0x40, 0x286)).empty());
  EXPECT_TRUE(ask(rig, lss_value(0x41, 3217)).empty());  // another product: starts over
  EXPECT_TRUE(ask(rig, lss_value(0x42, 0x0001'0004)).empty());
  EXPECT_TRUE(ask(rig, lss_value(0x43, kSerial)).empty());
  EXPECT_EQ(rig.device->lss().state(), LssState::kWaiting);
  switch_selective(rig);
  EXPECT_EQ(rig.device->lss().state(), LssState::kConfiguration);
}

TEST(Lss, configure_node_id_error_codes_and_reset_communication_applies_it) {
  Tmcm3216Rig rig(with_serial());
  switch_selective(rig);
  auto answer = ask(rig, lss({0x11, 0}));
  ASSERT_EQ(answer.size(), 1u);
  EXPECT_EQ(answer[0].data[0], 0x11);
  EXPECT_EQ(answer[0].data[1], 1);  // out of range
  answer = ask(rig, lss({0x11, 128}));
  EXPECT_EQ(answer[0].data[1], 1);
  answer = ask(rig, lss({0x11, 42}));
  EXPECT_EQ(answer[0].data[1], 0);
  EXPECT_EQ(rig.device->node_id(), 1);  // pending until a reset
  ask(rig, lss({0x04, 0x00}));
  EXPECT_EQ(rig.device->node_id(), 1);  // a configured node: switching to waiting is not enough
  const auto boot = rig.send(frame_of(0x000, {0x82, 1}));  // NMT reset communication
  ASSERT_EQ(boot.size(), 1u);
  EXPECT_EQ(boot[0].id, 0x700u + 42);
  EXPECT_EQ(rig.device->node_id(), 42);
  EXPECT_EQ(rig.read_u32(0x2708, 0) & 0xFF, 42u);
  EXPECT_EQ(rig.read_u32(0x1014, 0), 0x80u + 42);  // $NODEID objects follow
  rig.power_cycle(with_serial());  // not stored: gone
  EXPECT_EQ(rig.device->node_id(), 1);
}

TEST(Lss, configure_bit_timing_table_and_activation) {
  Tmcm3216Rig rig(with_serial());
  ask(rig, lss({0x04, 0x01}));
  auto answer = ask(rig, lss({0x13, 0, 8}));  // 10 kbit/s: not in table 177
  ASSERT_EQ(answer.size(), 1u);
  EXPECT_EQ(answer[0].data[0], 0x13);
  EXPECT_EQ(answer[0].data[1], 1);
  EXPECT_EQ(ask(rig, lss({0x13, 1, 0}))[0].data[1], 1);  // table selector 1: none
  EXPECT_EQ(ask(rig, lss({0x13, 0, 9}))[0].data[1], 1);  // automatic
  EXPECT_EQ(ask(rig, lss({0x13, 0, 3}))[0].data[1], 0);  // 250 kbit/s
  EXPECT_EQ(rig.device->lss().pending_bit_rate_kbit(), 250);
  EXPECT_EQ(rig.device->bit_rate_kbit(), 1000);
  EXPECT_TRUE(ask(rig, lss({0x15, 10, 0})).empty());  // activate after 2 x 10 ms
  for (int ms = 0; ms < 19; ++ms) rig.device->process(1000);  // 1 ms of the services
  EXPECT_EQ(rig.device->bit_rate_kbit(), 1000);
  rig.device->process(1000);  // 1 ms of the services
  EXPECT_EQ(rig.device->bit_rate_kbit(), 250);
  EXPECT_EQ(rig.read_u32(0x2707, 0) & 0xFFFF, 250u);
  EXPECT_EQ(rig.read_u32(0x2704, 0) & 0xFFFF, 1000u);  // stored setting unchanged
  EXPECT_EQ(canopen::LssSlave::bit_rate_of_index(5), 100);
}

TEST(Lss, configure_store_and_power_cycle_keeps_node_id_and_bit_rate) {
  Tmcm3216Rig rig(with_serial());
  switch_selective(rig);
  EXPECT_EQ(ask(rig, lss({0x11, 9}))[0].data[1], 0);
  EXPECT_EQ(ask(rig, lss({0x13, 0, 2}))[0].data[1], 0);  // 500 kbit/s
  const auto stored = ask(rig, lss({0x17}));
  ASSERT_EQ(stored.size(), 1u);
  EXPECT_EQ(stored[0].data[0], 0x17);
  EXPECT_EQ(stored[0].data[1], 0);
  EXPECT_EQ(rig.nvm->write_count(), 1u);
  rig.power_cycle(with_serial());
  EXPECT_EQ(rig.device->node_id(), 9);
  EXPECT_EQ(rig.device->bit_rate_kbit(), 500);
  EXPECT_EQ(rig.read_u32(0x2705, 0) & 0xFF, 9u);
}

TEST(Lss, store_failure_answers_error_2) {
  Tmcm3216Rig rig(with_serial());
  ask(rig, lss({0x04, 0x01}));
  rig.nvm->set_fail_writes(true);
  const auto stored = ask(rig, lss({0x17}));
  ASSERT_EQ(stored.size(), 1u);
  EXPECT_EQ(stored[0].data[1], 2);
  EXPECT_EQ(rig.read_u32(0x2705, 0) & 0xFF, 1u);
}

TEST(Lss, unconfigured_node_answers_only_lss_until_configured_then_boots) {
  Tmcm3216Rig rig(with_serial());
  ASSERT_EQ(rig.download(0x2705, 0, 255, 1), 0u);
  ASSERT_EQ(rig.download(0x2706, 1, 0x65766173), 0u);
  rig.power_cycle(with_serial());
  EXPECT_FALSE(rig.device->configured());
  EXPECT_TRUE(rig.can.take().empty());  // no boot-up
  EXPECT_TRUE(rig.send(frame_of(0x000, {0x82, 0})).empty());            // NMT: ignored
  EXPECT_TRUE(rig.send(frame_of(0x6FF, {0x40, 0, 0x10, 0, 0, 0, 0, 0})).empty());  // SDO to 127
  for (int i = 0; i < 100; ++i) rig.device->process(1000);  // 1 ms of the services
  EXPECT_TRUE(rig.can.take().empty());
  switch_selective(rig);
  EXPECT_EQ(ask(rig, lss({0x5E}))[0].data[1], 255);
  EXPECT_EQ(ask(rig, lss({0x11, 17}))[0].data[1], 0);
  // Back to waiting: the node starts with its new ID (CiA-305), boot-up included.
  const auto frames = rig.send(lss({0x04, 0x00}));
  ASSERT_EQ(frames.size(), 1u);
  EXPECT_EQ(frames[0].id, 0x700u + 17);
  EXPECT_EQ(frames[0].data[0], 0);
  EXPECT_TRUE(rig.device->configured());
  EXPECT_EQ(rig.device->nmt_state(), NmtState::kPreOperational);
  EXPECT_EQ(rig.read_u32(0x1000, 0), 0xFFFF0192u);
  // The stored setting is still 255: a power cycle makes the node unconfigured again.
  rig.power_cycle(with_serial());
  EXPECT_FALSE(rig.device->configured());
}

// python-canopen's LssMaster.fast_scan(): reset (bit 0x80), then for each part 0..3 bits 31..0,
// setting a bit where the slave stays silent, then confirming the part with BitChecked 0 and
// LSSNext = the next part (0 after the serial number).
std::vector<uint32_t> fast_scan(Tmcm3216Rig& rig, bool& found) {
  found = false;
  auto send = [&](uint32_t id, uint8_t bit, uint8_t sub, uint8_t next) {
    return !ask(rig, lss({0x51, static_cast<uint8_t>(id), static_cast<uint8_t>(id >> 8),
                          static_cast<uint8_t>(id >> 16), static_cast<uint8_t>(id >> 24), bit, sub, next}))
                .empty();
  };
  std::vector<uint32_t> id(4, 0);
  if (!send(0, 0x80, 0, 0)) return id;
  for (uint8_t sub = 0; sub < 4; ++sub) {
    for (int bit = 31; bit >= 0; --bit) {
      if (!send(id[sub], static_cast<uint8_t>(bit), sub, sub)) id[sub] |= 1u << bit;
    }
    if (!send(id[sub], 0, sub, static_cast<uint8_t>((sub + 1) & 3))) return id;
  }
  found = true;
  return id;
}

TEST(Lss, fastscan_finds_an_unconfigured_node_and_leaves_it_in_configuration) {
  Tmcm3216Rig rig(with_serial());
  bool found = true;
  fast_scan(rig, found);
  EXPECT_FALSE(found);  // node ID 1: configured nodes do not take part
  ASSERT_EQ(rig.download(0x2705, 0, 255, 1), 0u);
  ASSERT_EQ(rig.download(0x2706, 1, 0x65766173), 0u);
  rig.power_cycle(with_serial());
  const std::vector<uint32_t> id = fast_scan(rig, found);
  EXPECT_TRUE(found);
  EXPECT_EQ(id, (std::vector<uint32_t>{0x286, 3216, 0x0001'0004, kSerial}));
  EXPECT_EQ(rig.device->lss().state(), LssState::kConfiguration);
  // Configure, store, leave: boots with the new ID and keeps it over a power cycle.
  EXPECT_EQ(ask(rig, lss({0x11, 33}))[0].data[1], 0);
  EXPECT_EQ(ask(rig, lss({0x17}))[0].data[1], 0);
  const auto frames = rig.send(lss({0x04, 0x00}));
  ASSERT_EQ(frames.size(), 1u);
  EXPECT_EQ(frames[0].id, 0x700u + 33);
  rig.power_cycle(with_serial());
  EXPECT_EQ(rig.device->node_id(), 33);
  // Now configured: no longer part of a fastscan.
  fast_scan(rig, found);
  EXPECT_FALSE(found);
}

TEST(Lss, fastscan_with_a_wrong_part_is_silent) {
  Tmcm3216Rig rig(with_serial());
  ASSERT_EQ(rig.download(0x2705, 0, 255, 1), 0u);
  ASSERT_EQ(rig.download(0x2706, 1, 0x65766173), 0u);
  rig.power_cycle(with_serial());
  EXPECT_EQ(ask(rig, lss({0x51, 0, 0, 0, 0, 0x80, 0, 0})).size(), 1u);
  // Asking about part 1 while the slave is at part 0: no answer.
  EXPECT_TRUE(ask(rig, lss({0x51, 0x90, 0x0C, 0, 0, 0, 1, 2})).empty());
  // Full vendor ID with BitChecked 0: answer, moves to part 1.
  EXPECT_EQ(ask(rig, lss({0x51, 0x86, 0x02, 0, 0, 0, 0, 1})).size(), 1u);
  EXPECT_TRUE(ask(rig, lss({0x51, 0x91, 0x0C, 0, 0, 0, 1, 2})).empty());  // 3217: wrong
  EXPECT_EQ(ask(rig, lss({0x51, 0x90, 0x0C, 0, 0, 0, 1, 2})).size(), 1u);  // 3216
  EXPECT_EQ(rig.device->lss().state(), LssState::kWaiting);
  // Malformed: BitChecked 33, LSSSub 4, short frames are ignored.
  EXPECT_TRUE(ask(rig, lss({0x51, 0, 0, 0, 0, 33, 2, 2})).empty());
  EXPECT_TRUE(ask(rig, lss({0x51, 0, 0, 0, 0, 0, 4, 0})).empty());
  EXPECT_TRUE(ask(rig, frame_of(0x7E5, {0x51, 0, 0, 0, 0, 0x80})).empty());
}

}  // namespace
}  // namespace motwin::testing
