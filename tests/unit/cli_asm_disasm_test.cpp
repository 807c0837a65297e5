// `motwin asm` and `motwin disasm` as a user runs them: the real binary on files in a
// temporary directory, and a scripted module for reading program memory back.
#include <gtest/gtest.h>

#include <filesystem>
#include <fstream>
#include <iterator>
#include <memory>
#include <string>
#include <vector>

#include "support/motwin_cli.h"
#include "tools/child_process.h"
#include "tools/loopback_frame_server.h"
#include "tools/serve_process.h"
#include "tools/tmcl_binary.h"

namespace motwin::tools {
namespace {

using motwin::testing::run_motwin;


const std::string kProgramsDir = MOTWIN_TEST_PROGRAMS_DIR;

bool contains(const std::string& text, std::string_view part) { return text.find(part) != std::string::npos; }

std::string read_file(const std::filesystem::path& path) {
  std::ifstream in(path, std::ios::binary);
  return {std::istreambuf_iterator<char>(in), std::istreambuf_iterator<char>()};
}

void write_file(const std::filesystem::path& path, const std::string& text) { std::ofstream(path) << text; }

class AssemblerCli : public ::testing::Test {
 protected:
  void SetUp() override {
    Result<TemporaryDirectory> created = TemporaryDirectory::create("motwin-asm-cli-");
    ASSERT_TRUE(created) << created.error();
    directory_ = std::make_unique<TemporaryDirectory>(std::move(created.value()));
  }
  std::filesystem::path path(const std::string& name) const { return directory_->path() / name; }

