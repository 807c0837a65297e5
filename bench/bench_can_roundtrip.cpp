// CAN round trips through `motwin serve`'s socketcand server on 127.0.0.1 (realtime pacing):
// SDO expedited uploads from a TMCM-3216 and TMCL requests over CAN to a TMCM-1636, both
// modules on one bus (`--node`), against a bare socketcand-protocol echo server in this process
// that answers every `< send >` with a `< frame >` at once. The same client code measures all
// three; the ratio to the bare server is the figure (docs/benchmarks.md). Prints figures only:
// no timing is ever asserted.
//
//   bench_can_roundtrip [PATH/TO/motwin] [--requests N]
#include <netinet/in.h>
#include <netinet/tcp.h>
#include <sys/socket.h>
#include <unistd.h>

#include <algorithm>
#include <atomic>
#include <chrono>
#include <cstdio>
#include <cstring>
#include <filesystem>
#include <functional>
#include <optional>
#include <string>
#include <string_view>
#include <thread>
#include <vector>

#include "end_to_end.h"
#include "host/socketcand_protocol.h"
#include "tools/canopen_client.h"
#include "tools/serve_process.h"
#include "tools/tmcl_mnemonics.h"

namespace {

using namespace motwin;
using std::chrono::nanoseconds;

constexpr size_t kDefaultRequests = 5000;
constexpr size_t kWarmupRequests = 500;
constexpr size_t kBlockRequests = 500;
constexpr uint8_t kSdoNode = 1;

int fail(const std::string& message) {
  std::fprintf(stderr, "bench_can_roundtrip: %s\n", message.c_str());
  return 2;
}

using motwin::bench::find_motwin_next_to_this_program;
using motwin::bench::Percentiles;
using motwin::bench::percentiles;

// A bare socketcand server for one client: the session handshake, then each `< send ID ... >`
// is answered with a frame on ID - 0x80 (0x601 -> 0x581: an SDO server's reply ID) carrying the
// same data, written at once. The floor any socketcand server on this machine can reach.
class BareSocketcandEcho {
 public:
  bool start() {
    listen_fd_ = ::socket(AF_INET, SOCK_STREAM | SOCK_CLOEXEC, 0);
    sockaddr_in address{};
    address.sin_family = AF_INET;
    address.sin_addr.s_addr = htonl(INADDR_LOOPBACK);
    if (listen_fd_ < 0 || ::bind(listen_fd_, reinterpret_cast<sockaddr*>(&address), sizeof(address)) != 0 ||
        ::listen(listen_fd_, 1) != 0) {
      return false;
    }
    socklen_t length = sizeof(address);
    ::getsockname(listen_fd_, reinterpret_cast<sockaddr*>(&address), &length);
    port_ = ntohs(address.sin_port);
    thread_ = std::thread([this] { serve(); });
    return true;
  }
  ~BareSocketcandEcho() {
    ::shutdown(listen_fd_, SHUT_RDWR);
    if (client_fd_ >= 0) ::shutdown(client_fd_, SHUT_RDWR);
    if (thread_.joinable()) thread_.join();
    ::close(listen_fd_);
    if (client_fd_ >= 0) ::close(client_fd_);
  }
  uint16_t port() const { return port_; }

 private:
  void write_all(const std::string& text) { ::send(client_fd_, text.data(), text.size(), MSG_NOSIGNAL); }

  void serve() {
    client_fd_ = ::accept4(listen_fd_, nullptr, nullptr, SOCK_CLOEXEC);
    if (client_fd_ < 0) return;
    const int on = 1;
    ::setsockopt(client_fd_, IPPROTO_TCP, TCP_NODELAY, &on, sizeof(on));
    write_all("< hi >");
    host::SocketcandElementParser parser;
    std::vector<std::string> elements;
    char buffer[4096];
    for (;;) {
      const ssize_t n = ::recv(client_fd_, buffer, sizeof(buffer), 0);
      if (n <= 0) return;
      elements.clear();
      parser.push(std::string_view(buffer, static_cast<size_t>(n)), elements);
      for (const std::string& element : elements) {
        const std::vector<std::string_view> words = host::socketcand_words(element);
        if (words.empty()) continue;
        if (words[0] == "open" || words[0] == "rawmode") {
          write_all("< ok >");
          continue;
        }
        Result<can::CanFrame> frame = host::parse_socketcand_send(words);
        if (!frame) continue;
        frame->id -= 0x80;
        write_all(host::format_socketcand_frame(*frame, 0));
      }
    }
  }

