// TMCL round-trip latency over TCP on 127.0.0.1: `motwin serve` (realtime pacing) against a
// bare in-process server that answers each 9-byte frame with 9 bytes at once. The same client
// code measures both; the ratio of the two is what the target (median within 1.5x of the bare
// server) is about. Prints figures only: no timing is ever asserted. See docs/benchmarks.md.
//
//   bench_tcp_roundtrip [PATH/TO/motwin] [--requests N]
#include <unistd.h>

#include <algorithm>
#include <chrono>
#include <cstdio>
#include <cstdlib>
#include <filesystem>
#include <optional>
#include <string>
#include <string_view>
#include <vector>

#include "core/tmcl/serial_link.h"
#include "tools/loopback_frame_server.h"
#include "tools/serve_process.h"
#include "tools/tmcl_client.h"
#include "tools/tmcl_mnemonics.h"

namespace {

using namespace motwin;
using std::chrono::nanoseconds;

constexpr size_t kDefaultRequests = 20000;
constexpr size_t kWarmupRequests = 1000;
// The two servers take turns in blocks, so that a slow phase of the machine hits both alike.
constexpr size_t kBlockRequests = 1000;

struct Options {
  std::string motwin_path;
  size_t requests = kDefaultRequests;
};

int fail(const std::string& message) {
  std::fprintf(stderr, "bench_tcp_roundtrip: %s\n", message.c_str());
  return 2;
}

// `motwin` is at build/motwin, the benchmarks at build/bench/.
std::optional<std::string> find_motwin_next_to_this_program() {
  std::error_code error;
  const std::filesystem::path self = std::filesystem::read_symlink("/proc/self/exe", error);
  if (error) return std::nullopt;
  for (const std::filesystem::path& candidate : {self.parent_path() / "motwin", self.parent_path().parent_path() / "motwin"}) {
    if (::access(candidate.c_str(), X_OK) == 0) return candidate.string();
  }
  return std::nullopt;
}

std::optional<Options> parse_options(int argc, char** argv) {
  Options options;
  for (int i = 1; i < argc; ++i) {
    const std::string_view argument = argv[i];
    if (argument == "--requests" && i + 1 < argc) {
      const std::optional<int64_t> requests = tools::parse_integer(argv[++i]);
      if (!requests || *requests < 1) return std::nullopt;
      options.requests = static_cast<size_t>(*requests);
    } else if (!argument.starts_with("-") && options.motwin_path.empty()) {
      options.motwin_path = argument;
    } else {
      return std::nullopt;
    }
  }
  if (options.motwin_path.empty()) {
    const std::optional<std::string> found = find_motwin_next_to_this_program();
    if (!found) return std::nullopt;
    options.motwin_path = *found;
  }
  return options;
}

// One timed GAP round trip; std::nullopt (and a message) when the request failed.
std::optional<nanoseconds> timed_round_trip(tools::TmclClient& client, const tmcl::Instruction& request) {
  const auto start = std::chrono::steady_clock::now();
  const tools::Result<tools::TmclReply> reply = client.request(request);
  const auto elapsed = std::chrono::steady_clock::now() - start;
  if (!reply || reply->status != 100) {
    std::fprintf(stderr, "bench_tcp_roundtrip: %s: %s\n", client.peer_name().c_str(),
                 reply ? "error status" : reply.error().c_str());
    return std::nullopt;
  }
  return std::chrono::duration_cast<nanoseconds>(elapsed);
}

struct Percentiles {
  double median_us;
  double p99_us;
};

Percentiles percentiles(std::vector<nanoseconds> samples) {
  std::sort(samples.begin(), samples.end());
  const auto at = [&](double fraction) {
    const size_t index = std::min(samples.size() - 1, static_cast<size_t>(fraction * static_cast<double>(samples.size())));
    return static_cast<double>(samples[index].count()) / 1e3;
  };
  return {at(0.5), at(0.99)};
}

}  // namespace

int main(int argc, char** argv) {
  const std::optional<Options> options = parse_options(argc, argv);
  if (!options) {
    return fail("usage: bench_tcp_roundtrip [PATH/TO/motwin] [--requests N] (motwin not found next to this program?)");
  }

  tools::Result<tools::TemporaryDirectory> state_dir = tools::TemporaryDirectory::create("motwin-bench-");
  if (!state_dir) return fail(state_dir.error());
  tools::Result<tools::RunningServe> serve =
      tools::start_serve(options->motwin_path, {"--module", "tmcm-1636", "--tmcl-tcp", "127.0.0.1:0", "--state-dir",
                                                state_dir->path().string(), "--speed", "realtime"});
  if (!serve) return fail(serve.error());
  const std::optional<std::string> serve_address = serve->endpoint("tmcl-tcp");
  if (!serve_address) return fail("`motwin serve` printed no `endpoint tmcl-tcp` line");

  // The bare server answers with a well-formed reply so that both go through the same client.
  tools::Result<std::unique_ptr<tools::LoopbackFrameServer>> bare_server =
      tools::LoopbackFrameServer::start([](const tmcl::Frame& request, tmcl::Frame& reply) {
        reply = tmcl::encode_reply(2, request[0], tmcl::Reply{100, request[1], 0});
        return tmcl::kFrameLength;
      });
  if (!bare_server) return fail(bare_server.error());

  tools::Result<tools::TmclClient> serve_client = tools::TmclClient::connect_tcp(*serve_address);
  if (!serve_client) return fail(serve_client.error());
  tools::Result<tools::TmclClient> bare_client = tools::TmclClient::connect_tcp(bare_server.value()->address());
  if (!bare_client) return fail(bare_client.error());

  const tmcl::Instruction request = tools::parse_instruction("GAP 52, 0").value();
  for (size_t i = 0; i < kWarmupRequests; ++i) {
    if (!timed_round_trip(serve_client.value(), request) || !timed_round_trip(bare_client.value(), request)) return 2;
  }
  std::vector<nanoseconds> serve_samples;
  std::vector<nanoseconds> bare_samples;
  serve_samples.reserve(options->requests);
  bare_samples.reserve(options->requests);
  while (serve_samples.size() < options->requests) {
    const size_t block = std::min(kBlockRequests, options->requests - serve_samples.size());
    for (auto [client, samples] : {std::pair{&bare_client.value(), &bare_samples}, std::pair{&serve_client.value(), &serve_samples}}) {
      for (size_t i = 0; i < block; ++i) {
        const std::optional<nanoseconds> sample = timed_round_trip(*client, request);
        if (!sample) return 2;
        samples->push_back(*sample);
      }
    }
  }
  const int serve_exit_status = serve->process.stop();

  const Percentiles bare = percentiles(bare_samples);
  const Percentiles motwin = percentiles(serve_samples);
  std::printf("TMCL GAP 52 round trips over TCP on 127.0.0.1, %zu each (after %zu warm-up)\n", options->requests,
              kWarmupRequests);
  std::printf("  %-34s %10s %10s\n", "", "median", "p99");
  std::printf("  %-34s %8.1f us %8.1f us\n", "bare 9-byte server (in process)", bare.median_us, bare.p99_us);
  std::printf("  %-34s %8.1f us %8.1f us\n", "motwin serve --speed realtime", motwin.median_us, motwin.p99_us);
  std::printf("  %-34s %9.2fx %9.2fx   (target: median within 1.5x)\n", "ratio motwin / bare",
              motwin.median_us / bare.median_us, motwin.p99_us / bare.p99_us);
  if (serve_exit_status != 0) std::printf("note: motwin serve exited with status %d after SIGTERM\n", serve_exit_status);
  return 0;
}
