// Sustained PDO exchange at a 1 kHz SYNC with three axes mapped (issue 6 benchmark), in process:
// a virtual TMCM-3216 (host::make_module, ideal motors) on a host::CanBus at 1 Mbit/s, a master
// endpoint on the same bus, stepped simulated time. Per SYNC period (1 ms): the master sends one
// synchronous RPDO per axis (controlword 6040 + target position 607A, csp), then the SYNC; at the
// SYNC the module writes the RPDOs and sends one synchronous TPDO per axis (statusword 6041 +
// position actual value 6064); then the module runs 1 ms of 50 µs ticks. The baseline, measured
// in the same run, is the same module, configured and operational, ticking with no PDO traffic.
// Figures: real-time factor (simulated seconds per wall second) of each, their ratio, and PDOs
// per wall second; the bus load of the traffic at 1 Mbit/s. Everything goes through the public
// API: SDO frames configure the PDOs, NMT starts the node. docs/benchmarks.md.
#include <benchmark/benchmark.h>

#include <cstdio>
#include <map>
#include <memory>
#include <string>
#include <vector>

#include "bench_support.h"
#include "host/can_bus.h"
#include "host/module_registry.h"
#include "host/virtual_module.h"

namespace {

using motwin::can::CanFrame;
using motwin::host::CanBus;
using motwin::host::CanBusEndpoint;
using motwin::host::VirtualModule;

constexpr const char* kBaselineName = "tmcm3216_no_pdo_traffic_baseline";
constexpr uint8_t kNode = 1;
constexpr uint8_t kAxes = 3;
constexpr uint32_t kSyncPeriodUs = 1000;
constexpr uint32_t kSyncsPerIteration = 100;  // 0.1 s of simulated time
constexpr double kSimSecondsPerIteration = kSyncsPerIteration * kSyncPeriodUs * 1e-6;
constexpr uint16_t kAxisObjectStride = 0x800;  // 6040 -> 6840 -> 7040 (manual 2.6.1)
constexpr uint16_t kPdoAxisStride = 0x40;      // 1402 -> 1442 -> 1482
constexpr uint32_t kRpdoCobId[kAxes] = {0x401, 0x411, 0x421};
constexpr uint32_t kTpdoCobId[kAxes] = {0x381, 0x391, 0x3A1};
constexpr int32_t kStepsPerSync = 5;  // csp target increment: 5000 steps/s

CanFrame frame_of(uint32_t id, std::initializer_list<uint8_t> data) {
  const std::vector<uint8_t> bytes(data);
  return motwin::can::make_frame(id, bytes.data(), static_cast<uint8_t>(bytes.size()));
}

// The master's controller: counts the TPDOs and keeps the last SDO answer.
struct Master final : CanBusEndpoint {
  uint64_t tpdos = 0;
  uint16_t statusword[kAxes] = {};
  CanFrame sdo_answer{};
  bool has_sdo_answer = false;

  void on_frame(const CanFrame& frame, uint64_t /*timestamp_us*/) override {
    if (frame.id == 0x580u + kNode) {
      sdo_answer = frame;
      has_sdo_answer = true;
      return;
    }
    for (uint8_t axis = 0; axis < kAxes; ++axis) {
      if (frame.id == kTpdoCobId[axis]) {
        ++tpdos;
        statusword[axis] = static_cast<uint16_t>(frame.data[0] | (frame.data[1] << 8));
      }
    }
  }
};

// A TMCM-3216 and a master on one 1 Mbit/s bus, PDOs configured, node operational.
class SyncPdoRig {
 public:
  SyncPdoRig() {
    motwin::host::ModuleOptions options;
    options.node_id = kNode;
    options.log = [](const std::string&) {};
    motwin::host::MakeModuleResult made = motwin::host::make_module("tmcm-3216", options);
    if (!made) {
      error_ = "cannot make the tmcm-3216";
      return;
    }
    module_ = std::move(*made);
    bus_.set_clock([this] { return module_->sim_time_us(); });
    bus_.set_bit_rate(1'000'000);
    master_id_ = bus_.attach(master_);
    module_->can_node()->connect(bus_);
    configure();
  }
  ~SyncPdoRig() {
    if (module_) module_->can_node()->disconnect();
  }
  SyncPdoRig(const SyncPdoRig&) = delete;
  SyncPdoRig& operator=(const SyncPdoRig&) = delete;

