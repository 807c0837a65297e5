// Simulation speed of one TMCM-1636 axis as a real-time factor (simulated seconds per second of
// CPU time, one core): the full cascade (position P, velocity PI, FOC flux/torque PI, SVM) at the
// 50 µs tick on the motor plant (one exact current step per tick), sensors and supply bus. The
// baseline, measured in the same run, is the ideal motor (the axis follows its ramp, no
// regulators, no plant). Goal: at least 300x for the full cascade. See docs/benchmarks.md.
#include <benchmark/benchmark.h>

#include <memory>

#include "bench_support.h"
#include "../tests/unit/support/tmcm1636_rig.h"
#include "../tests/unit/support/tmcm1636_servo_rig.h"

namespace {

using motwin::testing::Tmcm1636Rig;
using motwin::testing::Tmcm1636ServoRig;

constexpr const char* kBaselineName = "ideal_motor_baseline";
constexpr double kGoalRealTimeFactor = 300.0;  // issue 18: position mode on a physical motor
constexpr uint64_t kTicksPerIteration = 20'000;  // one simulated second
constexpr double kSimSecondsPerIteration = kTicksPerIteration * motwin::modules::tmcm1636::kControlTickUs * 1e-6;

void report(benchmark::State& state) { motwin::bench::report_real_time_factor(state, kSimSecondsPerIteration); }

// Baseline: the ideal motor in velocity mode.
void ideal_motor(benchmark::State& state) {
  Tmcm1636Rig rig;
  rig.command(1, 0, 0, 2000);  // ROR 2000 rpm
  for (auto _ : state) {
    for (uint64_t i = 0; i < kTicksPerIteration; ++i) rig.module.tick();
    benchmark::DoNotOptimize(rig.module.axis().state.actual_position);
  }
  report(state);
}

// Velocity mode at 2000 rpm with a load: velocity PI, FOC, plant.
void servo_velocity(benchmark::State& state, const char* motor) {
  Tmcm1636ServoRig rig(Tmcm1636ServoRig::preset(motor));
  rig.ror(2000);
  rig.set("LOAD_TORQUE", 0.01);
  for (auto _ : state) {
    rig.run_ticks(kTicksPerIteration);
    benchmark::DoNotOptimize(rig.plant().speed_rad_s());
  }
  report(state);
}

// Position mode: MVP back and forth by 10 revolutions, so that the whole cascade and the ramp's
// braking point run (position P -> velocity PI -> FOC).
void servo_position(benchmark::State& state, const char* motor) {
  Tmcm1636ServoRig rig(Tmcm1636ServoRig::preset(motor));
  const int32_t distance = 10 * rig.gap(100);
  int32_t target = distance;
  for (auto _ : state) {
    rig.mvp(target);
    target = target == 0 ? distance : 0;
    rig.run_ticks(kTicksPerIteration);
    benchmark::DoNotOptimize(rig.plant().mechanical_angle_rad());
  }
  report(state);
}

}  // namespace

int main(int argc, char** argv) {
  benchmark::Initialize(&argc, argv);
  if (benchmark::ReportUnrecognizedArguments(argc, argv)) return 1;
  benchmark::RegisterBenchmark(kBaselineName, ideal_motor)->Unit(benchmark::kMillisecond);
  benchmark::RegisterBenchmark("servo_velocity/default-24v", servo_velocity, "default-24v")->Unit(benchmark::kMillisecond);
  benchmark::RegisterBenchmark("servo_position/default-24v", servo_position, "default-24v")->Unit(benchmark::kMillisecond);
  benchmark::RegisterBenchmark("servo_position/large-48v", servo_position, "large-48v")->Unit(benchmark::kMillisecond);
  benchmark::RegisterBenchmark("servo_velocity/dc-24v", servo_velocity, "dc-24v")->Unit(benchmark::kMillisecond);
  motwin::bench::RealTimeFactorReporter reporter({kBaselineName, "the ideal motor", kGoalRealTimeFactor, 40});
  benchmark::RunSpecifiedBenchmarks(&reporter);
  benchmark::Shutdown();
  return 0;
}
