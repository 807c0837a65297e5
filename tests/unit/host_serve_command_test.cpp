// `motwin serve` as a child process: the stdout contract, a TMCL exchange, clean shutdown on
// SIGTERM and exit status 2 with one error line for bad arguments.
#include <gtest/gtest.h>

#include <fcntl.h>
#include <poll.h>
#include <signal.h>
#include <spawn.h>
#include <sys/wait.h>
#include <unistd.h>

#include <chrono>
#include <filesystem>
#include <fstream>
#include <string>
#include <vector>

#include "core/modules/tmcm1636/tmcm1636_hardware.h"
#include "support/host_test_support.h"

extern char** environ;

namespace motwin::host {
namespace {

using testing::Bytes;
using testing::reply;
using testing::request;

class ServeProcess {
 public:
  explicit ServeProcess(std::vector<std::string> arguments) {
    arguments.insert(arguments.begin(), {MOTWIN_BINARY, "serve"});
    int out[2];
    int err[2];
    EXPECT_EQ(::pipe2(out, O_CLOEXEC), 0);
    EXPECT_EQ(::pipe2(err, O_CLOEXEC), 0);
    posix_spawn_file_actions_t actions;
    posix_spawn_file_actions_init(&actions);
    posix_spawn_file_actions_adddup2(&actions, out[1], 1);
    posix_spawn_file_actions_adddup2(&actions, err[1], 2);
    std::vector<char*> argv;
    for (std::string& argument : arguments) argv.push_back(argument.data());
    argv.push_back(nullptr);
    EXPECT_EQ(::posix_spawn(&pid_, MOTWIN_BINARY, &actions, nullptr, argv.data(), environ), 0);
    posix_spawn_file_actions_destroy(&actions);
    ::close(out[1]);
    ::close(err[1]);
    stdout_fd_ = out[0];
    stderr_fd_ = err[0];
  }
  ServeProcess(const ServeProcess&) = delete;
  ServeProcess& operator=(const ServeProcess&) = delete;
  ~ServeProcess() {
    if (pid_ > 0 && !exited_) {
      ::kill(pid_, SIGKILL);
      ::waitpid(pid_, nullptr, 0);
    }
    ::close(stdout_fd_);
    ::close(stderr_fd_);
  }

  // Stdout lines up to and including `ready` (or all of them if the process exits first).
  std::vector<std::string> lines_until_ready() {
    std::vector<std::string> lines;
    std::string pending;
    const auto deadline = std::chrono::steady_clock::now() + std::chrono::seconds(20);
    while (std::chrono::steady_clock::now() < deadline) {
      pollfd fd{stdout_fd_, POLLIN, 0};
      if (::poll(&fd, 1, 100) <= 0) continue;
      char buffer[512];
      const ssize_t n = ::read(stdout_fd_, buffer, sizeof(buffer));
      if (n <= 0) break;
      pending.append(buffer, static_cast<size_t>(n));
      for (size_t newline; (newline = pending.find('\n')) != std::string::npos;) {
        lines.push_back(pending.substr(0, newline));
        pending.erase(0, newline + 1);
        if (lines.back() == "ready") return lines;
      }
    }
    return lines;
  }
  std::string read_stderr() {
    std::string text;
    char buffer[512];
    ssize_t n;
    while ((n = ::read(stderr_fd_, buffer, sizeof(buffer))) > 0) text.append(buffer, static_cast<size_t>(n));
    return text;
  }
  void signal(int number) const { ::kill(pid_, number); }
  // Exit status, or -1 when killed by a signal.
  int wait() {
    int status = 0;
    ::waitpid(pid_, &status, 0);
    exited_ = true;
    return WIFEXITED(status) ? WEXITSTATUS(status) : -1;
  }