  const std::string& error() const { return error_; }
  Master& master() { return master_; }
  CanBus& bus() { return bus_; }

  // One SYNC period: RPDOs, SYNC, 1 ms of module ticks.
  void sync_period(uint16_t controlword) {
    const auto byte = [](uint32_t value, int shift) { return static_cast<uint8_t>(value >> shift); };
    const auto target = static_cast<uint32_t>(target_);
    for (uint8_t axis = 0; axis < kAxes; ++axis) {
      bus_.send(master_id_, frame_of(kRpdoCobId[axis], {byte(controlword, 0), byte(controlword, 8), byte(target, 0),
                                                        byte(target, 8), byte(target, 16), byte(target, 24)}));
    }
    bus_.send(master_id_, frame_of(0x080, {}));
    run_us(kSyncPeriodUs);
    if (controlword == 0x0F) target_ += kStepsPerSync;
  }
  void run_us(uint32_t us) { module_->run_ticks(us / module_->tick_period_us()); }

 private:
  bool sdo_write(uint16_t index, uint8_t sub, uint32_t value, uint8_t size) {
    const uint8_t command = static_cast<uint8_t>(0x23 | ((4 - size) << 2));
    master_.has_sdo_answer = false;
    const auto byte = [](uint32_t word, int shift) { return static_cast<uint8_t>(word >> shift); };
    bus_.send(master_id_, frame_of(0x600 + kNode, {command, byte(index, 0), byte(index, 8), sub, byte(value, 0),
                                                   byte(value, 8), byte(value, 16), byte(value, 24)}));
    const bool ok = master_.has_sdo_answer && master_.sdo_answer.data[0] == 0x60;
    if (!ok && error_.empty()) {
      char text[96];
      std::snprintf(text, sizeof(text), "SDO write %04X sub %u refused", index, sub);
      error_ = text;
    }
    return ok;
  }

