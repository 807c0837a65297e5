#include "tools/serve_process.h"

#include <stdlib.h>

#include <cerrno>
#include <cstring>
#include <system_error>

#include <fmt/format.h>

namespace motwin::tools {

std::optional<std::string> RunningServe::endpoint(std::string_view kind) const {
  for (const ServeEndpoint& candidate : endpoints) {
    if (candidate.kind == kind) return candidate.address;
  }
  return std::nullopt;
}

Result<RunningServe> start_serve(const std::string& motwin_path, const std::vector<std::string>& serve_arguments,
                                 std::chrono::milliseconds startup_timeout) {
  std::vector<std::string> argv{motwin_path, "serve"};
  argv.insert(argv.end(), serve_arguments.begin(), serve_arguments.end());
  Result<ChildProcess> child = ChildProcess::spawn(argv);
  if (!child) return Error{child.error()};
  RunningServe serve{std::move(child.value()), {}};
  const auto deadline = SteadyClock::now() + startup_timeout;
  constexpr std::string_view kEndpointPrefix = "endpoint ";
  for (;;) {
    const std::optional<std::string> line = serve.process.read_line(deadline);
    if (!line) {
      const int exit_status = serve.process.stop();
      return Error{fmt::format("`motwin serve` did not print `ready` within {} ms (exit status {})",
                               startup_timeout.count(), exit_status)};
    }
    if (*line == "ready") return serve;
    if (line->starts_with(kEndpointPrefix)) {
      const std::string rest = line->substr(kEndpointPrefix.size());
      const size_t space = rest.find(' ');
      if (space != std::string::npos) serve.endpoints.push_back({rest.substr(0, space), rest.substr(space + 1)});
    }
  }
}

Result<TemporaryDirectory> TemporaryDirectory::create(std::string_view name_prefix) {
  std::error_code error;
  std::filesystem::path base = std::filesystem::temp_directory_path(error);
  if (error) base = "/tmp";
  std::string pattern = (base / fmt::format("{}XXXXXX", name_prefix)).string();
  if (::mkdtemp(pattern.data()) == nullptr) {
    return Error{fmt::format("cannot create a temporary directory {}: {}", pattern, std::strerror(errno))};
  }
  return TemporaryDirectory(std::filesystem::path(pattern));
}

TemporaryDirectory::~TemporaryDirectory() {
  if (path_.empty()) return;
  std::error_code ignored;
  std::filesystem::remove_all(path_, ignored);
}

}  // namespace motwin::tools
