// Frames per second through serve_serial_frame() on a TMCM-1636 core (RAM EEPROM, scripted
// I/O), in process: framing, checksum, dispatch, parameter table, reply encoding. A baseline
// measured in the same run (the checksum of the frame alone) turns the absolute times into
// ratios that compare across machines. See docs/benchmarks.md.
#include <benchmark/benchmark.h>

#include <cstdio>
#include <map>
#include <memory>
#include <string>
#include <vector>

#include "bench_support.h"
#include "../tests/unit/support/tmcm1636_rig.h"
#include "core/tmcl/serial_link.h"
#include "tools/tmcl_mnemonics.h"

namespace {

using motwin::tmcl::Frame;

constexpr uint8_t kModuleAddress = 1;
constexpr const char* kBaselineName = "checksum_baseline";

Frame request_frame(const char* text) {
  const auto instruction = motwin::tools::parse_instruction(text);
  if (!instruction) {
    std::fprintf(stderr, "bench_tmcl_dispatch: %s: %s\n", text, instruction.error().c_str());
    std::abort();
  }
  return motwin::tmcl::encode_request(kModuleAddress, instruction.value());
}

Frame with_bad_checksum(Frame frame) {
  frame[motwin::tmcl::kFrameLength - 1] = static_cast<uint8_t>(frame[motwin::tmcl::kFrameLength - 1] + 1);
  return frame;
}

struct DispatchCase {
  std::string name;
  Frame frame;
};

std::vector<DispatchCase> dispatch_cases() {
  return {
      {"serve_serial_frame/GAP 52 actual position", request_frame("GAP 52, 0")},
      {"serve_serial_frame/SAP 43 max velocity", request_frame("SAP 43, 0, 4000")},
      {"serve_serial_frame/GGP 66 serial address", request_frame("GGP 66, 0")},
      {"serve_serial_frame/checksum error", with_bad_checksum(request_frame("GAP 52, 0"))},
  };
}

motwin::testing::Tmcm1636Rig& rig() {
  static auto* shared_rig = new motwin::testing::Tmcm1636Rig();
  return *shared_rig;
}

void serve_frames(benchmark::State& state, Frame frame) {
  motwin::testing::Tmcm1636Rig& module = rig();
  for (auto _ : state) {
    benchmark::DoNotOptimize(frame);
    motwin::tmcl::SerialResponse response = module.send(frame);
    benchmark::DoNotOptimize(response);
  }
  state.SetItemsProcessed(state.iterations());
}

void checksum_only(benchmark::State& state, Frame frame) {
  for (auto _ : state) {
    benchmark::DoNotOptimize(frame);  // the compiler may not fold the sum of a known frame
    uint8_t sum = motwin::tmcl::checksum(frame.data(), motwin::tmcl::kFrameLength - 1);
    benchmark::DoNotOptimize(sum);
  }
  state.SetItemsProcessed(state.iterations());
}

// The console table, then each case's time as a multiple of the baseline.
class RatioReporter final : public motwin::bench::SummaryReporter {
 public:
  void Finalize() override {
    ConsoleReporter::Finalize();
    const auto baseline = nanoseconds_per_frame_.find(kBaselineName);
    if (baseline == nanoseconds_per_frame_.end() || baseline->second <= 0) return;
    std::printf("\nRelative to %s (%.2f ns), same run:\n", kBaselineName, baseline->second);
    for (const auto& [name, nanoseconds] : nanoseconds_per_frame_) {
      if (name == kBaselineName) continue;
      std::printf("  %-45s %9.1f ns  %7.1fx baseline  %7.2f M frames/s\n", name.c_str(), nanoseconds,
                  nanoseconds / baseline->second, 1e3 / nanoseconds);
    }
  }

 protected:
  void collect(const Run& run) override {
    nanoseconds_per_frame_[run.run_name.function_name] = motwin::bench::real_time_seconds(run) * 1e9;
  }

 private:
  std::map<std::string, double> nanoseconds_per_frame_;
};

}  // namespace

int main(int argc, char** argv) {
  benchmark::Initialize(&argc, argv);
  if (benchmark::ReportUnrecognizedArguments(argc, argv)) return 1;
  benchmark::RegisterBenchmark(kBaselineName, checksum_only, request_frame("GAP 52, 0"));
  for (const DispatchCase& dispatch_case : dispatch_cases()) {
    benchmark::RegisterBenchmark(dispatch_case.name.c_str(), serve_frames, dispatch_case.frame);
  }
  RatioReporter reporter;
  benchmark::RunSpecifiedBenchmarks(&reporter);
  benchmark::Shutdown();
  return 0;
}
