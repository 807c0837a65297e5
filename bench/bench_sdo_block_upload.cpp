// Time for a 100 kB upload through the SDO server (issue 6): block transfer with CRC in sub-blocks
// of 127 segments against the segmented transfer of the same value, measured in the same run
// (the ratio is the figure; docs/benchmarks.md). In-process, frame by frame, no bus: what is
// measured is the server's protocol work and the streaming of the value through its buffer.
#include <benchmark/benchmark.h>

#include <cstdio>
#include <map>
#include <string>

#include "bench_support.h"
#include "core/canopen/sdo_server.h"
#include "../tests/unit/support/sdo_frames.h"

namespace {

using motwin::canopen::SdoServer;
using motwin::testing::block_upload;
using motwin::testing::frame_of;
using motwin::testing::RecordingCanController;
using motwin::testing::StreamingDictionary;

constexpr size_t kValueBytes = 100'000;

// The server under test, answering into a recording controller, with a kValueBytes domain at 2100.
struct UploadRig {
  UploadRig() { dictionary.domain_size = kValueBytes; }  // the server only keeps a reference

  StreamingDictionary dictionary;
  RecordingCanController can;
  SdoServer server{dictionary, can};
};

// Throughput of a case whose last upload delivered `received` bytes; an error if that is not the value.
void report(benchmark::State& state, size_t received, const char* wrong_size_error) {
  if (received != kValueBytes) state.SkipWithError(wrong_size_error);
  state.SetBytesProcessed(static_cast<int64_t>(state.iterations() * kValueBytes));
}

void BM_SdoUpload100kB_Segmented(benchmark::State& state) {
  UploadRig rig;
  SdoServer& server = rig.server;
  RecordingCanController& can = rig.can;
  size_t received = 0;
  for (auto _ : state) {
    server.on_request(frame_of(0x601, {0x40, 0x00, 0x21, 0x00, 0, 0, 0, 0}));
    server.process(0);
    can.take();
    uint8_t toggle = 0;
    received = 0;
    for (;;) {
      server.on_request(frame_of(0x601, {static_cast<uint8_t>(0x60 | toggle), 0, 0, 0, 0, 0, 0, 0}));
      server.process(0);
      const uint8_t command = can.frames.at(0).data[0];
      can.frames.clear();
      received += 7 - ((command >> 1) & 0x07);
      toggle ^= 0x10;
      if ((command & 0x01) != 0) break;
    }
  }
  report(state, received, "segmented upload delivered the wrong size");
}
BENCHMARK(BM_SdoUpload100kB_Segmented)->Unit(benchmark::kMillisecond);

void BM_SdoUpload100kB_Block(benchmark::State& state) {
  UploadRig rig;
  size_t received = 0;
  for (auto _ : state) {
    received = block_upload(rig.server, rig.can, 0x2100, 127).data.size();
  }
  report(state, received, "block upload delivered the wrong size");
}
BENCHMARK(BM_SdoUpload100kB_Block)->Unit(benchmark::kMillisecond);

// After the table: the time per 100 kB of each transfer and its ratio to the segmented upload.
class UploadReporter final : public motwin::bench::SummaryReporter {
 public:
  void Finalize() override {
    ConsoleReporter::Finalize();
    const auto baseline = seconds_.find("BM_SdoUpload100kB_Segmented");
    std::printf("\nOne 100 kB upload from the SDO server, in process, same run:\n");
    for (const auto& [name, seconds] : seconds_) {
      std::printf("  %-30s %8.3f ms", name.c_str(), seconds * 1e3);
      if (baseline != seconds_.end() && seconds > 0.0) std::printf("   %.2fx the segmented upload", seconds / baseline->second);
      std::printf("\n");
    }
  }

 protected:
  void collect(const Run& run) override { seconds_[run.run_name.function_name] = motwin::bench::real_time_seconds(run); }

 private:
  std::map<std::string, double> seconds_;
};

}  // namespace

int main(int argc, char** argv) {
  benchmark::Initialize(&argc, argv);
  if (benchmark::ReportUnrecognizedArguments(argc, argv)) return 1;
  UploadReporter reporter;
  benchmark::RunSpecifiedBenchmarks(&reporter);
  benchmark::Shutdown();
  return 0;
}
