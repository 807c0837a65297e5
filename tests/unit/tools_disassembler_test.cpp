// The .bin format and the disassembler: asm -> bin -> disasm -> asm gives the same bytes.
#include "tools/tmcl_disassembler.h"

#include <gtest/gtest.h>

#include <filesystem>
#include <fstream>
#include <string>
#include <vector>

#include "tools/serve_process.h"
#include "tools/tmcl_assembler.h"
#include "tools/tmcl_binary.h"

namespace motwin::tools {
namespace {

const std::string kProgramsDir = MOTWIN_TEST_PROGRAMS_DIR;

std::string all_errors(const AssemblyResult& result) {
  std::string out;
  for (const AssemblyError& error : result.errors) out += format_error(error) + "\n";
  return out;
}

AssemblyResult assemble_text(const std::string& source) {
  AssemblerOptions options;
  options.reader = [](const std::string&) { return std::optional<std::string>(); };
  return assemble_source(source, "disassembled.tmc", options);
}

// --- .bin ------------------------------------------------------------------------------------

TEST(AssemblerBinary, records_are_cmd_type_motor_value_big_endian_and_checksum) {
  const BinaryRecord record = encode_binary_record({19, 2, 0, -5000});  // CALC MUL, -5000
  EXPECT_EQ(record, (BinaryRecord{0x13, 0x02, 0x00, 0xFF, 0xFF, 0xEC, 0x78, 0x77}));
  const std::vector<tmcl::Instruction> program = {{4, 1, 0, -10000}, {22, 0, 0, 0x01020304}, {28, 0, 0, 0}};
  const std::vector<uint8_t> bytes = encode_program_binary(program);
  EXPECT_EQ(bytes, (std::vector<uint8_t>{0x04, 0x01, 0x00, 0xFF, 0xFF, 0xD8, 0xF0, 0xCB,  //
                                         0x16, 0x00, 0x00, 0x01, 0x02, 0x03, 0x04, 0x20,  //
                                         0x1C, 0x00, 0x00, 0x00, 0x00, 0x00, 0x00, 0x1C}));
  const Result<std::vector<tmcl::Instruction>> decoded = decode_program_binary(bytes);
  ASSERT_TRUE(decoded) << decoded.error();
  ASSERT_EQ(decoded->size(), 3u);
  EXPECT_EQ(decoded->at(0).value, -10000);
  EXPECT_EQ(decoded->at(1).value, 0x01020304);
  EXPECT_EQ(encode_program_binary(decoded.value()), bytes);
}

TEST(AssemblerBinary, reading_checks_length_and_checksums) {
  std::vector<uint8_t> bytes = encode_program_binary(std::vector<tmcl::Instruction>{{3, 0, 0, 0}, {28, 0, 0, 0}});
  EXPECT_TRUE(decode_program_binary({}));
  const Result<std::vector<tmcl::Instruction>> truncated =
      decode_program_binary(std::span<const uint8_t>(bytes.data(), 13));
  ASSERT_FALSE(truncated);
  EXPECT_EQ(truncated.error(),
            "not a TMCL program: 13 bytes is not a multiple of 8 (one 8-byte record per instruction)");
  bytes[8 + 6] = 0x01;  // the STOP's value, checksum left as it was
  const Result<std::vector<tmcl::Instruction>> corrupt = decode_program_binary(bytes);
  ASSERT_FALSE(corrupt);
  EXPECT_EQ(corrupt.error(), "checksum error in the instruction at address 1 (byte offset 8): got 0x1C, expected 0x1D");
}

TEST(AssemblerBinary, files_round_trip_and_errors_name_the_file) {
  Result<TemporaryDirectory> directory = TemporaryDirectory::create("motwin-bin-test-");
  ASSERT_TRUE(directory) << directory.error();
  const std::string path = (directory->path() / "program.bin").string();
  const std::vector<tmcl::Instruction> program = {{1, 0, 0, 350}, {28, 0, 0, 0}};
  const Result<size_t> written = write_program_binary(path, program);
  ASSERT_TRUE(written) << written.error();
  EXPECT_EQ(written.value(), 16u);
  EXPECT_EQ(std::filesystem::file_size(path), 16u);
  const Result<std::vector<tmcl::Instruction>> read = read_program_binary(path);
  ASSERT_TRUE(read) << read.error();
  EXPECT_EQ(encode_program_binary(read.value()), encode_program_binary(program));

  std::ofstream(path, std::ios::binary | std::ios::app) << "xyz";
  const Result<std::vector<tmcl::Instruction>> bad = read_program_binary(path);
  ASSERT_FALSE(bad);
  EXPECT_EQ(bad.error(), path +
                             ": not a TMCL program: 19 bytes is not a multiple of 8 (one 8-byte record per "
                             "instruction)");
  EXPECT_FALSE(read_program_binary((directory->path() / "absent.bin").string()));
  EXPECT_FALSE(read_program_binary(directory->path().string()));
  EXPECT_FALSE(write_program_binary((directory->path() / "no/such/dir.bin").string(), program));
}

// --- Disassembly -----------------------------------------------------------------------------

TEST(AssemblerDisassembly, jump_targets_get_labels_and_the_appended_stop_is_a_comment) {
  const AssemblyResult result =
      assemble_text("Loop: MVP ABS, 0, 51200\nCSUB Sub\nJC GE, Loop\nJA 1000\nSub: VECT 0, Done\nRSUB\nDone:\n");
  ASSERT_TRUE(result.ok()) << all_errors(result);
  EXPECT_EQ(disassemble(result.instructions),
            "// 7 instructions, disassembled by motwin\n"
            "L0:\n"
            "    MVP ABS, 0, 51200                // 0\n"
            "    CSUB L4                          // 1\n"
            "    JC GE, L0                        // 2\n"
            "    JA 1000                          // 3\n"
            "L4:\n"
            "    VECT 0, L6                       // 4\n"
            "    RSUB                             // 5\n"
            "L6:\n"
            "// STOP at address 6: appended by the assembler\n");
  DisassemblyOptions plain;
  plain.address_comments = false;
  plain.omit_final_stop = false;
  EXPECT_EQ(disassemble(std::vector<tmcl::Instruction>{{22, 0, 0, 1}, {28, 0, 0, 0}}, plain),
            "// 2 instructions, disassembled by motwin\n"
            "    JA L1\n"
            "L1:\n"
            "    STOP\n");
  // A program that does not end with STOP is written out in full.
  EXPECT_EQ(disassemble(std::vector<tmcl::Instruction>{{3, 0, 0, 0}}, plain),
            "// 1 instruction, disassembled by motwin\n"
            "    MST 0\n");
}

TEST(AssemblerDisassembly, every_manual_program_round_trips_to_the_same_bytes) {
  for (const auto& entry : std::filesystem::directory_iterator(kProgramsDir)) {
    if (entry.path().extension() != ".tmc" || entry.path().filename() == "TMCLParam.tmc") continue;
    SCOPED_TRACE(entry.path().string());
    const AssemblyResult original = assemble_file(entry.path().string());
    ASSERT_TRUE(original.ok()) << all_errors(original);
    const std::vector<uint8_t> bytes = encode_program_binary(original.instructions);
    const Result<std::string> disassembled = disassemble_binary(bytes);
    ASSERT_TRUE(disassembled) << disassembled.error();
    const std::string& source = disassembled.value();
    const AssemblyResult again = assemble_text(source);
    ASSERT_TRUE(again.ok()) << all_errors(again) << source;
    EXPECT_EQ(encode_program_binary(again.instructions), bytes) << source;
  }
}

TEST(AssemblerDisassembly, corrupt_bytes_are_refused) {
  const Result<std::string> odd = disassemble_binary(std::vector<uint8_t>{1, 2, 3});
  ASSERT_FALSE(odd);
  EXPECT_EQ(odd.error(), "not a TMCL program: 3 bytes is not a multiple of 8 (one 8-byte record per instruction)");
}

TEST(AssemblerDisassembly, odd_fields_and_unknown_commands_round_trip_in_numeric_form) {
  const std::vector<tmcl::Instruction> program = {
      {3, 0, 0, 5},    // MST with a value: numeric form
      {64, 1, 2, 3},   // UF0: no mnemonic
      {22, 0, 1, 2},   // JA with a motor field: numeric form, no label
      {21, 5, 0, -1},  // JC GE, -1: outside the program
      {129, 1, 0, 0},  // a control command
      {27, 0, 0, -1},  // WAIT TICKS, 0, -1
      {28, 0, 0, 0},   // STOP in the middle
      {0, 0, 0, 0},    // NOP
      {28, 0, 0, 0},
  };
  const std::string source = disassemble(program);
  const AssemblyResult again = assemble_text(source);
  ASSERT_TRUE(again.ok()) << all_errors(again) << source;
  EXPECT_EQ(encode_program_binary(again.instructions), encode_program_binary(program)) << source;
  EXPECT_NE(source.find("    3 0 0 5 "), std::string::npos) << source;
  EXPECT_NE(source.find("    64 1 2 3 "), std::string::npos) << source;
  EXPECT_NE(source.find("    22 0 1 2 "), std::string::npos) << source;
  EXPECT_NE(source.find("    JC GE, -1 "), std::string::npos) << source;
  EXPECT_EQ(source.find("L2:"), std::string::npos) << source;
}

}  // namespace
}  // namespace motwin::tools
