// Download (132, instructions answered 101, trailing NOP, 133) and read-back (134) against a
// scripted module on 127.0.0.1 that keeps a program memory and answers 134 with Motwin's
// layout (docs/assembler.md): type 0 -> command byte = stored opcode, value = stored value;
// type 1 -> value = (type << 8) | motor.
#include "tools/program_transfer.h"

#include <gtest/gtest.h>

#include <memory>
#include <mutex>
#include <string>
#include <vector>

#include "tools/loopback_frame_server.h"
#include "tools/tmcl_assembler.h"
#include "tools/tmcl_binary.h"

namespace motwin::tools {
namespace {

class FakeProgramModule {
 public:
  explicit FakeProgramModule(size_t capacity = 16) : memory_(capacity) {
    Result<std::unique_ptr<LoopbackFrameServer>> started = LoopbackFrameServer::start(
        [this](const tmcl::Frame& request, tmcl::Frame& reply) { return answer(request, reply); });
    EXPECT_TRUE(started) << (started ? "" : started.error());
    if (started) server_ = std::move(started.value());
  }

  TmclClient connect() {
    Result<TmclClient> client = TmclClient::connect_tcp(server_->address());
    EXPECT_TRUE(client) << (client ? "" : client.error());
    return std::move(client.value());
  }
  std::vector<tmcl::Instruction> requests() {
    std::lock_guard lock(mutex_);
    return requests_;
  }
  std::vector<tmcl::Instruction> memory() {
    std::lock_guard lock(mutex_);
    return memory_;
  }
  void set_memory(std::vector<tmcl::Instruction> memory) {
    std::lock_guard lock(mutex_);
    memory_ = std::move(memory);
  }
  // Answers a stored instruction with this command with status 4 (invalid value).
  void refuse_command(uint8_t command) {
    std::lock_guard lock(mutex_);
    refused_command_ = command;
  }

 private:
  size_t answer(const tmcl::Frame& request, tmcl::Frame& reply) {
    std::lock_guard lock(mutex_);
    const tmcl::Instruction in = tmcl::decode_instruction(request);
    requests_.push_back(in);
    tmcl::Reply out{100, in.command, in.value};
    if (in.command == 132) {
      download_mode_ = true;
      pointer_ = static_cast<size_t>(in.value);
    } else if (in.command == 133) {
      download_mode_ = false;
    } else if (in.command == 134) {
      const auto address = static_cast<size_t>(in.value);
      if (address >= memory_.size()) {
        out.status = 4;
      } else if (in.type == 0) {
        out.command = memory_[address].command;
        out.value = memory_[address].value;
      } else {
        out.value = (memory_[address].type << 8) | memory_[address].motor_bank;
      }
    } else if (download_mode_ && in.command < 128) {
      if (pointer_ >= memory_.size() || in.command == refused_command_) {
        out.status = 4;
      } else {
        memory_[pointer_++] = in;
        out.status = 101;
      }
    }
    reply = tmcl::encode_reply(2, 1, out);
    return reply.size();
  }

