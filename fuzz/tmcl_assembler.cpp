// The TMCL assembler and disassembler (src/tools): any source text, and any .bin bytes.
//
// Input: byte 0 bit 0 chooses the mode; the rest is TMCL-IDE source text (mode 0) or the bytes
// of a .bin file (mode 1). #include never reaches the file system (the reader finds nothing).
// Invariants:
// - source that assembles: disassembling its instructions and assembling that text again
//   succeeds and gives the same .bin bytes;
// - .bin bytes that decode: their disassembly assembles back to exactly those bytes;
// - a failed assembly names at least one error and produces no instructions worth using;
//   never a crash, never an exception escaping.
#include <cstddef>
#include <cstdint>
#include <optional>
#include <span>
#include <string>
#include <string_view>
#include <vector>

#include "fuzz_support.h"
#include "tools/tmcl_assembler.h"
#include "tools/tmcl_binary.h"
#include "tools/tmcl_disassembler.h"

namespace {

using namespace motwin;

tools::AssemblerOptions in_memory_options() {
  tools::AssemblerOptions options;
  options.reader = [](const std::string&) -> std::optional<std::string> { return std::nullopt; };
  return options;
}

// The assembler appends a STOP, and the disassembler writes a final plain STOP as a comment: a
// program that does not end with one comes back one STOP longer.
void check_round_trip(const std::vector<tmcl::Instruction>& instructions, std::vector<uint8_t> bytes,
                      const char* origin) {
  const tmcl::Instruction stop{tmcl::command::kStop, 0, 0, 0};
  const bool ends_with_stop = !instructions.empty() && instructions.back().command == stop.command &&
                              instructions.back().type == 0 && instructions.back().motor_bank == 0 &&
                              instructions.back().value == 0;
  if (!ends_with_stop) {
    const tools::BinaryRecord record = tools::encode_binary_record(stop);
    bytes.insert(bytes.end(), record.begin(), record.end());
  }
  const std::string text = tools::disassemble(instructions);
  const tools::AssemblyResult again = tools::assemble_source(text, "disassembly.tmc", in_memory_options());
  FUZZ_CHECK(again.ok(), "%s: the disassembly does not assemble: %s\n--- disassembly ---\n%s", origin,
             again.errors.empty() ? "" : tools::format_error(again.errors.front()).c_str(), text.c_str());
  const std::vector<uint8_t> rebuilt = tools::encode_program_binary(again.instructions);
  FUZZ_CHECK(rebuilt == bytes, "%s: %zu bytes became %zu different bytes after disassembly and assembly\n%s", origin,
             bytes.size(), rebuilt.size(), text.c_str());
}

}  // namespace

extern "C" int LLVMFuzzerTestOneInput(const uint8_t* data, size_t size) {
  if (size < 1 || size > 64 * 1024) return 0;
  const bool binary_mode = (data[0] & 1) != 0;
  const std::span<const uint8_t> body(data + 1, size - 1);
  if (binary_mode) {
    const auto decoded = tools::decode_program_binary(body);
    if (!decoded.ok()) {
      FUZZ_CHECK(!decoded.error().empty(), "a .bin file was refused without a reason");
      return 0;
    }
    if (decoded->size() > tools::kDefaultProgramMemorySize - 1) return 0;  // does not fit a module
    check_round_trip(decoded.value(), std::vector<uint8_t>(body.begin(), body.end()), ".bin");
    return 0;
  }
  const std::string_view source(reinterpret_cast<const char*>(body.data()), body.size());
  const tools::AssemblyResult result = tools::assemble_source(source, "fuzz.tmc", in_memory_options());
  if (!result.ok()) {
    FUZZ_CHECK(!tools::format_error(result.errors.front()).empty(), "an error without a message");
    return 0;
  }
  FUZZ_CHECK(result.instructions.size() <= tools::kDefaultProgramMemorySize, "%zu instructions exceed the memory",
             result.instructions.size());
  check_round_trip(result.instructions, tools::encode_program_binary(result.instructions), "source");
  return 0;
}
