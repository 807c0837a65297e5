// The cost of open web-console pages to the simulation (issue: "with four pages open at full
// update rate the real-time factor and the TMCL round trip stay within 10 % of no page"). One
// `motwin serve --web` of a TMCM-1636 on a physical motor (default-24v, turning), measured in
// blocks that take turns, so that a busy moment of the machine hits both alike:
//   - without any web client (blocks take turns: none, pages, pages, none, ...),
//   - with N pages (default 4) open, each as web/site/app.js has it with the Parameters view
//     shown and the Scope running at its highest rate: a session subscribed to the first 64
//     readable rows at 20 updates/s and one subscribed to 4 curves at 100 updates/s
//     (bench/web_pages.py, a python3-websocket stand-in for the browser; its CPU is reported
//     apart and never counted as the serve's).
// First `--speed fast`: the real-time factor, simulated seconds per CPU second of the serve
// (user + system, /proc/PID/stat). Then `--speed realtime`: the TMCL GAP 52 round trip over TCP
// (median and p99, one request at a time) and the serve's CPU per simulated second. The serve's
// simulated time is read from its own output: the benchmark toggles GPO0 (SIO 0, 2) and the serve
// prints "output GPO0 L at <sim seconds>". Each figure with pages is printed as a ratio to the
// same figure without, from the same run. Prints figures only: no timing is asserted
// (docs/benchmarks.md).
//
//   bench_web_pages [PATH/TO/motwin] [--rounds N] [--seconds S] [--requests N] [--pages N]
#include <signal.h>
#include <unistd.h>

#include <algorithm>
#include <chrono>
#include <cstdio>
#include <fstream>
#include <functional>
#include <optional>
#include <sstream>
#include <string>
#include <string_view>
#include <thread>
#include <vector>

#include "end_to_end.h"
#include "tools/serve_process.h"
#include "tools/tmcl_client.h"
#include "tools/tmcl_mnemonics.h"

#ifndef MOTWIN_BENCH_SOURCE_DIR
#error "MOTWIN_BENCH_SOURCE_DIR: bench/CMakeLists.txt gives the folder of web_pages.py"
#endif

namespace {

using namespace motwin;
using bench::Percentiles;
using bench::percentiles;
using bench::process_cpu_seconds;
using Clock = std::chrono::steady_clock;
using std::chrono::nanoseconds;

struct Options {
  std::string motwin_path;
  size_t rounds = 4;
  double seconds = 2.0;      // of each --speed fast block
  size_t requests = 4000;    // round trips of each --speed realtime block
  size_t pages = 4;
};

int fail(const std::string& message) {
  std::fprintf(stderr, "bench_web_pages: %s\n", message.c_str());
  return 2;
}

std::optional<Options> parse_options(int argc, char** argv) {
  Options options;
  for (int i = 1; i < argc; ++i) {
    const std::string_view argument = argv[i];
    const auto number = [&](int64_t low, int64_t high) -> std::optional<int64_t> {
      if (i + 1 >= argc) return std::nullopt;
      const std::optional<int64_t> value = tools::parse_integer(argv[++i]);
      if (!value || *value < low || *value > high) return std::nullopt;
      return value;
    };
    std::optional<int64_t> value;
    if (argument == "--rounds" && (value = number(1, 100))) {
      options.rounds = static_cast<size_t>(*value);
    } else if (argument == "--seconds" && (value = number(1, 600))) {
      options.seconds = static_cast<double>(*value);
    } else if (argument == "--requests" && (value = number(100, 1'000'000))) {
      options.requests = static_cast<size_t>(*value);
    } else if (argument == "--pages" && (value = number(1, 8))) {  // two sessions each; the server takes 16
      options.pages = static_cast<size_t>(*value);
    } else if (!argument.starts_with("-") && options.motwin_path.empty()) {
      options.motwin_path = argument;
    } else {
      return std::nullopt;
    }
  }
  if (options.motwin_path.empty()) {
    const std::optional<std::string> found = bench::find_motwin_next_to_this_program();
    if (!found) return std::nullopt;
    options.motwin_path = *found;
  }
  return options;
}


// A serve under measurement: its TMCL client and its simulated clock.
class Serve {
 public:
  static Result<Serve> start(const Options& options, const std::string& state_dir, const std::string& speed) {
    Result<tools::RunningServe> serve = tools::start_serve(
        options.motwin_path, {"--module", "tmcm-1636", "--motor", "default-24v", "--tmcl-tcp", "127.0.0.1:0", "--web",
                              "127.0.0.1:0", "--state-dir", state_dir, "--speed", speed});
    if (!serve) return Error{serve.error()};
    const std::optional<std::string> tcp = serve->endpoint("tmcl-tcp");
    const std::optional<std::string> web = serve->endpoint("web");
    if (!tcp || !web) return Error{"`motwin serve` printed no `endpoint tmcl-tcp` or `endpoint web` line"};
    Result<tools::TmclClient> client = tools::TmclClient::connect_tcp(*tcp);
    if (!client) return Error{client.error()};
    client->set_reply_timeout(std::chrono::seconds(10));
    const std::string web_port = web->substr(web->rfind(':') + 1);
    Serve result(std::move(*serve), std::move(*client), web_port);
    // The motor turns: the regulators and the physics do what they do in use.
    if (!result.ask("ROR 0, 1000")) return Error{"ROR 0, 1000 failed"};
    return result;
  }

