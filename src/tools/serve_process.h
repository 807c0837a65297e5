// Starts `motwin serve` as a child process and waits until it is ready, following the serve
// output contract: one `endpoint KIND ADDRESS` line per transport (for example
// `endpoint tmcl-tcp 127.0.0.1:40123`), then `ready`.
#pragma once

#include <chrono>
#include <filesystem>
#include <optional>
#include <string>
#include <string_view>
#include <utility>
#include <vector>

#include "tools/child_process.h"
#include "types/result.h"

namespace motwin::tools {

struct ServeEndpoint {
  std::string kind;     // "tmcl-tcp", "tmcl-pty" ...
  std::string address;  // the rest of the line: "127.0.0.1:40123", or "LINK /dev/pts/4" for tmcl-pty
};

struct RunningServe {
  ChildProcess process;
  std::vector<ServeEndpoint> endpoints;

  std::optional<std::string> endpoint(std::string_view kind) const;
};

// Runs `motwin_path serve serve_arguments...` and reads its stdout until `ready`.
Result<RunningServe> start_serve(const std::string& motwin_path, const std::vector<std::string>& serve_arguments,
                                 std::chrono::milliseconds startup_timeout = std::chrono::milliseconds(10000));

// A fresh directory under the system's temporary directory, removed with its contents.
class TemporaryDirectory {
 public:
  static Result<TemporaryDirectory> create(std::string_view name_prefix);
  TemporaryDirectory(TemporaryDirectory&& other) noexcept : path_(std::exchange(other.path_, {})) {}
  TemporaryDirectory& operator=(TemporaryDirectory&&) = delete;
  TemporaryDirectory(const TemporaryDirectory&) = delete;
  ~TemporaryDirectory();

  const std::filesystem::path& path() const { return path_; }

 private:
  explicit TemporaryDirectory(std::filesystem::path path) : path_(std::move(path)) {}
  std::filesystem::path path_;
};

}  // namespace motwin::tools
