#include "core/tmcl/program_memory.h"

#include <cstring>

namespace motwin::tmcl {

void encode_program_record(const Instruction& in, uint8_t* out) {
  const auto v = static_cast<uint32_t>(in.value);
  out[0] = in.command;
  out[1] = in.type;
  out[2] = in.motor_bank;
  out[3] = static_cast<uint8_t>(v >> 24);
  out[4] = static_cast<uint8_t>(v >> 16);
  out[5] = static_cast<uint8_t>(v >> 8);
  out[6] = static_cast<uint8_t>(v);
  uint8_t sum = 0;
  for (size_t i = 0; i < 7; ++i) sum = static_cast<uint8_t>(sum + out[i]);
  out[7] = sum;
}

bool decode_program_record(const uint8_t* in, Instruction& out) {
  uint8_t sum = 0;
  for (size_t i = 0; i < 7; ++i) sum = static_cast<uint8_t>(sum + in[i]);
  if (sum != in[7]) return false;
  out.command = in[0];
  out.type = in[1];
  out.motor_bank = in[2];
  out.value = static_cast<int32_t>((static_cast<uint32_t>(in[3]) << 24) | (static_cast<uint32_t>(in[4]) << 16) |
                                   (static_cast<uint32_t>(in[5]) << 8) | in[6]);
  return true;
}

void ProgramMemory::load() {
  const size_t bytes = static_cast<size_t>(capacity_) * kProgramRecordBytes;
  if (nvm_.size() >= nvm_offset_ + bytes) {
    std::memcpy(mirror_, nvm_.data() + nvm_offset_, bytes);
  } else {
    std::memset(mirror_, 0, bytes);
  }
  dirty_begin_ = UINT32_MAX;
  dirty_end_ = 0;
}

bool ProgramMemory::read(uint32_t address, Instruction& instruction) const {
  if (address >= capacity_) return false;
  return decode_program_record(mirror_ + static_cast<size_t>(address) * kProgramRecordBytes, instruction);
}

bool ProgramMemory::stage(uint32_t address, const Instruction& instruction) {
  if (address >= capacity_) return false;
  encode_program_record(instruction, mirror_ + static_cast<size_t>(address) * kProgramRecordBytes);
  if (address < dirty_begin_) dirty_begin_ = address;
  if (address + 1 > dirty_end_) dirty_end_ = address + 1;
  return true;
}

bool ProgramMemory::commit() {
  if (!has_staged_changes()) return true;
  const size_t offset = static_cast<size_t>(dirty_begin_) * kProgramRecordBytes;
  const size_t length = static_cast<size_t>(dirty_end_ - dirty_begin_) * kProgramRecordBytes;
  const bool ok = nvm_.write(nvm_offset_ + offset, mirror_ + offset, length);
  if (!ok) {
    load();
    return false;
  }
  dirty_begin_ = UINT32_MAX;
  dirty_end_ = 0;
  return true;
}

}  // namespace motwin::tmcl
