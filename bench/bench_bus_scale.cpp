// A full CAN bus in one `motwin serve` (realtime pacing, socketcand on 127.0.0.1): the CPU time the
// serve process uses per simulated second, and whether it keeps real time, with
//   - N idle TMCM-3216 nodes (N = 1, 32, 127; SDO uploads of 6041 from node 1 every 10 ms),
//   - 127 TMCM-3216 nodes with traffic: heartbeats from all (1017 = 100 ms), an SDO client polling
//     6041 of nodes 1..4 (one upload every 10 ms), and a 1 kHz SYNC with three RPDOs (1..3:
//     6040, 6060, 607A of axis 0) and three synchronous TPDOs (2..4) to and from nodes 1..8,
//     operational,
//   - N idle TMCM-1636 nodes on TMCL over CAN (distinct GP 71/70 IDs per node: 2n-1 / 2n; node 1
//     is asked GAP 1 every 10 ms), and 127 of them with one GAP every millisecond in turn to
//     nodes 1..8.
// The serve is a child process; its CPU time (user + system, /proc/PID/stat) is measured over a
// window after a warm-up, and the simulated time over the same window from the bus time stamps of
// the answers to the polls (the server stamps each frame with simulated time; a node answers at
// once), each paired with the wall time its request left. "sim/wall" below 1
// means the simulation fell behind the wall clock. The idle cost per node is the slope of the
// idle rows (1 to 127 nodes). CPU time, not wall time: the figures hold on a loaded machine.
// The bus has no bit timing (--can-bitrate 0): the full traffic is about five times what a 1 Mbit/s
// bus carries, so on a timed bus its frames would queue and their stamps run ahead of the
// simulation. Prints figures only: no timing is asserted (docs/PERFORMANCE.md).
//
//   bench_bus_scale [PATH/TO/motwin] [--seconds S] [--quick] [--only "TMCM-3216 127 full"]
#include <unistd.h>

#include <chrono>
#include <cstdio>
#include <cstring>
#include <filesystem>
#include <fstream>
#include <optional>
#include <span>
#include <sstream>
#include <string>
#include <string_view>
#include <thread>
#include <vector>

#include "end_to_end.h"
#include "tools/canopen_client.h"
#include "tools/serve_process.h"

