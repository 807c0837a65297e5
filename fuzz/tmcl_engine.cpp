// TMCL instructions through the engine of a TMCM-1636, as a host sends them, with control ticks
// in between so that stored programs (downloaded by the same input) run too.
//
// Invariants after every instruction and every batch of ticks:
// - every writable parameter holds a value inside its row's range (manual tables 11 and 13);
// - a rejected write (status 3 or 4) leaves the parameter as it was;
// - the reply status is a TMCL status.
#include <fuzzer/FuzzedDataProvider.h>

#include <array>
#include <cstddef>
#include <cstdint>
#include <memory>

#include "fuzz_support.h"

namespace {

using namespace motwin;

// The commands of the TMCM-1636 (manual table 4) and the control commands; others by chance.
constexpr std::array<uint8_t, 30> kCommands{1,  2,  3,  4,  5,  6,  7,   8,   9,   10,  11,  12,  13,  14,  15,
                                            19, 20, 21, 22, 26, 27, 36,  128, 129, 130, 131, 132, 133, 138, 255};

int32_t interesting_value(FuzzedDataProvider& in, const params::ParameterInfo* info) {
  switch (in.ConsumeIntegralInRange<int>(0, 5)) {
    case 0: return info ? static_cast<int32_t>(info->min) : 0;
    case 1: return info ? static_cast<int32_t>(info->max) : 1;
    case 2: return info ? static_cast<int32_t>(info->max + 1) : -1;
    case 3: return info ? static_cast<int32_t>(info->min - 1) : 1234;
    case 4: return in.ConsumeIntegralInRange<int32_t>(-1000, 100000);
    default: return in.ConsumeIntegral<int32_t>();
  }
}

tmcl::Instruction next_instruction(FuzzedDataProvider& in) {
  tmcl::Instruction instruction;
  instruction.command = in.ConsumeBool() ? kCommands[in.ConsumeIntegralInRange<size_t>(0, kCommands.size() - 1)]
                                         : in.ConsumeIntegral<uint8_t>();
  const params::ParameterInfo* info = nullptr;
  const bool axis = instruction.command >= 5 && instruction.command <= 8;
  const bool global = instruction.command >= 9 && instruction.command <= 12;
  if ((axis || global) && in.ConsumeBool()) {
    const auto rows = axis ? fuzz::Tmcm1636::axis_parameters().rows() : fuzz::Tmcm1636::global_parameters().rows();
    info = &rows[in.ConsumeIntegralInRange<size_t>(0, rows.size() - 1)].info;
    instruction.type = static_cast<uint8_t>(info->number);
  } else {
    instruction.type = in.ConsumeIntegral<uint8_t>();
  }
  instruction.motor_bank = in.ConsumeBool() ? 0 : in.ConsumeIntegral<uint8_t>();
  instruction.value = interesting_value(in, info);
  return instruction;
}

bool read_parameter(fuzz::Tmcm1636& module, const tmcl::Instruction& in, int32_t& value) {
  const bool axis = in.command == 5;
  const auto status = axis ? module.get_axis_parameter(in.type, in.motor_bank, value)
                           : module.get_global_parameter(in.type, in.motor_bank, value);
  return status == tmcl::Status::kOk;
}

}  // namespace

extern "C" int LLVMFuzzerTestOneInput(const uint8_t* data, size_t size) {
  FuzzedDataProvider in(data, size);
  auto rig = std::make_unique<fuzz::Tmcm1636Rig>();
  for (int step = 0; step < 256 && in.remaining_bytes() > 0; ++step) {
    if (in.ConsumeIntegralInRange<int>(0, 7) == 0) {
      const int ticks = in.ConsumeIntegralInRange<int>(1, 400);
      for (int t = 0; t < ticks; ++t) rig->module.tick();
      fuzz::check_parameter_ranges(rig->module, "after ticks");
      continue;
    }
    const tmcl::Instruction instruction = next_instruction(in);
    const bool is_set = instruction.command == 5 || instruction.command == 9;
    int32_t before = 0;
    const bool readable_before = is_set && read_parameter(rig->module, instruction, before);
    const tmcl::CommandResult result = rig->engine.execute(instruction, tmcl::Origin::kHost, 0);
    const uint8_t status = tmcl::to_byte(result.status);
    FUZZ_CHECK(status == 100 || status == 101 || status == 128 || (status >= 1 && status <= 6),
               "command %u type %u motor %u value %d: status %u", instruction.command, instruction.type,
               instruction.motor_bank, instruction.value, status);
    if (readable_before && (result.status == tmcl::Status::kWrongType || result.status == tmcl::Status::kInvalidValue)) {
      int32_t after = 0;
      FUZZ_CHECK(read_parameter(rig->module, instruction, after) && after == before,
                 "rejected command %u type %u value %d (status %u) changed the parameter from %d to %d",
                 instruction.command, instruction.type, instruction.value, status, before, after);
    }
    if (result.kind == tmcl::ReplyKind::kThenReset) rig->engine.complete_reset();
    fuzz::check_parameter_ranges(rig->module, "after an instruction");
  }
  return 0;
}