  bool ask(std::string_view text) {
    const Result<tools::TmclReply> reply = client_.request(tools::parse_instruction(text).value());
    return reply && reply->status == 100;
  }

  // The serve's simulated time now, in seconds: GPO0 toggled, and the time the serve prints.
  std::optional<double> sim_seconds() {
    level_ = !level_;
    const std::string expected = std::string("output GPO0 ") + (level_ ? "1" : "0") + " at ";
    if (!ask(std::string("SIO 0, 2, ") + (level_ ? "1" : "0"))) return std::nullopt;
    const auto deadline = tools::SteadyClock::now() + std::chrono::seconds(10);
    while (std::optional<std::string> line = serve_.process.read_line(deadline)) {
      if (line->starts_with(expected)) return std::stod(line->substr(expected.size()));
    }
    return std::nullopt;
  }

  std::optional<nanoseconds> round_trip() {
    static const tmcl::Instruction request = tools::parse_instruction("GAP 52, 0").value();
    const auto start = Clock::now();
    const Result<tools::TmclReply> reply = client_.request(request);
    const auto elapsed = Clock::now() - start;
    if (!reply || reply->status != 100) return std::nullopt;
    return std::chrono::duration_cast<nanoseconds>(elapsed);
  }

  std::optional<double> cpu_seconds() const { return process_cpu_seconds(serve_.process.pid()); }
  const std::string& web_port() const { return web_port_; }
  int stop() { return serve_.process.stop(); }

 private:
  Serve(tools::RunningServe serve, tools::TmclClient client, std::string web_port)
      : serve_(std::move(serve)), client_(std::move(client)), web_port_(std::move(web_port)) {}

  tools::RunningServe serve_;
  tools::TmclClient client_;
  std::string web_port_;
  bool level_ = false;
};

// The pages' stand-in while it runs (bench/web_pages.py).
class Pages {
 public:
  static Result<Pages> open(const Serve& serve, size_t pages) {
    const std::string script = std::string(MOTWIN_BENCH_SOURCE_DIR) + "/web_pages.py";
    Result<tools::ChildProcess> child =
        tools::ChildProcess::spawn({"/usr/bin/python3", script, serve.web_port(), "--pages", std::to_string(pages)});
    if (!child) return Error{child.error()};
    const std::optional<std::string> ready = child->read_line(tools::SteadyClock::now() + std::chrono::seconds(60));
    if (!ready || !ready->starts_with("ready")) {
      return Error{"web_pages.py did not open its pages (python3-websocket installed? scripts/install-deps.sh)"};
    }
    return Pages(std::move(*child));
  }

  std::optional<double> cpu_seconds() const { return process_cpu_seconds(child_.pid()); }

  // Closes the pages; the update rates each kind of session got (per second and session).
  std::optional<std::pair<double, double>> close() {
    ::kill(child_.pid(), SIGTERM);
    const std::optional<std::string> line = child_.read_line(tools::SteadyClock::now() + std::chrono::seconds(10));
    child_.wait_for_exit(std::chrono::seconds(5));
    double page_rate = 0, scope_rate = 0;
    if (!line || std::sscanf(line->c_str(), "updates %lf %lf", &page_rate, &scope_rate) != 2) return std::nullopt;
    return std::make_pair(page_rate, scope_rate);
  }

