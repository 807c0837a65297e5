// The CiA-402 power drive system state machine: the controlwords python-canopen and ros2_canopen
// write, and the statusword values (masks of docs/canopen.md
// "CiA-402 expectations of real masters") they expect.
#include <gtest/gtest.h>

#include "core/cia402/power_drive_system.h"

namespace motwin::cia402 {
namespace {

struct Fixture {
  PowerDriveSystem pds;
  PdsOptions options;
  Fixture() { pds.reset(); }
  uint16_t sw() const { return pds.statusword_state_bits(); }
  void cw(uint16_t value) { pds.on_controlword(value, options); }
};

TEST(Cia402Pds, PowerOnIsSwitchOnDisabled) {
  Fixture f;
  EXPECT_EQ(f.pds.state(), PdsState::kSwitchOnDisabled);
  EXPECT_EQ(f.sw() & 0x4F, 0x40);
  EXPECT_FALSE(f.pds.power_enabled());
}

TEST(Cia402Pds, PythonCanopenSequenceReachesOperationEnabled) {
  Fixture f;
  f.cw(0x06);
  EXPECT_EQ(f.sw() & 0x6F, 0x21);
  f.cw(0x07);
  EXPECT_EQ(f.sw() & 0x6F, 0x23);
  EXPECT_FALSE(f.pds.power_enabled());
  f.cw(0x0F);
  EXPECT_EQ(f.sw() & 0x6F, 0x27);
  EXPECT_EQ(f.pds.motion(), PdsMotion::kRun);
  EXPECT_TRUE(f.pds.power_enabled());
}

TEST(Cia402Pds, SwitchOnAndEnableFromReadyIsTransitions3And4) {
  Fixture f;
  f.cw(0x06);
  f.cw(0x0F);
  EXPECT_EQ(f.pds.state(), PdsState::kOperationEnabled);
}

TEST(Cia402Pds, EnableFromSwitchOnDisabledIsRefused) {
  Fixture f;
  f.cw(0x0F);
  EXPECT_EQ(f.pds.state(), PdsState::kSwitchOnDisabled);
  f.cw(0x07);
  EXPECT_EQ(f.pds.state(), PdsState::kSwitchOnDisabled);
}

TEST(Cia402Pds, ShutdownFromOperationEnabledSwitchesPowerOffAtOnce) {
  Fixture f;
  f.cw(0x06);
  f.cw(0x0F);
  f.cw(0x06);
  EXPECT_EQ(f.pds.state(), PdsState::kReadyToSwitchOn);
  EXPECT_FALSE(f.pds.power_enabled());
}

TEST(Cia402Pds, DisableOperationRampsDownThenSwitchedOn) {
  Fixture f;
  f.cw(0x06);
  f.cw(0x0F);
  f.cw(0x07);
  EXPECT_EQ(f.pds.state(), PdsState::kOperationEnabled);
  EXPECT_EQ(f.pds.motion(), PdsMotion::kSlowDownStop);
  f.pds.motion_stopped(f.options);
  EXPECT_EQ(f.pds.state(), PdsState::kSwitchedOn);
  EXPECT_EQ(f.sw() & 0x6F, 0x23);
}

TEST(Cia402Pds, DisableVoltageFromOperationEnabled) {
  Fixture f;
  f.cw(0x06);
  f.cw(0x0F);
  f.cw(0x00);
  EXPECT_EQ(f.pds.state(), PdsState::kSwitchOnDisabled);
}

struct QuickStopCase {
  int16_t option;
  PdsMotion ramp;
  PdsState after_stop;
};

class Cia402PdsQuickStop : public ::testing::TestWithParam<QuickStopCase> {};

TEST_P(Cia402PdsQuickStop, OptionCodeSelectsRampAndEndState) {
  Fixture f;
  f.options.quick_stop = GetParam().option;
  f.cw(0x06);
  f.cw(0x0F);
  f.cw(0x0B);  // quick stop: bit 2 = 0
  EXPECT_EQ(f.pds.state(), PdsState::kQuickStopActive);
  EXPECT_EQ(f.sw() & 0x6F, 0x07);
  EXPECT_EQ(f.pds.motion(), GetParam().ramp);
  f.pds.motion_stopped(f.options);
  EXPECT_EQ(f.pds.state(), GetParam().after_stop);
  if (GetParam().after_stop == PdsState::kQuickStopActive) {
    EXPECT_EQ(f.pds.motion(), PdsMotion::kHold);
    f.cw(0x0F);  // transition 16
    EXPECT_EQ(f.pds.state(), PdsState::kOperationEnabled);
  } else {
    EXPECT_EQ(f.sw() & 0x4F, 0x40);
  }
}

INSTANTIATE_TEST_SUITE_P(Options, Cia402PdsQuickStop,
                         ::testing::Values(QuickStopCase{1, PdsMotion::kSlowDownStop, PdsState::kSwitchOnDisabled},
                                           QuickStopCase{2, PdsMotion::kQuickStop, PdsState::kSwitchOnDisabled},
                                           QuickStopCase{5, PdsMotion::kSlowDownStop, PdsState::kQuickStopActive},
                                           QuickStopCase{6, PdsMotion::kQuickStop, PdsState::kQuickStopActive}));

// Transitions 7, 10 and 12: disable voltage (bit 1 = 0) and quick stop without a running drive
// function end in SWITCH ON DISABLED with the power stage off.
TEST(Cia402Pds, DisableVoltageAndQuickStopFromTheLowerStates) {
  for (uint16_t command : {0x00, 0x0D, 0x02}) {  // disable voltage (twice: other bits set), quick stop
    Fixture ready;
    ready.cw(0x06);
    ready.cw(command);
    EXPECT_EQ(ready.sw() & 0x4F, 0x40) << "7 by " << command;
    Fixture switched_on;
    switched_on.cw(0x06);
    switched_on.cw(0x07);
    switched_on.cw(command);
    EXPECT_EQ(switched_on.sw() & 0x4F, 0x40) << "10 by " << command;
    EXPECT_FALSE(switched_on.pds.power_enabled());
  }
  // 12 by disable voltage while the quick stop ramp still runs: power off at once.
  Fixture f;
  f.options.quick_stop = kQuickStopSlowDownStay;
  f.cw(0x06);
  f.cw(0x0F);
  f.cw(0x02);
  EXPECT_EQ(f.sw() & 0x6F, 0x07);
  EXPECT_EQ(f.pds.motion(), PdsMotion::kSlowDownStop);
  f.cw(0x00);
  EXPECT_EQ(f.sw() & 0x4F, 0x40);
  EXPECT_EQ(f.pds.motion(), PdsMotion::kOff);
}

TEST(Cia402Pds, FaultReactionThenFaultThenReset) {
  Fixture f;
  f.cw(0x06);
  f.cw(0x0F);
  f.pds.fault();
  EXPECT_EQ(f.pds.state(), PdsState::kFaultReactionActive);
  EXPECT_EQ(f.sw() & 0x4F, 0x0F);
  EXPECT_EQ(f.pds.motion(), PdsMotion::kQuickStop);
  f.cw(0x0F);  // ignored during the reaction
  EXPECT_EQ(f.pds.state(), PdsState::kFaultReactionActive);
  f.pds.motion_stopped(f.options);
  EXPECT_EQ(f.pds.state(), PdsState::kFault);
  EXPECT_EQ(f.sw() & 0x4F, 0x08);
  EXPECT_FALSE(f.pds.power_enabled());
  f.cw(0x06);  // no reset edge
  EXPECT_EQ(f.pds.state(), PdsState::kFault);
  EXPECT_FALSE(f.pds.take_fault_reset_event());
  f.cw(0x86);
  EXPECT_EQ(f.pds.state(), PdsState::kSwitchOnDisabled);
  EXPECT_TRUE(f.pds.take_fault_reset_event());
  EXPECT_FALSE(f.pds.take_fault_reset_event());
}

TEST(Cia402Pds, FaultResetNeedsRisingEdge) {
  Fixture f;
  f.cw(0x80);
  f.pds.fault();  // from switch on disabled: straight to fault
  EXPECT_EQ(f.pds.state(), PdsState::kFault);
  f.cw(0x80);  // bit 7 was already set: no edge
  EXPECT_EQ(f.pds.state(), PdsState::kFault);
  f.cw(0x00);
  f.cw(0x80);
  EXPECT_EQ(f.pds.state(), PdsState::kSwitchOnDisabled);
}

}  // namespace
}  // namespace motwin::cia402
