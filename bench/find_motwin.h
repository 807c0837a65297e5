// Where the end-to-end benchmarks find the `motwin` they start: next to the benchmark or one
// folder up (`motwin` is at build/motwin, the benchmarks at build/bench/).
#pragma once

#include <unistd.h>

#include <filesystem>
#include <optional>
#include <string>
#include <system_error>

namespace motwin::bench {

inline std::optional<std::string> find_motwin_next_to_this_program() {
  std::error_code error;
  const std::filesystem::path self = std::filesystem::read_symlink("/proc/self/exe", error);
  if (error) return std::nullopt;
  for (const std::filesystem::path& candidate : {self.parent_path() / "motwin", self.parent_path().parent_path() / "motwin"}) {
    if (::access(candidate.c_str(), X_OK) == 0) return candidate.string();
  }
  return std::nullopt;
}

}  // namespace motwin::bench