 private:
  explicit Pages(tools::ChildProcess child) : child_(std::move(child)) {}
  tools::ChildProcess child_;
};

struct Totals {
  double sim_s = 0;
  double serve_cpu_s = 0;
  double wall_s = 0;
  double pages_cpu_s = 0;
  std::vector<nanoseconds> round_trips;
};



// One block: `work` runs while the serve's CPU, simulated time and wall time (and the pages' CPU)
// are taken around it.
bool measure(Serve& serve, const Pages* pages, Totals& totals, const std::function<bool()>& work) {
  const std::optional<double> sim_before = serve.sim_seconds();
  const std::optional<double> cpu_before = serve.cpu_seconds();
  const std::optional<double> pages_before = pages ? pages->cpu_seconds() : 0.0;
  const auto wall_before = Clock::now();
  if (!work()) return false;
  const std::optional<double> sim_after = serve.sim_seconds();
  const std::optional<double> cpu_after = serve.cpu_seconds();
  const std::optional<double> pages_after = pages ? pages->cpu_seconds() : 0.0;
  if (!sim_before || !sim_after || !cpu_before || !cpu_after || !pages_before || !pages_after) return false;
  totals.sim_s += *sim_after - *sim_before;
  totals.serve_cpu_s += *cpu_after - *cpu_before;
  totals.pages_cpu_s += *pages_after - *pages_before;
  totals.wall_s += std::chrono::duration<double>(Clock::now() - wall_before).count();
  return true;
}

struct Rates {
  double page_sum = 0, scope_sum = 0;
  size_t count = 0;
};

// `rounds` turns of a block without pages and a block with them, the order swapped every other
// round (so that a drift of the machine's load hits both alike). `idle` runs in a measured window
// (CPU, simulated time); `timed` after it, with the same pages open.
bool run_blocks(Serve& serve, const Options& options, Totals& none, Totals& with_pages, Rates& rates,
                const std::function<bool()>& idle, const std::function<bool(Serve&, Totals&)>& timed) {
  const auto without_pages = [&] { return measure(serve, nullptr, none, idle) && timed(serve, none); };
  const auto with_open_pages = [&] {
    Result<Pages> pages = Pages::open(serve, options.pages);
    if (!pages) {
      std::fprintf(stderr, "bench_web_pages: %s\n", pages.error().c_str());
      return false;
    }
    if (!measure(serve, &*pages, with_pages, idle) || !timed(serve, with_pages)) return false;
    const std::optional<std::pair<double, double>> got = pages->close();
    if (!got) return false;
    rates.page_sum += got->first;
    rates.scope_sum += got->second;
    ++rates.count;
    return true;
  };
  for (size_t round = 0; round < options.rounds; ++round) {
    const bool pages_first = round % 2 == 1;
    if (!(pages_first ? with_open_pages() : without_pages())) return false;
    if (!(pages_first ? without_pages() : with_open_pages())) return false;
  }
  return true;
}

}  // namespace

