#include "tools/child_process.h"

#include <fcntl.h>
#include <poll.h>
#include <signal.h>
#include <spawn.h>
#include <sys/wait.h>
#include <unistd.h>

#include <cerrno>
#include <algorithm>
#include <cstring>
#include <thread>
#include <utility>

#include <fmt/format.h>

extern char** environ;

namespace motwin::tools {
namespace {

int exit_code_from_wait_status(int status) {
  if (WIFEXITED(status)) return WEXITSTATUS(status);
  if (WIFSIGNALED(status)) return 128 + WTERMSIG(status);
  return -1;
}

}  // namespace

Result<ChildProcess> ChildProcess::spawn(const std::vector<std::string>& argv, ChildOutput output) {
  if (argv.empty()) return Error{"no program to start"};
  int output_pipe[2];
  if (::pipe2(output_pipe, O_CLOEXEC) != 0) return Error{fmt::format("pipe: {}", std::strerror(errno))};
  UniqueFd read_end(output_pipe[0]);
  UniqueFd write_end(output_pipe[1]);

  // posix_spawn rather than fork: the callers may have threads running.
  posix_spawn_file_actions_t actions;
  posix_spawn_file_actions_init(&actions);
  posix_spawn_file_actions_adddup2(&actions, write_end.get(), STDOUT_FILENO);
  if (output == ChildOutput::kStdoutAndStderr) posix_spawn_file_actions_adddup2(&actions, write_end.get(), STDERR_FILENO);
  std::vector<char*> arguments;
  for (const std::string& argument : argv) arguments.push_back(const_cast<char*>(argument.c_str()));
  arguments.push_back(nullptr);
  pid_t pid = -1;
  const int rc = ::posix_spawn(&pid, argv[0].c_str(), &actions, nullptr, arguments.data(), environ);
  posix_spawn_file_actions_destroy(&actions);
  if (rc != 0) return Error{fmt::format("cannot start {}: {}", argv[0], std::strerror(rc))};
  return ChildProcess(pid, std::move(read_end));
}

ChildProcess::ChildProcess(ChildProcess&& other) noexcept
    : pid_(std::exchange(other.pid_, -1)),
      stdout_(std::move(other.stdout_)),
      pending_output_(std::move(other.pending_output_)) {}

ChildProcess& ChildProcess::operator=(ChildProcess&& other) noexcept {
  if (this != &other) {
    stop();
    pid_ = std::exchange(other.pid_, -1);
    stdout_ = std::move(other.stdout_);
    pending_output_ = std::move(other.pending_output_);
  }
  return *this;
}

std::optional<std::string> ChildProcess::read_line(SteadyClock::time_point deadline) {
  for (;;) {
    if (const size_t newline = pending_output_.find('\n'); newline != std::string::npos) {
      std::string line = pending_output_.substr(0, newline);
      pending_output_.erase(0, newline + 1);
      return line;
    }
    if (!stdout_.valid()) return std::nullopt;
    pollfd entry{stdout_.get(), POLLIN, 0};
    const int ready = ::poll(&entry, 1, poll_timeout_ms(deadline));
    if (ready < 0 && errno == EINTR) continue;
    if (ready <= 0) return std::nullopt;
    char chunk[512];
    const ssize_t n = ::read(stdout_.get(), chunk, sizeof chunk);
    if (n < 0 && errno == EINTR) continue;
    if (n <= 0) {
      stdout_.reset();
      return std::nullopt;
    }
    pending_output_.append(chunk, static_cast<size_t>(n));
  }
}

int ChildProcess::wait_for_exit(std::chrono::milliseconds timeout) {
  if (pid_ <= 0) return -1;
  const pid_t pid = std::exchange(pid_, -1);
  const auto deadline = SteadyClock::now() + timeout;
  int status = 0;
  for (;;) {
    const pid_t reaped = ::waitpid(pid, &status, WNOHANG);
    if (reaped == pid) break;
    if (reaped < 0 && errno != EINTR) return -1;
    if (SteadyClock::now() >= deadline) {
      ::kill(pid, SIGKILL);
      while (::waitpid(pid, &status, 0) < 0 && errno == EINTR) {
      }
      break;
    }
    std::this_thread::sleep_for(std::chrono::milliseconds(2));
  }
  return exit_code_from_wait_status(status);
}

int ChildProcess::stop(std::chrono::milliseconds grace) {
  if (pid_ <= 0) return -1;
  ::kill(pid_, SIGTERM);
  const int exit_status = wait_for_exit(grace);
  stdout_.reset();
  return exit_status;
}

Result<CompletedProcess> ChildProcess::run(const std::vector<std::string>& argv, std::chrono::milliseconds timeout) {
  Result<ChildProcess> child = spawn(argv, ChildOutput::kStdoutAndStderr);
  if (!child) return Error{child.error()};
  const auto deadline = SteadyClock::now() + timeout;
  CompletedProcess completed{0, {}};
  // Read until the output ends (the child exited or closed it) so that the pipe never fills.
  while (std::optional<std::string> line = child->read_line(deadline)) completed.output += *line + "\n";
  completed.output += child->pending_output_;  // a last line without a newline
  completed.exit_status = child->wait_for_exit(std::chrono::ceil<std::chrono::milliseconds>(
      std::max(deadline - SteadyClock::now(), SteadyClock::duration::zero())));
  return completed;
}

}  // namespace motwin::tools
