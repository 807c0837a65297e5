#include "tools/program_transfer.h"

#include <limits>
#include <string>

#include <fmt/format.h>

#include "core/tmcl/status.h"
#include "tools/tmcl_mnemonics.h"

namespace motwin::tools {
namespace {

namespace cmd = tmcl::command;

std::string status_text(uint8_t status) { return fmt::format("status {} ({})", status, tmcl::status_name(status)); }

// Sends `request`, expects `expected_status`; `what` names the step in errors. A reply with
// another status is stored in `*unexpected_status` when given.
Result<TmclReply> exchange(TmclClient& client, const tmcl::Instruction& request, uint8_t expected_status,
                           uint8_t module_address, const std::string& what, uint8_t* unexpected_status = nullptr) {
  Result<TmclReply> reply = client.request(request, module_address);
  if (!reply) return reply.error_with_context(what + ": ");
  if (reply->status != expected_status) {
    if (unexpected_status != nullptr) *unexpected_status = reply->status;
    return Error{fmt::format("{}: the module answered {}, expected {}", what, status_text(reply->status),
                             status_text(expected_status))};
  }
  return reply;
}

// One instruction with the two 134 requests.
Result<tmcl::Instruction> read_instruction(TmclClient& client, uint32_t address, uint8_t module_address,
                                           uint8_t* unexpected_status = nullptr) {
  const uint8_t ok = tmcl::to_byte(tmcl::Status::kOk);
  Result<TmclReply> opcode_and_value = exchange(client, read_back_request(address, 0), ok, module_address,
                                                fmt::format("reading address {} (134 type 0)", address), unexpected_status);
  if (!opcode_and_value) return Error{opcode_and_value.error()};
  Result<TmclReply> type_and_motor = exchange(client, read_back_request(address, 1), ok, module_address,
                                              fmt::format("reading address {} (134 type 1)", address));
  if (!type_and_motor) return Error{type_and_motor.error()};
  return decode_read_back(address, opcode_and_value->command, opcode_and_value->value, type_and_motor->value);
}

Result<std::vector<tmcl::Instruction>> check_range(uint32_t start, uint32_t count) {
  if (static_cast<uint64_t>(start) + count > static_cast<uint64_t>(std::numeric_limits<int32_t>::max())) {
    return Error{fmt::format("cannot read {} instructions from address {}: addresses end at {}", count, start,
                             std::numeric_limits<int32_t>::max())};
  }
  return std::vector<tmcl::Instruction>{};
}

}  // namespace

std::vector<TransferStep> download_steps(std::span<const tmcl::Instruction> instructions, uint32_t start) {
  const uint8_t ok = tmcl::to_byte(tmcl::Status::kOk);
  const uint8_t stored = tmcl::to_byte(tmcl::Status::kStoredInProgram);
  std::vector<TransferStep> steps;
  steps.reserve(instructions.size() + 3);
  steps.push_back({{cmd::kEnterDownloadMode, 0, 0, static_cast<int32_t>(start)},
                   ok,
                   fmt::format("entering download mode at address {} (132)", start)});
  for (size_t i = 0; i < instructions.size(); ++i) {
    steps.push_back({instructions[i], stored,
                     fmt::format("instruction {} at address {} ({})", i, start + i, format_instruction(instructions[i]))});
  }
  steps.push_back({{cmd::kNop, 0, 0, 0}, stored, "trailing NOP (command 0)"});
  steps.push_back({leave_download_request(), ok, "leaving download mode (133)"});
  return steps;
}

tmcl::Instruction leave_download_request() { return {cmd::kExitDownloadMode, 0, 0, 0}; }

tmcl::Instruction read_back_request(uint32_t address, uint8_t type) {
  return {cmd::kReadProgramMemory, type, 0, static_cast<int32_t>(address)};
}

Result<tmcl::Instruction> decode_read_back(uint32_t address, uint8_t opcode, int32_t value, int32_t type_and_motor) {
  const auto fields = static_cast<uint32_t>(type_and_motor);
  if (fields > 0xFFFF) {
    return Error{
        fmt::format("reading address {} (134 type 1): value 0x{:X} is not (type << 8) | motor", address, fields)};
  }
  return tmcl::Instruction{opcode, static_cast<uint8_t>(fields >> 8), static_cast<uint8_t>(fields), value};
}

Result<std::vector<tmcl::Instruction>> read_program(TmclClient& client, uint32_t start, uint32_t count,
                                                    uint8_t module_address) {
  Result<std::vector<tmcl::Instruction>> program = check_range(start, count);
  if (!program) return program;
  program->reserve(count);
  for (uint32_t address = start; address - start < count; ++address) {
    Result<tmcl::Instruction> instruction = read_instruction(client, address, module_address);
    if (!instruction) return Error{instruction.error()};
    program->push_back(instruction.value());
  }
  return program;
}

Result<std::vector<tmcl::Instruction>> read_stored_program(TmclClient& client, uint32_t start, uint32_t max_count,
                                                           uint8_t module_address) {
  Result<std::vector<tmcl::Instruction>> program = check_range(start, max_count);
  if (!program) return program;
  for (uint32_t address = start; address - start < max_count; ++address) {
    uint8_t status = tmcl::to_byte(tmcl::Status::kOk);
    Result<tmcl::Instruction> instruction = read_instruction(client, address, module_address, &status);
    if (!instruction) {
      if (address > start && status == tmcl::to_byte(tmcl::Status::kInvalidValue)) break;  // past the end
      return Error{instruction.error()};
    }
    if (instruction->command == cmd::kNop) break;
    program->push_back(instruction.value());
  }
  return program;
}

Result<size_t> download_program(TmclClient& client, std::span<const tmcl::Instruction> instructions, uint32_t start,
                                uint8_t module_address) {
  if (start > static_cast<uint32_t>(std::numeric_limits<int32_t>::max())) {
    return Error{fmt::format("start address {} is out of range", start)};
  }
  const std::vector<TransferStep> steps = download_steps(instructions, start);
  for (size_t i = 0; i < steps.size(); ++i) {
    Result<TmclReply> reply =
        exchange(client, steps[i].request, steps[i].expected_status, module_address, steps[i].what);
    if (reply) continue;
    // 132 refused, or 133 itself: nothing to leave.
    if (i == 0 || i + 1 == steps.size()) return Error{reply.error()};
    Result<TmclReply> left = client.request(leave_download_request(), module_address);
    const bool left_ok = left && left->status == tmcl::to_byte(tmcl::Status::kOk);
    return Error{fmt::format("{}; {}", reply.error(),
                             left_ok ? "download mode left (133): program memory may hold part of the new program"
                                     : "the module may still be in download mode (133 failed)")};
  }
  return instructions.size();
}

}  // namespace motwin::tools