  // python-canopen's order: COB-ID invalid, transmission type, COB-ID valid. The default mappings
  // are already RPDO 3 = 6040 + 607A and TPDO 3 = 6041 + 6064 of each axis (tables 45/47).
  void configure() {
    for (uint8_t axis = 0; axis < kAxes; ++axis) {
      const uint16_t rpdo = static_cast<uint16_t>(0x1402 + axis * kPdoAxisStride);
      const uint16_t tpdo = static_cast<uint16_t>(0x1802 + axis * kPdoAxisStride);
      sdo_write(rpdo, 1, kRpdoCobId[axis] | 0x8000'0000u, 4);
      sdo_write(rpdo, 2, 1, 1);  // synchronous: written at the next SYNC
      sdo_write(rpdo, 1, kRpdoCobId[axis], 4);
      sdo_write(tpdo, 1, kTpdoCobId[axis] | 0x8000'0000u, 4);
      sdo_write(tpdo, 2, 1, 1);  // every SYNC
      sdo_write(tpdo, 1, kTpdoCobId[axis] | 0x4000'0000u, 4);
      sdo_write(static_cast<uint16_t>(0x6060 + axis * kAxisObjectStride), 0, 8, 1);  // csp
    }
    bus_.send(master_id_, frame_of(0x000, {0x01, kNode}));  // NMT start
    run_us(10'000);
    // Shutdown, switch on, enable operation: the drives follow the RPDOs' controlwords.
    for (uint16_t controlword : {0x06, 0x07, 0x0F}) {
      for (int i = 0; i < 20; ++i) sync_period(controlword);
    }
    const uint64_t before = master_.tpdos;
    sync_period(0x0F);
    if (error_.empty() && master_.tpdos - before != kAxes) {
      error_ = "the TPDOs are not sent at every SYNC (mapping inactive?)";
    }
    for (uint8_t axis = 0; axis < kAxes && error_.empty(); ++axis) {
      if ((master_.statusword[axis] & 0x6F) != 0x27) error_ = "an axis did not reach OPERATION ENABLED";
    }
  }

  std::unique_ptr<VirtualModule> module_;
  CanBus bus_;
  Master master_;
  CanBus::EndpointId master_id_ = 0;
  int32_t target_ = 0;
  std::string error_;
};

void report(benchmark::State& state, uint64_t pdos) {
  const double sim_s = kSimSecondsPerIteration * static_cast<double>(state.iterations());
  state.counters["sim_s_per_s"] = benchmark::Counter(sim_s, benchmark::Counter::kIsRate);
  state.counters["pdos_per_s"] = benchmark::Counter(static_cast<double>(pdos), benchmark::Counter::kIsRate);
}

void tmcm3216_no_pdo_traffic_baseline(benchmark::State& state) {
  SyncPdoRig rig;
  if (!rig.error().empty()) {
    state.SkipWithError(rig.error().c_str());
    return;
  }
  for (auto _ : state) rig.run_us(kSyncsPerIteration * kSyncPeriodUs);
  report(state, 0);
}
BENCHMARK(tmcm3216_no_pdo_traffic_baseline)->Unit(benchmark::kMillisecond)->UseRealTime();

void tmcm3216_sync_1khz_3_rpdo_3_tpdo(benchmark::State& state) {
  SyncPdoRig rig;
  if (!rig.error().empty()) {
    state.SkipWithError(rig.error().c_str());
    return;
  }
  const uint64_t tpdos_before = rig.master().tpdos;
  const motwin::host::CanBusStats bus_before = rig.bus().stats();
  for (auto _ : state) {
    for (uint32_t i = 0; i < kSyncsPerIteration; ++i) rig.sync_period(0x0F);
  }
  const uint64_t syncs = static_cast<uint64_t>(state.iterations()) * kSyncsPerIteration;
  const uint64_t tpdos = rig.master().tpdos - tpdos_before;
  if (tpdos != syncs * kAxes) state.SkipWithError("a TPDO was missing at some SYNC");
  report(state, syncs * kAxes + tpdos);
  const motwin::host::CanBusStats& bus = rig.bus().stats();
  const double bus_time_ns = static_cast<double>(syncs) * kSyncPeriodUs * 1000.0;
  state.counters["bus_load_pct"] = 100.0 * static_cast<double>(bus.busy_ns - bus_before.busy_ns) / bus_time_ns;
}
BENCHMARK(tmcm3216_sync_1khz_3_rpdo_3_tpdo)->Unit(benchmark::kMillisecond)->UseRealTime();

class SyncPdoReporter final : public motwin::bench::SummaryReporter {
 public:
  void Finalize() override {
    ConsoleReporter::Finalize();
    const auto baseline = figures_.find(kBaselineName);
    std::printf("\nTMCM-3216 at a 1 kHz SYNC, three axes (simulated seconds per wall second), same run:\n");
    for (const auto& [name, figures] : figures_) {
      std::printf("  %-36s %7.1fx real time", name.c_str(), figures.factor);
      if (name != kBaselineName) {
        std::printf("  %9.0f PDOs/s  bus load %.0f %% at 1 Mbit/s", figures.pdos_per_s, figures.bus_load_pct);
        if (baseline != figures_.end() && figures.factor > 0.0) {
          std::printf("  (%.2fx the baseline's time)", baseline->second.factor / figures.factor);
        }
      }
      std::printf("\n");
    }
  }

 protected:
  void collect(const Run& run) override {
    Figures& figures = figures_[run.run_name.function_name];
    figures.factor = motwin::bench::find_counter(run, "sim_s_per_s").value_or(figures.factor);
    figures.pdos_per_s = motwin::bench::find_counter(run, "pdos_per_s").value_or(figures.pdos_per_s);
    figures.bus_load_pct = motwin::bench::find_counter(run, "bus_load_pct").value_or(figures.bus_load_pct);
  }

 private:
  struct Figures {
    double factor = 0;
    double pdos_per_s = 0;
    double bus_load_pct = 0;
  };
  std::map<std::string, Figures> figures_;
};

}  // namespace

int main(int argc, char** argv) {
  benchmark::Initialize(&argc, argv);
  if (benchmark::ReportUnrecognizedArguments(argc, argv)) return 1;
  SyncPdoReporter reporter;
  benchmark::RunSpecifiedBenchmarks(&reporter);
  benchmark::Shutdown();
  return 0;
}
