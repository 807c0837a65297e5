// The input loop of the targets that drive a TMCL module's engine on its simulated board
// (tmcm142_engine, tmcm3216_tmcl_engine): instructions drawn from the bytes (tmcl_instructions.h)
// with batches of control ticks between them, and after each step the invariants every such
// module keeps: every writable axis (of every motor) and bank-0 parameter inside its row's range,
// a write rejected with status 3 or 4 changes nothing, the statuses are TMCL statuses; plus the
// rig's own check of its simulated world (`check_world`).
#pragma once

#include <fuzzer/FuzzedDataProvider.h>

#include "fuzz_support.h"
#include "tmcl_instructions.h"

namespace motwin::fuzz {

struct ModuleEngineLimits {
  int tick_budget;  // control ticks per input at most
  int max_batch;    // ticks per batch at most
};

// `compare_write(instruction)`: whether a refused write can be compared with the value before
// (not for parameters that read differently each time or are cleared by reading).
template <class Module, class Rig, class CheckWorld, class CompareWrite>
void run_module_engine(FuzzedDataProvider& in, Rig& rig, ModuleEngineLimits limits, CheckWorld&& check_world,
                       CompareWrite&& compare_write) {
  int ticks_left = limits.tick_budget;
  for (int step = 0; step < 256 && in.remaining_bytes() > 0; ++step) {
    if (in.ConsumeIntegralInRange<int>(0, 5) == 0) {
      const int ticks = in.ConsumeIntegralInRange<int>(1, limits.max_batch);
      for (int t = 0; t < ticks && ticks_left > 0; ++t, --ticks_left) rig.tick();
      check_parameter_ranges(*rig.module, "after ticks");
      check_world(rig);
      continue;
    }
    const tmcl::Instruction instruction = next_instruction<Module>(in);
    execute_checked(*rig.module, rig.engine(), instruction, compare_write(instruction));
    check_parameter_ranges(*rig.module, "after an instruction");
  }
}

}  // namespace motwin::fuzz
