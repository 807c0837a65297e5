// TMCL round-trip latency over TCP on 127.0.0.1: `motwin serve` (realtime pacing) against a
// bare in-process server that answers each 9-byte frame with 9 bytes at once. The same client
// code measures both; the ratio of the two is what the target (median within 1.5x of the bare
// server) is about. Then the same round trip to the same serve while N other connections flood it
// with pipelined requests, as a ratio to the idle round trip of the same run: how much a
// well-behaved host's latency suffers from misbehaving ones. Prints figures only: no timing is
// ever asserted. See docs/benchmarks.md.
//
//   bench_tcp_roundtrip [PATH/TO/motwin] [--requests N] [--flooders N]
#include <unistd.h>

#include <algorithm>
#include <atomic>
#include <chrono>
#include <cstdio>
#include <cstdlib>
#include <filesystem>
#include <functional>
#include <optional>
#include <string>
#include <string_view>
#include <thread>
#include <vector>

#include "end_to_end.h"
#include "core/tmcl/serial_link.h"
#include "host/tmcl_host_service.h"
#include "tools/fd_io.h"
#include "tools/loopback_frame_server.h"
#include "tools/serve_process.h"
#include "tools/tmcl_client.h"
#include "tools/tmcl_mnemonics.h"

namespace {

using namespace motwin;
using std::chrono::nanoseconds;

constexpr size_t kDefaultRequests = 20000;
constexpr size_t kWarmupRequests = 1000;
// The servers (and the flooded serve) take turns in blocks, so that a slow phase of the machine
// hits all alike.
constexpr size_t kBlockRequests = 1000;
constexpr size_t kDefaultFlooders = 4;
// Requests each flooding connection keeps in flight: as many as the server queues for one
// connection before it stops reading it.
constexpr size_t kFloodWindow = host::TmclHostService::kMaxQueuedRequestsPerChannel;

struct Options {
  std::string motwin_path;
  size_t requests = kDefaultRequests;
  size_t flooders = kDefaultFlooders;
};

int fail(const std::string& message) {
  std::fprintf(stderr, "bench_tcp_roundtrip: %s\n", message.c_str());
  return 2;
}

using motwin::bench::find_motwin_next_to_this_program;
using motwin::bench::Percentiles;
using motwin::bench::percentiles;

std::optional<Options> parse_options(int argc, char** argv) {
  Options options;
  for (int i = 1; i < argc; ++i) {
    const std::string_view argument = argv[i];
    if (argument == "--requests" && i + 1 < argc) {
      const std::optional<int64_t> requests = tools::parse_integer(argv[++i]);
      if (!requests || *requests < 1) return std::nullopt;
      options.requests = static_cast<size_t>(*requests);
    } else if (argument == "--flooders" && i + 1 < argc) {
      const std::optional<int64_t> flooders = tools::parse_integer(argv[++i]);
      if (!flooders || *flooders < 0 || *flooders > 60) return std::nullopt;  // the server takes 64 clients
      options.flooders = static_cast<size_t>(*flooders);
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
  const Result<tools::TmclReply> reply = client.request(request);
  const auto elapsed = std::chrono::steady_clock::now() - start;
  if (!reply || reply->status != 100) {
    std::fprintf(stderr, "bench_tcp_roundtrip: %s: %s\n", client.peer_name().c_str(),
                 reply ? "error status" : reply.error().c_str());
    return std::nullopt;
  }
  return std::chrono::duration_cast<nanoseconds>(elapsed);
}


// A connection to the serve that pipelines GAP 52 requests, kFloodWindow at a time, reading the
// replies of each window before sending the next, until told to stop.
struct FloodConnection {
  tools::UniqueFd fd;
  uint64_t answered = 0;
  std::string error;
};

void flood_until_stopped(FloodConnection& connection, const tmcl::Frame& request, const std::atomic<bool>& stop) {
  std::vector<uint8_t> batch;
  for (size_t i = 0; i < kFloodWindow; ++i) batch.insert(batch.end(), request.begin(), request.end());
  std::vector<uint8_t> replies(batch.size());
  while (!stop.load(std::memory_order_relaxed)) {
    if (tools::write_all(connection.fd.get(), batch.data(), batch.size(), true).status != tools::IoStatus::kOk) {
      connection.error = "flooding connection: write failed";
      return;
    }
    const tools::IoResult read = tools::read_exact(connection.fd.get(), replies.data(), replies.size(),
                                                   tools::SteadyClock::now() + std::chrono::seconds(10));
    if (read.status != tools::IoStatus::kOk) {
      connection.error = "flooding connection: no replies within 10 s";
      return;
    }
    for (size_t i = 0; i < replies.size(); i += tmcl::kFrameLength) {
      if (replies[i + 2] != 100 || replies[i + 3] != request[1]) {
        connection.error = "flooding connection: a wrong reply " + tools::hex_bytes(&replies[i], tmcl::kFrameLength);
        return;
      }
    }
    connection.answered += kFloodWindow;
  }
}

// Runs `measure` while every connection floods; the flooders have stopped and read all their
// replies when it returns (so the next block finds the serve idle).
bool while_flooding(std::vector<FloodConnection>& connections, const tmcl::Frame& request,
                    const std::function<bool()>& measure) {
  std::atomic<bool> stop{false};
  std::vector<std::thread> threads;
  for (FloodConnection& connection : connections) {
    threads.emplace_back(flood_until_stopped, std::ref(connection), std::cref(request), std::cref(stop));
  }
  const bool measured = measure();
  stop.store(true);
  for (std::thread& thread : threads) thread.join();
  for (const FloodConnection& connection : connections) {
    if (!connection.error.empty()) {
      std::fprintf(stderr, "bench_tcp_roundtrip: %s\n", connection.error.c_str());
      return false;
    }
  }
  return measured;
}


}  // namespace

int main(int argc, char** argv) {
  const std::optional<Options> options = parse_options(argc, argv);
  if (!options) {
    return fail("usage: bench_tcp_roundtrip [PATH/TO/motwin] [--requests N] (motwin not found next to this program?)");
  }

  Result<tools::TemporaryDirectory> state_dir = tools::TemporaryDirectory::create("motwin-bench-");
  if (!state_dir) return fail(state_dir.error());
  Result<tools::RunningServe> serve =
      tools::start_serve(options->motwin_path, {"--module", "tmcm-1636", "--tmcl-tcp", "127.0.0.1:0", "--state-dir",
                                                state_dir->path().string(), "--speed", "realtime"});
  if (!serve) return fail(serve.error());
  const std::optional<std::string> serve_address = serve->endpoint("tmcl-tcp");
  if (!serve_address) return fail("`motwin serve` printed no `endpoint tmcl-tcp` line");

  // The bare server answers with a well-formed reply so that both go through the same client.
  Result<std::unique_ptr<tools::LoopbackFrameServer>> bare_server =
      tools::LoopbackFrameServer::start([](const tmcl::Frame& request, tmcl::Frame& reply) {
        reply = tmcl::encode_reply(2, request[0], tmcl::Reply{100, request[1], 0});
        return tmcl::kFrameLength;
      });
  if (!bare_server) return fail(bare_server.error());

  Result<tools::TmclClient> serve_client = tools::TmclClient::connect_tcp(*serve_address);
  if (!serve_client) return fail(serve_client.error());
  Result<tools::TmclClient> bare_client = tools::TmclClient::connect_tcp(bare_server.value()->address());
  if (!bare_client) return fail(bare_client.error());

  // Under a flood a reply may wait behind every other connection's queued requests.
  serve_client->set_reply_timeout(std::chrono::seconds(10));
  std::vector<FloodConnection> flooders(options->flooders);
  for (FloodConnection& flooder : flooders) {
    Result<tools::UniqueFd> fd = tools::connect_tcp_socket(*serve_address, std::chrono::seconds(5));
    if (!fd) return fail(fd.error());
    flooder.fd = std::move(fd.value());
  }

  const tmcl::Instruction request = tools::parse_instruction("GAP 52, 0").value();
  const tmcl::Frame flood_request = tmcl::encode_request(tools::kDefaultModuleAddress, request);
  for (size_t i = 0; i < kWarmupRequests; ++i) {
    if (!timed_round_trip(serve_client.value(), request) || !timed_round_trip(bare_client.value(), request)) return 2;
  }
  std::vector<nanoseconds> serve_samples;
  std::vector<nanoseconds> bare_samples;
  std::vector<nanoseconds> flooded_samples;
  serve_samples.reserve(options->requests);
  bare_samples.reserve(options->requests);
  flooded_samples.reserve(flooders.empty() ? 0 : options->requests);
  const auto block_of = [&request](tools::TmclClient& client, std::vector<nanoseconds>& samples, size_t count) {
    for (size_t i = 0; i < count; ++i) {
      const std::optional<nanoseconds> sample = timed_round_trip(client, request);
      if (!sample) return false;
      samples.push_back(*sample);
    }
    return true;
  };
  nanoseconds flooded_time{0};
  while (serve_samples.size() < options->requests) {
    const size_t block = std::min(kBlockRequests, options->requests - serve_samples.size());
    if (!block_of(bare_client.value(), bare_samples, block) || !block_of(serve_client.value(), serve_samples, block)) {
      return 2;
    }
    if (flooders.empty()) continue;
    const auto start = std::chrono::steady_clock::now();
    const auto flooded_block = [&] { return block_of(serve_client.value(), flooded_samples, block); };
    if (!while_flooding(flooders, flood_request, flooded_block)) return 2;
    flooded_time += std::chrono::duration_cast<nanoseconds>(std::chrono::steady_clock::now() - start);
  }
  uint64_t flood_answered = 0;
  for (const FloodConnection& flooder : flooders) flood_answered += flooder.answered;
  flooders.clear();  // closes the connections before the serve is stopped
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
  if (!flooded_samples.empty()) {
    const Percentiles flooded = percentiles(flooded_samples);
    const double flood_rate = static_cast<double>(flood_answered) / (static_cast<double>(flooded_time.count()) / 1e9);
    const std::string flooded_label = "motwin serve, " + std::to_string(options->flooders) + " flooding";
    std::printf("\nThe same round trip while %zu other connections flood the same serve"
                " (each keeps %zu GAP 52 in flight)\n", options->flooders, kFloodWindow);
    std::printf("  %-34s %10s %10s\n", "", "median", "p99");
    std::printf("  %-34s %8.1f us %8.1f us\n", "motwin serve, idle (above)", motwin.median_us, motwin.p99_us);
    std::printf("  %-34s %8.1f us %8.1f us   (flood: %.0f frames/s answered)\n", flooded_label.c_str(),
                flooded.median_us, flooded.p99_us, flood_rate);
    std::printf("  %-34s %9.2fx %9.2fx\n", "ratio flooded / idle", flooded.median_us / motwin.median_us,
                flooded.p99_us / motwin.p99_us);
  }
  if (serve_exit_status != 0) std::printf("note: motwin serve exited with status %d after SIGTERM\n", serve_exit_status);
  return 0;
}