namespace {

using namespace motwin;
using Clock = std::chrono::steady_clock;

int fail(const std::string& message) {
  std::fprintf(stderr, "bench_bus_scale: %s\n", message.c_str());
  return 2;
}

using motwin::bench::find_motwin_next_to_this_program;
using motwin::bench::process_cpu_seconds;


enum class Module { kTmcm3216, kTmcm1636 };
enum class Traffic { kIdle, kFull };

struct Scenario {
  Module module;
  size_t nodes;
  Traffic traffic;
};

struct Figures {
  double cpu_per_sim_s = 0;
  double sim_per_wall = 0;
  double frames_per_s = 0;  // frames the serve sent, per wall second
  size_t replies_missing = 0;
  double master_rounds_per_s = 0;  // SYNC + RPDO rounds the client sent
};

constexpr uint8_t kPdoNodes = 8;
constexpr uint8_t kSdoPolledNodes = 4;

can::CanFrame frame(uint32_t id, std::initializer_list<uint8_t> bytes) {
  can::CanFrame f{};
  f.id = id;
  f.dlc = static_cast<uint8_t>(bytes.size());
  size_t i = 0;
  for (const uint8_t b : bytes) f.data[i++] = b;
  return f;
}

bool download(tools::SocketcandClient& bus, uint8_t node, uint16_t index, uint8_t sub, std::vector<uint8_t> data,
              std::string& error) {
  const tools::SdoResult result = tools::sdo_download(bus, node, index, sub, data, 2000);
  if (!result.ok) {
    error = "node " + std::to_string(node) + ": SDO download " + std::to_string(index) + " failed";
    return false;
  }
  return true;
}

// Sets the scenario's nodes up over the bus: heartbeats, PDOs, NMT start.
bool configure(tools::SocketcandClient& bus, const Scenario& s, std::string& error) {
  if (s.module != Module::kTmcm3216) return true;
  if (s.traffic != Traffic::kFull) return true;
  for (size_t n = 1; n <= s.nodes; ++n) {
    if (!download(bus, static_cast<uint8_t>(n), 0x1017, 0, {100, 0}, error)) return false;
  }
  for (uint8_t n = 1; n <= kPdoNodes; ++n) {
    // TPDO 2 (6041 + 6061) synchronous like TPDO 3 and 4 by default; the RPDOs stay as they are.
    if (!download(bus, n, 0x1801, 2, {1}, error)) return false;
    // Profile position: the RPDOs below write it again, with controlword 0 and target 0.
    if (!download(bus, n, 0x6060, 0, {1}, error)) return false;
    if (!bus.send(frame(0x000, {0x01, n}))) {
      error = "cannot send NMT start";
      return false;
    }
  }
  return true;
}

Result<Figures> run_scenario(const std::string& motwin_path, const Scenario& s, double seconds) {
  Result<tools::TemporaryDirectory> state_dir = tools::TemporaryDirectory::create("motwin-bus-scale-");
  if (!state_dir) return Error{state_dir.error()};
  std::vector<std::string> arguments;
  for (size_t n = 1; n <= s.nodes; ++n) {
    arguments.push_back("--node");
    if (s.module == Module::kTmcm3216) {
      arguments.push_back("tmcm-3216:node-id=" + std::to_string(n));
    } else {
      arguments.push_back("tmcm-1636:receive-id=" + std::to_string(2 * n - 1) + ",send-id=" + std::to_string(2 * n));
    }
  }
  // No bit timing (--can-bitrate 0): the full traffic (49 frames per millisecond) is about five
  // times what a 1 Mbit/s bus carries; the figure is the serve's cost, not the bus's capacity.
  for (const char* a : {"--can", "socketcand:127.0.0.1:0", "--can-bitrate", "0", "--speed", "realtime", "--state-dir"}) {
    arguments.push_back(a);
  }
  arguments.push_back(state_dir->path().string());
  Result<tools::RunningServe> serve = tools::start_serve(motwin_path, arguments, std::chrono::milliseconds(120000));
  if (!serve) return Error{serve.error()};
  const std::optional<std::string> address = serve->endpoint("can-socketcand");
  if (!address) return Error{"no `endpoint can-socketcand` line"};
  const auto port = static_cast<uint16_t>(std::stoi(address->substr(address->rfind(':') + 1)));
  Result<std::unique_ptr<tools::SocketcandClient>> connected = tools::SocketcandClient::connect("127.0.0.1", port);
  if (!connected) return Error{connected.error()};
  tools::SocketcandClient& bus = **connected;
  std::string error;
  if (!configure(bus, s, error)) return Error{error};

  const bool full = s.traffic == Traffic::kFull;
  const bool canopen = s.module == Module::kTmcm3216;
  // One round of the bus traffic per millisecond: what the master sends.
  std::vector<can::CanFrame> round;
  if (full && canopen) {
    for (uint8_t n = 1; n <= kPdoNodes; ++n) {
      round.push_back(frame(0x200u + n, {0, 0}));                    // RPDO 1: 6040
      round.push_back(frame(0x300u + n, {0, 0, 1}));                 // RPDO 2: 6040, 6060
      round.push_back(frame(0x400u + n, {0, 0, 0, 0, 0, 0}));        // RPDO 3: 6040, 607A
    }
    round.push_back(frame(0x080, {}));  // SYNC after the RPDOs
  }
  uint64_t first_stamp_us = 0;
  uint64_t last_stamp_us = 0;
  Clock::time_point first_seen{};
  Clock::time_point last_seen{};
  size_t rounds = 0;
  bool stamped = false;
  size_t frames = 0;
  size_t requests = 0;
  size_t replies = 0;
  bool outstanding = false;
  Clock::time_point outstanding_since{};
  uint32_t polled = 0;
  uint32_t reply_id = 0;  // of the outstanding request

  const auto warm_up = std::chrono::milliseconds(1000);
  const Clock::time_point start = Clock::now();
  const Clock::time_point measure_from = start + warm_up;
  const Clock::time_point end = measure_from + std::chrono::duration_cast<Clock::duration>(std::chrono::duration<double>(seconds));
  std::optional<double> cpu_start;
  Clock::time_point next_round = start;
  Clock::time_point next_poll = start;
  const auto poll_period = full && !canopen ? std::chrono::milliseconds(1) : std::chrono::milliseconds(10);
  bool measuring = false;
  while (true) {
    const Clock::time_point now = Clock::now();
    if (!measuring && now >= measure_from) {
      measuring = true;
      cpu_start = process_cpu_seconds(serve->process.pid());
      stamped = false;
      frames = 0;
      rounds = 0;
      requests = replies = 0;
    }
    if (now >= end) break;
    // Every round that is due (a late client catches up, at most 10 ms of them).
    if (!round.empty() && now - next_round > std::chrono::milliseconds(10)) next_round = now - std::chrono::milliseconds(10);
    while (!round.empty() && now >= next_round) {
      if (!bus.send(std::span<const can::CanFrame>(round))) return Error{"the serve closed the connection"};
      ++rounds;
      next_round += std::chrono::milliseconds(1);
    }
    if (outstanding && now - outstanding_since > std::chrono::seconds(3)) outstanding = false;  // lost
    if (!outstanding && now >= next_poll) {
      // Polled: SDO uploads of 6041 (CANopen) or GAP 1 (TMCL) in turn.
      const uint32_t count = full ? (canopen ? kSdoPolledNodes : kPdoNodes) : 1;
      const uint32_t node = 1 + polled++ % count;
      reply_id = canopen ? 0x580u + node : 2 * node;
      const can::CanFrame request = canopen ? frame(0x600u + node, {0x40, 0x41, 0x60, 0, 0, 0, 0, 0})
                                            : frame(2 * node - 1, {6, 1, 0, 0, 0, 0, 0});
      if (!bus.send(request)) return Error{"the serve closed the connection"};
      ++requests;
      outstanding = true;
      outstanding_since = now;
      next_poll += poll_period;
      if (next_poll < now) next_poll = now;
    }
    // What the serve sent: waits at most 1 ms for the first (the client reads the socket only
    // with a timeout), then takes what is there.
    while (std::optional<tools::ReceivedFrame> received = bus.receive_stamped(1)) {
      ++frames;
      const uint32_t id = received->frame.id;
      if (id == reply_id && outstanding) {
        outstanding = false;
        ++replies;
        // The serve answers at once, stamping the answer with its simulated time: paired with the
        // wall time the request left, a sample of how far the simulation is behind.
        if (measuring && !stamped) {
          first_stamp_us = received->timestamp_us;
          first_seen = outstanding_since;
          stamped = true;
        }
        last_stamp_us = received->timestamp_us;
        last_seen = outstanding_since;
      }
      const Clock::time_point after = Clock::now();
      if ((!round.empty() && after >= next_round) || after - now >= std::chrono::milliseconds(1)) break;
    }
    if (!bus.connected()) return Error{"the serve closed the connection"};
  }
  const std::optional<double> cpu_end = process_cpu_seconds(serve->process.pid());
  serve->process.stop();
  if (!cpu_start || !cpu_end) return Error{"cannot read the serve's CPU time"};
  if (!stamped || last_stamp_us <= first_stamp_us) return Error{"no frames from the serve"};
  Figures figures;
  // Simulated against wall time between the first and the last answer of the window, each
  // paired with the wall time its request was sent.
  const double sim_span_s = static_cast<double>(last_stamp_us - first_stamp_us) * 1e-6;
  const double wall_span_s = std::chrono::duration<double>(last_seen - first_seen).count();
  if (wall_span_s < seconds / 2) return Error{"too few frames from the serve"};
  figures.sim_per_wall = sim_span_s / wall_span_s;
  figures.cpu_per_sim_s = (*cpu_end - *cpu_start) / (seconds * figures.sim_per_wall);
  figures.master_rounds_per_s = static_cast<double>(rounds) / seconds;
  figures.frames_per_s = static_cast<double>(frames) / seconds;
  figures.replies_missing = requests > replies + 1 ? requests - replies - 1 : 0;
  return figures;
}

const char* module_name(Module m) { return m == Module::kTmcm3216 ? "TMCM-3216" : "TMCM-1636"; }

}  // namespace

