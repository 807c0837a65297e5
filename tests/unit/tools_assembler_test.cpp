// The TMCL assembler: every example program of the TMCM-1636 manual (and the TMCM-142's
// test2.tmc) assembles to the expected instructions and labels; a reference program is
// byte-exact; each kind of bad input gets its error with file, line and column.
#include "tools/tmcl_assembler.h"

#include <gtest/gtest.h>

#include <map>
#include <stdexcept>
#include <string>
#include <vector>

#include "tools/tmcl_binary.h"
#include "tools/tmcl_client.h"

namespace motwin::tools {
namespace {

const std::string kProgramsDir = MOTWIN_TEST_PROGRAMS_DIR;

std::string program_path(const std::string& name) { return kProgramsDir + "/" + name; }

// Sources from memory: tests need no files.
SourceReader memory_reader(std::map<std::string, std::string> files) {
  return [files = std::move(files)](const std::string& path) -> std::optional<std::string> {
    const auto found = files.find(path);
    if (found == files.end()) return std::nullopt;
    return found->second;
  };
}

AssemblyResult assemble_memory(std::string_view source, std::map<std::string, std::string> includes = {},
                               AssemblerOptions options = {}) {
  options.reader = memory_reader(std::move(includes));
  return assemble_source(source, "main.tmc", options);
}

std::string all_errors(const AssemblyResult& result) {
  std::string out;
  for (const AssemblyError& error : result.errors) out += format_error(error) + "\n";
  return out;
}

// The .bin bytes as "CC TT MM V3 V2 V1 V0 CK" per instruction, one per line.
std::string binary_lines(const std::vector<tmcl::Instruction>& instructions) {
  std::string out;
  for (const tmcl::Instruction& instruction : instructions) {
    const BinaryRecord record = encode_binary_record(instruction);
    out += hex_bytes(record.data(), record.size()) + "\n";
  }
  return out;
}

// Asserts a single error and its location.
void expect_single_error(const AssemblyResult& result, AssemblyErrorKind kind, const std::string& file, int line,
                         int column, const std::string& message) {
  ASSERT_EQ(result.errors.size(), 1u) << all_errors(result);
  const AssemblyError& error = result.errors.front();
  EXPECT_EQ(error.kind, kind) << all_errors(result);
  EXPECT_EQ(error.location.file, file);
  EXPECT_EQ(error.location.line, line);
  EXPECT_EQ(error.location.column, column);
  EXPECT_EQ(error.message, message);
}

constexpr tmcl::Instruction kStop{28, 0, 0, 0};

// --- The manual's example programs ---------------------------------------------------------

struct ManualProgram {
  const char* file;
  size_t instructions;  // with the appended STOP
  std::vector<std::pair<const char*, uint32_t>> labels;
};

TEST(AssemblerManualExamples, every_example_program_assembles) {
  const std::vector<ManualProgram> programs = {
      {"manual_1_3_first_program.tmc", 18, {{"PositionTest", 12}}},
      {"manual_2_6_16_comp_jc.tmc", 5, {{"Label", 3}}},
      {"manual_2_6_18_ja_loop.tmc", 6, {{"Loop", 0}}},
      {"manual_2_6_19_csub_rsub.tmc", 9, {{"Loop", 0}, {"SubW", 5}}},
      {"manual_2_6_24_aap_potentiometer.tmc", 5, {{"Start", 0}}},
      {"manual_6_2_main_loop.tmc", 8, {{"MainLoop", 2}}},
      {"manual_6_3_symbolic_constants.tmc", 8, {{"MainLoop", 2}}},
      {"manual_6_4_variables.tmc", 5, {}},
      {"manual_6_6_jump_table.tmc", 17, {{"Func1", 0}, {"Func2", 1}, {"Func3", 2}}},
      {"tmcm142_5_2_test2.tmc", 14, {{"Loop", 8}}},
  };
  for (const ManualProgram& program : programs) {
    SCOPED_TRACE(program.file);
    const AssemblyResult result = assemble_file(program_path(program.file));
    ASSERT_TRUE(result.ok()) << all_errors(result);
    EXPECT_EQ(result.instructions.size(), program.instructions);
    EXPECT_EQ(result.instructions.back().command, kStop.command);
    for (const auto& [name, address] : program.labels) EXPECT_EQ(result.label_address(name), address) << name;
  }
}

TEST(AssemblerManualExamples, jump_table_of_6_6_is_byte_exact) {
  const AssemblyResult result = assemble_file(program_path("manual_6_6_jump_table.tmc"));
  ASSERT_TRUE(result.ok()) << all_errors(result);
  EXPECT_EQ(result.label_address("Func1"), 0u);
  EXPECT_EQ(result.label_address("Func2"), 1u);
  EXPECT_EQ(result.label_address("Func3"), 2u);
  EXPECT_EQ(result.label_address("Func1Start"), 3u);
  EXPECT_EQ(result.label_address("Func2Start"), 8u);
  EXPECT_EQ(result.label_address("Func3Start"), 12u);
  // Worked out by hand: cmd type motor value(big-endian) and the 8-bit sum of those 7 bytes.
  EXPECT_EQ(binary_lines(result.instructions),
            "16 00 00 00 00 00 03 19\n"    //  0 Func1: JA Func1Start (3)
            "16 00 00 00 00 00 08 1E\n"    //  1 Func2: JA Func2Start (8)
            "16 00 00 00 00 00 0C 22\n"    //  2 Func3: JA Func3Start (12)
            "04 00 00 00 00 03 E8 EF\n"    //  3 MVP ABS, 0, 1000
            "1B 01 00 00 00 00 00 1C\n"    //  4 WAIT POS, 0, 0
            "04 00 00 00 00 00 00 04\n"    //  5 MVP ABS, 0, 0
            "1B 01 00 00 00 00 00 1C\n"    //  6 WAIT POS, 0, 0
            "1C 00 00 00 00 00 00 1C\n"    //  7 STOP
            "02 00 00 00 00 01 F4 F7\n"    //  8 ROL 0, 500
            "1B 00 00 00 00 00 64 7F\n"    //  9 WAIT TICKS, 0, 100
            "03 00 00 00 00 00 00 03\n"    // 10 MST 0
            "1C 00 00 00 00 00 00 1C\n"    // 11 STOP
            "01 00 00 00 00 03 E8 EC\n"    // 12 ROR 0, 1000
            "1B 00 00 00 00 02 BC D9\n"    // 13 WAIT TICKS, 0, 700
            "03 00 00 00 00 00 00 03\n"    // 14 MST 0
            "1C 00 00 00 00 00 00 1C\n"    // 15 STOP
            "1C 00 00 00 00 00 00 1C\n");  // 16 STOP appended by the assembler
  const std::vector<uint8_t> bytes = encode_program_binary(result.instructions);
  ASSERT_EQ(bytes.size(), 17u * 8u);
  EXPECT_EQ(bytes[8 * 13 + 5], 0x02);
  EXPECT_EQ(bytes[8 * 13 + 6], 0xBC);
}

TEST(AssemblerManualExamples, potentiometer_and_negative_values_are_byte_exact) {
  const AssemblyResult potentiometer = assemble_file(program_path("manual_2_6_24_aap_potentiometer.tmc"));
  ASSERT_TRUE(potentiometer.ok()) << all_errors(potentiometer);
  EXPECT_EQ(binary_lines(potentiometer.instructions),
            "0F 00 01 00 00 00 00 10\n"    // GIO 0,1
            "13 02 00 00 00 00 04 19\n"    // CALC MUL, 4
            "22 00 00 00 00 00 00 22\n"    // AAP 0,0 (the manual's frame with address 1: checksum 23)
            "16 00 00 00 00 00 00 16\n"    // JA Start
            "1C 00 00 00 00 00 00 1C\n");  // STOP
  // The manual's CALC MUL, -5000 frame (01 13 02 00 FF FF EC 78, checksum 78) without the address.
  const AssemblyResult calc = assemble_memory("CALC MUL, -5000\nMVP REL, Motor0, -1000000\n");
  ASSERT_TRUE(calc.ok()) << all_errors(calc);
  EXPECT_EQ(binary_lines(calc.instructions),
            "13 02 00 FF FF EC 78 77\n"
            "04 01 00 FF F0 BD C0 71\n"
            "1C 00 00 00 00 00 00 1C\n");
}

TEST(AssemblerManualExamples, symbolic_constants_of_6_3_with_a_tmclparam_stand_in) {
  // The TMCL-IDE's TMCLParam.tmc numbers (older modules): speed 4, acceleration 5. It repeats the
  // built-in Motor0..Motor5, which is allowed.
  const std::string tmcl_param =
      "//Definitions of axis numbers\n"
      "Motor0 = 0\nMotor1 = 1\nMotor2 = 2\nMotor3 = 3\nMotor4 = 4\nMotor5 = 5\n"
      "APMaxPositioningSpeed = 4      //Maximum speed in position mode\n"
      "APMaxAcceleration = 5          //Maximum acceleration/deceleration\n"
      "APVMixedDecayPermanent = -1\n";
  AssemblerOptions options;
  options.reader = memory_reader({{"TMCLParam.tmc", tmcl_param}});
  const AssemblyResult result =
      assemble_source(*file_system_reader()(program_path("manual_6_3_symbolic_constants.tmc")), "main.tmc", options);
  ASSERT_TRUE(result.ok()) << all_errors(result);
  const std::vector<tmcl::Instruction> expected = {
      {5, 4, 0, 50000}, {5, 5, 0, 10000}, {4, 0, 0, 500000}, {27, 1, 0, 0},
      {4, 0, 0, 0},     {27, 1, 0, 0},    {22, 0, 0, 2},     kStop,
  };
  ASSERT_EQ(result.instructions.size(), expected.size());
  for (size_t i = 0; i < expected.size(); ++i) {
    EXPECT_EQ(encode_binary_record(result.instructions[i]), encode_binary_record(expected[i])) << i;
  }
  const SymbolDefinition* speed = result.find_symbol("APMaxPositioningSpeed");
  ASSERT_NE(speed, nullptr);
  EXPECT_EQ(speed->kind, SymbolKind::kConstant);
  EXPECT_EQ(speed->value, 4);
  EXPECT_EQ(speed->location.file, "TMCLParam.tmc");
  EXPECT_EQ(speed->location.line, 8);

  // The stand-in next to the test programs has the TMCM-1636's numbers (43, 44).
  const AssemblyResult on_disk = assemble_file(program_path("manual_6_3_symbolic_constants.tmc"));
  ASSERT_TRUE(on_disk.ok()) << all_errors(on_disk);
  EXPECT_EQ(on_disk.instructions[0].type, 43);
  EXPECT_EQ(on_disk.instructions[1].type, 44);
}

TEST(AssemblerManualExamples, variables_of_6_4_use_the_constant_as_parameter_number) {
  const AssemblyResult result = assemble_file(program_path("manual_6_4_variables.tmc"));
  ASSERT_TRUE(result.ok()) << all_errors(result);
  EXPECT_EQ(binary_lines(result.instructions),
            "09 2A 02 00 00 04 D2 0B\n"  // SGP 42, 2, 1234
            "0A 2A 02 00 00 00 00 36\n"  // GGP 42, 2
            "13 02 00 00 00 00 02 17\n"  // CALC MUL, 2
            "23 2A 02 00 00 00 00 4F\n"  // AGP 42, 2 (the manual's frame with address 1: checksum 50)
            "1C 00 00 00 00 00 00 1C\n");
}

TEST(AssemblerManualExamples, first_program_of_1_3) {
  const AssemblyResult result = assemble_file(program_path("manual_1_3_first_program.tmc"));
  ASSERT_TRUE(result.ok()) << all_errors(result);
  EXPECT_EQ(encode_binary_record(result.instructions[0]), encode_binary_record({5, 5, 0, 33911}));
  EXPECT_EQ(encode_binary_record(result.instructions[8]), encode_binary_record({27, 0, 0, 300}));
  EXPECT_EQ(encode_binary_record(result.instructions[14]), encode_binary_record({4, 0, 0, 655360}));
  EXPECT_EQ(encode_binary_record(result.instructions[16]), encode_binary_record({22, 0, 0, 12}));
}

// --- Syntax --------------------------------------------------------------------------------

TEST(AssemblerSyntax, labels_alone_or_before_an_instruction_and_used_before_definition) {
  const AssemblyResult result = assemble_memory(
      "  JA Later          // forward reference\n"
      "First:\n"
      "Second: Third: ROL 0, 100\n"
      "Later:MST 0\n"
      "  JC EQ, first     // names are case-insensitive\n"
      "End:\n");
  ASSERT_TRUE(result.ok()) << all_errors(result);
  EXPECT_EQ(result.label_address("First"), 1u);
  EXPECT_EQ(result.label_address("Second"), 1u);
  EXPECT_EQ(result.label_address("THIRD"), 1u);
  EXPECT_EQ(result.label_address("Later"), 2u);
  EXPECT_EQ(result.label_address("End"), 4u);  // the appended STOP
  ASSERT_EQ(result.instructions.size(), 5u);
  EXPECT_EQ(result.instructions[0].value, 2);
  EXPECT_EQ(result.instructions[3].type, 2);
  EXPECT_EQ(result.instructions[3].value, 1);
  EXPECT_EQ(result.instructions[4].command, kStop.command);
}

TEST(AssemblerSyntax, constants_numbers_comments_and_line_endings) {
  const AssemblyResult result = assemble_memory(
      "// header comment\r\n"
      "Speed = 0x1F40\r\n"
      "Negative=-5\r\n"
      "Alias = Speed      // a constant may name a constant defined above\r\n"
      "\t\r\n"
      "ROR Motor1, Alias\r\n"
      "CALC ADD Negative\r\n"
      "SAP 4 0 4294967295\r\n"
      "129 1 0 7          // the numeric form CMD TYPE MOTOR VALUE\r\n"
      "WAIT TICKS,0,-1");
  ASSERT_TRUE(result.ok()) << all_errors(result);
  EXPECT_EQ(binary_lines(result.instructions),
            "01 00 01 00 00 1F 40 61\n"
            "13 00 00 FF FF FF FB 0B\n"
            "05 04 00 FF FF FF FF 05\n"
            "81 01 00 00 00 00 07 89\n"
            "1B 00 00 FF FF FF FF 17\n"
            "1C 00 00 00 00 00 00 1C\n");
}

TEST(AssemblerSyntax, a_utf8_byte_order_mark_is_skipped) {
  const AssemblyResult result = assemble_memory("\xEF\xBB\xBFStart: JA Start\n");
  ASSERT_TRUE(result.ok()) << all_errors(result);
  EXPECT_EQ(result.label_address("Start"), 0u);
}

TEST(AssemblerSyntax, every_symbolic_operand_of_the_code_tables) {
  const AssemblyResult result = assemble_memory(
      "MVP COORD, 0, 3\nRFS STATUS, 0\nCALC LOAD, 1\nCALCX SWAP\nJC ESD, 0\nJC ETO, 0\n"
      "WAIT RFS, 0, 100\nWAIT LIMSW, 0, 0\nCLE EPO\nVECT 1, Handler\nEI 255\nHandler: RETI\n");
  ASSERT_TRUE(result.ok()) << all_errors(result);
  const std::vector<std::pair<uint8_t, uint8_t>> command_and_type = {
      {4, 2}, {13, 2}, {19, 9}, {33, 10}, {21, 12}, {21, 8}, {27, 4}, {27, 3}, {36, 4}, {37, 1}, {25, 255}, {38, 0}};
  for (size_t i = 0; i < command_and_type.size(); ++i) {
    EXPECT_EQ(result.instructions[i].command, command_and_type[i].first) << i;
    EXPECT_EQ(result.instructions[i].type, command_and_type[i].second) << i;
  }
  EXPECT_EQ(result.instructions[9].value, 11);  // VECT 1, Handler
}

TEST(AssemblerSyntax, an_operand_symbol_wins_over_a_constant_of_the_same_name) {
  const AssemblyResult result = assemble_memory("POS = 7\nWAIT POS, 0, POS\n");
  ASSERT_TRUE(result.ok()) << all_errors(result);
  EXPECT_EQ(result.instructions[0].type, 1);   // WAIT's POS
  EXPECT_EQ(result.instructions[0].value, 7);  // the constant
}

TEST(AssemblerSyntax, stop_is_appended_unless_disabled) {
  AssemblerOptions options;
  options.append_stop = false;
  const AssemblyResult without = assemble_memory("MST 0\n", {}, options);
  ASSERT_TRUE(without.ok());
  EXPECT_EQ(without.instructions.size(), 1u);
  const AssemblyResult empty = assemble_memory("// nothing\n");
  ASSERT_TRUE(empty.ok());
  ASSERT_EQ(empty.instructions.size(), 1u);
  EXPECT_EQ(empty.instructions[0].command, kStop.command);
}

// --- Includes --------------------------------------------------------------------------------

TEST(AssemblerIncludes, relative_to_the_including_file_then_the_include_dirs) {
  AssemblerOptions options;
  options.include_dirs = {"inc", "other"};
  options.reader = memory_reader({
      {"src/main.tmc", "#include lib/a.tmc\nJA InA\n"},
      {"src/lib/a.tmc", "#include \"b.tmc\"\nInA: ROR Motor0, FromB\n"},
      {"src/lib/b.tmc", "#include <common.tmc>\nFromB = 300\n"},
      {"inc/common.tmc", "Common = 1\n"},
      {"other/common.tmc", "Common = 2\n"},  // shadowed by inc/
  });
  const AssemblyResult result = assemble_file("src/main.tmc", options);
  ASSERT_TRUE(result.ok()) << all_errors(result);
  ASSERT_EQ(result.instructions.size(), 3u);
  EXPECT_EQ(result.instructions[0].value, 300);
  EXPECT_EQ(result.instructions[1].value, 0);
  EXPECT_EQ(result.find_symbol("Common")->value, 1);
  EXPECT_EQ(result.find_symbol("Common")->location.file, "inc/common.tmc");
  EXPECT_EQ(result.find_symbol("InA")->location.file, "src/lib/a.tmc");
  // The listing expands the includes in place.
  ASSERT_EQ(result.listing.size(), 8u);
  EXPECT_EQ(result.listing[1].location.file, "src/lib/a.tmc");
  EXPECT_EQ(result.listing[2].location.file, "src/lib/b.tmc");
  EXPECT_EQ(result.listing[3].location.file, "inc/common.tmc");
  EXPECT_EQ(result.listing[6].location.file, "src/main.tmc");
  EXPECT_EQ(result.listing[6].address, 1u);
}

TEST(AssemblerIncludes, a_file_included_twice_may_repeat_its_constants) {
  const AssemblyResult result = assemble_memory("#include k.tmc\n#include k.tmc\nMST K\n", {{"k.tmc", "K = 1\n"}});
  ASSERT_TRUE(result.ok()) << all_errors(result);
  EXPECT_EQ(result.instructions[0].motor_bank, 1);
}

TEST(AssemblerIncludes, include_not_found_names_the_searched_paths) {
  AssemblerOptions options;
  options.include_dirs = {"inc"};
  const AssemblyResult result = assemble_memory("MST 0\n#include   Missing.tmc // gone\n", {}, options);
  expect_single_error(result, AssemblyErrorKind::kIncludeNotFound, "main.tmc", 2, 12,
                      "include file 'Missing.tmc' not found (searched Missing.tmc, inc/Missing.tmc)");
  EXPECT_EQ(format_error(result.errors[0]),
            "main.tmc:2:12: error: include file 'Missing.tmc' not found (searched Missing.tmc, inc/Missing.tmc)");
  const AssemblyResult without_dirs = assemble_memory("#include Missing.tmc\n");
  ASSERT_EQ(without_dirs.errors.size(), 1u);
  EXPECT_EQ(without_dirs.errors[0].message,
            "include file 'Missing.tmc' not found (searched Missing.tmc; add a directory with -I)");
}

TEST(AssemblerIncludes, include_cycle_names_the_chain) {
  const AssemblyResult result = assemble_memory("#include a.tmc\n", {
                                                                        {"a.tmc", "// a\n#include b.tmc\n"},
                                                                        {"b.tmc", "MST 0\n  #include main.tmc\n"},
                                                                    });
  expect_single_error(result, AssemblyErrorKind::kIncludeCycle, "b.tmc", 2, 12,
                      "include cycle: main.tmc -> a.tmc -> b.tmc -> main.tmc");
  const AssemblyResult self = assemble_memory("#include main.tmc\n");
  expect_single_error(self, AssemblyErrorKind::kIncludeCycle, "main.tmc", 1, 10, "include cycle: main.tmc -> main.tmc");
}

// --- Errors: one test per kind ---------------------------------------------------------------

TEST(AssemblerErrors, unknown_mnemonic) {
  expect_single_error(assemble_memory("MST 0\n  MVX ABS, 0, 1\n"), AssemblyErrorKind::kUnknownMnemonic, "main.tmc", 2,
                      3,
                      "unknown mnemonic 'MVX': expected a TMCL mnemonic (such as MVP, SAP, GAP) or a command number");
  // After a label the column still points at the mnemonic.
  expect_single_error(assemble_memory("Here: FOO 1\n"), AssemblyErrorKind::kUnknownMnemonic, "main.tmc", 1, 7,
                      "unknown mnemonic 'FOO': expected a TMCL mnemonic (such as MVP, SAP, GAP) or a command number");
}

TEST(AssemblerErrors, undefined_label_or_constant) {
  expect_single_error(assemble_memory("Loop: MST 0\nJA  Nowhere\n"), AssemblyErrorKind::kUndefinedSymbol, "main.tmc", 2,
                      5,
                      "JA operand 1 (address): undefined label or constant 'Nowhere', expected a number, a label or a "
                      "constant");
  expect_single_error(assemble_memory("MVP ABX, 0, 1\n"), AssemblyErrorKind::kUndefinedSymbol, "main.tmc", 1, 5,
                      "MVP operand 1 (ABS|REL|COORD): undefined label or constant 'ABX', expected ABS, REL, COORD, a "
                      "number, a label or a constant");
  // A close name is suggested.
  expect_single_error(assemble_memory("JC GE, Lop\nLoop: MST 0\n"), AssemblyErrorKind::kUndefinedSymbol, "main.tmc", 1,
                      8,
                      "JC operand 2 (address): undefined label or constant 'Lop', expected a number, a label or a "
                      "constant; did you mean 'Loop'?");
  // A constant's value may only name what is defined above it.
  expect_single_error(assemble_memory("A = B\nB = 1\n"), AssemblyErrorKind::kUndefinedSymbol, "main.tmc", 1, 5,
                      "undefined label or constant 'B': the value of a constant is a number or a name defined above");
}

TEST(AssemblerErrors, duplicate_label) {
  expect_single_error(assemble_memory("Loop: MST 0\nMST 0\n loop:\n"), AssemblyErrorKind::kDuplicateSymbol, "main.tmc",
                      3, 2, "duplicate label 'loop': already a label (address 0, defined at main.tmc:1:1)");
}

TEST(AssemblerErrors, duplicate_constant) {
  expect_single_error(assemble_memory("Speed = 1\nSpeed = 1\nSpeed = 2\n"), AssemblyErrorKind::kDuplicateSymbol,
                      "main.tmc", 3, 1,
                      "duplicate constant 'Speed': already a constant (1, defined at main.tmc:1:1); a constant may "
                      "only be repeated with the same value");
  expect_single_error(assemble_memory("Motor0 = 0\nMotor1 = 7\n"), AssemblyErrorKind::kDuplicateSymbol, "main.tmc", 2,
                      1,
                      "duplicate constant 'Motor1': already a constant (1, built in); a constant may only be "
                      "repeated with the same value");
  expect_single_error(assemble_memory("Speed = 1\nSpeed: MST 0\n"), AssemblyErrorKind::kDuplicateSymbol, "main.tmc", 2,
                      1, "duplicate label 'Speed': already a constant (1, defined at main.tmc:1:1)");
}

TEST(AssemblerErrors, operand_out_of_range) {
  expect_single_error(assemble_memory("SAP 256, 0, 1\n"), AssemblyErrorKind::kOutOfRange, "main.tmc", 1, 5,
                      "SAP operand 1 (param): 256 is out of range for the byte field type (0..255)");
  expect_single_error(assemble_memory("Big = 300\nGAP 1, Big\n"), AssemblyErrorKind::kOutOfRange, "main.tmc", 2, 8,
                      "GAP operand 2 (motor): 300 is out of range for the byte field motor/bank (0..255)");
  expect_single_error(assemble_memory("ROR 0, 4294967296\n"), AssemblyErrorKind::kOutOfRange, "main.tmc", 1, 8,
                      "ROR operand 2 (velocity): 4294967296 is out of range for the 32-bit value field "
                      "(-2147483648..4294967295)");
  expect_single_error(assemble_memory("Huge = -2147483649\n"), AssemblyErrorKind::kOutOfRange, "main.tmc", 1, 8,
                      "constant 'Huge': -2147483649 is out of range for a 32-bit value (-2147483648..4294967295)");
}

TEST(AssemblerErrors, wrong_operand_count) {
  expect_single_error(assemble_memory("MVP ABS, 0\n"), AssemblyErrorKind::kOperandCount, "main.tmc", 1, 11,
                      "MVP takes 3 operands (ABS|REL|COORD, motor, value), got 2");
  expect_single_error(assemble_memory("RSUB 1 // no operands\n"), AssemblyErrorKind::kOperandCount, "main.tmc", 1, 6,
                      "RSUB takes no operands, got 1");
  expect_single_error(assemble_memory("GAP 1, 0, 5\n"), AssemblyErrorKind::kOperandCount, "main.tmc", 1, 11,
                      "GAP takes 2 operands (param, motor), got 3");
}

TEST(AssemblerErrors, program_longer_than_program_memory) {
  AssemblerOptions options;
  options.program_memory_size = 4;
  // The fifth instruction does not fit.
  expect_single_error(assemble_memory("MST 0\nMST 0\nMST 0\n\nMST 0\n  MST 0\nMST 0\n", {}, options),
                      AssemblyErrorKind::kProgramTooLong, "main.tmc", 6, 3,
                      "the program needs 7 instructions (with the STOP appended at its end), but program memory "
                      "holds 4");
  // Only the appended STOP does not fit: the error points at the last line.
  expect_single_error(assemble_memory("MST 0\nMST 0\nMST 0\nMST 0\n// end\n", {}, options),
                      AssemblyErrorKind::kProgramTooLong, "main.tmc", 5, 0,
                      "the program needs 5 instructions (with the STOP appended at its end), but program memory "
                      "holds 4");
  EXPECT_TRUE(assemble_memory("MST 0\nMST 0\nMST 0\n", {}, options).ok());
  // The default is 2048.
  std::string long_program;
  for (int i = 0; i < 2048; ++i) long_program += "MST 0\n";
  const AssemblyResult too_long = assemble_memory(long_program);
  ASSERT_EQ(too_long.errors.size(), 1u);
  EXPECT_EQ(too_long.errors[0].kind, AssemblyErrorKind::kProgramTooLong);
  EXPECT_EQ(too_long.errors[0].message,
            "the program needs 2049 instructions (with the STOP appended at its end), but program memory holds 2048");
}

TEST(AssemblerErrors, syntax_errors) {
  expect_single_error(assemble_memory("X = 1 + 2\n"), AssemblyErrorKind::kSyntax, "main.tmc", 1, 5,
                      "expected one number or name after 'X =', got '1 + 2' (expressions are not supported)");
  expect_single_error(assemble_memory("#define X 1\n"), AssemblyErrorKind::kSyntax, "main.tmc", 1, 1,
                      "unknown directive '#define': expected #include");
  expect_single_error(assemble_memory("GAP 5x, 0\n"), AssemblyErrorKind::kSyntax, "main.tmc", 1, 5,
                      "GAP operand 1 (param): '5x' is not a number (decimal or 0x hexadecimal, at most 64 bits)");
  expect_single_error(assemble_memory("1st = 4\n"), AssemblyErrorKind::kSyntax, "main.tmc", 1, 1,
                      "expected 'Name = value' (a name is a letter or '_' followed by letters, digits or '_')");
  expect_single_error(assemble_memory("Empty =\n"), AssemblyErrorKind::kSyntax, "main.tmc", 1, 7,
                      "expected a value after 'Empty ='");
  expect_single_error(assemble_memory("L: X = 1\n"), AssemblyErrorKind::kSyntax, "main.tmc", 1, 1,
                      "a label must be followed by an instruction, not by a constant definition");
  expect_single_error(assemble_memory("GAP 52,,0\n"), AssemblyErrorKind::kSyntax, "main.tmc", 1, 8,
                      "empty operand after '52'");
  expect_single_error(assemble_memory("#include\n"), AssemblyErrorKind::kSyntax, "main.tmc", 1, 9,
                      "expected a file name after #include");
}

TEST(AssemblerErrors, every_error_is_collected_in_source_order) {
  const AssemblyResult result = assemble_memory(
      "JA Missing\n"
      "#include nope.tmc\n"
      "Dup: MST 0\n"
      "Dup: FOO\n"
      "SAP 1, 2\n"
      "GAP 1, 999\n");
  EXPECT_EQ(all_errors(result),
            "main.tmc:1:4: error: JA operand 1 (address): undefined label or constant 'Missing', expected a number, "
            "a label or a constant\n"
            "main.tmc:2:10: error: include file 'nope.tmc' not found (searched nope.tmc; add a directory with -I)\n"
            "main.tmc:4:1: error: duplicate label 'Dup': already a label (address 1, defined at main.tmc:3:1)\n"
            "main.tmc:4:6: error: unknown mnemonic 'FOO': expected a TMCL mnemonic (such as MVP, SAP, GAP) or a "
            "command number\n"
            "main.tmc:5:9: error: SAP takes 3 operands (param, motor, value), got 2\n"
            "main.tmc:6:8: error: GAP operand 2 (motor): 999 is out of range for the byte field motor/bank (0..255)\n");
}

TEST(AssemblerErrors, unreadable_main_file_and_throwing_reader) {
  AssemblerOptions options;
  options.reader = memory_reader({});
  const AssemblyResult missing = assemble_file("absent.tmc", options);
  expect_single_error(missing, AssemblyErrorKind::kFileNotFound, "absent.tmc", 0, 0, "cannot read the file");
  EXPECT_EQ(format_error(missing.errors[0]), "absent.tmc: error: cannot read the file");

  options.reader = [](const std::string&) -> std::optional<std::string> { throw std::runtime_error("disk on fire"); };
  const AssemblyResult thrown = assemble_source("#include x.tmc\n", "main.tmc", options);
  expect_single_error(thrown, AssemblyErrorKind::kInternal, "main.tmc", 0, 0, "internal error: disk on fire");
  EXPECT_TRUE(assemble_file(program_path("does_not_exist.tmc")).errors.size() == 1);
}

// --- Listing and symbols ---------------------------------------------------------------------

TEST(AssemblerListing, shows_addresses_bytes_lines_and_include_boundaries) {
  const AssemblyResult result = assemble_memory(
      "// jump table\n#include k.tmc\nFunc1: JA Start\nStart: ROR Motor0, Speed\n", {{"k.tmc", "Speed = 1000\n"}});
  ASSERT_TRUE(result.ok()) << all_errors(result);
  EXPECT_EQ(format_listing(result),
            "ADDR  BYTES                    LINE  SOURCE\n"
            "                                     === main.tmc ===\n"
            "                                  1  // jump table\n"
            "                                  2  #include k.tmc\n"
            "                                     === k.tmc ===\n"
            "                                  1  Speed = 1000\n"
            "                                     === main.tmc ===\n"
            "   0  16 00 00 00 00 00 01 17     3  Func1: JA Start\n"
            "   1  01 00 00 00 00 03 E8 EC     4  Start: ROR Motor0, Speed\n"
            "   2  1C 00 00 00 00 00 00 1C        STOP  (appended by the assembler)\n");
  EXPECT_EQ(format_symbols(result),
            "label Func1 0 main.tmc:3\n"
            "label Start 1 main.tmc:4\n"
            "constant Speed 1000 k.tmc:1\n");
}

}  // namespace
}  // namespace motwin::tools
