// `motwin serve`: runs one virtual module and serves TMCL over TCP and/or a pseudo-terminal
// until SIGINT or SIGTERM.
//
// Output contract (stdout, one line each, flushed):
//   motwin: tmcm-1636 (1636V109) eeprom <path|none>
//   endpoint tmcl-tcp 127.0.0.1:<port>            one per --tmcl-tcp
//   endpoint tmcl-pty <LINK> </dev/pts/N>         for --tmcl-pty
//   endpoint can-socketcand 127.0.0.1:<port>      one per --can socketcand:... (CANopen modules)
//   endpoint can-slcan-tcp 127.0.0.1:<port>       one per --can slcan-tcp:...
//   endpoint can-slcan-pty <LINK> </dev/pts/N>     one per --can slcan:LINK
//   endpoint can-socketcan <IFACE>                 one per --can socketcan:IFACE
// With --node (several modules on one bus) the first line is one line per node instead:
//   motwin: node <name> <module> (<firmware>) eeprom <path|none>
//   ready
//   can-stats frames <n> load <percent>% ...      every --can-stats seconds
//   output GPO0 1 at <sim seconds>                whenever an output changes
// Errors before `ready`: one `motwin: error: ...` line on stderr, exit status 2.
#include <algorithm>
#include <csignal>
#include <cstdio>
#include <exception>
#include <functional>
#include <memory>
#include <optional>
#include <string>
#include <vector>

#include <sys/signalfd.h>
#include <unistd.h>

#include "cli/cli_errors.h"
#include "cli/commands.h"
#include "host/can_bus.h"
#include "host/can_capture.h"
#include "host/can_device_endpoints.h"
#include "host/can_endpoint.h"
#include "host/host_runtime.h"
#include "host/module_group.h"
#include "host/module_registry.h"
#include "host/pacing.h"
#include "host/persist_crash_hook.h"
#include "host/pty_endpoint.h"
#include "host/slcan_server.h"
#include "host/socketcand_server.h"
#include "host/state_dir.h"
#include "host/tcp_server.h"
#include "sim/scenario.h"
#include "sim/signals.h"

namespace motwin::cli {
namespace {

// How often a lagging simulation is reported on stderr, at most.
constexpr uint64_t kLagReportIntervalUs = 5'000'000;

struct ServeArguments {
  std::string module;  // default: the first registered module
  std::vector<std::string> tcp_endpoints;
  std::string pty_link;
  std::vector<std::string> can_endpoints;
  int node_id = 0;
  std::string can_capture;
  std::string state_dir;
  std::string speed = "realtime";
  std::vector<std::string> assignments;
  std::string scenario_path;
  std::string motor = "ideal";
  std::vector<std::string> nodes;
  std::string can_bitrate = "1M";
  double can_stats_s = 0;
  bool module_given = false;
};

struct ServeError {
  std::string message;
};

void print_line(const std::string& line) {
  std::fputs(line.c_str(), stdout);
  std::fputc('\n', stdout);
  std::fflush(stdout);
}

// SIGINT and SIGTERM arrive through a descriptor in the loop, so that shutdown happens between
// two loop iterations and never inside a write of the EEPROM image.
class ShutdownSignals {
 public:
  ShutdownSignals() {
    sigemptyset(&mask_);
    sigaddset(&mask_, SIGINT);
    sigaddset(&mask_, SIGTERM);
    ::sigprocmask(SIG_BLOCK, &mask_, &previous_mask_);
    fd_ = ::signalfd(-1, &mask_, SFD_NONBLOCK | SFD_CLOEXEC);
    // A client that disconnects while we write must not kill the server.
    ::signal(SIGPIPE, SIG_IGN);
  }
  ShutdownSignals(const ShutdownSignals&) = delete;
  ShutdownSignals& operator=(const ShutdownSignals&) = delete;
  ~ShutdownSignals() {
    if (fd_ >= 0) ::close(fd_);
    ::sigprocmask(SIG_SETMASK, &previous_mask_, nullptr);
  }
  int fd() const { return fd_; }

