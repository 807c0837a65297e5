// TMCL interpreter speed: instructions per simulated second and per wall-clock second, on a
// virtual TMCM-1636 (in memory) driven by the host runtime in `fast` pacing, exactly as
// `motwin serve --speed fast` runs it (tick chunks of 1 ms sim time, descriptors polled between
// them). The baseline, measured in the same run, is the same module ticking with no program
// running; each case is printed as a multiple of it, with the marginal cost per instruction.
// Prints figures only; see docs/benchmarks.md.
#include <benchmark/benchmark.h>

#include <cstdio>
#include <cstdlib>
#include <map>
#include <memory>
#include <string>
#include <vector>

#include "bench_support.h"
#include "core/tmcl/engine.h"
#include "host/host_runtime.h"
#include "host/module_registry.h"
#include "host/pacing.h"
#include "tools/tmcl_assembler.h"

namespace {

using namespace motwin;

constexpr const char* kBaselineName = "idle_module_baseline";
constexpr uint64_t kSimUsPerIteration = 1'000'000;  // one simulated second per iteration

struct Case {
  std::string name;
  std::string source;  // empty: no program (baseline)
};

std::vector<Case> cases() {
  return {
      {kBaselineName, ""},
      // The tight loop: one arithmetic instruction and one jump.
      {"calc_ja_loop", "Loop: CALC ADD, 1\n      JA Loop\n"},
      // Through the engine's dispatcher and the parameter table: a read, a compare, a branch.
      {"gap_comp_jc_loop", "Loop: GAP 52, 0\n      COMP 1000\n      JC GE, Loop\n      JA Loop\n"},
      // Almost all the time in WAIT TICKS (10 ms): a waiting program costs next to nothing.
      {"wait_ticks_loop", "Loop: CALC ADD, 1\n      WAIT TICKS, 0, 1\n      JA Loop\n"},
  };
}

struct Rig {
  std::unique_ptr<host::VirtualModule> module;
  std::unique_ptr<host::HostRuntime> runtime;
};

Rig make_rig(const std::string& source) {
  host::ModuleOptions options;
  options.log = [](const std::string&) {};
  host::MakeModuleResult made = host::make_module("tmcm-1636", options);
  if (!made) {
    std::fprintf(stderr, "bench_interpreter: %s\n", made.error().c_str());
    std::exit(2);
  }
  Rig rig{std::move(*made), nullptr};
  tmcl::TmclEngine& engine = rig.module->engine();
  if (!source.empty()) {
    const tools::AssemblyResult assembled = tools::assemble_source(source, "bench.tmc");
    if (!assembled.ok()) {
      std::fprintf(stderr, "bench_interpreter: %s\n", tools::format_error(assembled.errors.front()).c_str());
      std::exit(2);
    }
    engine.execute({tmcl::command::kEnterDownloadMode, 0, 0, 0}, tmcl::Origin::kHost);
    for (const tmcl::Instruction& in : assembled.instructions) engine.execute(in, tmcl::Origin::kHost);
    engine.execute({tmcl::command::kExitDownloadMode, 0, 0, 0}, tmcl::Origin::kHost);
    engine.execute({tmcl::command::kRunApplication, 1, 0, 0}, tmcl::Origin::kHost);
  }
  rig.runtime = std::make_unique<host::HostRuntime>(*rig.module, host::Pacing::fast());
  rig.runtime->start();
  return rig;
}

void run_case(benchmark::State& state, const std::string& source) {
  Rig rig = make_rig(source);
  host::HostRuntime& runtime = *rig.runtime;
  const tmcl::TmclInterpreter& interpreter = rig.module->engine().interpreter();
  const uint64_t instructions_before = interpreter.instructions_executed();
  uint64_t simulated_us = 0;
  for (auto _ : state) {
    const uint64_t until_us = runtime.sim_time_us() + kSimUsPerIteration;
    while (runtime.sim_time_us() < until_us) runtime.step(0);
    simulated_us += kSimUsPerIteration;
  }
  const auto instructions = static_cast<double>(interpreter.instructions_executed() - instructions_before);
  const double simulated_s = static_cast<double>(simulated_us) * 1e-6;
  state.counters["instr_per_sim_s"] = benchmark::Counter(simulated_s > 0 ? instructions / simulated_s : 0.0);
  state.counters["instr_per_wall_s"] = benchmark::Counter(instructions, benchmark::Counter::kIsRate);
  state.counters["sim_s_per_wall_s"] = benchmark::Counter(simulated_s, benchmark::Counter::kIsRate);
  state.counters["instr_per_iteration"] =
      benchmark::Counter(state.iterations() > 0 ? instructions / static_cast<double>(state.iterations()) : 0.0);
}

// The console table, then each case against the idle baseline.
class RatioReporter final : public motwin::bench::SummaryReporter {
 public:
  void Finalize() override {
    ConsoleReporter::Finalize();
    const auto baseline = figures_.find(kBaselineName);
    if (baseline == figures_.end() || baseline->second.wall_ms_per_sim_s <= 0) return;
    const double base_ms = baseline->second.wall_ms_per_sim_s;
    std::printf("\nOne simulated second of a TMCM-1636 (20000 control ticks) in fast pacing, same run:\n");
    std::printf("  %-22s %10.2f ms wall  %8.1fx real time   (no program)\n", kBaselineName, base_ms,
                1000.0 / base_ms);
    for (const auto& [name, f] : figures_) {
      if (name == kBaselineName) continue;
      const double extra_ns = f.instructions_per_iteration > 0
                                  ? (f.wall_ms_per_sim_s - base_ms) * 1e6 / f.instructions_per_iteration
                                  : 0.0;
      std::printf("  %-22s %10.2f ms wall  %8.1fx real time  %5.2fx baseline  %7.0f instr/sim s  %6.2f M instr/wall s"
                  "  %+6.1f ns/instr over baseline\n",
                  name.c_str(), f.wall_ms_per_sim_s, 1000.0 / f.wall_ms_per_sim_s, f.wall_ms_per_sim_s / base_ms,
                  f.instructions_per_sim_s, f.instructions_per_wall_s * 1e-6, extra_ns);
    }
  }

 protected:
  void collect(const Run& run) override {
    Figures& figures = figures_[run.run_name.function_name];
    figures.wall_ms_per_sim_s = motwin::bench::real_time_seconds(run) * 1e3;
    const auto counter = [&](const char* name) { return motwin::bench::find_counter(run, name).value_or(0.0); };
    figures.instructions_per_sim_s = counter("instr_per_sim_s");
    figures.instructions_per_wall_s = counter("instr_per_wall_s");
    figures.instructions_per_iteration = counter("instr_per_iteration");
  }

 private:
  struct Figures {
    double wall_ms_per_sim_s = 0;
    double instructions_per_sim_s = 0;
    double instructions_per_wall_s = 0;
    double instructions_per_iteration = 0;
  };

  std::map<std::string, Figures> figures_;
};

}  // namespace

int main(int argc, char** argv) {
  benchmark::Initialize(&argc, argv);
  if (benchmark::ReportUnrecognizedArguments(argc, argv)) return 1;
  for (const Case& c : cases()) {
    benchmark::RegisterBenchmark(c.name.c_str(), run_case, c.source)->Unit(benchmark::kMillisecond)->UseRealTime();
  }
  RatioReporter reporter;
  benchmark::RunSpecifiedBenchmarks(&reporter);
  benchmark::Shutdown();
  return 0;
}
