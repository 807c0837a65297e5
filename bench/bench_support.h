// Shared by the benchmarks that end with a summary per case after the console table: each case
// compared with a baseline measured in the same run (docs/benchmarks.md).
#pragma once

#include <benchmark/benchmark.h>
#include <unistd.h>

#include <cstdio>
#include <map>
#include <optional>
#include <string>
#include <vector>

namespace motwin::bench {

using Run = benchmark::BenchmarkReporter::Run;

// A user counter of `run`; nullopt when the case did not set it.
inline std::optional<double> find_counter(const Run& run, const std::string& name) {
  const auto found = run.counters.find(name);
  if (found == run.counters.end()) return std::nullopt;
  return found->second.value;
}

// The adjusted real time of `run` (per iteration) in seconds, whatever unit the case reports in.
inline double real_time_seconds(const Run& run) {
  switch (run.time_unit) {
    case benchmark::kNanosecond: return run.GetAdjustedRealTime() * 1e-9;
    case benchmark::kMicrosecond: return run.GetAdjustedRealTime() * 1e-6;
    case benchmark::kMillisecond: return run.GetAdjustedRealTime() * 1e-3;
    case benchmark::kSecond: return run.GetAdjustedRealTime();
  }
  return run.GetAdjustedRealTime();
}

// The console table (colours only on a terminal, as the library's own reporter chooses by
// default). collect() sees each run a summary compares: the plain runs or, with
// --benchmark_repetitions, the median aggregates; failed runs are left out.
class SummaryReporter : public benchmark::ConsoleReporter {
 public:
  SummaryReporter() : ConsoleReporter(::isatty(STDOUT_FILENO) ? OO_Defaults : OO_Tabular) {}

  void ReportRuns(const std::vector<Run>& runs) override {
    ConsoleReporter::ReportRuns(runs);
    for (const Run& run : runs) {
      if (run.error_occurred) continue;
      const bool is_median = run.run_type == Run::RT_Aggregate && run.aggregate_name == "median";
      if (run.run_type == Run::RT_Iteration || is_median) collect(run);
    }
  }

 protected:
  virtual void collect(const Run& run) = 0;
};

// Simulated seconds per second of CPU time, as counter "sim_s_per_s", for a case that simulates
// `sim_seconds_per_iteration` per iteration.
inline void report_real_time_factor(benchmark::State& state, double sim_seconds_per_iteration) {
  const double simulated_s = sim_seconds_per_iteration * static_cast<double>(state.iterations());
  state.counters["sim_s_per_s"] = benchmark::Counter(simulated_s, benchmark::Counter::kIsRate);
}

// The summary of the simulation-speed benchmarks: each case's real-time factor, how much slower
// than the baseline it is, and whether it meets the goal.
struct RealTimeFactorSummary {
  const char* baseline_name;   // the case the others are compared with
  const char* baseline_label;  // "the ideal motor": printed as "(2.0x slower than <label>)"
  double goal;                 // least acceptable real-time factor
  int name_width;              // of the case name column
  // Cases held to another case of the same run: `name` runs at least `least_ratio` of `reference`'s
  // real-time factor, and at most `most_ratio` of it when that is set (the TMCM-1636's CANopen
  // firmware against its TMCL firmware on one motion; the TMCM-3216's TMCL firmware within 10 %
  // of its CANopen firmware).
  struct Comparison {
    const char* name;
    const char* reference;
    const char* label;  // "canopen/tmcl"
    double least_ratio;
    double most_ratio = 0.0;  // 0: no upper bound
  };
  std::vector<Comparison> comparisons = {};
};

class RealTimeFactorReporter final : public SummaryReporter {
 public:
  explicit RealTimeFactorReporter(const RealTimeFactorSummary& summary) : summary_(summary) {}

  void Finalize() override {
    ConsoleReporter::Finalize();
    const auto baseline = factor_.find(summary_.baseline_name);
    std::printf("\nReal-time factor (simulated seconds per CPU second, one core), same run:\n");
    for (const auto& [name, factor] : factor_) {
      std::printf("  %-*s %9.0fx", summary_.name_width, name.c_str(), factor);
      if (baseline != factor_.end() && name != summary_.baseline_name && factor > 0.0) {
        std::printf("  (%5.1fx slower than %s)  goal >= %.0fx: %s", baseline->second / factor, summary_.baseline_label,
                    summary_.goal, factor >= summary_.goal ? "met" : "NOT met");
      }
      for (const RealTimeFactorSummary::Comparison& c : summary_.comparisons) {
        const auto reference = factor_.find(c.reference);
        if (name != c.name || reference == factor_.end() || reference->second <= 0.0) continue;
        const double ratio = factor / reference->second;
        const bool bounded = c.most_ratio > 0.0;
        const bool met = ratio >= c.least_ratio && (!bounded || ratio <= c.most_ratio);
        if (bounded) {
          std::printf("; %s %.3f, goal %.2f..%.2f: %s", c.label, ratio, c.least_ratio, c.most_ratio, met ? "met" : "NOT met");
        } else {
          std::printf("; %s %.3f, goal >= %.2f: %s", c.label, ratio, c.least_ratio, met ? "met" : "NOT met");
        }
      }
      std::printf("\n");
    }
  }

 protected:
  void collect(const Run& run) override {
    const std::optional<double> factor = find_counter(run, "sim_s_per_s");
    if (factor) factor_[run.run_name.function_name] = *factor;
  }

 private:
  RealTimeFactorSummary summary_;
  std::map<std::string, double> factor_;
};

}  // namespace motwin::bench