  int listen_fd_ = -1;
  int client_fd_ = -1;
  uint16_t port_ = 0;
  std::thread thread_;
};



using RoundTrip = std::function<bool()>;

std::optional<nanoseconds> timed(const RoundTrip& round_trip) {
  const auto start = std::chrono::steady_clock::now();
  if (!round_trip()) return std::nullopt;
  return std::chrono::duration_cast<nanoseconds>(std::chrono::steady_clock::now() - start);
}

// An SDO expedited upload request of 1000 sub 0, timed until the answer on 0x580 + node (the
// bare echo answers on that ID too, with the request's bytes).
RoundTrip sdo_round_trip(tools::SocketcandClient& bus) {
  return [&bus] {
    const uint8_t request[8] = {0x40, 0x00, 0x10, 0x00, 0, 0, 0, 0};
    if (!bus.send(can::make_frame(0x600u + kSdoNode, request, 8))) return false;
    for (;;) {
      const std::optional<can::CanFrame> reply = bus.receive(1000);
      if (!reply) return false;
      if (reply->id == 0x580u + kSdoNode) return true;
    }
  };
}

// TMCL GAP 4 over CAN: request on ID 1, reply on ID 2.
RoundTrip tmcl_round_trip(tools::SocketcandClient& bus) {
  return [&bus] {
    const uint8_t request[7] = {6, 4, 0, 0, 0, 0, 0};
    if (!bus.send(can::make_frame(1, request, 7))) return false;
    for (;;) {
      const std::optional<can::CanFrame> reply = bus.receive(1000);
      if (!reply) return false;
      if (reply->id == 2 && reply->dlc == 7 && reply->data[1] == 100) return true;
    }
  };
}

}  // namespace

int main(int argc, char** argv) {
  std::string motwin_path;
  size_t requests = kDefaultRequests;
  for (int i = 1; i < argc; ++i) {
    const std::string_view argument = argv[i];
    if (argument == "--requests" && i + 1 < argc) {
      const std::optional<int64_t> parsed = tools::parse_integer(argv[++i]);
      if (!parsed || *parsed < 1) return fail("usage: bench_can_roundtrip [PATH/TO/motwin] [--requests N]");
      requests = static_cast<size_t>(*parsed);
    } else if (!argument.starts_with("-") && motwin_path.empty()) {
      motwin_path = argument;
    } else {
      return fail("usage: bench_can_roundtrip [PATH/TO/motwin] [--requests N]");
    }
  }
  if (motwin_path.empty()) {
    const std::optional<std::string> found = find_motwin_next_to_this_program();
    if (!found) return fail("motwin not found next to this program; give its path");
    motwin_path = *found;
  }

  Result<tools::TemporaryDirectory> state_dir = tools::TemporaryDirectory::create("motwin-bench-");
  if (!state_dir) return fail(state_dir.error());
  Result<tools::RunningServe> serve = tools::start_serve(
      motwin_path, {"--node", "tmcm-3216:node-id=1", "--node", "tmcm-1636", "--can", "socketcand:127.0.0.1:0",
                    "--state-dir", state_dir->path().string(), "--speed", "realtime"});
  if (!serve) return fail(serve.error());
  const std::optional<std::string> address = serve->endpoint("can-socketcand");
  if (!address) return fail("`motwin serve` printed no `endpoint can-socketcand` line");
  const uint16_t serve_port = static_cast<uint16_t>(std::stoi(address->substr(address->rfind(':') + 1)));

  BareSocketcandEcho bare;
  if (!bare.start()) return fail("cannot start the bare socketcand server");
  Result<std::unique_ptr<tools::SocketcandClient>> serve_bus =
      tools::SocketcandClient::connect("127.0.0.1", serve_port);
  if (!serve_bus) return fail(serve_bus.error());
  Result<std::unique_ptr<tools::SocketcandClient>> bare_bus =
      tools::SocketcandClient::connect("127.0.0.1", bare.port());
  if (!bare_bus) return fail(bare_bus.error());

  struct Series {
    const char* name;
    RoundTrip round_trip;
    std::vector<nanoseconds> samples;
  };
  std::vector<Series> series;
  series.push_back({"bare socketcand echo (in process)", sdo_round_trip(**bare_bus), {}});
  series.push_back({"motwin SDO upload, TMCM-3216", sdo_round_trip(**serve_bus), {}});
  series.push_back({"motwin TMCL GAP over CAN, TMCM-1636", tmcl_round_trip(**serve_bus), {}});
  for (Series& s : series) {
    for (size_t i = 0; i < kWarmupRequests; ++i) {
      if (!s.round_trip()) return fail(std::string(s.name) + ": no answer during warm-up");
    }
    s.samples.reserve(requests);
  }
  // The series take turns in blocks, so that a slow phase of the machine hits all alike.
  while (series.front().samples.size() < requests) {
    const size_t block = std::min(kBlockRequests, requests - series.front().samples.size());
    for (Series& s : series) {
      for (size_t i = 0; i < block; ++i) {
        const std::optional<nanoseconds> sample = timed(s.round_trip);
        if (!sample) return fail(std::string(s.name) + ": no answer");
        s.samples.push_back(*sample);
      }
    }
  }
  const int serve_exit_status = serve->process.stop();

  const Percentiles floor = percentiles(series.front().samples);
  std::printf("CAN round trips through a socketcand server on 127.0.0.1, %zu each (after %zu warm-up)\n", requests,
              kWarmupRequests);
  std::printf("  %-38s %10s %10s %12s %8s\n", "", "median", "p99", "per second", "ratio");
  for (const Series& s : series) {
    const Percentiles p = percentiles(s.samples);
    std::printf("  %-38s %7.1f us %7.1f us %12.0f %7.2fx\n", s.name, p.median_us, p.p99_us, 1e6 / p.median_us,
                p.median_us / floor.median_us);
  }
  if (serve_exit_status != 0) std::printf("note: motwin serve exited with status %d after SIGTERM\n", serve_exit_status);
  return 0;
}