int main(int argc, char** argv) {
  std::string motwin_path;
  double seconds = 5.0;
  std::string only;  // one scenario, as its row names it: "TMCM-3216 127 full"
  for (int i = 1; i < argc; ++i) {
    const std::string_view argument = argv[i];
    if (argument == "--seconds" && i + 1 < argc) {
      seconds = std::atof(argv[++i]);
      if (seconds < 1.0) return fail("--seconds takes 1 or more");
    } else if (argument == "--only" && i + 1 < argc) {
      only = argv[++i];
    } else if (argument == "--quick") {
      seconds = 2.0;
    } else if (!argument.starts_with("-") && motwin_path.empty()) {
      motwin_path = argument;
    } else {
      return fail("usage: bench_bus_scale [PATH/TO/motwin] [--seconds S] [--quick] [--only \"TMCM-3216 127 full\"]");
    }
  }
  if (motwin_path.empty()) {
    const std::optional<std::string> found = find_motwin_next_to_this_program();
    if (!found) return fail("motwin not found next to this program; give its path");
    motwin_path = *found;
  }

  const std::vector<Scenario> scenarios = {
      {Module::kTmcm3216, 1, Traffic::kIdle},   {Module::kTmcm3216, 32, Traffic::kIdle},
      {Module::kTmcm3216, 127, Traffic::kIdle}, {Module::kTmcm3216, 127, Traffic::kFull},
      {Module::kTmcm1636, 1, Traffic::kIdle},   {Module::kTmcm1636, 32, Traffic::kIdle},
      {Module::kTmcm1636, 127, Traffic::kIdle}, {Module::kTmcm1636, 127, Traffic::kFull},
  };
  std::printf("One `motwin serve` per row, realtime pacing, socketcand on 127.0.0.1; CPU time of the serve "
              "process per simulated second over %.0f s (after 1 s of warm-up)\n",
              seconds);
  std::printf("  %-10s %5s  %-7s %16s %9s %10s %8s  %s\n", "module", "nodes", "traffic", "CPU s / sim s", "sim/wall",
              "frames/s", "SYNC/s", "real time");
  std::vector<std::pair<Scenario, Figures>> results;
  for (const Scenario& s : scenarios) {
    const std::string name = std::string(module_name(s.module)) + " " + std::to_string(s.nodes) + " " +
                             (s.traffic == Traffic::kFull ? "full" : "idle");
    if (!only.empty() && name != only) continue;
    Result<Figures> figures = run_scenario(motwin_path, s, seconds);
    if (!figures) return fail(std::string(module_name(s.module)) + " x" + std::to_string(s.nodes) + ": " + figures.error());
    // Within 2 %: the pacer drops what it cannot catch up, so a serve that falls behind shows a
    // lower ratio at once.
    const bool kept = figures->sim_per_wall >= 0.98;
    std::printf("  %-10s %5zu  %-7s %16.4f %9.3f %10.0f %8.0f  %s%s\n", module_name(s.module), s.nodes,
                s.traffic == Traffic::kFull ? "full" : "idle", figures->cpu_per_sim_s, figures->sim_per_wall,
                figures->frames_per_s, figures->master_rounds_per_s, kept ? "kept" : "LAGS",
                figures->replies_missing > 0 ? (" (" + std::to_string(figures->replies_missing) + " replies missing)").c_str() : "");
    results.emplace_back(s, *figures);
  }
  for (const Module m : {Module::kTmcm3216, Module::kTmcm1636}) {
    const Figures* one = nullptr;
    const Figures* many = nullptr;
    for (const auto& [s, f] : results) {
      if (s.module != m || s.traffic != Traffic::kIdle) continue;
      if (s.nodes == 1) one = &f;
      if (s.nodes == 127) many = &f;
    }
    if (one == nullptr || many == nullptr) continue;
    const double per_node = (many->cpu_per_sim_s - one->cpu_per_sim_s) / 126.0;
    std::printf("idle cost per node, %s: %.3f ms CPU per simulated second (%.3f %% of a core), slope of 1..127 nodes\n",
                module_name(m), per_node * 1e3, per_node * 100.0);
  }
  return 0;
}
