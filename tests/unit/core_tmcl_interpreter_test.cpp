// The TMCL interpreter on the TMCM-1636: download, flow, arithmetic, waits, interrupts.
#include <gtest/gtest.h>

#include <vector>

#include "support/tmcm1636_rig.h"

namespace motwin::testing {
namespace {

using tmcl::Instruction;
namespace cmd = tmcl::command;

// Downloads with the TMCL-IDE protocol: 132, instructions (status 101), NOP, 133.
void download(Tmcm1636Rig& rig, const std::vector<Instruction>& program, uint32_t start = 0) {
  ASSERT_EQ(rig.command(cmd::kEnterDownloadMode, 0, 0, static_cast<int32_t>(start)).status, 100);
  // GP 129 cannot be read by the host now: a GGP would be stored like any instruction.
  EXPECT_TRUE(rig.module.runtime().download_mode);
  for (const auto& in : program) {
    const auto reply = rig.command(in.command, in.type, in.motor_bank, in.value);
    ASSERT_EQ(reply.status, 101);
    EXPECT_EQ(reply.command, in.command);
    EXPECT_EQ(reply.value, in.value);
  }
  ASSERT_EQ(rig.command(cmd::kNop, 0, 0, 0).status, 101);
  ASSERT_EQ(rig.command(cmd::kExitDownloadMode, 0, 0, 0).status, 100);
  EXPECT_EQ(rig.command(10, 129, 0, 0).value, 0) << "GP 129 after download mode";
}

void run_program(Tmcm1636Rig& rig, const std::vector<Instruction>& program, uint32_t ms) {
  download(rig, program);
  ASSERT_EQ(rig.command(cmd::kRunApplication, 1, 0, 0).status, 100);
  rig.run_ms(ms);
}

int32_t user_variable(Tmcm1636Rig& rig, uint8_t n) { return rig.command(10, n, 2, 0).value; }

Instruction calc(uint8_t op, int32_t v) { return {cmd::kCalc, op, 0, v}; }
Instruction load(int32_t v) { return calc(9, v); }
Instruction store_var(uint8_t n) { return {cmd::kAgp, n, 2, 0}; }
Instruction stop() { return {cmd::kStop, 0, 0, 0}; }

TEST(TmclInterpreter, download_then_read_back_with_134) {
  Tmcm1636Rig rig;
  const std::vector<Instruction> program = {{cmd::kMvp, 0, 0, 90000}, {cmd::kWait, 1, 0, 0}, {cmd::kJa, 0, 0, 0}, stop()};
  download(rig, program, 10);
  for (size_t i = 0; i < program.size(); ++i) {
    const auto value = rig.command(cmd::kReadProgramMemory, 0, 0, static_cast<int32_t>(10 + i));
    const auto fields = rig.command(cmd::kReadProgramMemory, 1, 0, static_cast<int32_t>(10 + i));
    EXPECT_EQ(value.command, program[i].command);
    EXPECT_EQ(value.value, program[i].value);
    EXPECT_EQ(fields.value, (program[i].type << 8) | program[i].motor_bank);
  }
  EXPECT_EQ(rig.command(cmd::kReadProgramMemory, 0, 0, 2048).status, 4);
}

TEST(TmclInterpreter, program_survives_reset_and_autostart_runs_it) {
  Tmcm1636Rig rig;
  download(rig, {load(5), calc(0, 2), store_var(3), stop()});
  rig.send(tmcl::encode_request(1, Instruction{255, 0, 0, 1234}));
  rig.engine.complete_reset();  // GP 77 = 1 by default: autostart
  rig.run_ms(5);
  EXPECT_EQ(user_variable(rig, 3), 7);
  EXPECT_EQ(rig.command(10, 128, 0, 0).value, 0) << "stopped at STOP";
  EXPECT_EQ(rig.module.engine().interpreter().stop_reason(), tmcl::StopReason::kStopInstruction);
}

TEST(TmclInterpreter, autostart_off_leaves_the_program_stopped) {
  Tmcm1636Rig rig;
  download(rig, {load(5), store_var(3), stop()});
  rig.command(9, 77, 0, 0);
  rig.engine.power_up();
  rig.run_ms(5);
  EXPECT_EQ(user_variable(rig, 3), 0);
}

TEST(TmclInterpreter, interrupted_download_keeps_the_old_program) {
  Tmcm1636Rig rig;
  download(rig, {load(1), store_var(0), stop()});
  ASSERT_EQ(rig.command(cmd::kEnterDownloadMode, 0, 0, 0).status, 100);
  rig.command(cmd::kCalc, 9, 0, 99);  // staged only
  rig.engine.power_up();              // power lost before 133
  EXPECT_EQ(rig.command(cmd::kReadProgramMemory, 0, 0, 0).value, 1);
}

TEST(TmclInterpreter, host_reads_while_running_leave_the_accumulator_alone) {
  Tmcm1636Rig rig;
  // Loop: A = A + 1 forever, copying A to variable 0.
  run_program(rig, {load(0), calc(0, 1), store_var(0), {cmd::kJa, 0, 0, 1}}, 0);
  for (int i = 0; i < 200; ++i) {
    rig.run_ms(1);
    rig.gap(52);
    rig.command(10, 0, 2, 0);
    rig.command(15, 0, 1, 0);
  }
  // 200 ms = 4000 ticks = 4000 instructions: 1 LOAD then 1333 rounds of 3 instructions.
  EXPECT_EQ(user_variable(rig, 0), 1333);
}

TEST(TmclInterpreter, program_reads_load_the_accumulator) {
  Tmcm1636Rig rig;
  rig.command(5, 43, 0, 1234);
  run_program(rig, {{cmd::kGap, 43, 0, 0}, store_var(1), {cmd::kGgp, 66, 0, 0}, store_var(2), stop()}, 2);
  EXPECT_EQ(user_variable(rig, 1), 1234);
  EXPECT_EQ(user_variable(rig, 2), 1);
}

struct CalcCase {
  uint8_t op;
  int32_t accumulator;
  int32_t operand;
  int32_t expected;
};

TEST(TmclInterpreter, calc_every_operation_wraps_as_32_bit) {
  const CalcCase cases[] = {
      {0, 5, 7, 12},           {0, INT32_MAX, 1, INT32_MIN}, {1, 5, 7, -2},         {1, INT32_MIN, 1, INT32_MAX},
      {2, -5000, 3, -15000},   {2, 65536, 65536, 0},         {3, 7, 2, 3},          {3, -7, 2, -3},
      {3, INT32_MIN, -1, INT32_MIN}, {4, 7, 3, 1},           {4, -7, 3, -1},        {5, 0xF0, 0x3C, 0x30},
      {6, 0xF0, 0x0F, 0xFF},   {7, 0xFF, 0x0F, 0xF0},        {8, 0, 123, -1},       {9, 42, -9, -9},
  };
  for (const auto& c : cases) {
    Tmcm1636Rig rig;
    run_program(rig, {load(c.accumulator), calc(c.op, c.operand), store_var(0), stop()}, 2);
    EXPECT_EQ(user_variable(rig, 0), c.expected) << "op " << int(c.op) << " " << c.accumulator << ", " << c.operand;
  }
}

TEST(TmclInterpreter, division_by_zero_keeps_the_accumulator) {
  for (uint8_t op : {3, 4}) {
    Tmcm1636Rig rig;
    run_program(rig, {load(77), calc(op, 0), store_var(0), stop()}, 2);
    EXPECT_EQ(user_variable(rig, 0), 77);
    EXPECT_EQ(rig.command(10, 128, 0, 0).value, 0) << "the program went on to STOP";
  }
}

TEST(TmclInterpreter, calcx_uses_the_x_register) {
  // X = 6 (LOAD copies A to X), A = 7: ADD 13, SUB 1, MUL 42, DIV 1, MOD 1, SWAP, NOT on X.
  const std::pair<uint8_t, int32_t> cases[] = {{0, 13}, {1, 1}, {2, 42}, {3, 1}, {4, 1}, {5, 6}, {6, 7}, {7, 1}, {10, 6}};
  for (auto [op, expected] : cases) {
    Tmcm1636Rig rig;
    run_program(rig, {load(6), {cmd::kCalcx, 9, 0, 0}, load(7), {cmd::kCalcx, op, 0, 0}, store_var(0), stop()}, 2);
    EXPECT_EQ(user_variable(rig, 0), expected) << "CALCX " << int(op);
  }
  Tmcm1636Rig rig;
  run_program(rig, {load(6), {cmd::kCalcx, 9, 0, 0}, {cmd::kCalcx, 8, 0, 0}, {cmd::kCalcx, 10, 0, 0}, store_var(0), stop()}, 2);
  EXPECT_EQ(user_variable(rig, 0), ~6) << "NOT inverts X";
}

TEST(TmclInterpreter, jc_every_comparison_condition) {
  // COMP 10 with A in {9, 10, 11}; JC cond -> variable 0 = 1 when taken.
  const int32_t accumulators[] = {9, 10, 11};
  const bool expected[8][3] = {
      {false, true, false}, {true, false, true}, {false, true, false}, {true, false, true},
      {false, false, true}, {false, true, true}, {true, false, false}, {true, true, false},
  };
  for (uint8_t cond = 0; cond < 8; ++cond) {
    for (int i = 0; i < 3; ++i) {
      Tmcm1636Rig rig;
      run_program(rig, {load(accumulators[i]), {cmd::kComp, 0, 0, 10}, {cmd::kJc, cond, 0, 5}, stop(), stop(),
                        load(1), store_var(0), stop()}, 2);
      EXPECT_EQ(user_variable(rig, 0), expected[cond][i] ? 1 : 0) << "JC " << int(cond) << " A=" << accumulators[i];
    }
  }
}

TEST(TmclInterpreter, wait_timeout_sets_eto_and_cle_clears_each_flag) {
  Tmcm1636Rig rig;
  // MVP far away, WAIT POS with a 5-tick (50 ms) timeout, then JC ETO.
  run_program(rig, {{cmd::kMvp, 0, 0, 10000000}, {cmd::kWait, 1, 0, 5}, {cmd::kJc, 8, 0, 4}, stop(),
                    {cmd::kGgp, 132, 0, 0}, store_var(0), stop()}, 200);
  EXPECT_GE(user_variable(rig, 0), 50);
  EXPECT_LE(user_variable(rig, 0), 52);
  EXPECT_EQ(rig.module.runtime().error_flags & tmcl::kErrorTimeout, tmcl::kErrorTimeout);
  rig.module.runtime().error_flags = 0x1F;
  for (uint8_t type = 1; type <= 5; ++type) {
    ASSERT_EQ(rig.command(cmd::kCle, type, 0, 0).status, 100);
    EXPECT_EQ(rig.module.runtime().error_flags, static_cast<uint8_t>(0x1F & ~((1 << type) - 1))) << "CLE " << int(type);
  }
  rig.module.runtime().error_flags = 0x1F;
  rig.command(cmd::kCle, 0, 0, 0);
  EXPECT_EQ(rig.module.runtime().error_flags, 0);
}

TEST(TmclInterpreter, wait_ticks_from_the_accumulator) {
  Tmcm1636Rig rig;
  run_program(rig, {load(30), {cmd::kWait, 0, 0, -1}, load(1), store_var(0), stop()}, 250);
  EXPECT_EQ(user_variable(rig, 0), 0) << "still waiting at 250 ms";
  rig.run_ms(60);
  EXPECT_EQ(user_variable(rig, 0), 1);
}

TEST(TmclInterpreter, wait_pos_blocks_only_the_program) {
  Tmcm1636Rig rig;
  run_program(rig, {{cmd::kMvp, 0, 0, 20000}, {cmd::kWait, 1, 0, 0}, {cmd::kGap, 52, 0, 0}, store_var(0), stop()}, 10);
  EXPECT_EQ(rig.command(10, 128, 0, 0).value, 1) << "running";
  EXPECT_EQ(rig.gap(43), 4000) << "host commands are served meanwhile";
  rig.run_ms(3000);
  EXPECT_NEAR(user_variable(rig, 0), 20000, 5);
}

TEST(TmclInterpreter, csub_nests_eight_deep_and_ignores_the_ninth) {
  // Address 0: A = 0; CSUB 3; STOP. Address 3: A += 1; AGP 0; CSUB 3 (recursion).
  // The ninth CSUB is ignored: execution falls through to RSUB x 8.
  Tmcm1636Rig rig;
  run_program(rig, {load(0), {cmd::kCsub, 0, 0, 3}, stop(), calc(0, 1), store_var(0), {cmd::kCsub, 0, 0, 3},
                    {cmd::kRsub, 0, 0, 0}}, 20);
  EXPECT_EQ(user_variable(rig, 0), 8) << "8 nested calls, the ninth ignored";
  EXPECT_EQ(rig.module.engine().interpreter().stop_reason(), tmcl::StopReason::kStopInstruction);
}

TEST(TmclInterpreter, rsub_on_an_empty_stack_is_ignored) {
  Tmcm1636Rig rig;
  run_program(rig, {{cmd::kRsub, 0, 0, 0}, load(4), store_var(0), stop()}, 2);
  EXPECT_EQ(user_variable(rig, 0), 4);
}

TEST(TmclInterpreter, jump_outside_the_program_stops_with_a_reason) {
  Tmcm1636Rig rig;
  run_program(rig, {{cmd::kJa, 0, 0, 5000}}, 2);
  EXPECT_EQ(rig.command(10, 128, 0, 0).value, 0);
  EXPECT_EQ(rig.module.engine().interpreter().stop_reason(), tmcl::StopReason::kJumpOutsideProgram);
  EXPECT_STREQ(tmcl::stop_reason_text(tmcl::StopReason::kJumpOutsideProgram), "jump, call or return outside program memory");
  const auto reason = rig.command(cmd::kGetApplicationStatus, 4, 0, 0).value;
  EXPECT_EQ(reason >> 16, static_cast<int>(tmcl::StopReason::kJumpOutsideProgram));
  EXPECT_EQ(reason & 0xFFFF, 0);
}

TEST(TmclInterpreter, control_commands_in_a_program_stop_it) {
  // A download cannot store control commands (they run at once); an image from elsewhere can.
  Tmcm1636Rig rig;
  ASSERT_TRUE(rig.module.program_memory()->stage(0, {cmd::kRunApplication, 0, 0, 0}));
  ASSERT_TRUE(rig.module.program_memory()->commit());
  rig.command(cmd::kRunApplication, 1, 0, 0);
  rig.run_ms(2);
  EXPECT_EQ(rig.module.engine().interpreter().stop_reason(), tmcl::StopReason::kInvalidInstruction);
}

TEST(TmclInterpreter, step_executes_one_instruction_and_135_reports_state) {
  Tmcm1636Rig rig;
  download(rig, {load(3), calc(0, 4), store_var(0), stop()});
  rig.command(cmd::kResetApplication, 0, 0, 0);
  EXPECT_EQ(rig.command(10, 128, 0, 0).value, 3) << "reset";
  rig.command(cmd::kStepApplication, 0, 0, 0);
  rig.run_ms(1);
  rig.command(cmd::kStepApplication, 0, 0, 0);
  rig.run_ms(1);
  EXPECT_EQ(rig.command(cmd::kGetApplicationStatus, 2, 0, 0).value, 7) << "accumulator";
  EXPECT_EQ(rig.command(10, 130, 0, 0).value, 2) << "program counter";
  const auto status = rig.command(cmd::kGetApplicationStatus, 1, 0, 0).value;
  EXPECT_EQ(status >> 24, 2) << "step mode";
  EXPECT_EQ(status & 0xFFFF, 2);
  EXPECT_EQ(user_variable(rig, 0), 0);
  rig.command(cmd::kRunApplication, 0, 0, 0);
  rig.run_ms(1);
  EXPECT_EQ(user_variable(rig, 0), 7);
  rig.command(cmd::kResetApplication, 0, 0, 0);
  EXPECT_EQ(rig.command(cmd::kGetApplicationStatus, 2, 0, 0).value, 0) << "131 clears the accumulator";
}

TEST(TmclInterpreter, timer_interrupt_counts_at_its_period_in_simulated_time) {
  Tmcm1636Rig rig;
  // SGP 0, 3, 100 (timer 0: 100 ms); VECT 0 -> 6; EI 0; EI 255; loop: JA 4.
  // 6: GGP 0, 2; CALC ADD 1; AGP 0, 2; RETI.
  ASSERT_EQ(rig.command(cmd::kSgp, 0, 3, 100).status, 100);
  EXPECT_EQ(rig.command(cmd::kGgp, 0, 3, 0).value, 100);
  run_program(rig, {{cmd::kVect, 0, 0, 6}, {cmd::kEi, 0, 0, 0}, {cmd::kEi, 255, 0, 0}, load(0), {cmd::kJa, 0, 0, 4}, stop(),
                    {cmd::kGgp, 0, 2, 0}, calc(0, 1), store_var(0), {cmd::kReti, 0, 0, 0}}, 1050);
  EXPECT_EQ(user_variable(rig, 0), 10);
  rig.run_ms(1000);
  EXPECT_EQ(user_variable(rig, 0), 20);
  EXPECT_EQ(rig.module.runtime().accumulator, 0) << "the interrupted accumulator came back";
}

TEST(TmclInterpreter, input_edge_interrupt_fires_on_the_configured_edge) {
  Tmcm1636Rig rig;
  ASSERT_EQ(rig.command(cmd::kSgp, 40, 3, 1).status, 100);  // input 1: rising edge
  EXPECT_EQ(rig.command(cmd::kSgp, 40, 3, 4).status, 4);
  run_program(rig, {{cmd::kVect, 40, 0, 5}, {cmd::kEi, 40, 0, 0}, {cmd::kEi, 255, 0, 0}, {cmd::kJa, 0, 0, 3}, stop(),
                    {cmd::kGgp, 1, 2, 0}, calc(0, 1), {cmd::kAgp, 1, 2, 0}, {cmd::kReti, 0, 0, 0}}, 10);
  rig.io.digital_inputs[1] = true;
  rig.run_ms(10);
  rig.io.digital_inputs[1] = false;
  rig.run_ms(10);
  rig.io.digital_inputs[1] = true;
  rig.run_ms(10);
  EXPECT_EQ(user_variable(rig, 1), 2) << "two rising edges, the falling one ignored";
}

}  // namespace
}  // namespace motwin::testing
