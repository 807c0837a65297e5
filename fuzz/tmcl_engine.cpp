// TMCL instructions through the engine of a TMCM-1636, as a host sends them, with control ticks
// in between so that stored programs (downloaded by the same input) run too.
//
// Invariants after every instruction and every batch of ticks:
// - every writable parameter holds a value inside its row's range (manual tables 11 and 13);
// - a rejected write (status 3 or 4) leaves the parameter as it was;
// - the reply status is a TMCL status.
#include <fuzzer/FuzzedDataProvider.h>

#include <cstddef>
#include <cstdint>
#include <memory>

#include "fuzz_support.h"
#include "tmcl_instructions.h"

namespace {
using namespace motwin;
}  // namespace

extern "C" int LLVMFuzzerTestOneInput(const uint8_t* data, size_t size) {
  FuzzedDataProvider in(data, size);
  auto rig = fuzz::fresh_rig<fuzz::Tmcm1636Rig>();
  // At most 2000 control ticks per input, in batches of up to 400 (the seeds of make_seeds.py
  // draw 1..400; fuzz/README.md, Decisions).
  int ticks_left = 2'000;
  for (int step = 0; step < 256 && in.remaining_bytes() > 0; ++step) {
    if (in.ConsumeIntegralInRange<int>(0, 7) == 0) {
      const int ticks = in.ConsumeIntegralInRange<int>(1, 400);
      for (int t = 0; t < ticks && ticks_left > 0; ++t, --ticks_left) rig->module.tick();
      fuzz::check_parameter_ranges(rig->module, "after ticks");
      continue;
    }
    const tmcl::Instruction instruction = fuzz::next_instruction<fuzz::Tmcm1636>(in);
    const bool is_set = instruction.command == 5 || instruction.command == 9;
    fuzz::execute_checked(rig->module, rig->engine, instruction, is_set);
    fuzz::check_parameter_ranges(rig->module, "after an instruction");
  }
  return 0;
}