 private:
  sigset_t mask_{};
  sigset_t previous_mask_{};
  int fd_ = -1;
};

// Signal bounds are short decimals: "4095", "-50", "0.5".
std::string fmt_range(double value) {
  char buffer[32];
  std::snprintf(buffer, sizeof(buffer), "%g", value);
  return buffer;
}

std::string format_sim_seconds(uint64_t sim_time_us) {
  char buffer[40];
  std::snprintf(buffer, sizeof(buffer), "%llu.%06llu", static_cast<unsigned long long>(sim_time_us / 1'000'000u),
                static_cast<unsigned long long>(sim_time_us % 1'000'000u));
  return buffer;
}

// "1M", "500k", "125000", "0" (no bus timing).
std::optional<uint32_t> parse_bit_rate(const std::string& text) {
  if (text.empty()) return std::nullopt;
  uint64_t multiplier = 1;
  std::string digits = text;
  if (digits.back() == 'k' || digits.back() == 'K') multiplier = 1000;
  if (digits.back() == 'M' || digits.back() == 'm') multiplier = 1'000'000;
  if (multiplier != 1) digits.pop_back();
  if (digits.empty() || digits.find_first_not_of("0123456789") != std::string::npos || digits.size() > 9) {
    return std::nullopt;
  }
  const uint64_t value = std::stoull(digits) * multiplier;
  if (value > 1'000'000) return std::nullopt;  // classic CAN ends at 1 Mbit/s
  return static_cast<uint32_t>(value);
}

// One `can-stats` line for the interval since `before` (`interval_us` of simulated time).
// Nodes that are or were off speed (or lost frames) follow, one " node NAME ..." part each.
std::string format_can_stats(host::CanBus& bus, const host::CanBusStats& before, uint64_t interval_us,
                             const std::vector<std::pair<std::string, host::CanBusNode*>>& nodes) {
  const host::CanBusStats& now = bus.stats();
  const uint64_t frames = now.frames - before.frames;
  const double load = interval_us == 0 ? 0.0
                                       : 100.0 * static_cast<double>(now.busy_ns - before.busy_ns) /
                                             (static_cast<double>(interval_us) * 1000.0);
  const double mean_delay_ms =
      frames == 0 ? 0.0 : static_cast<double>(now.total_queue_delay_ns - before.total_queue_delay_ns) / 1e6 /
                              static_cast<double>(frames);
  char line[200];
  std::snprintf(line, sizeof(line),
                "can-stats frames %llu (+%llu) bits %llu load %.1f%% queue-delay mean %.3f ms max %.3f ms bitrate %u",
                static_cast<unsigned long long>(now.frames), static_cast<unsigned long long>(frames),
                static_cast<unsigned long long>(now.bits - before.bits), load, mean_delay_ms,
                static_cast<double>(now.max_queue_delay_ns) / 1e6, bus.bit_rate());
  std::string text = line;
  for (const auto& [name, node] : nodes) {
    const host::CanNodeBusStats* stats = bus.node_stats(*node);
    if (stats != nullptr && stats->any_trouble()) text += host::format_node_bus_stats(name, *stats);
  }
  return text;
}

int run_serve(const ServeArguments& arguments) {
  std::setvbuf(stdout, nullptr, _IOLBF, 0);
  ShutdownSignals shutdown_signals;
  if (shutdown_signals.fd() < 0) throw ServeError{"cannot set up signal handling"};

  // Everything the user typed is checked before any file or socket is touched.
  const host::ModuleDescriptor* descriptor = host::find_module(arguments.module);
  if (descriptor == nullptr) {
    throw ServeError{"unknown module \"" + arguments.module + "\" (available: " + host::module_names() + ")"};
  }
  const Result<host::Pacing> pacing = host::Pacing::parse(arguments.speed);
  if (!pacing) throw ServeError{pacing.error()};
  // The crash-point test hook, before any image is opened: opening may already write one.
  if (const Result<void> hook = host::install_persist_crash_hook_from_environment(); !hook) {
    throw ServeError{hook.error()};
  }

  host::ModuleOptions options;
  options.motor = arguments.motor;
  for (const std::string& text : arguments.assignments) {
    const Result<sim::SignalAssignment> assignment = sim::parse_signal_assignment(descriptor->input_signals(), text);
    if (!assignment) throw ServeError{"--set " + text + ": " + assignment.error()};
    options.initial_inputs.push_back(host::InitialInput{std::string(assignment->signal->name), assignment->value});
  }
  std::optional<std::vector<sim::ScenarioEvent>> scenario;
  if (!arguments.scenario_path.empty()) {
    Result<std::vector<sim::ScenarioEvent>> events =
        sim::load_scenario_file(arguments.scenario_path, descriptor->input_signals());
    if (!events) throw ServeError{events.error()};
    scenario = std::move(*events);
  }
  std::vector<host::TcpEndpointSpec> tcp_specs;
  for (const std::string& text : arguments.tcp_endpoints) {
    const Result<host::TcpEndpointSpec> spec = host::parse_tcp_endpoint(text);
    if (!spec) throw ServeError{"--tmcl-tcp: " + spec.error()};
    tcp_specs.push_back(*spec);
  }
  std::vector<host::CanEndpointSpec> can_specs;
  for (const std::string& text : arguments.can_endpoints) {
    const Result<host::CanEndpointSpec> spec = host::parse_can_endpoint(text);
    if (!spec) throw ServeError{"--can: " + spec.error()};
    can_specs.push_back(*spec);
  }
  options.node_id = static_cast<uint8_t>(arguments.node_id);
  if (tcp_specs.empty() && arguments.pty_link.empty() && can_specs.empty()) {
    if (descriptor->endpoints.default_endpoint == host::DefaultEndpoint::kTmclTcp) {
      tcp_specs.push_back(host::TcpEndpointSpec{});  // 127.0.0.1:5000
    } else {
      can_specs.push_back(host::CanEndpointSpec{});  // socketcand 127.0.0.1:29536
    }
  }

  if (arguments.state_dir != host::kNoStateDir) {
    if (!arguments.state_dir.empty()) {
      options.state_dir = arguments.state_dir;
    } else if (std::optional<std::filesystem::path> default_dir = host::default_state_dir()) {
      options.state_dir = *default_dir;
    } else {
      throw ServeError{"no home directory for the default state directory; give --state-dir DIR (or none)"};
    }
  }
  std::vector<host::NodeSpec> node_specs;
  for (size_t i = 0; i < arguments.nodes.size(); ++i) {
    const Result<host::NodeSpec> spec = host::parse_node_spec(arguments.nodes[i], i + 1);
    if (!spec) throw ServeError{"--node " + arguments.nodes[i] + ": " + spec.error()};
    node_specs.push_back(*spec);
  }
  const std::optional<uint32_t> bit_rate = parse_bit_rate(arguments.can_bitrate);
  if (!bit_rate) throw ServeError{"--can-bitrate: expected bit/s such as 1M, 500k, 125000 or 0, got \"" +
                                  arguments.can_bitrate + "\""};

  std::unique_ptr<host::VirtualModule> owned_module;
  host::ModuleGroup* group = nullptr;
  if (!node_specs.empty()) {
    // Several modules on one bus: they speak CAN only (docs/canopen.md).
    if (!arguments.tcp_endpoints.empty() || !arguments.pty_link.empty() || !arguments.assignments.empty() ||
        !arguments.scenario_path.empty() || arguments.node_id != 0 || arguments.motor != "ideal" || arguments.module_given) {
      throw ServeError{"--node cannot be combined with --module, --tmcl-tcp, --tmcl-pty, --set, --scenario, --motor or "
                       "--node-id (give per-node options: --node tmcm-3216:node-id=2)"};
    }
    tcp_specs.clear();
    if (can_specs.empty()) can_specs.push_back(host::CanEndpointSpec{});
    Result<std::unique_ptr<host::ModuleGroup>> made = host::ModuleGroup::make(node_specs, options.state_dir);
    if (!made) throw ServeError{made.error()};
    group = made->get();
    owned_module = std::move(*made);
  } else {
    host::MakeModuleResult made = descriptor->make(options);
    if (!made) throw ServeError{made.error()};
    owned_module = std::move(*made);
  }
  host::VirtualModule& module = *owned_module;
  if (group == nullptr) {
    const host::ModuleEndpoints& offered = descriptor->endpoints;
    if ((!tcp_specs.empty() && !offered.tmcl_tcp) || (!arguments.pty_link.empty() && !offered.tmcl_pty)) {
      throw ServeError{std::string(module.name()) + " has no TMCL interface" +
                       (offered.canopen ? " (its firmware speaks CANopen): use --can" : " on TCP or a pty")};
    }
    if (!can_specs.empty() && !offered.has_can()) {
      throw ServeError{std::string(module.name()) + " has no CAN interface (--can)"};
    }
  }

  host::HostRuntime runtime(module, *pacing);
  if (scenario) runtime.set_scenario(std::move(*scenario));

  // Endpoints are destroyed before the runtime they are attached to.
  std::vector<std::unique_ptr<host::TmclTcpServer>> tcp_servers;
  for (const host::TcpEndpointSpec& spec : tcp_specs) {
    Result<std::unique_ptr<host::TmclTcpServer>> opened =
        host::TmclTcpServer::open(runtime.loop(), runtime.service(), spec);
    if (!opened) throw ServeError{opened.error()};
    tcp_servers.push_back(std::move(*opened));
  }
  std::unique_ptr<host::TmclPtyEndpoint> pty;
  if (!arguments.pty_link.empty()) {
    Result<std::unique_ptr<host::TmclPtyEndpoint>> opened =
        host::TmclPtyEndpoint::open(runtime.loop(), runtime.service(), arguments.pty_link);
    if (!opened) throw ServeError{opened.error()};
    pty = std::move(*opened);
  }
  // The virtual CAN bus, stamped with simulated time; the modules leave it before they go away.
  host::CanBus can_bus([&module] { return module.sim_time_us(); });
  can_bus.set_bit_rate(*bit_rate);
  struct BusMembership {
    std::vector<host::CanBusNode*> nodes;
    std::vector<std::pair<std::string, host::CanBusNode*>> named;  // for --can-stats
    ~BusMembership() {
      for (host::CanBusNode* node : nodes) node->disconnect();
    }
  } bus_membership;
  if (!can_specs.empty()) {
    if (group != nullptr) {
      for (host::ModuleGroup::Member& member : group->members()) {
        bus_membership.nodes.push_back(member.module->can_node());
        bus_membership.named.emplace_back(member.name, member.module->can_node());
      }
    } else {
      bus_membership.nodes.push_back(module.can_node());
      bus_membership.named.emplace_back(std::string(module.name()), module.can_node());
    }
    for (host::CanBusNode* node : bus_membership.nodes) node->connect(can_bus);
  }
  std::unique_ptr<host::CanCapture> can_capture;
  struct CaptureMembership {
    host::CanBus& bus;
    host::CanBus::EndpointId id = 0;
    ~CaptureMembership() {
      if (id != 0) bus.detach(id);
    }
  } capture_membership{can_bus};
  if (!arguments.can_capture.empty()) {
    if (can_specs.empty()) throw ServeError{"--can-capture needs a CAN bus (--can)"};
    Result<std::unique_ptr<host::CanCapture>> opened = host::CanCapture::open(arguments.can_capture);
    if (!opened) throw ServeError{"--can-capture: " + opened.error()};
    can_capture = std::move(*opened);
    capture_membership.id = can_bus.attach(*can_capture);
  }
  std::vector<std::unique_ptr<host::SocketcandServer>> can_servers;
  std::vector<std::unique_ptr<host::SlcanTcpServer>> slcan_servers;
  std::vector<std::unique_ptr<host::SlcanPtyEndpoint>> slcan_ptys;
  std::vector<std::unique_ptr<host::SocketcanEndpoint>> socketcan_endpoints;
  std::vector<std::string> can_endpoint_lines;
  for (const host::CanEndpointSpec& spec : can_specs) {
    if (spec.transport == host::CanTransport::kSlcanPty) {
      Result<std::unique_ptr<host::SlcanPtyEndpoint>> opened =
          host::SlcanPtyEndpoint::open(runtime.loop(), can_bus, spec.device);
      if (!opened) throw ServeError{"--can slcan:" + spec.device + ": " + opened.error()};
      can_endpoint_lines.push_back("endpoint can-slcan-pty " + (*opened)->link_path() + " " + (*opened)->device_path());
      slcan_ptys.push_back(std::move(*opened));
      continue;
    }
    if (spec.transport == host::CanTransport::kSocketcan) {
      Result<std::unique_ptr<host::SocketcanEndpoint>> opened =
          host::SocketcanEndpoint::open(runtime.loop(), can_bus, spec.device);
      if (!opened) throw ServeError{"--can: " + opened.error()};
      can_endpoint_lines.push_back("endpoint can-socketcan " + (*opened)->interface_name());
      socketcan_endpoints.push_back(std::move(*opened));
      continue;
    }
    if (spec.transport == host::CanTransport::kSlcanTcp) {
      Result<std::unique_ptr<host::SlcanTcpServer>> opened =
          host::SlcanTcpServer::open(runtime.loop(), can_bus, spec.tcp);
      if (!opened) throw ServeError{"--can: " + opened.error()};
      can_endpoint_lines.push_back("endpoint can-slcan-tcp " + (*opened)->local_address());
      slcan_servers.push_back(std::move(*opened));
      continue;
    }
    Result<std::unique_ptr<host::SocketcandServer>> opened =
        host::SocketcandServer::open(runtime.loop(), can_bus, spec.tcp);
    if (!opened) throw ServeError{"--can: " + opened.error()};
    can_endpoint_lines.push_back("endpoint can-socketcand " + (*opened)->local_address());
    can_servers.push_back(std::move(*opened));
  }

  std::shared_ptr<std::function<void()>> stats_reporter;
  runtime.set_output_listener([](const sim::OutputChange& change) {
    print_line("output " + std::string(change.signal) + " " + std::to_string(change.level) + " at " +
               format_sim_seconds(change.sim_time_us));
  });
  runtime.loop().watch(shutdown_signals.fd(), POLLIN, [&runtime, &shutdown_signals](short) {
    signalfd_siginfo info{};
    while (::read(shutdown_signals.fd(), &info, sizeof(info)) == static_cast<ssize_t>(sizeof(info))) {
    }
    runtime.loop().request_stop();
  });
  uint64_t reported_lag_us = 0;
  std::function<void()> report_lag = [&] {
    const uint64_t dropped_us = runtime.pacer().dropped_backlog_sim_us();
    if (dropped_us > reported_lag_us) {
      std::fprintf(stderr, "motwin: the simulation cannot keep up with --speed %s; it now lags %.1f ms of sim time\n",
                   runtime.pacer().pacing().describe().c_str(), static_cast<double>(dropped_us) / 1000.0);
      reported_lag_us = dropped_us;
    }
    runtime.loop().add_timer_after(kLagReportIntervalUs, report_lag);
  };
  runtime.loop().add_timer_after(kLagReportIntervalUs, report_lag);

  if (group != nullptr) {
    for (host::ModuleGroup::Member& member : group->members()) {
      print_line("motwin: node " + member.name + " " + std::string(member.module->name()) + " (" +
                 std::string(member.module->firmware_version()) + ") eeprom " + member.module->nvm_location());
    }
  } else {
    print_line("motwin: " + std::string(module.name()) + " (" + std::string(module.firmware_version()) + ") eeprom " +
               module.nvm_location());
  }
  if (arguments.can_stats_s > 0) {
    if (can_specs.empty()) throw ServeError{"--can-stats needs a CAN bus (--can)"};
    const uint64_t period_us = static_cast<uint64_t>(arguments.can_stats_s * 1e6);
    auto previous = std::make_shared<std::pair<host::CanBusStats, uint64_t>>(can_bus.stats(), module.sim_time_us());
    std::shared_ptr<std::function<void()>> report_stats = std::make_shared<std::function<void()>>();
    *report_stats = [&runtime, &can_bus, &module, &bus_membership, previous, period_us,
                     weak = std::weak_ptr(report_stats)] {
      print_line(format_can_stats(can_bus, previous->first, module.sim_time_us() - previous->second,
                                  bus_membership.named));
      *previous = {can_bus.stats(), module.sim_time_us()};
      if (const auto again = weak.lock()) runtime.loop().add_timer_after(period_us, *again);
    };
    stats_reporter = report_stats;
    runtime.loop().add_timer_after(period_us, *report_stats);
  }
  for (const auto& server : tcp_servers) print_line("endpoint tmcl-tcp " + server->local_address());
  if (pty) print_line("endpoint tmcl-pty " + pty->link_path() + " " + pty->device_path());
  for (const std::string& line : can_endpoint_lines) print_line(line);
  runtime.start();
  print_line("ready");

  runtime.run();

  runtime.loop().unwatch(shutdown_signals.fd());
  pty.reset();
  tcp_servers.clear();
  can_servers.clear();
  slcan_servers.clear();
  slcan_ptys.clear();
  socketcan_endpoints.clear();
  return kExitSuccess;
}

// "Endpoints: --tmcl-tcp, ...; default ..." for a module's part of the help.
std::string endpoints_help(const host::ModuleEndpoints& endpoints) {
  std::vector<std::string> offered;
  if (endpoints.tmcl_tcp) offered.push_back("--tmcl-tcp");
  if (endpoints.tmcl_pty) offered.push_back("--tmcl-pty");
  if (endpoints.tmcl_can) offered.push_back("--can (TMCL on GP 71/70)");
  if (endpoints.canopen) offered.push_back("--can (CANopen)");
  std::string text = "  Endpoints: ";
  for (size_t i = 0; i < offered.size(); ++i) text += (i > 0 ? ", " : "") + offered[i];
  text += endpoints.default_endpoint == host::DefaultEndpoint::kTmclTcp ? "; default --tmcl-tcp 127.0.0.1:5000\n"
                                                                        : "; default --can socketcand:127.0.0.1:29536\n";
  return text;
}

std::string signals_help(const host::ModuleDescriptor& module) {
  std::string text = "Signals of " + std::string(module.name) + " (--set, --scenario):\n";
  for (const sim::SignalInfo& signal : module.input_signals()) {
    char line[160];
    const std::string range = signal.whole_numbers_only && signal.min == 0 && signal.max == 1
                                  ? "0/1"
                                  : fmt_range(signal.min) + ".." + fmt_range(signal.max);
    std::snprintf(line, sizeof(line), "  %-9s %-9s %s\n", std::string(signal.name).c_str(), range.c_str(),
                  std::string(signal.description).c_str());
    text += line;
  }
  return text;
}

// Each line of a help paragraph, indented.
std::string indented(std::string_view paragraph, std::string_view indent) {
  std::string text;
  while (!paragraph.empty()) {
    const size_t end = std::min(paragraph.find('\n'), paragraph.size());
    text += std::string(indent) + std::string(paragraph.substr(0, end)) + "\n";
    paragraph.remove_prefix(std::min(end + 1, paragraph.size()));
  }
  return text;
}

// The footer's part on the modules: a line each, then each module's help, endpoints, motors and
// signals, all from the descriptors.
std::string modules_help() {
  std::string text = "\nModules (--module, --node):\n";
  for (const host::ModuleDescriptor& module : host::registered_modules()) {
    char line[200];
    std::snprintf(line, sizeof(line), "  %-10s %s\n", std::string(module.name).c_str(), std::string(module.summary).c_str());
    text += line;
  }
  for (const host::ModuleDescriptor& module : host::registered_modules()) {
    text += "\n" + std::string(module.name) + " (firmware " + std::string(module.firmware) + "):\n";
    text += indented(module.help, "  ");
    text += endpoints_help(module.endpoints);
    std::string motors;
    for (std::string_view name : module.motors.names()) motors += std::string(name) + "|";
    text += "  Motors (--motor " + motors + "FILE):\n" + indented(module.motors.help, "    ");
    text += signals_help(module);
  }
  return text;
}

}  // namespace

void add_serve_command(CLI::App& app, int& exit_status) {
  auto arguments = std::make_shared<ServeArguments>();
  arguments->module = std::string(host::registered_modules().front().name);
  CLI::App* serve = app.add_subcommand("serve", "Run a virtual module and serve TMCL to host software");
  CLI::Option* module_option =
      serve->add_option("--module", arguments->module, "Module to run: " + host::module_names())
          ->type_name("NAME")
          ->capture_default_str();
  serve->add_option("--node", arguments->nodes,
                    "Put several modules on one CAN bus in this process instead of --module: "
                    "MODULE[:KEY=VALUE,...] with keys name (state subdirectory, default MODULE-POSITION), node-id "
                    "and serial (CANopen), motor, receive-id and send-id (TMCL: GP 71/70, stored). Repeatable; the nodes speak "
                    "CAN only (see the examples below)")
      ->type_name("MODULE[:KEY=VALUE,...]")
      ->expected(1)
      ->multi_option_policy(CLI::MultiOptionPolicy::TakeAll);
  serve->add_option("--can-bitrate", arguments->can_bitrate,
                    "Bit rate of the virtual bus (1M, 500k, 125000 ...): each frame occupies it for its bit count "
                    "with stuff bits and is stamped when its last bit is out; a TMCL module whose GP 69 differs is "
                    "cut off, as is a CANopen module whose active bit rate (set at reset or by LSS) differs (counted "
                    "per node in --can-stats). 0: frames take no time")
      ->type_name("RATE")
      ->capture_default_str();
  serve->add_option("--can-stats", arguments->can_stats_s,
                    "Print a \"can-stats\" line (frames, bus load %, queueing delay; nodes at another bit rate with "
                    "their error counters) every SECONDS of wall time")
      ->type_name("SECONDS")
      ->check(CLI::PositiveNumber);
  serve->add_option("--tmcl-tcp", arguments->tcp_endpoints,
                    "Serve TMCL over TCP (raw 9-byte frames, as PyTrinamic's socket interface sends them) on "
                    "HOST:PORT; HOST defaults to 127.0.0.1, port 0 picks a free port. Repeatable. Without any "
                    "--tmcl-tcp or --tmcl-pty: 127.0.0.1:5000")
      ->type_name("HOST:PORT")
      ->expected(1)
      ->multi_option_policy(CLI::MultiOptionPolicy::TakeAll);
  serve->add_option("--tmcl-pty", arguments->pty_link,
                    "Serve TMCL on a pseudo-terminal and make LINK a symbolic link to it (for pyserial and other "
                    "serial-port software; the baud rate, and GP 65, have no effect)")
      ->type_name("LINK");
  serve->add_option("--can", arguments->can_endpoints,
                    "Put the module on a virtual CAN bus served as socketcand[:HOST]:PORT (python-can's "
                    "interface='socketcand'), slcan-tcp:[HOST:]PORT (interface='slcan', "
                    "channel='socket://HOST:PORT'), slcan:LINK (an SLCAN adapter on a pseudo-terminal, LINK a "
                    "symbolic link to it) or socketcan:IFACE (a Linux CAN interface such as vcan0); port 0 picks a "
                    "free port. Repeatable: all share one bus. Modules that start on the bus (" +
                        host::module_names([](const host::ModuleDescriptor& module) {
                          return module.endpoints.default_endpoint == host::DefaultEndpoint::kCanSocketcand;
                        }) +
                        ") default to socketcand:127.0.0.1:29536; TMCL modules (" +
                        host::module_names([](const host::ModuleDescriptor& module) { return module.endpoints.tmcl_can; }) +
                        ") answer TMCL on GP 71/70. See docs/canopen.md")
      ->type_name("socketcand:HOST:PORT|slcan-tcp:HOST:PORT|slcan:LINK|socketcan:IFACE")
      ->expected(1)
      ->multi_option_policy(CLI::MultiOptionPolicy::TakeAll);
  serve->add_option("--can-capture", arguments->can_capture,
                    "Write every frame of the CAN bus to FILE (simulated time): pcap with link type 227 when FILE "
                    "ends in .pcap (Wireshark, tshark), otherwise a candump -L log")
      ->type_name("FILE");
  serve->add_option("--node-id", arguments->node_id,
                    "CANopen node ID as the module's address switches would set it (1..127); without it the "
                    "stored node ID (default 1) applies")
      ->type_name("N")
      ->check(CLI::Range(1, 127));
  serve->add_option("--state-dir", arguments->state_dir,
                    "Directory of the EEPROM image file <module>.eeprom (default $XDG_DATA_HOME/motwin or "
                    "~/.local/share/motwin); \"none\" keeps the image in memory only")
      ->type_name("DIR");
  serve->add_option("--speed", arguments->speed,
                    "Simulated time: realtime (follows the wall clock), fast (as fast as the CPU allows) or a "
                    "factor of real time such as 2 or 0.5")
      ->type_name("realtime|fast|FACTOR")
      ->capture_default_str();
  serve->add_option("--set", arguments->assignments,
                    "Set an input before start-up, e.g. --set GPI0=1 --set VSUPPLY=26.5. Repeatable")
      ->type_name("SIGNAL=VALUE")
      ->expected(1)
      ->multi_option_policy(CLI::MultiOptionPolicy::TakeAll);
  serve->add_option("--motor", arguments->motor,
                    "Motor behind the power stage: ideal (the default; fast), a preset (a physical model) or a "
                    "description file; each module's choices are listed below")
      ->type_name("NAME|FILE")
      ->capture_default_str();
  serve->add_option("--scenario", arguments->scenario_path,
                    "Scenario file: lines \"<time_s> <SIGNAL> <value>\" (sim seconds), # comments")
      ->type_name("FILE");

  serve->footer(
      "Prints \"motwin: <module> (<firmware>) eeprom <path>\", one \"endpoint ...\" line per endpoint and "
      "\"ready\" on stdout, then \"output GPO0 1 at <sim seconds>\" for each output change. SIGINT or SIGTERM "
      "stops the server cleanly (exit status 0); a start-up error exits with status 2.\n"
      "\n"
      "Examples:\n"
      "  motwin serve --module tmcm-142 --tmcl-pty /tmp/tmcm142 --motor nema17\n"
      "  motwin serve --node tmcm-3216:node-id=1 --node tmcm-3216:node-id=2 --node tmcm-1636\n" +
      modules_help());

  serve->callback([arguments, module_option, &exit_status] {
    arguments->module_given = module_option->count() > 0;
    try {
      exit_status = run_serve(*arguments);
    } catch (const ServeError& serve_error) {
      print_error(serve_error.message);
      exit_status = kExitUsageError;
    } catch (const std::exception& unexpected) {
      print_error(unexpected.what());
      exit_status = kExitUsageError;
    }
  });
}

}  // namespace motwin::cli
