#include "tools/tmcl_binary.h"

#include <cerrno>
#include <cstring>
#include <filesystem>
#include <fstream>
#include <iterator>

#include <fmt/format.h>

#include "core/tmcl/serial_link.h"

namespace motwin::tools {

BinaryRecord encode_binary_record(const tmcl::Instruction& instruction) {
  const auto value = static_cast<uint32_t>(instruction.value);
  BinaryRecord record{instruction.command,
                      instruction.type,
                      instruction.motor_bank,
                      static_cast<uint8_t>(value >> 24),
                      static_cast<uint8_t>(value >> 16),
                      static_cast<uint8_t>(value >> 8),
                      static_cast<uint8_t>(value),
                      0};
  record[7] = tmcl::checksum(record.data(), 7);
  return record;
}

std::vector<uint8_t> encode_program_binary(std::span<const tmcl::Instruction> instructions) {
  std::vector<uint8_t> bytes;
  bytes.reserve(instructions.size() * kBinaryRecordSize);
  for (const tmcl::Instruction& instruction : instructions) {
    const BinaryRecord record = encode_binary_record(instruction);
    bytes.insert(bytes.end(), record.begin(), record.end());
  }
  return bytes;
}

Result<std::vector<tmcl::Instruction>> decode_program_binary(std::span<const uint8_t> bytes) {
  if (bytes.size() % kBinaryRecordSize != 0) {
    return Error{
        fmt::format("not a TMCL program: {} bytes is not a multiple of {} (one {}-byte record per instruction)",
                    bytes.size(), kBinaryRecordSize, kBinaryRecordSize)};
  }
  std::vector<tmcl::Instruction> instructions;
  instructions.reserve(bytes.size() / kBinaryRecordSize);
  for (size_t offset = 0; offset < bytes.size(); offset += kBinaryRecordSize) {
    const uint8_t* record = bytes.data() + offset;
    const uint8_t expected = tmcl::checksum(record, 7);
    if (record[7] != expected) {
      return Error{
          fmt::format("checksum error in the instruction at address {} (byte offset {}): got 0x{:02X}, "
                      "expected 0x{:02X}",
                      offset / kBinaryRecordSize, offset, record[7], expected)};
    }
    const uint32_t value =
        (uint32_t{record[3]} << 24) | (uint32_t{record[4]} << 16) | (uint32_t{record[5]} << 8) | uint32_t{record[6]};
    instructions.push_back({record[0], record[1], record[2], static_cast<int32_t>(value)});
  }
  return instructions;
}

Result<size_t> write_program_binary(const std::string& path, std::span<const tmcl::Instruction> instructions) {
  const std::vector<uint8_t> bytes = encode_program_binary(instructions);
  std::ofstream out(path, std::ios::binary | std::ios::trunc);
  if (!out) return Error{fmt::format("cannot write {}: {}", path, std::strerror(errno))};
  out.write(reinterpret_cast<const char*>(bytes.data()), static_cast<std::streamsize>(bytes.size()));
  out.close();
  if (!out) return Error{fmt::format("cannot write {}: {}", path, std::strerror(errno))};
  return bytes.size();
}

Result<std::vector<tmcl::Instruction>> read_program_binary(const std::string& path) {
  std::error_code error;
  if (std::filesystem::is_directory(path, error)) return Error{fmt::format("cannot read {}: it is a directory", path)};
  std::ifstream in(path, std::ios::binary);
  if (!in) return Error{fmt::format("cannot read {}: {}", path, std::strerror(errno))};
  const std::vector<uint8_t> bytes{std::istreambuf_iterator<char>(in), std::istreambuf_iterator<char>()};
  if (in.bad()) return Error{fmt::format("cannot read {}: {}", path, std::strerror(errno))};
  Result<std::vector<tmcl::Instruction>> decoded = decode_program_binary(bytes);
  if (!decoded) return decoded.error_with_context(path + ": ");
  return decoded;
}

}  // namespace motwin::tools