int main(int argc, char** argv) {
  const std::optional<Options> options = parse_options(argc, argv);
  if (!options) {
    return fail("usage: bench_web_pages [PATH/TO/motwin] [--rounds N] [--seconds S] [--requests N] [--pages N]"
                " (motwin not found next to this program?)");
  }
  Result<tools::TemporaryDirectory> state_dir = tools::TemporaryDirectory::create("motwin-bench-");
  if (!state_dir) return fail(state_dir.error());

  const auto sleep_block = [&] {
    std::this_thread::sleep_for(std::chrono::duration<double>(options->seconds));
    return true;
  };
  const auto no_round_trips = [](Serve&, Totals&) { return true; };

  // --speed fast: simulated seconds per CPU second.
  Totals fast_none, fast_pages;
  Rates fast_rates;
  {
    Result<Serve> serve = Serve::start(*options, state_dir->path().string(), "fast");
    if (!serve) return fail(serve.error());
    if (!run_blocks(*serve, *options, fast_none, fast_pages, fast_rates, sleep_block, no_round_trips)) {
      return fail("a --speed fast block failed");
    }
    serve->stop();
  }

  // --speed realtime: CPU per simulated second with no TMCL host talking, and the TMCL round trip.
  Totals paced_none, paced_pages;
  Rates paced_rates;
  {
    Result<Serve> serve = Serve::start(*options, state_dir->path().string(), "realtime");
    if (!serve) return fail(serve.error());
    for (size_t i = 0; i < 1000; ++i) {
      if (!serve->round_trip()) return fail("warm-up round trip failed");
    }
    const auto timed_block = [&](Serve& s, Totals& totals) {
      for (size_t i = 0; i < options->requests; ++i) {
        const std::optional<nanoseconds> sample = s.round_trip();
        if (!sample) return false;
        totals.round_trips.push_back(*sample);
      }
      return true;
    };
    if (!run_blocks(*serve, *options, paced_none, paced_pages, paced_rates, sleep_block, timed_block)) {
      return fail("a --speed realtime block failed");
    }
    serve->stop();
  }

  const size_t pages = options->pages;
  const double fast_factor_none = fast_none.sim_s / fast_none.serve_cpu_s;
  const double fast_factor_pages = fast_pages.sim_s / fast_pages.serve_cpu_s;
  std::printf("Web-console pages against none: one `motwin serve --web` of a TMCM-1636 (motor default-24v, turning),"
              " %zu rounds of a block without and a block with pages\n",
              options->rounds);
  std::printf("Each page: Parameters (64 rows, 20 updates/s) and Scope (4 curves, 100 updates/s), %zu GAP/s per page\n",
              size_t{64 * 20 + 4 * 100});
  std::printf("\n--speed fast, %.0f s blocks            sim s   serve CPU s   real-time factor\n", options->seconds);
  std::printf("  %-31s %8.1f %13.2f %15.1fx\n", "no page", fast_none.sim_s, fast_none.serve_cpu_s, fast_factor_none);
  std::printf("  %-31s %8.1f %13.2f %15.1fx\n", (std::to_string(pages) + " pages").c_str(), fast_pages.sim_s,
              fast_pages.serve_cpu_s, fast_factor_pages);
  std::printf("  ratio of the real-time factor, %zu pages / no page: %.3fx   (goal: at least 0.90x)\n", pages,
              fast_factor_pages / fast_factor_none);

  const Percentiles rtt_none = percentiles(paced_none.round_trips);
  const Percentiles rtt_pages = percentiles(paced_pages.round_trips);
  const double cpu_none = paced_none.serve_cpu_s / paced_none.sim_s;
  const double cpu_pages = paced_pages.serve_cpu_s / paced_pages.sim_s;
  std::printf("\n--speed realtime: TMCL GAP 52 round trip over TCP (%zu a block)   median        p99\n",
              options->requests);
  std::printf("  %-31s %8.1f us %8.1f us\n", "no page", rtt_none.median_us, rtt_none.p99_us);
  std::printf("  %-31s %8.1f us %8.1f us\n", (std::to_string(pages) + " pages").c_str(), rtt_pages.median_us,
              rtt_pages.p99_us);
  std::printf("  ratio of the TMCL round trip, %zu pages / no page: %.3fx / %.3fx   (goal: at most 1.10x)\n", pages,
              rtt_pages.median_us / rtt_none.median_us, rtt_pages.p99_us / rtt_none.p99_us);
  std::printf("\n--speed realtime, no TMCL host talking, %.0f s blocks: serve CPU per simulated second\n",
              options->seconds);
  std::printf("  %-31s %8.1f ms (%.1f %% of a core)\n", "no page", cpu_none * 1e3,
              100.0 * paced_none.serve_cpu_s / paced_none.wall_s);
  std::printf("  %-31s %8.1f ms (%.1f %% of a core)\n", (std::to_string(pages) + " pages").c_str(), cpu_pages * 1e3,
              100.0 * paced_pages.serve_cpu_s / paced_pages.wall_s);

  const double pages_cpu =
      (fast_pages.pages_cpu_s + paced_pages.pages_cpu_s) / (fast_pages.wall_s + paced_pages.wall_s);
  const size_t blocks = std::max<size_t>(fast_rates.count + paced_rates.count, 1);
  std::printf("\nThe pages' stand-in (python3, bench/web_pages.py; not counted above): %.1f %% of a core;"
              " updates per session %.1f/s (Parameters), %.1f/s (Scope)\n",
              100.0 * pages_cpu, (fast_rates.page_sum + paced_rates.page_sum) / static_cast<double>(blocks),
              (fast_rates.scope_sum + paced_rates.scope_sum) / static_cast<double>(blocks));
  return 0;
}
