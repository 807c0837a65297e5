// TMCL instructions through the engine of the TMCM-3216's TMCL firmware on its simulated board
// (three ideal motors: switches, home cams and null channels placed), as a host sends them, with
// control ticks in between so that motions of every motor, reference searches of every mode,
// position compare and downloaded programs run too. The three-motor counterpart of
// `tmcm142_engine`, on the same loop (tmcl_module_engine.h).
//
// Invariants after every instruction and every batch of ticks:
// - every writable axis parameter of every motor and every bank-0 parameter holds a value inside
//   its row's range;
// - a rejected write (status 3 or 4) leaves the parameter as it was;
// - the reply status is a TMCL status;
// - every rotor position is finite.
#include <fuzzer/FuzzedDataProvider.h>

#include <cmath>
#include <cstddef>
#include <cstdint>
#include <memory>

#include "fuzz_support.h"
#include "tmcl_module_engine.h"
#include "tmcm3216_tmcl_rig.h"

namespace {

using namespace motwin;
using fuzz::Tmcm3216Tmcl;
using Rig = fuzz::Tmcm3216TmclRig;

void check_motors(Rig& rig) {
  for (uint8_t axis = 0; axis < modules::tmcm3216::kAxisCount; ++axis) {
    const double position = rig.board.rotor_revolutions(axis);
    FUZZ_CHECK(std::isfinite(position), "rotor %u at %g", axis, position);
  }
}

}  // namespace

extern "C" int LLVMFuzzerTestOneInput(const uint8_t* data, size_t size) {
  FuzzedDataProvider in(data, size);
  auto rig = fuzz::fresh_rig<Rig>();
  // 50 ms of motion per input at most, in batches of up to 5 ms, as tmcm142_engine.
  // GP 133 (random number) reads a new value each time, AP 207 is cleared by reading, AP 209 (the
  // encoder position) follows the rotor and GP 131 records the refusal itself.
  fuzz::run_module_engine<Tmcm3216Tmcl>(in, *rig, {1'000, 100}, check_motors, [](const tmcl::Instruction& instruction) {
    return (instruction.command == 5 && instruction.type != 207 && instruction.type != 209) ||
           (instruction.command == 9 && instruction.type != 133 && instruction.type != 131);
  });
  return 0;
}
