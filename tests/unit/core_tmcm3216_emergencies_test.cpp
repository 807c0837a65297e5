// The TMCM-3216's axis emergencies (src/core/modules/tmcm3216/tmcm3216_emergencies.h): the exact
// EMCY frames of manual table 365 for every condition the model can produce, the 1001 bits, one
// message per rising edge, the 1015 inhibit time of the producer, and fault reset with 0000.
#include <gtest/gtest.h>

#include <array>
#include <cstdint>
#include <vector>

#include "board/stepper_drive.h"
#include "core/canopen/emergency.h"
#include "core/modules/tmcm3216/tmcm3216_emergencies.h"
#include "support/sdo_frames.h"

namespace motwin::testing {
namespace {

using modules::tmcm3216::AxisCondition;
using modules::tmcm3216::AxisConditions;
using modules::tmcm3216::condition_bit;
using modules::tmcm3216::EmergencyResult;
using modules::tmcm3216::Tmcm3216Emergencies;
using Bytes = std::array<uint8_t, 8>;

struct Bench {
  RecordingCanController can;
  canopen::EmergencyProducer producer{can};
  Tmcm3216Emergencies monitor;

  explicit Bench(uint8_t node_id = 1) { producer.set_cob_id(0x80u + node_id); }
  EmergencyResult update(uint8_t axis, const AxisConditions& c, uint8_t other = 0) {
    return monitor.update(axis, c, producer, other);
  }
  // Everything the producer lets out now.
  std::vector<can::CanFrame> sent(uint32_t elapsed_us = 0) {
    producer.process(elapsed_us);
    return can.take();
  }
};

void expect_frame(const can::CanFrame& f, uint32_t cob_id, const Bytes& bytes) {
  EXPECT_EQ(f.id, cob_id);
  EXPECT_FALSE(f.extended);
  ASSERT_EQ(f.dlc, 8);
  for (int i = 0; i < 8; ++i) EXPECT_EQ(f.data[i], bytes[i]) << "byte " << i;
}

AxisConditions driver(uint8_t flags) {
  AxisConditions c;
  c.driver_errors = flags;
  return c;
}

struct Case {
  const char* name;
  uint8_t axis;
  AxisConditions conditions;
  Bytes frame;  // a fault's 1001 byte has the FAULT bits (0x21) it sets too
  uint8_t bits;  // the monitor's 1001 bits while active
  bool fault;
};

TEST(Tmcm3216Emergencies, every_axis_condition_sends_the_frame_of_table_365) {
  AxisConditions stall;
  stall.stall = true;
  AxisConditions following;
  following.following_error = true;
  AxisConditions sw_pos, sw_neg, switch_pos, switch_neg;
  sw_pos.software_limit_positive = true;
  sw_neg.software_limit_negative = true;
  switch_pos.limit_switch_positive = true;
  switch_neg.limit_switch_negative = true;
  const Case cases[] = {
      {"open load A", 1, driver(board::kDriverOpenLoadA), {0x00, 0x10, 0x01, 1, 1, 0, 0, 0}, 0x01, false},
      {"open load B", 2, driver(board::kDriverOpenLoadB), {0x00, 0x10, 0x01, 2, 2, 0, 0, 0}, 0x01, false},
      {"overcurrent high side", 0, driver(board::kDriverOvercurrentHighSide), {0x10, 0x23, 0x23, 0, 0, 0, 0, 0}, 0x03,
       true},
      {"overcurrent bridge B", 1, driver(board::kDriverOvercurrentB), {0x11, 0x23, 0x23, 0, 1, 0, 0, 0}, 0x03, true},
      {"overcurrent bridge A", 2, driver(board::kDriverOvercurrentA), {0x12, 0x23, 0x23, 0, 2, 0, 0, 0}, 0x03, true},
      {"stallGuard2", 0, stall, {0x30, 0x32, 0x21, 0, 0, 0, 0, 0}, 0x21, true},
      {"overtemperature pre-warning", 1, driver(board::kDriverTemperatureWarning), {0x10, 0x43, 0x09, 1, 1, 0, 0, 0},
       0x09, false},
      {"overtemperature", 2, driver(board::kDriverOvertemperature), {0x10, 0x43, 0x29, 0, 2, 0, 0, 0}, 0x09, true},
      {"following error", 0, following, {0x11, 0x86, 0x21, 0, 0, 0, 0, 0}, 0x21, true},
      {"undervoltage", 1, driver(board::kDriverUndervoltage), {0x00, 0xFF, 0x25, 0, 1, 0, 0, 0}, 0x05, true},
      {"positive software limit", 2, sw_pos, {0x01, 0xFF, 0x81, 1, 2, 0, 0, 0}, 0x81, false},
      {"negative software limit", 0, sw_neg, {0x01, 0xFF, 0x81, 2, 0, 0, 0, 0}, 0x81, false},
      {"positive limit switch", 1, switch_pos, {0x01, 0xFF, 0x81, 3, 1, 0, 0, 0}, 0x81, false},
      {"negative limit switch", 2, switch_neg, {0x01, 0xFF, 0x81, 4, 2, 0, 0, 0}, 0x81, false},
  };
  for (const Case& c : cases) {
    SCOPED_TRACE(c.name);
    Bench bench;
    const EmergencyResult result = bench.update(c.axis, c.conditions);
    EXPECT_EQ(result.fault, c.fault);
    EXPECT_FALSE(result.stop);
    EXPECT_NE(result.raised, 0);
    const auto frames = bench.sent();
    ASSERT_EQ(frames.size(), 1u);
    expect_frame(frames[0], 0x81, c.frame);
    EXPECT_EQ(bench.monitor.error_register(), c.bits);
    EXPECT_EQ(bench.monitor.error_register(c.axis), c.bits);
    EXPECT_EQ(bench.monitor.fault_present(c.axis), c.fault);
    EXPECT_EQ(bench.monitor.active_faults(c.axis) != 0, c.fault);
    for (uint8_t other = 0; other < 3; ++other) {
      if (other != c.axis) {
        EXPECT_EQ(bench.monitor.active_conditions(other), 0) << "axis " << int{other};
      }
    }
  }
}

TEST(Tmcm3216Emergencies, cob_id_follows_the_node_id) {
  Bench bench(0x7F);
  bench.update(2, driver(board::kDriverOvertemperature));
  const auto frames = bench.sent();
  ASSERT_EQ(frames.size(), 1u);
  expect_frame(frames[0], 0xFF, {0x10, 0x43, 0x29, 0, 2, 0, 0, 0});
}

TEST(Tmcm3216Emergencies, shutdown_switch_is_one_message_with_byte_2_255_and_a_fault_of_every_axis) {
  Bench bench;
  const EmergencyResult result = bench.monitor.update_shutdown(true, bench.producer);
  EXPECT_TRUE(result.fault);
  EXPECT_EQ(result.raised, condition_bit(AxisCondition::kShutdownSwitch));
  auto frames = bench.sent();
  ASSERT_EQ(frames.size(), 1u);
  expect_frame(frames[0], 0x81, {0x41, 0x54, 0x21, 0, 0xFF, 0, 0, 0});
  for (uint8_t axis = 0; axis < 3; ++axis) {
    EXPECT_EQ(bench.monitor.active_faults(axis), condition_bit(AxisCondition::kShutdownSwitch));
  }
  // Staying open sends nothing more.
  for (int i = 0; i < 100; ++i) bench.monitor.update_shutdown(true, bench.producer);
  EXPECT_TRUE(bench.sent().empty());
  // A reset while the switch is still open: refused, 5441 again.
  EXPECT_FALSE(bench.monitor.fault_reset(0, bench.producer));
  frames = bench.sent();
  ASSERT_EQ(frames.size(), 1u);
  expect_frame(frames[0], 0x81, {0x41, 0x54, 0x21, 0, 0xFF, 0, 0, 0});
  // Closed: axis 0 resets; axes 1 and 2 still hold 1001.
  bench.monitor.update_shutdown(false, bench.producer);
  EXPECT_TRUE(bench.monitor.fault_reset(0, bench.producer));
  frames = bench.sent();
  ASSERT_EQ(frames.size(), 1u);
  expect_frame(frames[0], 0x81, {0x00, 0x00, 0x21, 0, 0, 0, 0, 0});
  EXPECT_FALSE(bench.monitor.fault_present(0));
  EXPECT_TRUE(bench.monitor.fault_present(1));
  EXPECT_TRUE(bench.monitor.fault_reset(1, bench.producer));
  EXPECT_TRUE(bench.monitor.fault_reset(2, bench.producer));
  frames = bench.sent();
  ASSERT_EQ(frames.size(), 2u);
  expect_frame(frames[0], 0x81, {0x00, 0x00, 0x21, 0, 1, 0, 0, 0});
  expect_frame(frames[1], 0x81, {0x00, 0x00, 0x00, 0, 2, 0, 0, 0});
  EXPECT_EQ(bench.monitor.error_register(), 0);
}

TEST(Tmcm3216Emergencies, error_register_collects_every_active_condition_and_the_communication_bits) {
  Bench bench;
  bench.update(0, driver(board::kDriverOvercurrentA));
  bench.update(1, driver(board::kDriverTemperatureWarning));
  bench.update(2, driver(board::kDriverUndervoltage), 0x11);  // heartbeat error active
  auto frames = bench.sent();
  ASSERT_EQ(frames.size(), 3u);
  expect_frame(frames[0], 0x81, {0x12, 0x23, 0x23, 0, 0, 0, 0, 0});
  expect_frame(frames[1], 0x81, {0x10, 0x43, 0x0B, 1, 1, 0, 0, 0});
  expect_frame(frames[2], 0x81, {0x00, 0xFF, 0x3F, 0, 2, 0, 0, 0});
  EXPECT_EQ(bench.monitor.error_register(), 0x0F);
  EXPECT_EQ(bench.monitor.error_register(0), 0x03);
  EXPECT_EQ(bench.monitor.error_register(1), 0x09);
  EXPECT_EQ(bench.monitor.error_register(2), 0x05);
  // A second condition on the same axis adds its bits to the same axis.
  AxisConditions c = driver(board::kDriverOvercurrentA);
  c.limit_switch_positive = true;
  bench.update(0, c);
  frames = bench.sent();
  ASSERT_EQ(frames.size(), 1u);
  expect_frame(frames[0], 0x81, {0x01, 0xFF, 0x8F, 3, 0, 0, 0, 0});
  EXPECT_EQ(bench.monitor.active_conditions(0), condition_bit(AxisCondition::kOvercurrentBridgeA) |
                                                     condition_bit(AxisCondition::kLimitSwitchPositive));
  EXPECT_EQ(bench.monitor.active_faults(0), condition_bit(AxisCondition::kOvercurrentBridgeA));
}

TEST(Tmcm3216Emergencies, one_message_per_rising_edge) {
  Bench bench;
  AxisConditions on;
  on.limit_switch_negative = true;
  const AxisConditions off;
  EXPECT_NE(bench.update(1, on).raised, 0);
  for (int i = 0; i < 1000; ++i) EXPECT_EQ(bench.update(1, on).raised, 0);
  EXPECT_EQ(bench.sent().size(), 1u);
  // A warning goes with its condition (no message) and a new touch reports again.
  bench.update(1, off);
  EXPECT_EQ(bench.monitor.active_conditions(1), 0);
  EXPECT_EQ(bench.monitor.error_register(), 0);
  EXPECT_TRUE(bench.sent().empty());
  bench.update(1, on);
  auto frames = bench.sent();
  ASSERT_EQ(frames.size(), 1u);
  expect_frame(frames[0], 0x81, {0x01, 0xFF, 0x81, 4, 1, 0, 0, 0});
  // A fault stays active when its condition flickers: no second message until a fault reset.
  for (int i = 0; i < 50; ++i) {
    bench.update(0, driver(i % 2 == 0 ? board::kDriverOvercurrentHighSide : 0));
  }
  frames = bench.sent();
  ASSERT_EQ(frames.size(), 1u);
  // 1001 is the module's: axis 1 still stands on its switch (bit 7).
  expect_frame(frames[0], 0x81, {0x10, 0x23, 0xA3, 0, 0, 0, 0, 0});
  EXPECT_TRUE(bench.monitor.fault_present(0));
}

TEST(Tmcm3216Emergencies, inhibit_time_spaces_the_messages_and_loses_none) {
  Bench bench;
  bench.producer.set_inhibit_time_100us(100);  // 1015 = 10 ms
  bench.update(0, driver(board::kDriverOpenLoadA | board::kDriverOpenLoadB | board::kDriverOvertemperature));
  auto frames = bench.sent();
  ASSERT_EQ(frames.size(), 1u);
  expect_frame(frames[0], 0x81, {0x00, 0x10, 0x01, 1, 0, 0, 0, 0});
  // Each 1001 byte is the one at the time of its report (the third condition, a fault, adds
  // bit 3 and the FAULT bits).
  EXPECT_TRUE(bench.sent(9'999).empty());
  frames = bench.sent(1);
  ASSERT_EQ(frames.size(), 1u);
  expect_frame(frames[0], 0x81, {0x00, 0x10, 0x01, 2, 0, 0, 0, 0});
  EXPECT_TRUE(bench.sent(5'000).empty());
  frames = bench.sent(5'000);
  ASSERT_EQ(frames.size(), 1u);
  expect_frame(frames[0], 0x81, {0x10, 0x43, 0x29, 0, 0, 0, 0, 0});
  EXPECT_EQ(bench.producer.lost(), 0u);
  // A fault reset right after waits for the inhibit time too.
  bench.update(0, AxisConditions{});
  EXPECT_TRUE(bench.monitor.fault_reset(0, bench.producer));
  EXPECT_TRUE(bench.sent(9'000).empty());
  frames = bench.sent(1'000);
  ASSERT_EQ(frames.size(), 1u);
  expect_frame(frames[0], 0x81, {0x00, 0x00, 0x00, 0, 0, 0, 0, 0});
}

TEST(Tmcm3216Emergencies, fault_reset_sends_0000_when_the_condition_is_gone) {
  Bench bench;
  bench.update(2, driver(board::kDriverOvertemperature | board::kDriverOpenLoadB));
  bench.sent();
  // Still hot: the reset is refused, 4310 again, the warning stays.
  EXPECT_FALSE(bench.monitor.fault_reset(2, bench.producer));
  auto frames = bench.sent();
  ASSERT_EQ(frames.size(), 1u);
  expect_frame(frames[0], 0x81, {0x10, 0x43, 0x29, 0, 2, 0, 0, 0});
  EXPECT_EQ(bench.monitor.active_faults(2), condition_bit(AxisCondition::kOvertemperature));
  // Cooled down (the open load warning remains): 0000 with the motor in byte 2, 1001 = generic.
  bench.update(2, driver(board::kDriverOpenLoadB));
  EXPECT_TRUE(bench.sent().empty()) << "a latched fault that goes away sends nothing by itself";
  EXPECT_TRUE(bench.monitor.fault_present(2));
  EXPECT_TRUE(bench.monitor.fault_reset(2, bench.producer));
  frames = bench.sent();
  ASSERT_EQ(frames.size(), 1u);
  expect_frame(frames[0], 0x81, {0x00, 0x00, 0x01, 0, 2, 0, 0, 0});
  EXPECT_EQ(bench.monitor.active_conditions(2), condition_bit(AxisCondition::kOpenLoadB));
  // The next overtemperature is a new event.
  bench.update(2, driver(board::kDriverOvertemperature | board::kDriverOpenLoadB));
  frames = bench.sent();
  ASSERT_EQ(frames.size(), 1u);
  expect_frame(frames[0], 0x81, {0x10, 0x43, 0x29, 0, 2, 0, 0, 0});
}

TEST(Tmcm3216Emergencies, overtemperature_sends_one_message_per_step) {
  Bench bench;
  // Warm, then hot: the pre-warning, then the error.
  bench.update(0, driver(board::kDriverTemperatureWarning));
  bench.update(0, driver(board::kDriverTemperatureWarning | board::kDriverOvertemperature));
  auto frames = bench.sent();
  ASSERT_EQ(frames.size(), 2u);
  expect_frame(frames[0], 0x81, {0x10, 0x43, 0x09, 1, 0, 0, 0, 0});
  expect_frame(frames[1], 0x81, {0x10, 0x43, 0x29, 0, 0, 0, 0, 0});
  // Straight to hot (both flags in one reading): the error alone.
  const uint8_t hot = board::kDriverTemperatureWarning | board::kDriverOvertemperature;
  EXPECT_TRUE(bench.update(1, driver(hot)).fault);
  for (int i = 0; i < 10; ++i) bench.update(1, driver(hot));
  frames = bench.sent();
  ASSERT_EQ(frames.size(), 1u);
  expect_frame(frames[0], 0x81, {0x10, 0x43, 0x29, 0, 1, 0, 0, 0});
  EXPECT_EQ(bench.monitor.active_conditions(1), condition_bit(AxisCondition::kOvertemperature));
  // Cooled below the error but still warm: the reset is executed (0000), then the pre-warning
  // that the error had covered is reported.
  bench.update(1, driver(board::kDriverTemperatureWarning));
  EXPECT_TRUE(bench.sent().empty());
  EXPECT_TRUE(bench.monitor.fault_reset(1, bench.producer));
  EXPECT_EQ(bench.update(1, driver(board::kDriverTemperatureWarning)).raised,
            condition_bit(AxisCondition::kOvertemperatureWarning));
  bench.update(1, driver(board::kDriverTemperatureWarning));
  frames = bench.sent();
  ASSERT_EQ(frames.size(), 2u);
  expect_frame(frames[0], 0x81, {0x00, 0x00, 0x09, 0, 1, 0, 0, 0});  // axis 0 is still hot
  expect_frame(frames[1], 0x81, {0x10, 0x43, 0x09, 1, 1, 0, 0, 0});
  // An unpowered axis: the error is a warning that goes with its flag; the pre-warning follows.
  AxisConditions off = driver(hot);
  off.power_enabled = false;
  EXPECT_FALSE(bench.update(2, off).fault);
  off.driver_errors = board::kDriverTemperatureWarning;
  bench.update(2, off);
  frames = bench.sent();
  ASSERT_EQ(frames.size(), 2u);
  expect_frame(frames[0], 0x81, {0x10, 0x43, 0x09, 0, 2, 0, 0, 0});
  expect_frame(frames[1], 0x81, {0x10, 0x43, 0x09, 1, 2, 0, 0, 0});
}

TEST(Tmcm3216Emergencies, fault_reset_without_a_cause_still_reports_0000) {
  // FAULT from outside the monitor (NMT stopped while operation enabled): the reset is executed.
  Bench bench;
  EXPECT_TRUE(bench.monitor.fault_reset(1, bench.producer, 0x11));
  const auto frames = bench.sent();
  ASSERT_EQ(frames.size(), 1u);
  expect_frame(frames[0], 0x81, {0x00, 0x00, 0x11, 0, 1, 0, 0, 0});
}

TEST(Tmcm3216Emergencies, stall_follows_20A7) {
  Bench bench;
  AxisConditions stall;
  stall.stall = true;
  stall.stall_enters_fault = false;  // 20A7 = 1: stop only
  EmergencyResult r = bench.update(0, stall);
  EXPECT_TRUE(r.stop);
  EXPECT_FALSE(r.fault);
  auto frames = bench.sent();
  ASSERT_EQ(frames.size(), 1u);
  expect_frame(frames[0], 0x81, {0x30, 0x32, 0x21, 0, 0, 0, 0, 0});
  EXPECT_FALSE(bench.monitor.fault_present(0));
  bench.update(0, AxisConditions{});  // the drive cleared the stall flag once the axis stood
  EXPECT_EQ(bench.monitor.active_conditions(0), 0);

  stall.stall_enters_fault = true;  // 20A7 = 0: FAULT
  r = bench.update(0, stall);
  EXPECT_TRUE(r.fault);
  EXPECT_FALSE(r.stop);
  frames = bench.sent();
  ASSERT_EQ(frames.size(), 1u);
  expect_frame(frames[0], 0x81, {0x30, 0x32, 0x21, 0, 0, 0, 0, 0});
  // The stepper's flag is still set when the reset comes (the drive clears it in the next
  // tick): the stall is an event, the reset clears it and the flag is no new stall.
  EXPECT_TRUE(bench.monitor.fault_reset(0, bench.producer));
  frames = bench.sent();
  ASSERT_EQ(frames.size(), 1u);
  expect_frame(frames[0], 0x81, {0x00, 0x00, 0x00, 0, 0, 0, 0, 0});
  EXPECT_EQ(bench.update(0, stall).raised, 0);
  bench.update(0, AxisConditions{});
  EXPECT_TRUE(bench.sent().empty());
  EXPECT_EQ(bench.update(0, stall).raised, condition_bit(AxisCondition::kStall));
  EXPECT_EQ(bench.sent().size(), 1u);
}

TEST(Tmcm3216Emergencies, following_error_is_cleared_by_the_reset) {
  Bench bench;
  AxisConditions c;
  c.following_error = true;
  EXPECT_TRUE(bench.update(1, c).fault);
  bench.sent();
  EXPECT_TRUE(bench.monitor.fault_reset(1, bench.producer));
  const auto frames = bench.sent();
  ASSERT_EQ(frames.size(), 1u);
  expect_frame(frames[0], 0x81, {0x00, 0x00, 0x00, 0, 1, 0, 0, 0});
}

TEST(Tmcm3216Emergencies, driver_faults_wait_for_the_power_stage) {
  Bench bench;
  AxisConditions c = driver(board::kDriverUndervoltage);
  c.power_enabled = false;
  EmergencyResult r = bench.update(0, c);
  EXPECT_FALSE(r.fault) << "the motor is off: nothing to stop";
  auto frames = bench.sent();
  ASSERT_EQ(frames.size(), 1u);
  expect_frame(frames[0], 0x81, {0x00, 0xFF, 0x05, 0, 0, 0, 0, 0});
  EXPECT_EQ(bench.monitor.active_conditions(0), condition_bit(AxisCondition::kUndervoltage));
  EXPECT_FALSE(bench.monitor.fault_present(0));
  for (int i = 0; i < 10; ++i) EXPECT_FALSE(bench.update(0, c).fault);
  EXPECT_TRUE(bench.sent().empty());
  // Switched on while the supply is still low: now it is the fault, reported again.
  c.power_enabled = true;
  r = bench.update(0, c);
  EXPECT_TRUE(r.fault);
  EXPECT_EQ(r.raised, condition_bit(AxisCondition::kUndervoltage));
  frames = bench.sent();
  ASSERT_EQ(frames.size(), 1u);
  expect_frame(frames[0], 0x81, {0x00, 0xFF, 0x25, 0, 0, 0, 0, 0});
  EXPECT_TRUE(bench.monitor.fault_present(0));
  EXPECT_FALSE(bench.update(0, c).fault);
  EXPECT_TRUE(bench.sent().empty());
  // Unpowered and recovered: the warning goes with it, nothing to reset.
  AxisConditions other = driver(board::kDriverOvertemperature);
  other.power_enabled = false;
  bench.update(1, other);
  bench.update(1, AxisConditions{});
  EXPECT_EQ(bench.monitor.active_conditions(1), 0);
  // Stall and following error are faults whatever the flag says (they need a running motor).
  AxisConditions stall;
  stall.stall = true;
  stall.power_enabled = false;
  EXPECT_TRUE(bench.update(2, stall).fault);
}

TEST(Tmcm3216Emergencies, limits_are_no_error_while_homing) {
  Bench bench;
  AxisConditions c;
  c.homing = true;
  c.limit_switch_negative = true;
  c.software_limit_negative = true;
  EXPECT_EQ(bench.update(0, c).raised, 0);
  // Homing ends on the switch: still no message (no new touch).
  c.homing = false;
  EXPECT_EQ(bench.update(0, c).raised, 0);
  EXPECT_TRUE(bench.sent().empty());
  // Off the switch and back on it: reported.
  c.limit_switch_negative = false;
  c.software_limit_negative = false;
  bench.update(0, c);
  c.limit_switch_negative = true;
  EXPECT_EQ(bench.update(0, c).raised, condition_bit(AxisCondition::kLimitSwitchNegative));
  const auto frames = bench.sent();
  ASSERT_EQ(frames.size(), 1u);
  expect_frame(frames[0], 0x81, {0x01, 0xFF, 0x81, 4, 0, 0, 0, 0});
  // Faults are faults while homing too.
  c.homing = true;
  c.driver_errors = board::kDriverOvercurrentB;
  EXPECT_TRUE(bench.update(0, c).fault);
}

TEST(Tmcm3216Emergencies, producer_off_keeps_the_state_and_sends_nothing) {
  Bench bench;
  bench.producer.set_cob_id(0x8000'0081);  // 1014 bit 31
  EXPECT_TRUE(bench.update(0, driver(board::kDriverUndervoltage)).fault);
  EXPECT_TRUE(bench.sent().empty());
  EXPECT_EQ(bench.monitor.error_register(), 0x05);
  EXPECT_FALSE(bench.monitor.fault_reset(0, bench.producer));
  EXPECT_TRUE(bench.sent().empty());
}

TEST(Tmcm3216Emergencies, reset_forgets_everything_and_bad_axes_are_ignored) {
  Bench bench;
  bench.update(0, driver(board::kDriverOvercurrentA));
  bench.monitor.update_shutdown(true, bench.producer);
  bench.sent();
  bench.monitor.reset();
  EXPECT_EQ(bench.monitor.error_register(), 0);
  for (uint8_t axis = 0; axis < 3; ++axis) EXPECT_EQ(bench.monitor.active_conditions(axis), 0);
  // The condition is still there after the reset: a new event.
  EXPECT_TRUE(bench.update(0, driver(board::kDriverOvercurrentA)).fault);
  EXPECT_EQ(bench.sent().size(), 1u);
  EXPECT_EQ(bench.update(3, driver(board::kDriverOvercurrentA)).raised, 0);
  EXPECT_FALSE(bench.monitor.fault_reset(3, bench.producer));
  EXPECT_TRUE(bench.sent().empty());
}

TEST(Tmcm3216Emergencies, table_rows_are_the_manuals) {
  const auto table = modules::tmcm3216::emergency_table();
  ASSERT_EQ(table.size(), static_cast<size_t>(AxisCondition::kCount));
  EXPECT_EQ(modules::tmcm3216::emergency_definition(AxisCondition::kOvertemperatureWarning).code, 0x4310);
  EXPECT_EQ(modules::tmcm3216::emergency_definition(AxisCondition::kOvertemperatureWarning).sub, 1);
  EXPECT_EQ(modules::tmcm3216::emergency_definition(AxisCondition::kLimitSwitchNegative).sub, 4);
}

}  // namespace
}  // namespace motwin::testing
