// What the end-to-end benchmarks (a `motwin serve` started and measured from outside) share:
// finding the `motwin` to start, a process's CPU time, the percentiles of round trips.
#pragma once

#include <unistd.h>

#include <algorithm>
#include <chrono>
#include <filesystem>
#include <fstream>
#include <iterator>
#include <optional>
#include <sstream>
#include <string>
#include <system_error>
#include <vector>

namespace motwin::bench {

// Next to the benchmark or one folder up (`motwin` is at build/motwin, the benchmarks at
// build/bench/).
inline std::optional<std::string> find_motwin_next_to_this_program() {
  std::error_code error;
  const std::filesystem::path self = std::filesystem::read_symlink("/proc/self/exe", error);
  if (error) return std::nullopt;
  for (const std::filesystem::path& candidate : {self.parent_path() / "motwin", self.parent_path().parent_path() / "motwin"}) {
    if (::access(candidate.c_str(), X_OK) == 0) return candidate.string();
  }
  return std::nullopt;
}

// User + system CPU seconds of a process so far (/proc/PID/stat).
inline std::optional<double> process_cpu_seconds(pid_t pid) {
  std::ifstream file("/proc/" + std::to_string(pid) + "/stat");
  std::string text((std::istreambuf_iterator<char>(file)), std::istreambuf_iterator<char>());
  const size_t close = text.rfind(')');
  if (close == std::string::npos) return std::nullopt;
  std::istringstream fields(text.substr(close + 2));
  std::string field;
  unsigned long long user = 0, system = 0;
  // After the command: state (3) ... utime (14), stime (15).
  for (int number = 3; number <= 15 && fields >> field; ++number) {
    if (number == 14) user = std::stoull(field);
    if (number == 15) system = std::stoull(field);
  }
  return static_cast<double>(user + system) / static_cast<double>(::sysconf(_SC_CLK_TCK));
}

struct Percentiles {
  double median_us;
  double p99_us;
};

// Median and 99th percentile of round-trip times, in microseconds.
inline Percentiles percentiles(std::vector<std::chrono::nanoseconds> samples) {
  std::sort(samples.begin(), samples.end());
  const auto at = [&](double fraction) {
    const size_t index =
        std::min(samples.size() - 1, static_cast<size_t>(fraction * static_cast<double>(samples.size())));
    return static_cast<double>(samples[index].count()) / 1e3;
  };
  return {at(0.5), at(0.99)};
}

}  // namespace motwin::bench
