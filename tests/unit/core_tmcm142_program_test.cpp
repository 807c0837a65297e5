// TMCL programs on the TMCM-142 (ideal stepper): WAIT REFSW / LIMSW / RFS with a timeout set
// ETO (JC ETO taken) and leave it clear when the condition comes in time; the coordinate
// commands SCO/GCO/CCO/ACO and MVP COORD run from a program; the position-reached interrupt.
#include <initializer_list>

#include <gtest/gtest.h>

#include "core/modules/tmcm142/tmcm142_hardware.h"
#include "core/tmcl/instruction.h"
#include "core/tmcl/interpreter.h"
#include "support/tmcl_command.h"
#include "support/tmcm142_rig.h"

namespace motwin::testing {
namespace {

using tmcl::Instruction;
namespace cmd = tmcl::command;

constexpr uint8_t kOk = 100;
constexpr uint8_t kWaitReferenceSwitch = 2;
constexpr uint8_t kWaitLimitSwitch = 3;
constexpr uint8_t kWaitReferenceSearch = 4;
constexpr uint8_t kJcEto = 8;

void download(Tmcm142Rig& rig, std::initializer_list<Instruction> program) { download_program(rig, program); }

// Speeds in µsteps/s (unit mode 1), trapezoid corners.
void use_pps(Tmcm142Rig& rig, int32_t vmax, int32_t acceleration) {
  ASSERT_EQ(rig.sap(255, 1), kOk);
  ASSERT_EQ(rig.sap(4, vmax), kOk);
  ASSERT_EQ(rig.sap(5, acceleration), kOk);
  ASSERT_EQ(rig.sap(18, modules::tmcm142::kMaxBow), kOk);  // max. bow: trapezoid
}

// Program: tick timer before (var 1) and after (var 2) `WAIT condition, 0, 5` (50 ms), then
// var 0 = 1 if JC ETO jumps, 2 if not. `start` runs first (a motion or a search, or a NOP).
void run_wait_program(Tmcm142Rig& rig, Instruction start, uint8_t condition, int32_t timeout_ticks, uint32_t max_ms) {
  download(rig, {
      start,                                   // 0
      {cmd::kGgp, 132, 0, 0},                  // 1: tick timer (ms)
      {cmd::kAgp, 1, 2, 0},                    // 2
      {cmd::kWait, condition, 0, timeout_ticks},  // 3
      {cmd::kGgp, 132, 0, 0},                  // 4
      {cmd::kAgp, 2, 2, 0},                    // 5
      {cmd::kJc, kJcEto, 0, 10},               // 6
      {cmd::kCalc, 9, 0, 2},                   // 7: not taken
      {cmd::kAgp, 0, 2, 0},                    // 8
      {cmd::kStop, 0, 0, 0},                   // 9
      {cmd::kCalc, 9, 0, 1},                   // 10: taken
      {cmd::kAgp, 0, 2, 0},                    // 11
      {cmd::kStop, 0, 0, 0},                   // 12
  });
  ASSERT_EQ(rig.command(cmd::kRunApplication, 1, 0, 0).status, kOk);
  rig.run_until([&] { return rig.ggp(128) == 0; }, max_ms);
  ASSERT_EQ(rig.ggp(128), 0) << "the program ended";
}

TEST(Tmcm142Program, wait_refsw_limsw_and_rfs_time_out_and_set_eto) {
  struct Case {
    const char* name;
    Instruction start;
    uint8_t condition;
  };
  const Case cases[] = {
      {"WAIT REFSW (no home switch)", {cmd::kNop, 0, 0, 0}, kWaitReferenceSwitch},
      {"WAIT LIMSW (rotating, no switch)", {cmd::kRor, 0, 0, 50000}, kWaitLimitSwitch},
      {"WAIT RFS (the left switch far away)", {cmd::kRfs, 0, 0, 0}, kWaitReferenceSearch},
  };
  for (const auto& c : cases) {
    Tmcm142Rig rig;
    use_pps(rig, 100000, 1000000);
    rig.place_limit_switches(-1e9, 1e9);
    run_wait_program(rig, c.start, c.condition, 5, 1000);
    EXPECT_EQ(rig.ggp(0, 2), 1) << c.name << ": JC ETO taken";
    const int32_t waited_ms = rig.ggp(2, 2) - rig.ggp(1, 2);
    EXPECT_GE(waited_ms, 50) << c.name;
    EXPECT_LE(waited_ms, 51) << c.name;
    EXPECT_EQ(rig.module.runtime().error_flags, tmcl::kErrorTimeout) << c.name << ": only ETO";
    ASSERT_EQ(rig.command(cmd::kCle, 1, 0, 0).status, kOk);  // CLE ETO
    EXPECT_EQ(rig.module.runtime().error_flags, 0);
  }
}

// The same waits with the condition met before the timeout: no ETO.
TEST(Tmcm142Program, waits_met_in_time_leave_eto_clear) {
  {
    // Right switch 20000 µsteps ahead at 50000 µsteps/s: about 0.43 s, timeout 1 s.
    Tmcm142Rig rig;
    use_pps(rig, 50000, 1000000);
    rig.place_limit_switches(-1e9, 20000);
    run_wait_program(rig, {cmd::kRor, 0, 0, 50000}, kWaitLimitSwitch, 100, 2000);
    EXPECT_EQ(rig.ggp(0, 2), 2) << "WAIT LIMSW: JC ETO not taken";
    EXPECT_NEAR(rig.ggp(2, 2) - rig.ggp(1, 2), 425, 3) << "20000 / 50000 s + half the 50 ms acceleration";
    EXPECT_EQ(rig.module.runtime().error_flags, 0);
  }
  {
    // RFS mode 1: left switch 30000 below, fast 100000, slow 5000 µsteps/s; timeout 3 s.
    Tmcm142Rig rig;
    use_pps(rig, 100000, 2000000);
    ASSERT_EQ(rig.sap(194, 100000), kOk);
    ASSERT_EQ(rig.sap(195, 5000), kOk);
    rig.place_limit_switches(-30000, 1e9);
    run_wait_program(rig, {cmd::kRfs, 0, 0, 0}, kWaitReferenceSearch, 300, 4000);
    EXPECT_EQ(rig.ggp(0, 2), 2) << "WAIT RFS: JC ETO not taken";
    EXPECT_LT(rig.ggp(2, 2) - rig.ggp(1, 2), 3000);
    EXPECT_EQ(rig.gap(1), 0);
    EXPECT_NEAR(rig.rotor_microsteps(), -30000.0, 1.0);
    EXPECT_EQ(rig.module.runtime().error_flags, 0);
  }
}

// SCO, MVP COORD, CCO, GCO (loads the accumulator), ACO (stores it) from a program. A bad
// coordinate number is not fatal: the instruction has no effect and the program goes on.
TEST(Tmcm142Program, coordinates_are_set_captured_read_and_moved_to_from_a_program) {
  Tmcm142Rig rig;
  use_pps(rig, 200000, 2000000);
  download(rig, {
      {cmd::kSco, 1, 0, 30000},             // 0: SCO 1, 0, 30000
      {cmd::kMvp, 2, 0, 1},                 // 1: MVP COORD, 0, 1
      {cmd::kWait, 1, 0, 0},                // 2: WAIT POS
      {cmd::kCco, 2, 0, 0},                 // 3: CCO 2, 0 (actual position)
      {cmd::kGco, 2, 0, 0},                 // 4: GCO 2, 0 -> A
      {cmd::kCalc, 0, 0, -45000},           // 5: A = -15000
      {cmd::kAco, 3, 0, 0},                 // 6: ACO 3, 0
      {cmd::kSco, 25, 0, 1},                // 7: no coordinate 25 (status 3, ignored)
      {cmd::kMvp, 2, 0, 3},                 // 8: MVP COORD, 0, 3
      {cmd::kWait, 1, 0, 0},                // 9: WAIT POS
      {cmd::kGap, 1, 0, 0},                 // 10: actual position -> A
      {cmd::kAgp, 0, 2, 0},                 // 11
      {cmd::kGco, 1, 0, 0},                 // 12
      {cmd::kAgp, 1, 2, 0},                 // 13
      {cmd::kStop, 0, 0, 0},                // 14
  });
  ASSERT_EQ(rig.command(cmd::kRunApplication, 1, 0, 0).status, kOk);
  rig.run_until([&] { return rig.ggp(128) == 0; }, 3000);
  ASSERT_EQ(rig.ggp(128), 0);
  EXPECT_EQ(rig.module.engine().interpreter().stop_reason(), tmcl::StopReason::kStopInstruction);
  EXPECT_EQ(rig.module.coordinate(1), 30000);
  EXPECT_EQ(rig.module.coordinate(2), 30000) << "captured at the first target";
  EXPECT_EQ(rig.module.coordinate(3), -15000) << "ACO: the accumulator";
  EXPECT_EQ(rig.ggp(0, 2), -15000);
  EXPECT_EQ(rig.ggp(1, 2), 30000) << "GCO loaded the accumulator";
  EXPECT_EQ(rig.gap(1), -15000);
  EXPECT_NEAR(rig.rotor_microsteps(), -15000.0, 0.01);
  // From the host GCO does not touch the accumulator.
  EXPECT_EQ(rig.command(cmd::kGco, 1, 0, 0).value, 30000);
  EXPECT_EQ(rig.module.runtime().accumulator, 30000);
}

// Vector 3 (position reached, motor 0): one interrupt per arrival, not while standing on the
// target when the interrupt is enabled.
TEST(Tmcm142Program, position_reached_interrupt_fires_once_per_arrival) {
  Tmcm142Rig rig;
  use_pps(rig, 200000, 2000000);
  download(rig, {
      {cmd::kVect, tmcl::vector::kPositionReached0, 0, 8},  // 0
      {cmd::kEi, tmcl::vector::kPositionReached0, 0, 0},    // 1
      {cmd::kEi, 255, 0, 0},                                // 2
      {cmd::kWait, 0, 0, 10},                               // 3: 100 ms at rest on the target
      {cmd::kMvp, 0, 0, 20000},                             // 4
      {cmd::kWait, 0, 0, 50},                               // 5: 500 ms
      {cmd::kMvp, 1, 0, -5000},                             // 6: MVP REL
      {cmd::kJa, 0, 0, 7},                                  // 7: idle
      {cmd::kGgp, 0, 2, 0},                                 // 8: interrupt: count in var 0,
      {cmd::kCalc, 0, 0, 1},                                // 9
      {cmd::kAgp, 0, 2, 0},                                 // 10
      {cmd::kGap, 1, 0, 0},                                 // 11: and the position in var 1
      {cmd::kAgp, 1, 2, 0},                                 // 12
      {cmd::kReti, 0, 0, 0},                                // 13
  });
  ASSERT_EQ(rig.command(cmd::kRunApplication, 1, 0, 0).status, kOk);
  rig.run_ms(90);
  EXPECT_EQ(rig.ggp(0, 2), 0) << "at rest on the target when enabled: no edge";
  rig.run_ms(310);  // the move starts at 100 ms and takes 200 ms
  EXPECT_EQ(rig.ggp(0, 2), 1) << "the first arrival";
  EXPECT_EQ(rig.ggp(1, 2), 20000);
  rig.run_ms(600);  // the second move starts at 600 ms and takes 100 ms
  EXPECT_EQ(rig.ggp(0, 2), 2) << "the second arrival";
  EXPECT_EQ(rig.ggp(1, 2), 15000);
  EXPECT_EQ(rig.ggp(128), 1) << "still running in its idle loop";
}

}  // namespace
}  // namespace motwin::testing
