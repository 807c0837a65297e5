// Simulation speed of the whole TMCM-142 (module firmware: S-ramp, microstep sequencer, switches,
// encoder, easyPID, deviation check, TMCL engine tick; plus the motor and its sensors) as a
// real-time factor (simulated seconds per second of CPU time, one core) at the 50 µs tick. The
// baseline, measured in the same run, is the module on the ideal stepper. Goal: at least 200x
// on the physical NEMA23 model with the easyPID closed. See docs/benchmarks.md.
#include <benchmark/benchmark.h>

#include "bench_support.h"
#include "../tests/unit/support/tmcm142_rig.h"

namespace {

using motwin::testing::StepperMotor;
using motwin::testing::Tmcm142Rig;

constexpr const char* kBaselineName = "tmcm142_ideal_stepper_baseline";
constexpr double kGoalRealTimeFactor = 200.0;
constexpr uint64_t kTicksPerIteration = 20'000;  // one simulated second
constexpr double kSimSecondsPerIteration = kTicksPerIteration * motwin::modules::tmcm142::kControlTickS;

void report(benchmark::State& state) { motwin::bench::report_real_time_factor(state, kSimSecondsPerIteration); }

// MVP back and forth by one revolution with S-ramps (default bows), one simulated second each.
void moves(benchmark::State& state, StepperMotor motor, bool closed_loop) {
  Tmcm142Rig rig(motor);
  rig.sap(255, 1);
  rig.sap(4, 204800);
  rig.sap(5, 1000000);
  rig.sap(40, closed_loop ? 1 : 0);
  rig.sap(212, closed_loop ? 5000 : 0);
  int32_t target = 204800;
  for (auto _ : state) {
    rig.command(4, 0, 0, target);
    target = target == 0 ? 204800 : 0;
    for (uint64_t i = 0; i < kTicksPerIteration; ++i) rig.tick();
    benchmark::DoNotOptimize(rig.stage.drive.electrical_angle);
  }
  report(state);
}

}  // namespace

int main(int argc, char** argv) {
  benchmark::Initialize(&argc, argv);
  if (benchmark::ReportUnrecognizedArguments(argc, argv)) return 1;
  benchmark::RegisterBenchmark(kBaselineName, moves, StepperMotor::kIdeal, false)->Unit(benchmark::kMillisecond);
  benchmark::RegisterBenchmark("tmcm142_nema23_open_loop", moves, StepperMotor::kPhysical, false)
      ->Unit(benchmark::kMillisecond);
  benchmark::RegisterBenchmark("tmcm142_nema23_easypid", moves, StepperMotor::kPhysical, true)
      ->Unit(benchmark::kMillisecond);
  motwin::bench::RealTimeFactorReporter reporter({kBaselineName, "the ideal stepper", kGoalRealTimeFactor, 40});
  benchmark::RunSpecifiedBenchmarks(&reporter);
  benchmark::Shutdown();
  return 0;
}
