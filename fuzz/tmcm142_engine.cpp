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

#include <cmath>
#include <cstddef>
#include <cstdint>
#include <memory>

#include "fuzz_support.h"
#include "tmcl_module_engine.h"
#include "tmcm142_rig.h"

namespace {

using namespace motwin;
using fuzz::Tmcm142;
using Rig = fuzz::Tmcm142Rig;

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
  auto rig = fuzz::fresh_rig<Rig>();
  // 50 ms of motion per input at most, in batches of up to 5 ms (fuzz/README.md, Decisions).
  // GP 133 (random number) reads a new value each time, AP 44 and 207 are cleared by reading and
  // GP 131 (last TMCL error) records the refusal itself: no "unchanged" to compare.
  fuzz::run_module_engine<Tmcm142>(in, *rig, {1'000, 100}, check_motor, [](const tmcl::Instruction& instruction) {
    return (instruction.command == 5 && instruction.type != 44 && instruction.type != 207) ||
           (instruction.command == 9 && instruction.type != 133 && instruction.type != 131);
  });
  return 0;
}
