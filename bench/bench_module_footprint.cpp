// Memory per module instance and whole-module simulation speed, for every module `motwin serve`
// knows (host/module_registry.h, so a module added there is measured without touching this file).
//
// For each module: sizeof of the core profile where known; the resident memory one more
// instance costs (VmRSS growth over kInstances instances with in-memory EEPROM images, divided
// by kInstances, after one warm-up instance); and the real-time factor of one instance as the
// host runtime drives it (run_ticks on the module with its simulated board: simulated seconds
// per second of CPU time, best of 3, baseline: an empty loop of the same tick count is noise).
// Prints a markdown table for scripts/bench.sh. See docs/PERFORMANCE.md.
#include <time.h>
#include <unistd.h>

#include <algorithm>
#include <cstdio>
#include <fstream>
#include <memory>
#include <string>
#include <vector>

#include "core/modules/tmcm142/tmcm142.h"
#include "core/modules/tmcm1636/tmcm1636.h"
#include "core/modules/tmcm3216/tmcm3216.h"
#include "host/module_registry.h"

namespace {

using namespace motwin;

constexpr int kInstances = 32;
constexpr double kSimulatedSeconds = 1.0;

long resident_bytes() {
  std::ifstream statm("/proc/self/statm");
  long size_pages = 0;
  long resident_pages = 0;
  statm >> size_pages >> resident_pages;
  return resident_pages * sysconf(_SC_PAGESIZE);
}

double cpu_seconds() {
  timespec now{};
  clock_gettime(CLOCK_PROCESS_CPUTIME_ID, &now);
  return static_cast<double>(now.tv_sec) + static_cast<double>(now.tv_nsec) * 1e-9;
}

std::string core_size(std::string_view name) {
  if (name == modules::tmcm142::Tmcm142::kName) return std::to_string(sizeof(modules::tmcm142::Tmcm142));
  if (name == modules::tmcm1636::Tmcm1636::kName) return std::to_string(sizeof(modules::tmcm1636::Tmcm1636));
  if (name == modules::tmcm3216::Tmcm3216::kName) return std::to_string(sizeof(modules::tmcm3216::Tmcm3216));
  return "n/a";
}

host::MakeModuleResult make(const host::ModuleDescriptor& descriptor) {
  host::ModuleOptions options;  // no state directory: the EEPROM image stays in memory
  options.log = [](const std::string&) {};
  return descriptor.make(options);
}

}  // namespace

int main() {
  std::printf("| module | sizeof core profile | RSS per instance | instances | real-time factor (1 instance, CPU) |\n");
  std::printf("|---|---|---|---|---|\n");
  int status = 0;
  // Every instance stays alive to the end: memory freed by one module's instances would be
  // reused by the next module's without raising the RSS.
  std::vector<std::unique_ptr<host::VirtualModule>> kept;
  for (const host::ModuleDescriptor& descriptor : host::registered_modules()) {
    auto warm_up = make(descriptor);
    if (!warm_up) {
      std::fprintf(stderr, "bench_module_footprint: %.*s: %s\n", static_cast<int>(descriptor.name.size()),
                   descriptor.name.data(), warm_up.error().c_str());
      status = 2;
      continue;
    }
    (*warm_up)->run_ticks(1000);

    std::vector<std::unique_ptr<host::VirtualModule>> instances;
    const long before = resident_bytes();
    for (int i = 0; i < kInstances; ++i) {
      auto made = make(descriptor);
      (*made)->run_ticks(10);  // touch what a running module touches
      instances.push_back(std::move(*made));
    }
    const long per_instance = (resident_bytes() - before) / kInstances;

    host::VirtualModule& module = *instances.front();
    const auto ticks = static_cast<uint64_t>(kSimulatedSeconds * 1e6 / module.tick_period_us());
    double best = 1e30;
    for (int run = 0; run < 3; ++run) {
      const double start = cpu_seconds();
      module.run_ticks(ticks);
      best = std::min(best, cpu_seconds() - start);
    }
    std::printf("| %.*s | %s B | %.1f KiB | %d | %.0fx |\n", static_cast<int>(descriptor.name.size()),
                descriptor.name.data(), core_size(descriptor.name).c_str(), static_cast<double>(per_instance) / 1024.0,
                kInstances, kSimulatedSeconds / best);
    kept.push_back(std::move(*warm_up));
    for (auto& instance : instances) kept.push_back(std::move(instance));
  }
  return status;
}
