// A child program whose standard output is read line by line (its stderr is inherited), for
// tools and tests that drive `motwin serve`. Only the process started here is ever signalled.
#pragma once

#include <sys/types.h>

#include <chrono>
#include <cstdint>
#include <optional>
#include <string>
#include <vector>

#include "tools/fd_io.h"
#include "tools/unique_fd.h"
#include "types/result.h"

namespace motwin::tools {

enum class ChildOutput : uint8_t {
  kStdout,           // stdout is read through the pipe; stderr goes where ours goes
  kStdoutAndStderr,  // both into the pipe (ordering between them is not preserved)
};

struct CompletedProcess {
  int exit_status;     // as ChildProcess::wait_for_exit returns it
  std::string output;  // stdout and stderr together
};

class ChildProcess {
 public:
  // argv[0] is the program's path. The child must keep its output small or have it read:
  // a full pipe blocks it.
  static Result<ChildProcess> spawn(const std::vector<std::string>& argv, ChildOutput output = ChildOutput::kStdout);

  // Runs a program to completion and collects its stdout and stderr; killed after `timeout`.
  static Result<CompletedProcess> run(const std::vector<std::string>& argv, std::chrono::milliseconds timeout);

  ChildProcess(ChildProcess&& other) noexcept;
  ChildProcess& operator=(ChildProcess&& other) noexcept;
  ChildProcess(const ChildProcess&) = delete;
  ChildProcess& operator=(const ChildProcess&) = delete;
  ~ChildProcess() { stop(); }

  pid_t pid() const { return pid_; }

  // The next line of its stdout without the newline; std::nullopt when `deadline` passes or the
  // output ends first.
  std::optional<std::string> read_line(SteadyClock::time_point deadline);

  // Waits for it to exit; SIGKILL once `timeout` has passed. Returns its exit status, or 128 +
  // signal number when a signal ended it; -1 when it was already reaped.
  int wait_for_exit(std::chrono::milliseconds timeout);

  // SIGTERM, then wait_for_exit(grace).
  int stop(std::chrono::milliseconds grace = std::chrono::milliseconds(2000));

 private:
  ChildProcess(pid_t pid, UniqueFd stdout_read) : pid_(pid), stdout_(std::move(stdout_read)) {}

  pid_t pid_ = -1;
  UniqueFd stdout_;
  std::string pending_output_;
};

}  // namespace motwin::tools
