// TMCL instructions through the engine of a TMCM-142 on its simulated board (ideal motor:
// switches and encoder as the sim places them), as a host sends them, with control ticks in
// between so that motions, reference searches and downloaded programs run too. The TMCM-142
// counterpart of `tmcl_engine`.
//
// Invariants after every instruction and every batch of ticks:
// - every writable axis and global parameter holds a value inside its row's range;
// - a rejected write (status 3 or 4) leaves the parameter as it was;
// - the reply status is a TMCL status;
// - the rotor position and the encoder count are finite and the count is the sensors' count at
//   the rotor position.
#include <fuzzer/FuzzedDataProvider.h>

#include <array>
#include <cmath>
#include <cstddef>
#include <cstdint>
#include <memory>

#include "board/ram_non_volatile_memory.h"
#include "core/modules/tmcm142/tmcm142.h"
#include "fuzz_support.h"
#include "sim/tmcm142_sim_board.h"
#include "sim/tmcm142_sim_io.h"

namespace {

using namespace motwin;
using Tmcm142 = modules::tmcm142::Tmcm142;
using Tmcm142Nvm = board::RamNonVolatileMemory<Tmcm142::kNvmLayout.total_size>;

// TMCL commands (as the tmcl_engine target) and the control commands; others by chance.
constexpr std::array<uint8_t, 30> kCommands{1,  2,  3,  4,  5,  6,  7,   8,   9,   10,  11,  12,  13,  14,  15,
                                            19, 20, 21, 22, 26, 27, 36,  128, 129, 130, 131, 132, 133, 138, 255};

struct Rig {
  sim::Tmcm142SimIo io;
  sim::Tmcm142SimBoard board{io};
  Tmcm142Nvm nvm;
  std::unique_ptr<Tmcm142> module;

  Rig() {
    Tmcm142::format_factory_image(nvm.mutable_data(), nvm.size());
    // Switches a reference search can find: left below, right above, a home cam between.
    board.set_input("REF_L_AT", -0.5);
    board.set_input("REF_R_AT", 0.5);
    board.set_input("REF_H_FROM", 0.1);
    board.set_input("REF_H_TO", 0.2);
    board.before_tick();
    module = std::make_unique<Tmcm142>(nvm, board.power_stage(), io);
    module->engine().power_up();
  }
  void tick() {
    board.before_tick();
    module->tick();
    board.after_tick(modules::tmcm142::kControlTickS);
  }
};

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
    const auto rows = axis ? Tmcm142::axis_parameters().rows() : Tmcm142::global_parameters().rows();
    info = &rows[in.ConsumeIntegralInRange<size_t>(0, rows.size() - 1)].info;
    instruction.type = static_cast<uint8_t>(info->number);
  } else {
    instruction.type = in.ConsumeIntegral<uint8_t>();
  }
  instruction.motor_bank = in.ConsumeBool() ? 0 : in.ConsumeIntegral<uint8_t>();
  instruction.value = interesting_value(in, info);
  return instruction;
}

bool read_parameter(Tmcm142& module, const tmcl::Instruction& in, int32_t& value) {
  const auto status = in.command == 5 ? module.get_axis_parameter(in.type, in.motor_bank, value)
                                      : module.get_global_parameter(in.type, in.motor_bank, value);
  return status == tmcl::Status::kOk;
}

void check_ranges(Tmcm142& module, const char* when) {
  for (const auto* table : {&Tmcm142::axis_parameters(), &Tmcm142::global_parameters()}) {
    const bool axis = table == &Tmcm142::axis_parameters();
    for (const auto& row : table->rows()) {
      if (!params::has(row.info.access, params::Access::kWrite) || !params::has(row.info.access, params::Access::kRead)) {
        continue;
      }
      int32_t value = 0;
      const auto number = static_cast<uint8_t>(row.info.number);
      const auto status = axis ? module.get_axis_parameter(number, 0, value) : module.get_global_parameter(number, 0, value);
      if (status != tmcl::Status::kOk) continue;
      FUZZ_CHECK(params::in_range(row.info, value), "%s: %s %u (%.*s) holds %d, range %lld..%lld", when,
                 axis ? "AP" : "GP", row.info.number, static_cast<int>(row.info.name.size()), row.info.name.data(),
                 value, static_cast<long long>(row.info.min), static_cast<long long>(row.info.max));
    }
  }
}

void check_motor(Rig& rig) {
  const double position = rig.board.rotor_revolutions();
  FUZZ_CHECK(std::isfinite(position), "rotor at %g", position);
  rig.board.before_tick();
  FUZZ_CHECK(rig.board.power_stage().feedback.encoder_count == rig.board.sensors().encoder_count_at(position),
             "encoder count %d, rotor at %g", rig.board.power_stage().feedback.encoder_count, position);
}

}  // namespace

extern "C" int LLVMFuzzerTestOneInput(const uint8_t* data, size_t size) {
  FuzzedDataProvider in(data, size);
  auto rig = std::make_unique<Rig>();
  tmcl::TmclEngine& engine = rig->module->engine();
  int ticks_left = 20'000;  // 1 s of motion per input at most
  for (int step = 0; step < 256 && in.remaining_bytes() > 0; ++step) {
    if (in.ConsumeIntegralInRange<int>(0, 5) == 0) {
      const int ticks = in.ConsumeIntegralInRange<int>(1, 2000);
      for (int t = 0; t < ticks && ticks_left > 0; ++t, --ticks_left) rig->tick();
      check_ranges(*rig->module, "after ticks");
      check_motor(*rig);
      continue;
    }
    const tmcl::Instruction instruction = next_instruction(in);
    // GP 133 (random number) reads a new value each time: no "unchanged" to compare.
    const bool is_set = instruction.command == 5 || (instruction.command == 9 && instruction.type != 133);
    int32_t before = 0;
    const bool readable_before = is_set && read_parameter(*rig->module, instruction, before);
    const tmcl::CommandResult result = engine.execute(instruction, tmcl::Origin::kHost, 0);
    const uint8_t status = tmcl::to_byte(result.status);
    FUZZ_CHECK(status == 100 || status == 101 || status == 128 || (status >= 1 && status <= 6),
               "command %u type %u motor %u value %d: status %u", instruction.command, instruction.type,
               instruction.motor_bank, instruction.value, status);
    if (readable_before && (result.status == tmcl::Status::kWrongType || result.status == tmcl::Status::kInvalidValue)) {
      int32_t after = 0;
      FUZZ_CHECK(read_parameter(*rig->module, instruction, after) && after == before,
                 "rejected command %u type %u value %d (status %u) changed the parameter from %d to %d",
                 instruction.command, instruction.type, instruction.value, status, before, after);
    }
    if (result.kind == tmcl::ReplyKind::kThenReset) engine.complete_reset();
    check_ranges(*rig->module, "after an instruction");
  }
  return 0;
}