  std::mutex mutex_;
  std::vector<tmcl::Instruction> memory_;
  std::vector<tmcl::Instruction> requests_;
  bool download_mode_ = false;
  size_t pointer_ = 0;
  int refused_command_ = -1;
  std::unique_ptr<LoopbackFrameServer> server_;
};

std::vector<uint8_t> bytes_of(const std::vector<tmcl::Instruction>& program) { return encode_program_binary(program); }

TEST(AssemblerProgramTransfer, download_sends_132_each_instruction_a_nop_and_133) {
  FakeProgramModule module;
  TmclClient client = module.connect();
  const std::vector<tmcl::Instruction> program = {{22, 0, 0, 2}, {5, 4, 0, 50000}, {28, 0, 0, 0}};
  const Result<size_t> downloaded = download_program(client, program, 3);
  ASSERT_TRUE(downloaded) << downloaded.error();
  EXPECT_EQ(downloaded.value(), 3u);
  const std::vector<tmcl::Instruction> expected_requests = {{132, 0, 0, 3}, {22, 0, 0, 2}, {5, 4, 0, 50000},
                                                            {28, 0, 0, 0},  {0, 0, 0, 0},  {133, 0, 0, 0}};
  EXPECT_EQ(bytes_of(module.requests()), bytes_of(expected_requests));
  const std::vector<tmcl::Instruction> memory = module.memory();
  EXPECT_EQ(bytes_of({memory[3], memory[4], memory[5], memory[6]}),
            bytes_of({{22, 0, 0, 2}, {5, 4, 0, 50000}, {28, 0, 0, 0}, {0, 0, 0, 0}}));
}

TEST(AssemblerProgramTransfer, read_back_uses_both_134_types) {
  FakeProgramModule module;
  module.set_memory({{4, 1, 0, -10000}, {35, 42, 2, 0}, {21, 12, 0, 7}, {28, 0, 0, 0}, {0, 0, 0, 0}});
  TmclClient client = module.connect();
  const Result<std::vector<tmcl::Instruction>> read = read_program(client, 1, 2);
  ASSERT_TRUE(read) << read.error();
  EXPECT_EQ(bytes_of(read.value()), bytes_of({{35, 42, 2, 0}, {21, 12, 0, 7}}));
  EXPECT_EQ(bytes_of(module.requests()), bytes_of({{134, 0, 0, 1}, {134, 1, 0, 1}, {134, 0, 0, 2}, {134, 1, 0, 2}}));

  // Up to the NOP that ends a download; or to the end of memory.
  const Result<std::vector<tmcl::Instruction>> stored = read_stored_program(client, 0, 2048);
  ASSERT_TRUE(stored) << stored.error();
  EXPECT_EQ(stored->size(), 4u);
  module.set_memory({{3, 0, 0, 0}, {28, 0, 0, 0}});
  const Result<std::vector<tmcl::Instruction>> full = read_stored_program(client, 0, 2048);
  ASSERT_TRUE(full) << full.error();
  EXPECT_EQ(bytes_of(full.value()), bytes_of({{3, 0, 0, 0}, {28, 0, 0, 0}}));

  const Result<std::vector<tmcl::Instruction>> outside = read_program(client, 5, 1);
  ASSERT_FALSE(outside);
  EXPECT_EQ(outside.error(),
            "reading address 5 (134 type 0): the module answered status 4 (invalid value), expected status 100 (ok)");
}

TEST(AssemblerProgramTransfer, assembled_program_downloads_and_reads_back_identically) {
  FakeProgramModule module(64);
  TmclClient client = module.connect();
  const AssemblyResult assembled = assemble_file(std::string(MOTWIN_TEST_PROGRAMS_DIR) + "/manual_6_6_jump_table.tmc");
  ASSERT_TRUE(assembled.ok());
  ASSERT_TRUE(download_program(client, assembled.instructions));
  const Result<std::vector<tmcl::Instruction>> read = read_stored_program(client, 0, 64);
  ASSERT_TRUE(read) << read.error();
  EXPECT_EQ(bytes_of(read.value()), bytes_of(assembled.instructions));
}

TEST(AssemblerProgramTransfer, a_refused_instruction_stops_the_download_and_leaves_download_mode) {
  FakeProgramModule module;
  module.refuse_command(5);
  TmclClient client = module.connect();
  const Result<size_t> downloaded =
      download_program(client, std::vector<tmcl::Instruction>{{3, 0, 0, 0}, {5, 4, 0, 9}});
  ASSERT_FALSE(downloaded);
  EXPECT_EQ(downloaded.error(),
            "instruction 1 at address 1 (SAP 4, 0, 9): the module answered status 4 (invalid value), expected status "
            "101 (command stored); download mode left (133): program memory may hold part of the new program");
  const std::vector<tmcl::Instruction> requests = module.requests();
  ASSERT_FALSE(requests.empty());
  EXPECT_EQ(requests.back().command, 133);
}

TEST(AssemblerProgramTransfer, a_reply_to_134_may_carry_the_stored_opcode) {
  const tmcl::Frame reply = tmcl::encode_reply(2, 1, tmcl::Reply{100, 4, 1000});  // MVP ... 1000 stored
  const Result<TmclReply> decoded = decode_reply(reply, {134, 0, 0, 5});
  ASSERT_TRUE(decoded) << decoded.error();
  EXPECT_EQ(decoded->command, 4);
  EXPECT_EQ(decoded->value, 1000);
  EXPECT_FALSE(decode_reply(reply, {6, 1, 0, 0}));  // other commands must still be echoed
}

}  // namespace
}  // namespace motwin::tools
