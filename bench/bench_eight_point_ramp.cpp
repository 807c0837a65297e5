// Cost of one 50 µs tick of the TMCM-3216's EightPoint ramp generator (band walk, braking curve
// solved every tick) against the plain TrapezoidRamp doing the same moves in the same run. The
// three axes of the module each run one ramp per tick, so this is a small part of its budget;
// the ratio says what the eight points cost over the trapezoid. Also the EightPoint ramp as a
// trapezoid (V1 = V2 = 0) and in velocity mode.
#include <benchmark/benchmark.h>

#include <cstdio>
#include <map>
#include <string>
#include <vector>

#include "bench_support.h"
#include "core/motion/eight_point_ramp.h"
#include "core/motion/trapezoid_ramp.h"

namespace {

using motwin::motion::EightPointConfig;
using motwin::motion::EightPointRamp;
using motwin::motion::TrapezoidRamp;
using motwin::motion::TrapezoidRampConfig;

constexpr const char* kBaselineName = "trapezoid_ramp_baseline";
constexpr double kDt = 50e-6;
constexpr int kTicksPerIteration = 20'000;  // one simulated second
constexpr int32_t kMove = 60'000;            // accelerates, cruises and brakes within the second

EightPointConfig eight_point() {
  EightPointConfig c;
  c.vstart_pps = 500;
  c.a1_pps2 = 400000;
  c.v1_pps = 20000;
  c.a2_pps2 = 800000;
  c.v2_pps = 60000;
  c.vmax_pps = 100000;
  c.amax_pps2 = 400000;
  c.dmax_pps2 = 600000;
  c.d2_pps2 = 900000;
  c.d1_pps2 = 500000;
  c.vstop_pps = 1000;
  return c;
}

void report(benchmark::State& state) {
  // Seconds per tick (the console shows it with an SI prefix, e.g. 25n).
  state.counters["time_per_tick"] = benchmark::Counter(static_cast<double>(state.iterations()) * kTicksPerIteration,
                                                       benchmark::Counter::kIsRate | benchmark::Counter::kInvert);
}

void trapezoid(benchmark::State& state) {
  const TrapezoidRampConfig config{100000, 400000, true};
  TrapezoidRamp ramp;
  int32_t target = kMove;
  for (auto _ : state) {
    ramp.set_position_target(target);
    target = target == 0 ? kMove : 0;
    for (int i = 0; i < kTicksPerIteration; ++i) ramp.step(config, kDt);
    benchmark::DoNotOptimize(ramp.position_q16());
  }
  report(state);
}

void eight_point_moves(benchmark::State& state, EightPointConfig config) {
  EightPointRamp ramp;
  int32_t target = kMove;
  for (auto _ : state) {
    ramp.set_position_target(target);
    target = target == 0 ? kMove : 0;
    for (int i = 0; i < kTicksPerIteration; ++i) ramp.step(config, kDt);
    benchmark::DoNotOptimize(ramp.position_q32());
  }
  if (ramp.velocity() != 0.0) state.SkipWithError("move did not end within the second");
  report(state);
}

void eight_point_velocity(benchmark::State& state) {
  const EightPointConfig config = eight_point();
  EightPointRamp ramp;
  double target = 90000;
  for (auto _ : state) {
    ramp.set_velocity_target(target);
    target = -target;
    for (int i = 0; i < kTicksPerIteration; ++i) ramp.step(config, kDt);
    benchmark::DoNotOptimize(ramp.position_q32());
  }
  report(state);
}

class RatioReporter final : public motwin::bench::SummaryReporter {
 public:
  void Finalize() override {
    ConsoleReporter::Finalize();
    const auto baseline = seconds_per_tick_.find(kBaselineName);
    std::printf("\nCost of one 50 us ramp tick (one core), same run:\n");
    for (const auto& [name, seconds] : seconds_per_tick_) {
      std::printf("  %-34s %7.1f ns", name.c_str(), seconds * 1e9);
      if (baseline != seconds_per_tick_.end() && name != kBaselineName && baseline->second > 0.0) {
        std::printf("  (%4.2fx the trapezoid)", seconds / baseline->second);
      }
      std::printf("\n");
    }
  }

 protected:
  void collect(const Run& run) override {
    if (const std::optional<double> seconds = motwin::bench::find_counter(run, "time_per_tick")) {
      seconds_per_tick_[run.run_name.function_name] = *seconds;
    }
  }

 private:
  std::map<std::string, double> seconds_per_tick_;
};

}  // namespace

int main(int argc, char** argv) {
  benchmark::Initialize(&argc, argv);
  if (benchmark::ReportUnrecognizedArguments(argc, argv)) return 1;
  EightPointConfig as_trapezoid = eight_point();
  as_trapezoid.v1_pps = 0;
  as_trapezoid.v2_pps = 0;
  benchmark::RegisterBenchmark(kBaselineName, trapezoid)->Unit(benchmark::kMicrosecond);
  benchmark::RegisterBenchmark("eight_point_ramp_moves", eight_point_moves, eight_point())
      ->Unit(benchmark::kMicrosecond);
  benchmark::RegisterBenchmark("eight_point_ramp_as_trapezoid", eight_point_moves, as_trapezoid)
      ->Unit(benchmark::kMicrosecond);
  benchmark::RegisterBenchmark("eight_point_ramp_velocity_mode", eight_point_velocity)->Unit(benchmark::kMicrosecond);
  RatioReporter reporter;
  benchmark::RunSpecifiedBenchmarks(&reporter);
  benchmark::Shutdown();
  return 0;
}
