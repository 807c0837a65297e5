// The TMCL interpreter's conditions and arithmetic at their edges (TMCM-1636): JC on each error
// flag (ETO, EAL, EDV, EPO, ESD) with the other flags set or clear, COMP with negative operands
// and the INT32 limits (no wrap in the comparison), CALCX DIV/MOD by X = 0, and GP 85 (user
// variables restored at power-up or not).
#include <gtest/gtest.h>

#include <climits>
#include <vector>

#include "support/tmcm1636_rig.h"

namespace motwin::testing {
namespace {

using tmcl::Instruction;
namespace cmd = tmcl::command;

constexpr uint8_t kOk = 100;

void download(Tmcm1636Rig& rig, const std::vector<Instruction>& program) {
  ASSERT_EQ(rig.command(cmd::kEnterDownloadMode, 0, 0, 0).status, kOk);
  for (const auto& in : program) ASSERT_EQ(rig.command(in.command, in.type, in.motor_bank, in.value).status, 101);
  ASSERT_EQ(rig.command(cmd::kExitDownloadMode, 0, 0, 0).status, kOk);
}

void run_program(Tmcm1636Rig& rig, const std::vector<Instruction>& program, uint32_t ms) {
  download(rig, program);
  ASSERT_EQ(rig.command(cmd::kRunApplication, 1, 0, 0).status, kOk);
  rig.run_ms(ms);
}

int32_t user_variable(Tmcm1636Rig& rig, uint8_t n) { return rig.command(cmd::kGgp, n, 2, 0).value; }

Instruction load(int32_t v) { return {cmd::kCalc, 9, 0, v}; }
Instruction store_var(uint8_t n) { return {cmd::kAgp, n, 2, 0}; }
Instruction stop() { return {cmd::kStop, 0, 0, 0}; }

// JC 8..12 test one error flag each; the other flags do not matter.
TEST(TmclConditions, jc_on_each_error_flag_with_the_others_set_or_clear) {
  struct FlagCondition {
    uint8_t condition;
    uint8_t flag;
    const char* name;
  };
  const FlagCondition conditions[] = {
      {8, tmcl::kErrorTimeout, "ETO"},       {9, tmcl::kErrorExternalAlarm, "EAL"}, {10, tmcl::kErrorDeviation, "EDV"},
      {11, tmcl::kErrorPosition, "EPO"},     {12, tmcl::kErrorShutdown, "ESD"},
  };
  for (const auto& c : conditions) {
    // Flags: none, only this one, all but this one, all five.
    const uint8_t flag_sets[] = {0, c.flag, static_cast<uint8_t>(0x1F & ~c.flag), 0x1F};
    const bool taken[] = {false, true, false, true};
    for (int i = 0; i < 4; ++i) {
      Tmcm1636Rig rig;
      rig.module.runtime().error_flags = flag_sets[i];
      // 0: LOAD 2; 1: JC c, 4; 2: LOAD 1; 3: JA 5; 4: LOAD 3 (taken); 5: AGP 0, 2; 6: STOP.
      run_program(rig, {load(2), {cmd::kJc, c.condition, 0, 4}, load(1), {cmd::kJa, 0, 0, 5}, load(3), store_var(0), stop()}, 2);
      EXPECT_EQ(user_variable(rig, 0), taken[i] ? 3 : 1) << "JC " << c.name << " with flags " << int(flag_sets[i]);
      EXPECT_EQ(rig.module.runtime().error_flags, flag_sets[i]) << "JC " << c.name << " leaves the flags alone";
      EXPECT_EQ(rig.command(cmd::kGgp, 128, 0, 0).value, 0) << "ended at STOP";
    }
  }
}

// Only CLE of the matching type clears the flag a JC tests: JC EAL taken, CLE EAL, JC EAL not taken.
TEST(TmclConditions, cle_in_a_program_clears_the_flag_jc_tests) {
  Tmcm1636Rig rig;
  rig.module.runtime().error_flags = tmcl::kErrorExternalAlarm | tmcl::kErrorShutdown;
  // 0: JC EAL, 2; 1: STOP; 2: CLE EAL; 3: JC EAL, 7; 4: JC ESD, 9; 5: STOP; 6: STOP; 7: LOAD 66; 8: STOP;
  // 9: LOAD 55; 10: AGP 0, 2; 11: STOP.
  run_program(rig, {{cmd::kJc, 9, 0, 2}, stop(), {cmd::kCle, 2, 0, 0}, {cmd::kJc, 9, 0, 7}, {cmd::kJc, 12, 0, 9}, stop(),
                    stop(), load(66), stop(), load(55), store_var(0), stop()}, 2);
  EXPECT_EQ(user_variable(rig, 0), 55) << "EAL cleared, ESD still set";
  EXPECT_EQ(rig.module.runtime().error_flags, tmcl::kErrorShutdown);
}

// COMP stores both operands; JC compares them as signed 32-bit numbers, never their wrapped
// difference (INT32_MIN - INT32_MAX = 1 would otherwise read as "greater").
TEST(TmclConditions, comp_with_negative_operands_and_the_int32_limits) {
  struct CompCase {
    int32_t accumulator;
    int32_t operand;
    int order;  // sign of accumulator - operand, worked out by hand
  };
  const CompCase cases[] = {
      {-5, -3, -1},        {-3, -5, 1},         {-7, -7, 0},          {-1, 0, -1},         {0, -1, 1},
      {INT32_MIN, INT32_MAX, -1},               {INT32_MAX, INT32_MIN, 1},                {INT32_MIN, INT32_MIN, 0},
      {INT32_MAX, INT32_MAX, 0},                {INT32_MIN, 1, -1},  {INT32_MAX, -1, 1},  {-1, INT32_MIN, 1},
  };
  // Expected JC 0..7 (ZE, NZ, EQ, NE, GT, GE, LT, LE) for order -1, 0, +1.
  const bool expected[3][8] = {
      {false, true, false, true, false, false, true, true},   // A < operand
      {true, false, true, false, false, true, false, true},   // A == operand
      {false, true, false, true, true, true, false, false},   // A > operand
  };
  for (const auto& c : cases) {
    // One run per case: 8 JCs, each setting bit `cond` of variable 0 when taken.
    // Layout per condition k (base 3 + 5k): JC k, +3; JA +4 (skip); GGP 0,2 / CALC OR bit / AGP 0,2.
    std::vector<Instruction> program = {load(0), store_var(0), {cmd::kJa, 0, 0, 3}};
    for (uint8_t cond = 0; cond < 8; ++cond) {
      const auto base = static_cast<int32_t>(program.size());
      program.push_back(load(c.accumulator));
      program.push_back({cmd::kComp, 0, 0, c.operand});
      program.push_back({cmd::kJc, cond, 0, base + 4});
      program.push_back({cmd::kJa, 0, 0, base + 7});
      program.push_back({cmd::kGgp, 0, 2, 0});
      program.push_back({cmd::kCalc, 6, 0, 1 << cond});
      program.push_back(store_var(0));
    }
    program.push_back(stop());
    Tmcm1636Rig rig;
    run_program(rig, program, 10);
    ASSERT_EQ(rig.command(cmd::kGgp, 128, 0, 0).value, 0) << "program ended";
    const int32_t taken = user_variable(rig, 0);
    for (uint8_t cond = 0; cond < 8; ++cond) {
      EXPECT_EQ((taken >> cond) & 1, expected[c.order + 1][cond] ? 1 : 0)
          << "COMP " << c.operand << " with A = " << c.accumulator << ", JC " << int(cond);
    }
  }
}

// CALCX divides A by X: X = 0 keeps A (the program goes on), as CALC DIV 0 does.
TEST(TmclConditions, calcx_div_and_mod_by_a_zero_x_keep_the_accumulator) {
  for (uint8_t op : {3, 4}) {
    Tmcm1636Rig rig;
    // X = 0 (LOAD 0, CALCX LOAD), A = -77, CALCX op, AGP 0, 2; then X must still be 0: SWAP, AGP 1, 2.
    run_program(rig, {load(0), {cmd::kCalcx, 9, 0, 0}, load(-77), {cmd::kCalcx, op, 0, 0}, store_var(0),
                      {cmd::kCalcx, 10, 0, 0}, store_var(1), stop()}, 2);
    EXPECT_EQ(user_variable(rig, 0), -77) << "CALCX " << int(op) << " by X = 0";
    EXPECT_EQ(user_variable(rig, 1), 0) << "X unchanged";
    EXPECT_EQ(rig.module.engine().interpreter().stop_reason(), tmcl::StopReason::kStopInstruction);
  }
}

// CALCX DIV/MOD with negative operands truncate towards zero; INT32_MIN / -1 stays INT32_MIN.
TEST(TmclConditions, calcx_div_and_mod_with_negatives_and_the_overflowing_quotient) {
  struct Case {
    uint8_t op;
    int32_t a;
    int32_t x;
    int32_t expected;
  };
  const Case cases[] = {
      {3, -7, 2, -3}, {4, -7, 2, -1}, {3, 7, -2, -3}, {4, 7, -2, 1}, {3, INT32_MIN, -1, INT32_MIN}, {4, INT32_MIN, -1, 0},
      {0, INT32_MAX, 1, INT32_MIN}, {1, INT32_MIN, 1, INT32_MAX}, {2, INT32_MIN, -1, INT32_MIN},
  };
  for (const auto& c : cases) {
    Tmcm1636Rig rig;
    run_program(rig, {load(c.x), {cmd::kCalcx, 9, 0, 0}, load(c.a), {cmd::kCalcx, c.op, 0, 0}, store_var(0), stop()}, 2);
    EXPECT_EQ(user_variable(rig, 0), c.expected) << "CALCX " << int(c.op) << " A = " << c.a << ", X = " << c.x;
  }
}

// GP 85 = 0: stored user variables (0..55) come back at power-up; 1: they start at 0, and RSGP
// still fetches the stored copy. Variables above 55 are never stored.
TEST(TmclConditions, gp_85_decides_whether_user_variables_are_restored) {
  Tmcm1636Rig rig;
  ASSERT_EQ(rig.command(cmd::kSgp, 3, 2, 1234).status, kOk);
  ASSERT_EQ(rig.command(cmd::kStgp, 3, 2, 0).status, kOk);
  ASSERT_EQ(rig.command(cmd::kSgp, 3, 2, 99).status, kOk);  // RAM only
  ASSERT_EQ(rig.command(cmd::kSgp, 100, 2, 7).status, kOk);
  EXPECT_NE(rig.command(cmd::kStgp, 100, 2, 0).status, kOk) << "variable 100 is not storable";
  EXPECT_EQ(rig.command(cmd::kGgp, 85, 0, 0).value, 0) << "factory default";
  rig.engine.power_up();
  EXPECT_EQ(user_variable(rig, 3), 1234) << "GP 85 = 0: restored";
  EXPECT_EQ(user_variable(rig, 100), 0);

  ASSERT_EQ(rig.command(cmd::kSgp, 85, 0, 1).status, kOk);  // stored at once (access A)
  rig.engine.power_up();
  EXPECT_EQ(rig.command(cmd::kGgp, 85, 0, 0).value, 1);
  EXPECT_EQ(user_variable(rig, 3), 0) << "GP 85 = 1: starts at 0";
  ASSERT_EQ(rig.command(cmd::kRsgp, 3, 2, 0).status, kOk);
  EXPECT_EQ(user_variable(rig, 3), 1234) << "the stored copy is still there";

  ASSERT_EQ(rig.command(cmd::kSgp, 85, 0, 0).status, kOk);
  ASSERT_EQ(rig.command(cmd::kSgp, 3, 2, 5).status, kOk);
  rig.engine.power_up();
  EXPECT_EQ(user_variable(rig, 3), 1234) << "GP 85 = 0 again";
  EXPECT_EQ(rig.command(cmd::kSgp, 85, 0, 2).status, 4) << "0 or 1 only";
  EXPECT_EQ(rig.command(cmd::kGgp, 85, 0, 0).value, 0);
}

}  // namespace
}  // namespace motwin::testing
