// Resting axes of the TMCM-3216 (docs/tmcm-3216-drive.md "Idle ticks"): the module and its
// simulated board skip the ticks of an axis whose last full tick changed nothing. These tests run
// the same story on two rigs, one with the skipping and one with every tick a full one, and
// compare everything observable after every tick; and they check that each way of changing an
// axis (a frame, an object written through the dictionary or an accessor, the board's feedback,
// a signal, a rotor moved) takes effect on the next tick.
#include <gtest/gtest.h>

#include <cstdint>
#include <functional>
#include <string>
#include <utility>

#include "support/tmcm3216_board_rig.h"

namespace motwin::modules::tmcm3216 {
namespace {

using testing::Tmcm3216BoardRig;

const Tmcm3216& constant(const Tmcm3216BoardRig& rig) { return *rig.device; }

bool any_resting(const Tmcm3216BoardRig& rig) {
  for (uint8_t axis = 0; axis < kAxisCount; ++axis) {
    if (constant(rig).axis_resting(axis) && rig.board.axis_resting(axis)) return true;
  }
  return false;
}

// Everything a master or the board sees of the module, compared between the two rigs.
void expect_same(const Tmcm3216BoardRig& resting, const Tmcm3216BoardRig& full, const std::string& when) {
  ASSERT_EQ(resting.can.frames.size(), full.can.frames.size()) << when;
  for (size_t i = 0; i < full.can.frames.size(); ++i) {
    ASSERT_EQ(resting.can.frames[i].id, full.can.frames[i].id) << when << ", frame " << i;
    ASSERT_EQ(resting.can.frames[i].dlc, full.can.frames[i].dlc) << when << ", frame " << i;
    for (int b = 0; b < 8; ++b) ASSERT_EQ(resting.can.frames[i].data[b], full.can.frames[i].data[b]) << when;
  }
  for (uint8_t axis = 0; axis < kAxisCount; ++axis) {
    const board::StepperPowerStage& a = resting.board.board().axes[axis];
    const board::StepperPowerStage& b = full.board.board().axes[axis];
    ASSERT_TRUE(a.drive == b.drive) << when << ", axis " << int{axis};
    ASSERT_TRUE(a.feedback == b.feedback) << when << ", axis " << int{axis};
    const Tmcm3216Drive& da = constant(resting).drive(axis);
    const Tmcm3216Drive& db = constant(full).drive(axis);
    ASSERT_EQ(da.statusword(), db.statusword()) << when << ", axis " << int{axis};
    ASSERT_EQ(da.position_actual(), db.position_actual()) << when;
    ASSERT_EQ(da.position_demand(), db.position_demand()) << when;
    const Tmcm3216Stepper& sa = constant(resting).stepper(axis);
    const Tmcm3216Stepper& sb = constant(full).stepper(axis);
    ASSERT_EQ(sa.encoder_count(), sb.encoder_count()) << when;
    ASSERT_EQ(sa.current_ma(), sb.current_ma()) << when;
    ASSERT_EQ(sa.standby(), sb.standby()) << when;
    ASSERT_EQ(sa.switches().raw, sb.switches().raw) << when;
    ASSERT_EQ(sa.driver_error_flags(), sb.driver_error_flags()) << when;
    ASSERT_EQ(resting.board.rotor_revolutions(axis), full.board.rotor_revolutions(axis)) << when;
    const std::string speed = "AXIS" + std::to_string(axis) + "_SPEED_RPM";
    ASSERT_EQ(resting.board.read_signal(speed), full.board.read_signal(speed)) << when;
    const sim::StallGuardModel& ga = resting.board.stallguard(axis);
    const sim::StallGuardModel& gb = full.board.stallguard(axis);
    ASSERT_EQ(ga.last_load_fraction(), gb.last_load_fraction()) << when << ", axis " << int{axis};
    ASSERT_EQ(ga.last_full_steps_per_s(), gb.last_full_steps_per_s()) << when << ", axis " << int{axis};
  }
  ASSERT_EQ(constant(resting).error_register(), constant(full).error_register()) << when;
}

struct TwoRigs {
  Tmcm3216BoardRig resting;
  Tmcm3216BoardRig full;
  TwoRigs() {
    full.device->set_resting_axes_enabled(false);
    full.board.set_resting_axes_enabled(false);
  }
  void both(const std::function<void(Tmcm3216BoardRig&)>& step) {
    step(resting);
    step(full);
  }
  void ticks(uint64_t n, const std::string& when) {
    for (uint64_t i = 0; i < n; ++i) {
      resting.tick();
      full.tick();
      expect_same(resting, full, when + ", tick " + std::to_string(i));
      if (::testing::Test::HasFatalFailure()) return;
    }
  }
  void write(uint16_t index, int64_t value, uint8_t sub = 0) {
    both([&](Tmcm3216BoardRig& rig) { ASSERT_EQ(rig.write_object(index, sub, value), canopen::SdoAbort::kNone); });
  }
};

TEST(Tmcm3216RestingAxes, an_idle_module_rests_and_every_change_wakes_it_with_the_same_result) {
  TwoRigs rigs;
  rigs.ticks(100, "idle after power-up");
  ASSERT_TRUE(any_resting(rigs.resting)) << "an idle axis rests";
  EXPECT_FALSE(any_resting(rigs.full));
  // A stored resolution, switch configuration and brake currents, written while resting.
  rigs.write(0x2000, 4);           // 16 microsteps
  rigs.write(0x2005, 0x3);         // right and left switch disabled
  rigs.write(0x200C, 100, 2);      // brake release current
  rigs.ticks(60, "objects written");
  // Inputs of the board: switch levels, a driver fault, the supply, the encoder.
  rigs.both([](Tmcm3216BoardRig& rig) { rig.board.set_input("AXIS1_REF_H", 1); });
  rigs.ticks(40, "home switch");
  rigs.both([](Tmcm3216BoardRig& rig) { rig.board.set_input("AXIS2_OPEN_COIL_A", 1); });
  rigs.ticks(40, "open coil");
  rigs.both([](Tmcm3216BoardRig& rig) { rig.board.set_input("VSUPPLY", 6); });
  rigs.ticks(40, "undervoltage");
  rigs.both([](Tmcm3216BoardRig& rig) { rig.board.set_input("VSUPPLY", 24); });
  rigs.ticks(40, "supply back");
  rigs.both([](Tmcm3216BoardRig& rig) { rig.board.set_rotor_revolutions(0, 0.25); });
  rigs.ticks(40, "rotor turned by hand");
  // Operational, then axis 0 enabled in profile position and moved, stopped, disabled.
  rigs.both([](Tmcm3216BoardRig& rig) { rig.nmt(0x01); });
  rigs.ticks(40, "operational");
  rigs.write(0x6060, 1);
  rigs.write(0x6081, 20000);
  rigs.write(0x6083, 200000);
  rigs.write(0x6084, 200000);
  rigs.write(0x6040, 6);
  rigs.ticks(5, "shutdown");
  rigs.write(0x6040, 7);
  rigs.ticks(5, "switched on");
  rigs.write(0x6040, 15);
  rigs.ticks(400, "operation enabled");
  rigs.write(0x607A, 3000);
  rigs.write(0x6040, 0x1F);
  rigs.ticks(4000, "moving");
  rigs.write(0x6040, 0x0F);
  rigs.ticks(200, "at the target");
  rigs.write(0x6040, 0);
  rigs.ticks(2000, "disabled");
  EXPECT_TRUE(any_resting(rigs.resting)) << "resting again once disabled";
  // The shutdown switch opens and closes while the axes rest.
  rigs.both([](Tmcm3216BoardRig& rig) { rig.board.set_input("ENABLE", 0); });
  rigs.ticks(40, "shutdown switch open");
  rigs.both([](Tmcm3216BoardRig& rig) { rig.board.set_input("ENABLE", 1); });
  rigs.ticks(40, "shutdown switch closed");
  // SYNCs (a frame between ticks) and a heartbeat.
  rigs.write(0x1017, 10);
  for (int i = 0; i < 5; ++i) {
    rigs.both([](Tmcm3216BoardRig& rig) { rig.sync(); });
    rigs.ticks(23, "SYNC " + std::to_string(i));
  }
}

// A powered axis standing still rests too (its standstill time read alike: before the standby
// delay 2089, or past the power-down ramp 20B9 at the standby current), and the standby delay and
// the ramp still come on the very tick they come on with every tick a full one.
TEST(Tmcm3216RestingAxes, a_powered_axis_at_standstill_rests_and_its_standby_current_comes_on_time) {
  TwoRigs rigs;
  rigs.both([](Tmcm3216BoardRig& rig) { rig.nmt(0x01); });
  rigs.write(0x2089, 5);   // standby after 50 ms
  rigs.write(0x20B9, 1);   // a power-down step per 2^18 clocks (16.4 ms)
  rigs.write(0x2003, 200);
  rigs.write(0x2004, 20);
  rigs.write(0x6060, 1);
  rigs.write(0x6040, 6);
  rigs.ticks(5, "shutdown");
  rigs.write(0x6040, 7);
  rigs.ticks(5, "switched on");
  rigs.write(0x6040, 15);
  rigs.ticks(200, "operation enabled");
  const Tmcm3216& resting = constant(rigs.resting);
  ASSERT_TRUE(resting.stepper(0).power_stage_on());
  EXPECT_TRUE(resting.axis_resting(0)) << "a powered axis standing still before its standby delay rests";
  EXPECT_FALSE(resting.stepper(0).standby());
  const int32_t run_current_ma = resting.stepper(0).current_ma();
  // Past 2089 the current steps down to the standby current; identical tick for tick.
  rigs.ticks(12000, "standby delay and power-down ramp");
  ASSERT_TRUE(resting.stepper(0).power_stage_on());
  EXPECT_TRUE(resting.stepper(0).standby());
  EXPECT_LT(resting.stepper(0).current_ma(), run_current_ma);
  EXPECT_TRUE(resting.axis_resting(0)) << "at the standby current it rests again";
  EXPECT_TRUE(rigs.resting.board.axis_resting(0)) << "the board rests a powered motor standing past the pause";
  // A move wakes it; at the target it rests again and the standby delay starts anew. The first
  // StallGuard measurements after the standstill are the same with the board's resting ticks.
  rigs.write(0x6081, 20000);
  rigs.write(0x607A, 2000);
  rigs.write(0x6040, 0x1F);
  rigs.ticks(3000, "moving from standby");
  rigs.write(0x6040, 0x0F);
  rigs.ticks(20000, "standing again");
  EXPECT_TRUE(resting.stepper(0).standby());
  EXPECT_TRUE(resting.axis_resting(0));
  EXPECT_TRUE(rigs.resting.board.axis_resting(0));
  EXPECT_EQ(resting.drive(0).position_actual(), 2000);
  // Slow moves (below the StallGuard fade speed) after a standstill that the board rested, in
  // StealthChop with its filter and in SpreadCycle with the four-step filter: the first full
  // step after the pause measures as with every tick a full one.
  rigs.write(0x6081, 3000);
  rigs.write(0x20B0, 100000);  // StealthChop below this speed while 20B1 is not 0
  for (const auto& [stealth_chop, position] : {std::pair{true, 2600}, std::pair{false, 2000}}) {
    rigs.write(0x20B1, stealth_chop ? 20 : 0);
    rigs.write(stealth_chop ? 0x20A9 : 0x209D, 1);  // the StallGuard4 / StallGuard2 filter
    rigs.ticks(600, "chopper set");
    rigs.write(0x607A, position);
    rigs.write(0x6040, 0x1F);
    rigs.ticks(8000, "a slow move");
    EXPECT_EQ(resting.drive(0).position_actual(), position);
    rigs.write(0x6040, 0x0F);
    rigs.ticks(12000, "standing through the standby delay and ramp");
    EXPECT_TRUE(rigs.resting.board.axis_resting(0));
  }
  EXPECT_GT(rigs.resting.board.stallguard(0).measurements(), 0u);
}

// Each way in, on a resting axis: the change shows in the very next tick.
struct RestingRig : Tmcm3216BoardRig {
  RestingRig() {
    tick(100);
    EXPECT_TRUE(device->axis_resting(0));
    EXPECT_TRUE(board.axis_resting(0));
  }
};

TEST(Tmcm3216RestingAxes, an_object_written_through_the_dictionary_takes_effect_on_the_next_tick) {
  RestingRig rig;
  // 2005 bit 2: the left switch inverted; its level is low, so it reads active at once.
  ASSERT_EQ(rig.write_object(0x2005, 0, switch_bits::kLeftInverted), canopen::SdoAbort::kNone);
  rig.tick();
  EXPECT_TRUE(constant(rig).stepper(0).switches().left);
}

TEST(Tmcm3216RestingAxes, an_object_written_through_the_stepper_accessor_takes_effect_on_the_next_tick) {
  RestingRig rig;
  rig.device->stepper(0).objects.switch_config = switch_bits::kLeftInverted;
  rig.tick();
  EXPECT_TRUE(constant(rig).stepper(0).switches().left);
}

TEST(Tmcm3216RestingAxes, a_frame_takes_effect_on_the_next_tick) {
  RestingRig rig;
  // NMT operational, then an RPDO 2 (6040 = 6, 6060 = 1): the axis to READY TO SWITCH ON.
  rig.nmt(0x01);
  rig.tick();
  can::CanFrame rpdo{};
  rpdo.id = 0x301;
  rpdo.dlc = 3;
  rpdo.data[0] = 6;
  rpdo.data[2] = 1;
  rig.device->receive(rpdo);
  rig.tick();
  EXPECT_EQ(constant(rig).drive(0).state(), cia402::PdsState::kReadyToSwitchOn);
}

TEST(Tmcm3216RestingAxes, a_changed_board_feedback_takes_effect_on_the_next_tick) {
  RestingRig rig;
  // Written into the board's feedback directly (as a board without the sim would): the sim
  // board's next sensing overwrites it, so the module is ticked alone.
  rig.board.board().axes[0].feedback.switches = 0x4;  // home switch level high
  rig.device->tick();
  EXPECT_TRUE(constant(rig).stepper(0).switches().home);
}

TEST(Tmcm3216RestingAxes, a_signal_takes_effect_on_the_next_board_tick) {
  RestingRig rig;
  rig.board.set_input("AXIS0_REF_R", 1);
  rig.tick();
  EXPECT_EQ(rig.board.board().axes[0].feedback.switches & 0x1, 0x1);
  EXPECT_TRUE(constant(rig).stepper(0).switches().right);
}

TEST(Tmcm3216RestingAxes, a_rotor_moved_is_sensed_on_the_next_board_tick) {
  RestingRig rig;
  const int32_t before = rig.board.board().axes[0].feedback.encoder_count;
  rig.board.set_rotor_revolutions(0, 0.5);
  rig.tick();
  EXPECT_EQ(rig.board.board().axes[0].feedback.encoder_count, before + 2000);  // 4000 counts per revolution
}

TEST(Tmcm3216RestingAxes, a_changed_drive_moves_a_resting_motor_on_the_next_tick) {
  RestingRig rig;
  // The drive output written directly: the resting sim axis must apply it, not skip it.
  board::StepperDrive& drive = rig.board.board().axes[0].drive;
  drive.enabled = true;
  drive.electrical_angle += 1u << 28;  // 1/16 of an electrical revolution forward
  rig.board.after_tick(kTickUs * 1e-6);
  EXPECT_NE(rig.board.rotor_revolutions(0), 0.0);
}

}  // namespace
}  // namespace motwin::modules::tmcm3216
