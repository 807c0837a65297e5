// Every example program of the TMCM-1636 manual (tests/programs/*.tmc) assembled with Motwin's
// assembler, downloaded as the TMCL-IDE downloads (132, instructions, NOP, 133, binary frames)
// into a TMCM-1636 with its ideal motor, read back with 134, and run: the motion or variable
// results the manual describes.
#include <gtest/gtest.h>

#include <filesystem>
#include <string>
#include <vector>

#include "support/tmcm1636_rig.h"
#include "tools/tmcl_assembler.h"
#include "tools/tmcl_mnemonics.h"

namespace motwin::testing {
namespace {

using tmcl::Instruction;
namespace cmd = tmcl::command;

const std::string kProgramsDir = MOTWIN_TEST_PROGRAMS_DIR;

tools::AssemblyResult assemble(const std::string& name) {
  tools::AssemblyResult result = tools::assemble_file(kProgramsDir + "/" + name);
  for (const tools::AssemblyError& error : result.errors) ADD_FAILURE() << tools::format_error(error);
  return result;
}

// The TMCL-IDE download, then every address read back with both 134 types.
void download(Tmcm1636Rig& rig, const std::vector<Instruction>& program) {
  ASSERT_EQ(rig.command(cmd::kEnterDownloadMode, 0, 0, 0).status, 100);
  for (const Instruction& in : program) {
    ASSERT_EQ(rig.command(in.command, in.type, in.motor_bank, in.value).status, 101) << tools::format_instruction(in);
  }
  ASSERT_EQ(rig.command(cmd::kNop, 0, 0, 0).status, 101);
  ASSERT_EQ(rig.command(cmd::kExitDownloadMode, 0, 0, 0).status, 100);
  for (size_t address = 0; address < program.size(); ++address) {
    const tmcl::Reply opcode = rig.command(cmd::kReadProgramMemory, 0, 0, static_cast<int32_t>(address));
    const tmcl::Reply fields = rig.command(cmd::kReadProgramMemory, 1, 0, static_cast<int32_t>(address));
    const Instruction stored{opcode.command, static_cast<uint8_t>(fields.value >> 8),
                             static_cast<uint8_t>(fields.value & 0xFF), opcode.value};
    EXPECT_EQ(tools::format_instruction(stored), tools::format_instruction(program[address])) << "address " << address;
  }
}

tools::AssemblyResult load_and_start(Tmcm1636Rig& rig, const std::string& name, uint32_t address = 0) {
  tools::AssemblyResult assembled = assemble(name);
  download(rig, assembled.instructions);
  EXPECT_EQ(rig.command(cmd::kRunApplication, 1, 0, static_cast<int32_t>(address)).status, 100);
  return assembled;
}

struct Sample {
  uint32_t t_ms;
  int32_t position;  // AP 52
  int32_t velocity;  // AP 42
  int32_t target;    // AP 50
  bool reached;      // AP 55
};

// Runs `ms` milliseconds, sampling every millisecond (direct-mode reads, as a host polls).
std::vector<Sample> record(Tmcm1636Rig& rig, uint32_t ms, uint32_t t0_ms = 0) {
  std::vector<Sample> samples;
  for (uint32_t t = 1; t <= ms; ++t) {
    rig.run_ms(1);
    samples.push_back(Sample{t0_ms + t, rig.gap(52), rig.gap(42), rig.gap(50), rig.gap(55) != 0});
  }
  return samples;
}

// Where the axis turned round, in order. WAIT POS ends as soon as the position reached flag is
// set (within AP 53 counts of the target and slower than AP 54 rpm), so a program that moves
// on at once turns round near its target without standing still there.
std::vector<int32_t> turning_points(const std::vector<Sample>& samples) {
  std::vector<int32_t> out;
  int direction = 0;
  int32_t previous = samples.empty() ? 0 : samples.front().position;
  for (const Sample& s : samples) {
    const int d = s.position > previous ? 1 : (s.position < previous ? -1 : 0);
    if (d != 0) {
      if (direction != 0 && d != direction) out.push_back(previous);
      direction = d;
    }
    previous = s.position;
  }
  return out;
}

int32_t application_status(Tmcm1636Rig& rig) { return rig.command(cmd::kGgp, 128, 0, 0).value; }
tmcl::StopReason stop_reason(Tmcm1636Rig& rig) { return rig.module.engine().interpreter().stop_reason(); }

// Turning round at a, b, a, b ... (`cycles` times each), each within `tolerance` counts.
void expect_oscillation(const std::vector<int32_t>& turns, int32_t a, int32_t b, size_t cycles, int32_t tolerance) {
  ASSERT_GE(turns.size(), 2 * cycles) << ::testing::PrintToString(turns);
  for (size_t i = 0; i < 2 * cycles; ++i) {
    const int32_t expected = i % 2 == 0 ? a : b;
    EXPECT_LE(std::abs(turns[i] - expected), tolerance)
        << "turning point " << i << " should be near " << expected << ": " << ::testing::PrintToString(turns);
  }
}

TEST(ManualPrograms, every_program_assembles_downloads_and_reads_back) {
  size_t programs = 0;
  for (const auto& entry : std::filesystem::directory_iterator(kProgramsDir)) {
    if (entry.path().extension() != ".tmc") continue;
    SCOPED_TRACE(entry.path().filename().string());
    Tmcm1636Rig rig;
    const tools::AssemblyResult assembled = assemble(entry.path().filename().string());
    ASSERT_FALSE(assembled.instructions.empty());
    EXPECT_EQ(assembled.instructions.back().command, cmd::kStop) << "the appended STOP";
    download(rig, assembled.instructions);
    ++programs;
  }
  EXPECT_GE(programs, 10u);
}

// 1.3: ADC offsets, position reached window, position P, acceleration, encoder mode, ROR 200 for
// 3 s, clear-on-null settings (AP 67/68 are not TMCM-1636 parameters: no effect, the program
// continues), another 3 s, then back and forth between 0 and 655360 forever.
TEST(ManualPrograms, first_program_1_3_rotates_then_moves_between_0_and_655360) {
  Tmcm1636Rig rig;
  const tools::AssemblyResult assembled = load_and_start(rig, "manual_1_3_first_program.tmc");
  ASSERT_EQ(assembled.label_address("PositionTest"), 12u);
  rig.run_ms(1000);
  EXPECT_EQ(rig.gap(5), 33911);
  EXPECT_EQ(rig.gap(6), 32514);
  EXPECT_EQ(rig.gap(53), 1000);
  EXPECT_EQ(rig.gap(44), 10000);
  EXPECT_EQ(rig.gap(15), 2);
  EXPECT_EQ(rig.gap(42), 200) << "ROR 0, 200";
  EXPECT_GT(rig.gap(52), 0);
  rig.run_ms(5000 - 1);  // both WAIT TICKS, 0, 300 are still running at 5.999 s
  EXPECT_EQ(rig.gap(42), 200);
  const std::vector<Sample> samples = record(rig, 12000, 6000);
  // The first turn ends the rotation (MVP ABS 0); then WAIT POS with the manual's position
  // reached distance of 1000 counts (AP 53) between 0 and 655360.
  const std::vector<int32_t> turns = turning_points(samples);
  ASSERT_FALSE(turns.empty());
  EXPECT_GT(turns.front(), 100000) << "6 s at 200 rpm";
  expect_oscillation(std::vector<int32_t>(turns.begin() + 1, turns.end()), 0, 655360, 2, 1000);
  EXPECT_EQ(application_status(rig), 1) << "JA PositionTest loops forever";
}

// 2.6.16/2.6.17: GAP 1 (as printed; on the TMCM-1636 the raw ADC of phase B, 32767 at rest)
// is >= 1000, so JC GE jumps to Label: ROL 0, 1000.
TEST(ManualPrograms, comp_jc_2_6_16_jumps_when_the_value_is_at_least_1000) {
  Tmcm1636Rig rig;
  load_and_start(rig, "manual_2_6_16_comp_jc.tmc");
  rig.run_ms(1000);
  EXPECT_EQ(rig.gap(40), -1000) << "ROL 0, 1000 at Label";
  EXPECT_EQ(rig.gap(42), -1000);
  EXPECT_EQ(rig.command(cmd::kGetApplicationStatus, 2, 0, 0).value, rig.gap(1)) << "GAP loaded the accumulator";
  EXPECT_EQ(stop_reason(rig), tmcl::StopReason::kStopInstruction);
  EXPECT_EQ(rig.module.engine().interpreter().stop_address(), 4u) << "the appended STOP after Label";
}

// 2.6.18: JA Loop between 51200 and 0.
TEST(ManualPrograms, ja_loop_2_6_18_moves_between_51200_and_0_forever) {
  Tmcm1636Rig rig;
  load_and_start(rig, "manual_2_6_18_ja_loop.tmc");
  expect_oscillation(turning_points(record(rig, 6000)), 51200, 0, 3, 5);
  EXPECT_EQ(application_status(rig), 1);
}

// 2.6.19/2.6.20: the subroutine waits for the position and then 50 ticks (0.5 s) before RSUB.
TEST(ManualPrograms, csub_rsub_2_6_19_waits_half_a_second_at_each_end) {
  Tmcm1636Rig rig;
  const tools::AssemblyResult assembled = load_and_start(rig, "manual_2_6_19_csub_rsub.tmc");
  ASSERT_EQ(assembled.label_address("SubW"), 5u);
  const std::vector<Sample> samples = record(rig, 8000);
  // The 0.5 s wait lets the axis come to rest exactly at each end before it turns round.
  const std::vector<int32_t> turns = turning_points(samples);
  ASSERT_GE(turns.size(), 4u) << ::testing::PrintToString(turns);
  EXPECT_EQ(std::vector<int32_t>(turns.begin(), turns.begin() + 4), (std::vector<int32_t>{10000, 0, 10000, 0}));
  // From the position reached flag (WAIT POS ends) to the next MVP: the 50 ticks of WAIT TICKS.
  uint32_t arrived = 0;
  uint32_t left = 0;
  for (const Sample& s : samples) {
    if (arrived == 0 && s.target == 10000 && s.reached) arrived = s.t_ms;
    if (arrived != 0 && s.target == 0) {
      left = s.t_ms;
      break;
    }
  }
  ASSERT_NE(arrived, 0u);
  ASSERT_NE(left, 0u);
  EXPECT_GE(left - arrived, 500u);
  EXPECT_LE(left - arrived, 502u);
}

// 2.6.24: GIO 0, 1 reads analog input 0, CALC MUL 4, AAP 0, 0. On the TMCM-1636 axis parameter
// 0 is the read-only raw ADC value (its target position is AP 50): AAP answers status 3 and has
// no effect, the program goes on looping with the accumulator at 4 x the input.
TEST(ManualPrograms, aap_2_6_24_computes_4_times_the_analog_input) {
  Tmcm1636Rig rig;
  rig.io.analog_inputs[0] = 1000;
  load_and_start(rig, "manual_2_6_24_aap_potentiometer.tmc");
  rig.run_ms(10);
  EXPECT_EQ(rig.command(cmd::kGetApplicationStatus, 2, 0, 0).value, 4000);
  rig.io.analog_inputs[0] = 2500;
  rig.run_ms(10);
  EXPECT_EQ(rig.command(cmd::kGetApplicationStatus, 2, 0, 0).value, 10000);
  EXPECT_EQ(rig.gap(50), 0) << "AAP 0 does not reach the target position on this module";
  EXPECT_EQ(application_status(rig), 1);
}

// 6.2: SAP 4 and 5 are other modules' numbers (read-only ADC values and the ADC offset here),
// then the main loop between 5000 and 0.
TEST(ManualPrograms, main_loop_6_2_moves_between_5000_and_0) {
  Tmcm1636Rig rig;
  load_and_start(rig, "manual_6_2_main_loop.tmc");
  expect_oscillation(turning_points(record(rig, 4000)), 5000, 0, 3, 5);
}

// 6.3: TMCLParam.tmc names, max velocity 50000 rpm, acceleration 10000 rpm/s, 500000 and 0.
TEST(ManualPrograms, symbolic_constants_6_3_set_speed_and_acceleration_and_loop) {
  Tmcm1636Rig rig;
  load_and_start(rig, "manual_6_3_symbolic_constants.tmc");
  const std::vector<Sample> samples = record(rig, 6000);
  EXPECT_EQ(rig.gap(43), 50000);
  EXPECT_EQ(rig.gap(44), 10000);
  int32_t fastest = 0;
  for (const Sample& s : samples) fastest = std::max(fastest, s.velocity);
  EXPECT_GT(fastest, 4000) << "faster than the default 4000 rpm";
  EXPECT_LE(fastest, 50000);
  expect_oscillation(turning_points(samples), 500000, 0, 2, 5);
}

// 6.4: the user variable 42 is initialised with 1234 and doubled.
TEST(ManualPrograms, variables_6_4_double_user_variable_42) {
  Tmcm1636Rig rig;
  const tools::AssemblyResult assembled = load_and_start(rig, "manual_6_4_variables.tmc");
  rig.run_ms(5);
  EXPECT_EQ(rig.command(cmd::kGgp, 42, 2, 0).value, 2468);
  EXPECT_EQ(stop_reason(rig), tmcl::StopReason::kStopInstruction);
  EXPECT_EQ(rig.module.engine().interpreter().stop_address(), assembled.instructions.size() - 1);
}

// 6.6: the host calls the routines with 129 type 1 and the addresses of the jump table.
TEST(ManualPrograms, jump_table_6_6_called_by_129_type_1_with_addresses_0_1_2) {
  Tmcm1636Rig rig;
  const tools::AssemblyResult assembled = assemble("manual_6_6_jump_table.tmc");
  ASSERT_EQ(assembled.label_address("Func1"), 0u);
  ASSERT_EQ(assembled.label_address("Func2"), 1u);
  ASSERT_EQ(assembled.label_address("Func3"), 2u);
  download(rig, assembled.instructions);

  // Func1: to 1000, then back to 0, then STOP.
  ASSERT_EQ(rig.command(cmd::kRunApplication, 1, 0, 0).status, 100);
  const std::vector<Sample> func1 = record(rig, 3000);
  const std::vector<int32_t> turns = turning_points(func1);
  ASSERT_EQ(turns.size(), 1u) << ::testing::PrintToString(turns);
  EXPECT_NEAR(turns[0], 1000, 5) << "turned round at 1000 (WAIT POS: within AP 53 = 5 counts)";
  EXPECT_EQ(func1.back().position, 0) << "then at rest at 0";
  EXPECT_EQ(func1.back().velocity, 0);
  EXPECT_EQ(application_status(rig), 0);
  EXPECT_EQ(stop_reason(rig), tmcl::StopReason::kStopInstruction);

  // Func2: ROL 500 for 1 s (100 ticks of 10 ms), then MST.
  ASSERT_EQ(rig.command(cmd::kRunApplication, 1, 0, 1).status, 100);
  rig.run_ms(900);
  EXPECT_EQ(rig.gap(42), -500);
  EXPECT_EQ(rig.gap(40), -500);
  EXPECT_EQ(application_status(rig), 1) << "in WAIT TICKS";
  rig.run_ms(200);
  EXPECT_EQ(rig.gap(40), 0) << "MST after 1 s";
  EXPECT_LT(rig.gap(42), 0) << "still braking with the ramp";
  rig.run_ms(1000);
  EXPECT_EQ(rig.gap(42), 0);
  EXPECT_LT(rig.gap(52), 0) << "it turned left";
  EXPECT_EQ(application_status(rig), 0);
  const int32_t after_func2 = rig.gap(52);

  // Func3: ROR 1000 for 7 s, then MST.
  ASSERT_EQ(rig.command(cmd::kRunApplication, 1, 0, 2).status, 100);
  rig.run_ms(6900);
  EXPECT_EQ(rig.gap(42), 1000);
  EXPECT_EQ(application_status(rig), 1);
  rig.run_ms(200);
  EXPECT_EQ(rig.gap(40), 0) << "MST after 7 s";
  rig.run_ms(1000);
  EXPECT_EQ(rig.gap(42), 0);
  EXPECT_GT(rig.gap(52), after_func2);
  EXPECT_EQ(application_status(rig), 0);
  EXPECT_EQ(stop_reason(rig), tmcl::StopReason::kStopInstruction);
}

// A host polling the actual position while Func3 runs never disturbs the program (its
// accumulator stays what the program made it).
TEST(ManualPrograms, host_polling_during_a_program_leaves_its_accumulator_alone) {
  Tmcm1636Rig rig;
  load_and_start(rig, "manual_6_4_variables.tmc");
  rig.run_ms(5);
  const int32_t accumulator = rig.command(cmd::kGetApplicationStatus, 2, 0, 0).value;
  EXPECT_EQ(accumulator, 2468);
  for (int i = 0; i < 100; ++i) {
    rig.gap(52);
    rig.command(cmd::kGgp, 42, 2, 0);
  }
  EXPECT_EQ(rig.command(cmd::kGetApplicationStatus, 2, 0, 0).value, accumulator);
}

}  // namespace
}  // namespace motwin::testing