 private:
  pid_t pid_ = -1;
  int stdout_fd_ = -1;
  int stderr_fd_ = -1;
  bool exited_ = false;
};

TEST(ServeCommand, prints_its_endpoints_answers_tmcl_and_stops_cleanly_on_sigterm) {
  testing::ScratchDirectory scratch;
  const std::string link = (scratch.path() / "tmcm1636").string();
  const std::string state = (scratch.path() / "state").string();
  ServeProcess serve({"--module", "tmcm-1636", "--tmcl-tcp", "127.0.0.1:0", "--tmcl-pty", link, "--state-dir", state,
                      "--set", "VSUPPLY=30"});
  const std::vector<std::string> lines = serve.lines_until_ready();
  ASSERT_EQ(lines.size(), 4u) << serve.read_stderr();
  EXPECT_EQ(lines[0], "motwin: tmcm-1636 (1636V109) eeprom " + state + "/tmcm-1636.eeprom");
  const std::string tcp_prefix = "endpoint tmcl-tcp 127.0.0.1:";
  ASSERT_EQ(lines[1].rfind(tcp_prefix, 0), 0u) << lines[1];
  const int port = std::stoi(lines[1].substr(tcp_prefix.size()));
  EXPECT_GT(port, 0);
  EXPECT_EQ(lines[2].rfind("endpoint tmcl-pty " + link + " /dev/pts/", 0), 0u) << lines[2];
  const std::string device = lines[2].substr(("endpoint tmcl-pty " + link + " ").size());
  EXPECT_EQ(std::filesystem::read_symlink(link).string(), device);
  EXPECT_EQ(lines[3], "ready");

  {
    testing::TcpTestClient client(static_cast<uint16_t>(port));
    ASSERT_TRUE(client.connected());
    client.send(request(15, 2, 1, 0));  // GIO 2, 1: ADC_VM
    ASSERT_TRUE(testing::pump_until([] { ::usleep(1000); }, [&] { return client.has(9); }));
    EXPECT_EQ(client.take(9), reply(100, 15, modules::tmcm1636::supply_adc_from_millivolt(30000)));
  }
  serve.signal(SIGTERM);
  EXPECT_EQ(serve.wait(), 0);
  EXPECT_FALSE(std::filesystem::is_symlink(link));  // removed at shutdown
  EXPECT_TRUE(std::filesystem::exists(state + "/tmcm-1636.eeprom"));
}

// ,echo after an address: that endpoint only echoes (the RS485 transceiver), and its line says so.
TEST(ServeCommand, the_echo_option_is_per_endpoint_and_shown_in_its_line) {
  testing::ScratchDirectory scratch;
  const std::string link = (scratch.path() / "rs485").string();
  ServeProcess serve({"--module", "tmcm-1636", "--tmcl-tcp", "127.0.0.1:0,echo", "--tmcl-tcp", "127.0.0.1:0",
                      "--tmcl-pty", link + ",echo", "--state-dir", "none"});
  const std::vector<std::string> lines = serve.lines_until_ready();
  ASSERT_EQ(lines.size(), 5u) << serve.read_stderr();
  const std::string tcp_prefix = "endpoint tmcl-tcp 127.0.0.1:";
  ASSERT_EQ(lines[1].rfind(tcp_prefix, 0), 0u) << lines[1];
  EXPECT_TRUE(lines[1].ends_with(" echo")) << lines[1];
  ASSERT_EQ(lines[2].rfind(tcp_prefix, 0), 0u) << lines[2];
  EXPECT_EQ(lines[2].find(' ', tcp_prefix.size()), std::string::npos) << lines[2];
  EXPECT_EQ(lines[3].rfind("endpoint tmcl-pty " + link + " /dev/pts/", 0), 0u) << lines[3];
  EXPECT_TRUE(lines[3].ends_with(" echo")) << lines[3];
  EXPECT_TRUE(std::filesystem::is_symlink(link)) << "the link has no option in its name";
  {
    testing::TcpTestClient echoing(static_cast<uint16_t>(std::stoi(lines[1].substr(tcp_prefix.size()))));
    testing::TcpTestClient plain(static_cast<uint16_t>(std::stoi(lines[2].substr(tcp_prefix.size()))));
    const Bytes frame = request(6, 43, 0, 0);  // GAP 43: max velocity
    echoing.send(frame);
    plain.send(frame);
    ASSERT_TRUE(testing::pump_until([] { ::usleep(1000); }, [&] { return echoing.has(18) && plain.has(9); }));
    EXPECT_EQ(echoing.take(9), frame);
    EXPECT_EQ(echoing.take(9), reply(100, 6, 4000));
    EXPECT_EQ(plain.take(9), reply(100, 6, 4000));
  }
  serve.signal(SIGTERM);
  EXPECT_EQ(serve.wait(), 0);
}

TEST(ServeCommand, bad_arguments_exit_with_status_2_and_one_error_line) {
  testing::ScratchDirectory scratch;
  const std::string scenario = (scratch.path() / "bad.scn").string();
  std::ofstream(scenario) << "0.5 GPI0 1\nlater GPI0 0\n";
  const std::vector<std::pair<std::vector<std::string>, std::string>> cases = {
      {{"--tmcl-tcp", "127.0.0.1:70000"},
       "motwin: error: --tmcl-tcp: expected HOST:PORT with a port from 0 to 65535, got \"127.0.0.1:70000\"\n"},
      {{"--tmcl-tcp", "127.0.0.1:0,ecko"},
       "motwin: error: --tmcl-tcp: unknown option \"ecko\" in \"127.0.0.1:0,ecko\": the options after the address "
       "are echo (and the address has no comma)\n"},
      {{"--tmcl-pty", "/tmp/motwin-test-link,rs485"},
       "motwin: error: --tmcl-pty: unknown option \"rs485\" in \"/tmp/motwin-test-link,rs485\": the options after "
       "the address are echo (and the address has no comma)\n"},
      {{"--module", "tmcm-9"}, "motwin: error: unknown module \"tmcm-9\" (available: tmcm-1636, tmcm-142, tmcm-3216)\n"},
      {{"--speed", "slow"},
       "motwin: error: --speed takes realtime, fast or a factor from 0.001 to 10000, got \"slow\"\n"},
      {{"--set", "GPI0=3"}, "motwin: error: --set GPI0=3: GPI0 takes 0 or 1 (digital input level), got 3\n"},
      {{"--scenario", scenario}, "motwin: error: " + scenario + ":2: expected a time in seconds, got \"later\"\n"},
  };
  for (const auto& [arguments, expected_error] : cases) {
    SCOPED_TRACE(arguments.back());
    std::vector<std::string> all = arguments;
    all.insert(all.end(), {"--state-dir", "none", "--tmcl-tcp", "127.0.0.1:0"});
    ServeProcess serve(all);
    EXPECT_TRUE(serve.lines_until_ready().empty());
    EXPECT_EQ(serve.wait(), 2);
    EXPECT_EQ(serve.read_stderr(), expected_error);
  }
}

}  // namespace
}  // namespace motwin::host
