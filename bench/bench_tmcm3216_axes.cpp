// Simulation speed of the whole TMCM-3216 with its three axes turning (module firmware: CiA-402
// drive in profile velocity mode, EightPoint ramp, stepper axis with StallGuard/CoolStep and the
// emergency monitor, CANopen timers; plus the three motors and their sensors) as a real-time
// factor (simulated seconds per second of CPU time, one core) at the 50 µs tick. The baseline,
// measured in the same run, is the module on three ideal steppers. Goal: at least 100x per
// module with three physical motors (docs/benchmarks.md).
#include <benchmark/benchmark.h>

#include <cmath>
#include <cstdint>
#include <cstdio>
#include <cstdlib>
#include <optional>

#include "bench_support.h"
#include "../tests/unit/support/tmcm3216_board_rig.h"

namespace {

using motwin::sim::StepperMotorDescription;
using motwin::testing::Tmcm3216BoardRig;

constexpr const char* kBaselineName = "tmcm3216_ideal_steppers_baseline";
constexpr double kGoalRealTimeFactor = 100.0;  // issue 18: three physical axes
constexpr uint64_t kTicksPerIteration = 20'000;  // one simulated second
constexpr double kSimSecondsPerIteration = kTicksPerIteration * motwin::modules::tmcm3216::kTickUs * 1e-6;
constexpr uint16_t kAxisObjectStride = 0x800;        // 6040 -> 6840 -> 7040 (manual 2.6.1)
constexpr uint16_t kManufacturerAxisStride = 0x200;  // 2005 -> 2205 -> 2405
constexpr int32_t kVelocityPps = 102400;       // two revolutions per second at 256 µsteps

void write(Tmcm3216BoardRig& rig, uint16_t index, int64_t value) {
  if (rig.write_object(index, 0, value) != motwin::canopen::SdoAbort::kNone) {
    std::fprintf(stderr, "bench_tmcm3216_axes: %04X refused %lld\n", index, static_cast<long long>(value));
    std::abort();
  }
}

// Profile velocity mode on every axis, limit switches off; then one simulated second per
// iteration with all three axes turning (reversing each second, so the ramps run too).
void turning_axes(benchmark::State& state, std::optional<StepperMotorDescription> motor) {
  std::optional<Tmcm3216BoardRig> rig;
  if (motor) {
    rig.emplace(*motor);
  } else {
    rig.emplace();
  }
  for (uint16_t axis = 0; axis < 3; ++axis) {
    const auto k = static_cast<uint16_t>(axis * kAxisObjectStride);
    write(*rig, static_cast<uint16_t>(0x2005 + axis * kManufacturerAxisStride), 3);  // no limit switches
    write(*rig, 0x6083 + k, 512000);
    write(*rig, 0x6084 + k, 512000);
    write(*rig, 0x6060 + k, 3);
    for (int controlword : {6, 7, 15}) write(*rig, 0x6040 + k, controlword);
  }
  int32_t velocity = kVelocityPps;
  bool checked = false;
  for (auto _ : state) {
    for (uint16_t axis = 0; axis < 3; ++axis) write(*rig, static_cast<uint16_t>(0x60FF + axis * kAxisObjectStride), velocity);
    velocity = -velocity;
    const double start_rev = rig->board.rotor_revolutions(2);
    rig->tick(kTicksPerIteration);
    // A figure of motors standing still would flatter the plant: each second turns them about
    // 1.9 revolutions (2 rev/s less the ramp).
    if (!checked && std::fabs(rig->board.rotor_revolutions(2) - start_rev) < 1.5) {
      state.SkipWithError("the axes did not turn");
      break;
    }
    checked = true;
  }
  motwin::bench::report_real_time_factor(state, kSimSecondsPerIteration);
}

}  // namespace

int main(int argc, char** argv) {
  benchmark::Initialize(&argc, argv);
  if (benchmark::ReportUnrecognizedArguments(argc, argv)) return 1;
  benchmark::RegisterBenchmark(kBaselineName, turning_axes, std::nullopt)->Unit(benchmark::kMillisecond);
  benchmark::RegisterBenchmark("tmcm3216_three_nema17", turning_axes,
                               std::optional<StepperMotorDescription>(StepperMotorDescription::nema17()))
      ->Unit(benchmark::kMillisecond);
  benchmark::RegisterBenchmark("tmcm3216_three_nema23", turning_axes,
                               std::optional<StepperMotorDescription>(StepperMotorDescription::nema23()))
      ->Unit(benchmark::kMillisecond);
  motwin::bench::RealTimeFactorReporter reporter({kBaselineName, "the ideal steppers", kGoalRealTimeFactor, 40});
  benchmark::RunSpecifiedBenchmarks(&reporter);
  benchmark::Shutdown();
  return 0;
}
