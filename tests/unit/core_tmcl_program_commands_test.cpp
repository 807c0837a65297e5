// Commands run from a stored program on the TMCM-1636 that the other interpreter tests reach only
// from the host: SIO/GIO, STAP/RSAP, STGP/RSGP (none of the writes loads the accumulator; the
// reads do), and the input interrupts on falling and both edges, DI of one vector and of all.
#include <gtest/gtest.h>

#include <vector>

#include "core/tmcl/interpreter.h"
#include "support/tmcm1636_rig.h"

namespace motwin::testing {
namespace {

using tmcl::Instruction;
namespace cmd = tmcl::command;

constexpr uint8_t kOk = 100;

void run_program(Tmcm1636Rig& rig, const std::vector<Instruction>& program, uint32_t ms) {
  ASSERT_EQ(rig.command(cmd::kEnterDownloadMode, 0, 0, 0).status, kOk);
  for (const auto& in : program) ASSERT_EQ(rig.command(in.command, in.type, in.motor_bank, in.value).status, 101);
  ASSERT_EQ(rig.command(cmd::kExitDownloadMode, 0, 0, 0).status, kOk);
  ASSERT_EQ(rig.command(cmd::kRunApplication, 1, 0, 0).status, kOk);
  rig.run_ms(ms);
}

int32_t user_variable(Tmcm1636Rig& rig, uint8_t n) { return rig.command(cmd::kGgp, n, 2, 0).value; }

TEST(TmclProgramCommands, sio_stap_rsap_stgp_rsgp_from_a_program) {
  Tmcm1636Rig rig;
  rig.io.digital_inputs[3] = true;
  run_program(rig, {
      {cmd::kCalc, 9, 0, 777},    // 0: A = 777
      {cmd::kSio, 1, 2, 1},       // 1: SIO 1, 2, 1: GPO1 on
      {cmd::kSio, 0, 2, 5},       // 2: value 5: status 4, no effect, the program goes on
      {cmd::kSap, 11, 0, 3000},   // 3: AP 11 (max current) = 3000
      {cmd::kStap, 11, 0, 0},     // 4: stored
      {cmd::kSap, 11, 0, 1500},   // 5: RAM only
      {cmd::kSgp, 5, 2, 55},      // 6: user variable 5 = 55
      {cmd::kStgp, 5, 2, 0},      // 7: stored
      {cmd::kSgp, 5, 2, 1},       // 8: RAM only
      {cmd::kAgp, 7, 2, 0},       // 9: var 7 = A: still 777
      {cmd::kGap, 11, 0, 0},      // 10: A = 1500
      {cmd::kAgp, 10, 2, 0},      // 11
      {cmd::kRsap, 11, 0, 0},     // 12: AP 11 back to 3000
      {cmd::kRsgp, 5, 2, 0},      // 13: var 5 back to 55
      {cmd::kAgp, 11, 2, 0},      // 14: A (1500) unchanged by RSAP/RSGP
      {cmd::kGio, 1, 2, 0},       // 15: GPO1 read back -> A = 1
      {cmd::kAgp, 8, 2, 0},       // 16
      {cmd::kGio, 3, 0, 0},       // 17: GPI3 -> A = 1
      {cmd::kCalc, 0, 0, 10},     // 18: A = 11
      {cmd::kAgp, 9, 2, 0},       // 19
      {cmd::kStop, 0, 0, 0},      // 20
  }, 5);
  ASSERT_EQ(rig.module.engine().interpreter().stop_reason(), tmcl::StopReason::kStopInstruction);
  EXPECT_EQ(rig.module.engine().interpreter().stop_address(), 20u);
  EXPECT_TRUE(rig.io.outputs[1]);
  EXPECT_FALSE(rig.io.outputs[0]);
  EXPECT_EQ(user_variable(rig, 7), 777) << "SIO/SAP/STAP/SGP/STGP do not load the accumulator";
  EXPECT_EQ(user_variable(rig, 10), 1500) << "GAP loads it";
  EXPECT_EQ(user_variable(rig, 11), 1500) << "RSAP/RSGP do not load it";
  EXPECT_EQ(rig.gap(11), 3000) << "RSAP";
  EXPECT_EQ(user_variable(rig, 5), 55) << "RSGP";
  EXPECT_EQ(user_variable(rig, 8), 1) << "GIO of the output bank";
  EXPECT_EQ(user_variable(rig, 9), 11) << "GIO of the input bank";
  // The stored values survive a power-up.
  ASSERT_EQ(rig.command(cmd::kSap, 11, 0, 1000).status, kOk);
  ASSERT_EQ(rig.command(cmd::kSgp, 5, 2, 2).status, kOk);
  rig.command(cmd::kSgp, 77, 0, 0);  // no autostart
  rig.engine.power_up();
  EXPECT_EQ(rig.gap(11), 3000);
  EXPECT_EQ(user_variable(rig, 5), 55);
}

// Interrupt routine at 6 counting in user variable `counter`; main loop at 5.
std::vector<Instruction> counting_program(uint8_t vector, uint8_t counter) {
  return {
      {cmd::kVect, vector, 0, 6},   // 0
      {cmd::kEi, vector, 0, 0},     // 1
      {cmd::kEi, 255, 0, 0},        // 2
      {cmd::kNop, 0, 0, 0},         // 3
      {cmd::kNop, 0, 0, 0},         // 4
      {cmd::kJa, 0, 0, 5},          // 5
      {cmd::kGgp, counter, 2, 0},   // 6
      {cmd::kCalc, 0, 0, 1},        // 7
      {cmd::kAgp, counter, 2, 0},   // 8
      {cmd::kReti, 0, 0, 0},        // 9
  };
}

// Input 2 (vector 41) toggled up, down, up, down: falling edges count 2, both edges 4.
TEST(TmclProgramCommands, input_interrupts_on_falling_and_on_both_edges) {
  const uint8_t triggers[] = {2, 3};
  const int32_t expected[] = {2, 4};
  for (int i = 0; i < 2; ++i) {
    Tmcm1636Rig rig;
    ASSERT_EQ(rig.command(cmd::kSgp, 41, 3, triggers[i]).status, kOk);
    EXPECT_EQ(rig.command(cmd::kGgp, 41, 3, 0).value, triggers[i]);
    run_program(rig, counting_program(41, 0), 5);
    for (bool level : {true, false, true, false}) {
      rig.io.digital_inputs[2] = level;
      rig.run_ms(5);
    }
    EXPECT_EQ(user_variable(rig, 0), expected[i]) << "trigger " << int(triggers[i]);
    EXPECT_EQ(rig.command(cmd::kGgp, 128, 0, 0).value, 1) << "back in the main loop";
  }
}

// DI 39 stops one vector (edges while disabled are lost, the level at EI is no edge); DI 255
// stops all of them.
TEST(TmclProgramCommands, di_disables_one_vector_and_di_255_all) {
  Tmcm1636Rig rig;
  ASSERT_EQ(rig.command(cmd::kSgp, 39, 3, 3).status, kOk);  // input 0: both edges
  run_program(rig, {
      {cmd::kVect, 39, 0, 10},  // 0
      {cmd::kEi, 39, 0, 0},     // 1
      {cmd::kEi, 255, 0, 0},    // 2
      {cmd::kWait, 0, 0, 10},   // 3: 0..100 ms enabled
      {cmd::kDi, 39, 0, 0},     // 4
      {cmd::kWait, 0, 0, 10},   // 5: 100..200 ms vector 39 disabled
      {cmd::kEi, 39, 0, 0},     // 6
      {cmd::kWait, 0, 0, 10},   // 7: 200..300 ms enabled
      {cmd::kDi, 255, 0, 0},    // 8: from 300 ms all disabled
      {cmd::kJa, 0, 0, 9},      // 9
      {cmd::kGgp, 0, 2, 0},     // 10
      {cmd::kCalc, 0, 0, 1},    // 11
      {cmd::kAgp, 0, 2, 0},     // 12
      {cmd::kReti, 0, 0, 0},    // 13
  }, 0);
  const auto input_at = [&](uint32_t& now_ms, uint32_t at_ms, bool level) {
    rig.run_ms(at_ms - now_ms);
    now_ms = at_ms;
    rig.io.digital_inputs[0] = level;
  };
  uint32_t now = 0;
  input_at(now, 20, true);
  input_at(now, 40, false);  // two edges while enabled (the interrupts run during the WAIT)
  input_at(now, 120, true);
  input_at(now, 140, false);  // lost: DI 39
  input_at(now, 160, true);   // high when EI 39 comes at 200 ms: no edge
  input_at(now, 220, false);  // counted
  input_at(now, 320, true);   // lost: DI 255
  input_at(now, 340, false);
  rig.run_ms(20);
  EXPECT_EQ(user_variable(rig, 0), 3);
  EXPECT_EQ(rig.module.runtime().program_counter, 9u) << "the WAITs went on after each interrupt";
}

}  // namespace
}  // namespace motwin::testing
