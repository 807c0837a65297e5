// TMCL instructions as the engine targets (tmcl_engine, tmcm142_engine) draw them from the fuzzed
// bytes: mostly known commands, and for SAP/GAP/STAP/RSAP and SGP/GGP/STGP/RSGP mostly parameter
// numbers of the module's tables with values at and just beyond their limits.
#pragma once

#include <fuzzer/FuzzedDataProvider.h>

#include <array>
#include <cstddef>
#include <cstdint>

#include "fuzz_support.h"

#include "core/params/parameter.h"
#include "core/tmcl/engine.h"

namespace motwin::fuzz {

// The TMCL commands of the TMCM-1636 and TMCM-142 (manual table 4), the control commands and the
// datalogger's 142 and 157 (docs/datalogger.md); others by chance.
inline constexpr std::array<uint8_t, 32> kTmclCommands{1,  2,  3,  4,  5,   6,   7,   8,   9,   10,  11,
                                                       12, 13, 14, 15, 19,  20,  21,  22,  26,  27,  36,
                                                       128, 129, 130, 131, 132, 133, 138, 142, 157, 255};

inline int32_t interesting_value(FuzzedDataProvider& in, const params::ParameterInfo* info) {
  switch (in.ConsumeIntegralInRange<int>(0, 5)) {
    case 0: return info ? static_cast<int32_t>(info->min) : 0;
    case 1: return info ? static_cast<int32_t>(info->max) : 1;
    case 2: return info ? static_cast<int32_t>(info->max + 1) : -1;
    case 3: return info ? static_cast<int32_t>(info->min - 1) : 1234;
    case 4: return in.ConsumeIntegralInRange<int32_t>(-1000, 100000);
    default: return in.ConsumeIntegral<int32_t>();
  }
}

template <typename Module>
tmcl::Instruction next_instruction(FuzzedDataProvider& in) {
  tmcl::Instruction instruction;
  instruction.command = in.ConsumeBool()
                            ? kTmclCommands[in.ConsumeIntegralInRange<size_t>(0, kTmclCommands.size() - 1)]
                            : in.ConsumeIntegral<uint8_t>();
  const params::ParameterInfo* info = nullptr;
  const bool axis = instruction.command >= 5 && instruction.command <= 8;
  const bool global = instruction.command >= 9 && instruction.command <= 12;
  if ((axis || global) && in.ConsumeBool()) {
    const auto rows = axis ? Module::axis_parameters().rows() : Module::global_parameters().rows();
    info = &rows[in.ConsumeIntegralInRange<size_t>(0, rows.size() - 1)].info;
    instruction.type = static_cast<uint8_t>(info->number);
  } else {
    instruction.type = in.ConsumeIntegral<uint8_t>();
  }
  // Mostly a motor the module has (no bytes drawn for a one-motor module, as before).
  instruction.motor_bank = in.ConsumeBool() ? in.ConsumeIntegralInRange<uint8_t>(0, Module::kMotorCount - 1)
                                            : in.ConsumeIntegral<uint8_t>();
  instruction.value = interesting_value(in, info);
  return instruction;
}

// Reads the parameter a SAP (5) or SGP (9) instruction writes; false when the module refuses.
template <typename Module>
bool read_parameter(Module& module, const tmcl::Instruction& in, int32_t& value) {
  const bool axis = in.command == 5;
  const auto status = axis ? module.get_axis_parameter(in.type, in.motor_bank, value)
                           : module.get_global_parameter(in.type, in.motor_bank, value);
  return status == tmcl::Status::kOk;
}

// Executes one instruction on the module's engine and checks that the reply status is a TMCL
// status and that a rejected write (status 3 or 4) left the parameter as it was; `compare_write`
// false skips the latter (not a SAP/SGP, or a parameter that reads differently each time).
template <typename Module>
void execute_checked(Module& module, tmcl::TmclEngine& engine, const tmcl::Instruction& instruction,
                     bool compare_write) {
  int32_t before = 0;
  const bool readable_before = compare_write && read_parameter(module, instruction, before);
  const tmcl::CommandResult result = engine.execute(instruction, tmcl::Origin::kHost, 0);
  const uint8_t status = tmcl::to_byte(result.status);
  FUZZ_CHECK(tmcl::is_status_code(status),
             "command %u type %u motor %u value %d: status %u", instruction.command, instruction.type,
             instruction.motor_bank, instruction.value, status);
  if (readable_before && (result.status == tmcl::Status::kWrongType || result.status == tmcl::Status::kInvalidValue)) {
    int32_t after = 0;
    FUZZ_CHECK(read_parameter(module, instruction, after) && after == before,
               "rejected command %u type %u value %d (status %u) changed the parameter from %d to %d",
               instruction.command, instruction.type, instruction.value, status, before, after);
  }
  if (result.kind == tmcl::ReplyKind::kThenReset) engine.complete_reset();
}

}  // namespace motwin::fuzz
