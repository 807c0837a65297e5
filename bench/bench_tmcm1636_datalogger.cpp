// What the datalogger (command 142, docs/datalogger.md) costs the simulation: the real-time
// factor of one TMCM-1636 servo axis (velocity mode at 2000 rpm under load, the full cascade on
// the motor plant) while a capture of 2000 samples of two channels (AP 42 velocity, AP 0 phase A
// ADC) at the full 2000 Hz base rate runs, against the same run without a capture, measured in
// the same run. Each iteration is one simulated second, the length of such a capture. Goal
// (issue 16): the capture costs at most 10 % of the real-time factor. See docs/benchmarks.md.
#include <benchmark/benchmark.h>

#include <cstdio>
#include <map>
#include <string>

#include "bench_support.h"
#include "../tests/unit/support/tmcm1636_servo_rig.h"

namespace {

using motwin::testing::Tmcm1636ServoRig;

constexpr const char* kBaselineName = "servo_baseline_without_capture";
constexpr const char* kCaptureName = "servo_capturing_2ch_2000hz";
constexpr double kGoalRatio = 0.90;
constexpr uint64_t kTicksPerIteration = 20'000;  // one simulated second
constexpr double kSimSecondsPerIteration = kTicksPerIteration * motwin::modules::tmcm1636::kControlTickUs * 1e-6;
constexpr uint8_t kRamDebug = 142;

Tmcm1636ServoRig& turning_rig() {
  static Tmcm1636ServoRig rig(Tmcm1636ServoRig::preset("default-24v"));
  static bool started = false;
  if (!started) {
    rig.ror(2000);
    rig.set("LOAD_TORQUE", 0.01);
    rig.run_ticks(40'000);  // up to speed
    started = true;
  }
  return rig;
}

void without_capture(benchmark::State& state) {
  Tmcm1636ServoRig& rig = turning_rig();
  for (auto _ : state) {
    rig.run_ticks(kTicksPerIteration);
    benchmark::DoNotOptimize(rig.plant().speed_rad_s());
  }
  motwin::bench::report_real_time_factor(state, kSimSecondsPerIteration);
}

// Each iteration arms a new capture (INIT, 4000 words, prescaler 0, AP 42 and AP 0, unconditional)
// and simulates the second it lasts; the last iteration checks that it completed.
void with_capture(benchmark::State& state) {
  Tmcm1636ServoRig& rig = turning_rig();
  bool completed = true;
  for (auto _ : state) {
    rig.command(kRamDebug, 0, 0, 0);
    rig.command(kRamDebug, 1, 0, 4000);
    rig.command(kRamDebug, 3, 0, 0);
    rig.command(kRamDebug, 4, 1, 42);
    rig.command(kRamDebug, 4, 1, 0);
    rig.command(kRamDebug, 7, 0, 0);
    rig.run_ticks(kTicksPerIteration);
    completed = completed && rig.command(kRamDebug, 8, 0, 0).value == 3;
    benchmark::DoNotOptimize(rig.plant().speed_rad_s());
  }
  if (!completed) state.SkipWithError("the capture did not complete within its simulated second");
  motwin::bench::report_real_time_factor(state, kSimSecondsPerIteration);
}

// The real-time factors in the format of bench_support.h's reporter (scripts/bench.sh reads it),
// with the capture's ratio to the run without it.
class CaptureCostReporter final : public motwin::bench::SummaryReporter {
 public:
  void Finalize() override {
    ConsoleReporter::Finalize();
    std::printf("\nReal-time factor (simulated seconds per CPU second, one core), same run:\n");
    const auto baseline = factor_.find(kBaselineName);
    const auto capture = factor_.find(kCaptureName);
    if (baseline != factor_.end()) std::printf("  %-32s %9.0fx\n", kBaselineName, baseline->second);
    if (capture != factor_.end()) {
      std::printf("  %-32s %9.0fx", kCaptureName, capture->second);
      if (baseline != factor_.end() && baseline->second > 0.0) {
        const double ratio = capture->second / baseline->second;
        std::printf("  (capture/without %.3f, goal >= %.2f: %s)", ratio, kGoalRatio, ratio >= kGoalRatio ? "met" : "NOT met");
      }
      std::printf("\n");
    }
  }

 protected:
  void collect(const Run& run) override {
    const auto factor = motwin::bench::find_counter(run, "sim_s_per_s");
    if (factor) factor_[run.run_name.function_name] = *factor;
  }

 private:
  std::map<std::string, double> factor_;
};

}  // namespace

int main(int argc, char** argv) {
  benchmark::Initialize(&argc, argv);
  if (benchmark::ReportUnrecognizedArguments(argc, argv)) return 1;
  benchmark::RegisterBenchmark(kBaselineName, without_capture)->Unit(benchmark::kMillisecond);
  benchmark::RegisterBenchmark(kCaptureName, with_capture)->Unit(benchmark::kMillisecond);
  CaptureCostReporter reporter;
  benchmark::RunSpecifiedBenchmarks(&reporter);
  benchmark::Shutdown();
  return 0;
}