  std::unique_ptr<TemporaryDirectory> directory_;
};

TEST_F(AssemblerCli, assembles_a_manual_program_into_a_byte_exact_bin) {
  const std::string output = path("jump.bin").string();
  const std::string source = kProgramsDir + "/manual_6_6_jump_table.tmc";
  const CompletedProcess run = run_motwin({"asm", source, "-o", output, "--symbols", path("jump.sym").string()});
  ASSERT_EQ(run.exit_status, 0) << run.output;
  EXPECT_EQ(run.output, source + ": 17 instructions (STOP appended), 136 bytes written to " + output + "\n");
  const std::string bytes = read_file(output);
  ASSERT_EQ(bytes.size(), 136u);
  EXPECT_EQ(bytes.substr(0, 8), std::string("\x16\x00\x00\x00\x00\x00\x03\x19", 8));
  EXPECT_EQ(bytes.substr(13 * 8, 8), std::string("\x1B\x00\x00\x00\x00\x02\xBC\xD9", 8));
  const std::string symbols = read_file(path("jump.sym"));
  EXPECT_TRUE(contains(symbols, "label Func1 0 " + source + ":6\n")) << symbols;
  EXPECT_TRUE(contains(symbols, "label Func2 1 ")) << symbols;
  EXPECT_TRUE(contains(symbols, "label Func3 2 ")) << symbols;
}

TEST_F(AssemblerCli, default_output_name_include_dirs_and_listing_on_stdout) {
  write_file(path("main.tmc"), "#include params.tmc\nStart: ROR Motor0, Speed\nJA Start\n");
  std::filesystem::create_directory(path("lib"));
  write_file(path("lib/params.tmc"), "Speed = 1000\n");
  const CompletedProcess run =
      run_motwin({"asm", path("main.tmc").string(), "-I", path("lib").string(), "--listing", "-"});
  ASSERT_EQ(run.exit_status, 0) << run.output;
  EXPECT_TRUE(contains(run.output, "   0  01 00 00 00 00 03 E8 EC     2  Start: ROR Motor0, Speed\n")) << run.output;
  EXPECT_TRUE(contains(run.output, "   2  1C 00 00 00 00 00 00 1C        STOP  (appended by the assembler)\n"))
      << run.output;
  EXPECT_EQ(std::filesystem::file_size(path("main.bin")), 24u);
}

TEST_F(AssemblerCli, errors_are_file_line_column_lines_and_exit_1) {
  write_file(path("bad.tmc"), "JA Nowhere\nMST 0\n  MVX 1\nSAP 300, 0, 0\n");
  const CompletedProcess run = run_motwin({"asm", path("bad.tmc").string()});
  EXPECT_EQ(run.exit_status, 1) << run.output;
  const std::string file = path("bad.tmc").string();
  EXPECT_TRUE(contains(run.output, file + ":1:4: error: JA operand 1 (address): undefined label or constant 'Nowhere'"))
      << run.output;
  EXPECT_TRUE(contains(run.output, file + ":3:3: error: unknown mnemonic 'MVX'")) << run.output;
  EXPECT_TRUE(contains(run.output, file + ":4:5: error: SAP operand 1 (param): 300 is out of range")) << run.output;
  EXPECT_TRUE(contains(run.output, "motwin: error: 3 errors in " + file + "; nothing written\n")) << run.output;
  EXPECT_FALSE(std::filesystem::exists(path("bad.bin")));
}

TEST_F(AssemblerCli, usage_errors_exit_2) {
  const CompletedProcess missing = run_motwin({"asm", path("absent.tmc").string()});
  EXPECT_EQ(missing.exit_status, 2) << missing.output;
  EXPECT_EQ(missing.output, path("absent.tmc").string() + ": error: cannot read the file\n");
  EXPECT_EQ(run_motwin({"asm"}).exit_status, 2);
  EXPECT_EQ(run_motwin({"disasm"}).exit_status, 2);
  write_file(path("ok.tmc"), "MST 0\n");
  const CompletedProcess unwritable = run_motwin({"asm", path("ok.tmc").string(), "-o", path("no/dir.bin").string()});
  EXPECT_EQ(unwritable.exit_status, 2) << unwritable.output;
  EXPECT_TRUE(contains(unwritable.output, "motwin: error: cannot write")) << unwritable.output;
  write_file(path("source.bin"), "MST 0\n");
  const CompletedProcess overwrite = run_motwin({"asm", path("source.bin").string()});
  EXPECT_EQ(overwrite.exit_status, 2) << overwrite.output;
  EXPECT_TRUE(contains(overwrite.output, "would overwrite the source")) << overwrite.output;
  EXPECT_EQ(read_file(path("source.bin")), "MST 0\n");
  write_file(path("odd.bin"), "123456789");
  const CompletedProcess corrupt = run_motwin({"disasm", path("odd.bin").string()});
  EXPECT_EQ(corrupt.exit_status, 2) << corrupt.output;
  EXPECT_TRUE(contains(corrupt.output, "9 bytes is not a multiple of 8")) << corrupt.output;
}

TEST_F(AssemblerCli, disasm_output_assembles_to_the_same_bytes) {
  const std::string first = path("first.bin").string();
  ASSERT_EQ(run_motwin({"asm", kProgramsDir + "/manual_1_3_first_program.tmc", "-o", first}).exit_status, 0);
  const CompletedProcess disassembled = run_motwin({"disasm", first});
  ASSERT_EQ(disassembled.exit_status, 0) << disassembled.output;
  EXPECT_TRUE(contains(disassembled.output, "L12:\n    MVP ABS, 0, 0 ")) << disassembled.output;
  EXPECT_TRUE(contains(disassembled.output, "    JA L12 ")) << disassembled.output;
  write_file(path("again.tmc"), disassembled.output);
  ASSERT_EQ(run_motwin({"asm", path("again.tmc").string()}).exit_status, 0);
  EXPECT_EQ(read_file(path("again.bin")), read_file(first));
}

TEST_F(AssemblerCli, disasm_reads_a_modules_program_memory_with_134) {
  // Program memory: JA 1, STOP, then the NOP a download leaves.
  const std::vector<tmcl::Instruction> memory = {{22, 0, 0, 1}, {28, 0, 0, 0}, {0, 0, 0, 0}};
  Result<std::unique_ptr<LoopbackFrameServer>> server =
      LoopbackFrameServer::start([memory](const tmcl::Frame& request, tmcl::Frame& reply) -> size_t {
        const tmcl::Instruction in = tmcl::decode_instruction(request);
        tmcl::Reply out{100, in.command, in.value};
        if (in.command != 134 || in.value < 0 || static_cast<size_t>(in.value) >= memory.size()) {
          out.status = 4;
        } else if (in.type == 0) {
          out.command = memory[static_cast<size_t>(in.value)].command;
          out.value = memory[static_cast<size_t>(in.value)].value;
        } else {
          const tmcl::Instruction& stored = memory[static_cast<size_t>(in.value)];
          out.value = (stored.type << 8) | stored.motor_bank;
        }
        reply = tmcl::encode_reply(2, 1, out);
        return reply.size();
      });
  ASSERT_TRUE(server) << server.error();
  const CompletedProcess run = run_motwin({"disasm", "--tcp", server.value()->address(), "--no-addresses"});
  ASSERT_EQ(run.exit_status, 0) << run.output;
  EXPECT_EQ(run.output,
            "// 2 instructions, disassembled by motwin\n"
            "    JA L1\n"
            "L1:\n"
            "// STOP at address 1: appended by the assembler\n");
  const CompletedProcess counted =
      run_motwin({"disasm", "--tcp", server.value()->address(), "--count", "3", "--keep-final-stop"});
  ASSERT_EQ(counted.exit_status, 0) << counted.output;
  EXPECT_TRUE(contains(counted.output, "    0 0 0 0 ")) << counted.output;
}

}  // namespace
}  // namespace motwin::tools
