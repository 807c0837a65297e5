// The `.bin` program format of the TMCL-IDE's binary export (docs/tmcl-protocol.md
// "TMCL-IDE program syntax"): 8 bytes per instruction, in address order: command, type, motor/bank,
// value (big-endian, 4 bytes) and the 8-bit sum of those 7 bytes. No header; the file length is 8 x
// the instruction count.
#pragma once

#include <array>
#include <cstddef>
#include <cstdint>
#include <span>
#include <string>
#include <vector>

#include "core/tmcl/instruction.h"
#include "types/result.h"

namespace motwin::tools {

inline constexpr size_t kBinaryRecordSize = 8;
using BinaryRecord = std::array<uint8_t, kBinaryRecordSize>;

BinaryRecord encode_binary_record(const tmcl::Instruction& instruction);

std::vector<uint8_t> encode_program_binary(std::span<const tmcl::Instruction> instructions);
// Fails when the length is not a multiple of 8 or a record's checksum does not match (the
// message names the address and byte offset).
Result<std::vector<tmcl::Instruction>> decode_program_binary(std::span<const uint8_t> bytes);

// Returns the number of bytes written.
Result<size_t> write_program_binary(const std::string& path, std::span<const tmcl::Instruction> instructions);
Result<std::vector<tmcl::Instruction>> read_program_binary(const std::string& path);

}  // namespace motwin::tools
