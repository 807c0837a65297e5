// `motwin serve`: runs one virtual module and serves TMCL over TCP and/or a pseudo-terminal
// until SIGINT or SIGTERM.
//
// Output contract (stdout, one line each, flushed):
//   motwin: tmcm-1636 (1636V109) eeprom <path|none>
//   endpoint tmcl-tcp 127.0.0.1:<port>[ echo]     one per --tmcl-tcp (echo: given ,echo)
//   endpoint tmcl-pty <LINK> </dev/pts/N>[ echo]  for --tmcl-pty
//   endpoint can-socketcand 127.0.0.1:<port>      one per --can socketcand:... (CANopen modules)
//   endpoint can-slcan-tcp 127.0.0.1:<port>       one per --can slcan-tcp:...
//   endpoint can-slcan-pty <LINK> </dev/pts/N>     one per --can slcan:LINK
//   endpoint can-socketcan <IFACE>                 one per --can socketcan:IFACE
//   endpoint can-socketcand-client <HOST:PORT> <CHANNEL>  one per --can socketcand-client:...
//   endpoint web <HOST:PORT>                       for --web (the console's page and WebSocket)
// With --node (several modules on one bus) the first line is one line per node instead:
//   motwin: node <name> <module> (<firmware>) eeprom <path|none>
//   ready
//   can-stats frames <n> load <percent>% ...      every --can-stats seconds
//   output GPO0 1 at <sim seconds>                whenever an output changes
// Errors before `ready`: one `motwin: error: ...` line on stderr, exit status 2.
#include <algorithm>
#include <charconv>
#include <csignal>
#include <cstdio>
#include <filesystem>
#include <functional>
#include <memory>
#include <optional>
#include <string>
#include <vector>

#include <sys/signalfd.h>
#include <unistd.h>

#include "cli/cli_errors.h"
#include "cli/commands.h"
#include "cli/module_inputs.h"
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
#include "host/socketcand_client.h"
#include "host/socketcand_server.h"
#include "host/state_dir.h"
#include "host/tcp_server.h"
#include "host/tmcl_endpoint_options.h"
#include "host/web/web_server.h"
#include "sim/scenario.h"
#include "sim/signals.h"
#include "tools/web/web_console.h"
#include "types/result.h"

namespace motwin::cli {
namespace {

// How often a lagging simulation is reported on stderr, at most.
constexpr uint64_t kLagReportIntervalUs = 5'000'000;

struct ServeArguments {
  std::string module;  // default: the first registered module
  std::vector<std::string> tcp_endpoints;
  std::string pty_link;
  std::vector<std::string> can_endpoints;
  std::string web_endpoint;
  std::string web_token;
  int node_id = 0;
  std::string can_capture;
  std::string state_dir;
  std::string speed = "realtime";
  std::vector<std::string> assignments;
  std::string scenario_path;
  std::string motor = "ideal";
  std::string firmware;  // empty: the module's default generation
  std::vector<std::string> nodes;
  std::string can_bitrate = "1M";
  double can_stats_s = 0;
  int boot_delay_ms = -1;       // -1: the module's default
  int comm_boot_delay_ms = -1;  // -1: the module's default
  bool module_given = false;
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

// --- Checking the arguments ----------------------------------------------------------------------

// The result, or its failure with `context` in front.
template <class T>
Result<T> with_context(Result<T> result, const std::string& context) {
  if (!result) return result.error_with_context(context);
  return result;
}

// Every text of a repeatable option parsed by `parse` (given the text and its 1-based
// position), or the first failure.
template <class T, class Parse>
Result<std::vector<T>> parse_each(const std::vector<std::string>& texts, Parse parse) {
  std::vector<T> parsed;
  for (size_t i = 0; i < texts.size(); ++i) {
    Result<T> one = parse(texts[i], i + 1);
    if (!one) return Error{one.error()};
    parsed.push_back(std::move(*one));
  }
  return parsed;
}

// What runs: one module (--module) or several on one bus (--node), with their options.
struct ModulePlan {
  // --module running --firmware (with --node: the nodes' own, host::node_module).
  host::ModuleDescriptor descriptor{};
  std::vector<host::NodeSpec> nodes;
  host::Pacing pacing;
  host::ModuleOptions options;  // with --node only the state directory applies
  std::optional<std::vector<sim::ScenarioEvent>> scenario;
};

// TMCL over TCP on one address, with or without the transceiver's echo.
struct TmclTcpPlan {
  host::TcpEndpointSpec spec;
  host::LineEcho echo = host::LineEcho::kNone;
};

// Where it is served.
struct EndpointPlan {
  std::vector<TmclTcpPlan> tmcl_tcp;
  std::string tmcl_pty_link;
  host::LineEcho tmcl_pty_echo = host::LineEcho::kNone;
  std::vector<host::CanEndpointSpec> can;
  uint32_t can_bit_rate = 0;
  std::string can_capture;  // a file; empty: none
  double can_stats_s = 0;   // 0: no can-stats lines
  std::optional<host::web::WebEndpointSpec> web;  // --web
};

struct ServePlan {
  ModulePlan module;
  EndpointPlan endpoints;
};

// --state-dir: a directory, none (nullopt: the image stays in memory) or, not given, the default.
Result<std::optional<std::filesystem::path>> state_dir_of(const std::string& state_dir) {
  if (state_dir == host::kNoStateDir) return std::optional<std::filesystem::path>{};
  if (!state_dir.empty()) return std::optional<std::filesystem::path>{state_dir};
  if (std::optional<std::filesystem::path> default_dir = host::default_state_dir()) return default_dir;
  return Error{"no home directory for the default state directory; give --state-dir DIR (or none)"};
}

// --node puts several modules on one bus: they speak CAN only (docs/canopen.md), and each node
// takes its own options.
Result<void> check_node_options(const ServeArguments& arguments) {
  if (arguments.nodes.empty()) return {};
  if (!arguments.tcp_endpoints.empty() || !arguments.pty_link.empty() || !arguments.assignments.empty() ||
      !arguments.scenario_path.empty() || arguments.node_id != 0 || arguments.motor != "ideal" || arguments.module_given ||
      !arguments.firmware.empty()) {
    return Error{"--node cannot be combined with --module, --firmware, --tmcl-tcp, --tmcl-pty, --set, --scenario, --motor or "
                 "--node-id (give per-node options: --node tmcm-3216:node-id=2)"};
  }
  return {};
}

Result<ModulePlan> check_module_arguments(const ServeArguments& arguments) {
  ModulePlan plan;
  Result<host::ModuleDescriptor> descriptor = host::find_module_with_firmware(arguments.module, arguments.firmware);
  if (!descriptor) return Error{descriptor.error()};
  plan.descriptor = std::move(*descriptor);
  plan.options.firmware = arguments.firmware;
  const Result<host::Pacing> pacing = host::Pacing::parse(arguments.speed);
  if (!pacing) return Error{pacing.error()};
  plan.pacing = *pacing;
  Result<ModuleInputs> inputs =
      read_module_inputs(plan.descriptor.input_signals(), arguments.assignments, arguments.scenario_path);
  if (!inputs) return Error{inputs.error()};
  plan.options.initial_inputs = std::move(inputs->initial_inputs);
  plan.scenario = std::move(inputs->scenario);
  plan.options.motor = arguments.motor;
  plan.options.node_id = static_cast<uint8_t>(arguments.node_id);
  Result<std::optional<std::filesystem::path>> state_dir = state_dir_of(arguments.state_dir);
  if (!state_dir) return Error{state_dir.error()};
  plan.options.state_dir = *state_dir;
  Result<std::vector<host::NodeSpec>> nodes =
      parse_each<host::NodeSpec>(arguments.nodes, [](const std::string& text, size_t position) {
        return with_context(host::parse_node_spec(text, position), "--node " + text + ": ");
      });
  if (!nodes) return Error{nodes.error()};
  plan.nodes = std::move(*nodes);
  // --boot-delay-ms / --comm-boot-delay-ms: the module's, or every CANopen node's unless its own
  // key says otherwise.
  if (arguments.boot_delay_ms >= 0) plan.options.boot_delay_ms = static_cast<uint32_t>(arguments.boot_delay_ms);
  if (arguments.comm_boot_delay_ms >= 0) {
    plan.options.communication_boot_delay_ms = static_cast<uint32_t>(arguments.comm_boot_delay_ms);
  }
  const bool delays_given = plan.options.boot_delay_ms || plan.options.communication_boot_delay_ms;
  if (plan.nodes.empty() && delays_given && plan.descriptor.canopen == nullptr) {
    return Error{"--boot-delay-ms and --comm-boot-delay-ms are for CANopen modules (" +
                 host::module_names([](const host::ModuleDescriptor& module) { return module.canopen != nullptr; }) +
                 ")"};
  }
  for (host::NodeSpec& node : plan.nodes) {
    const Result<host::ModuleDescriptor> node_module = host::node_module(node);
    if (!node_module || node_module->canopen == nullptr) continue;
    if (!node.boot_delay_ms) node.boot_delay_ms = plan.options.boot_delay_ms;
    if (!node.communication_boot_delay_ms) node.communication_boot_delay_ms = plan.options.communication_boot_delay_ms;
  }
  return plan;
}

// "1M", "500k", "125000", "0" (no bus timing).
Result<uint32_t> parse_bit_rate(std::string_view text) {
  const Error expected{"--can-bitrate: expected bit/s such as 1M, 500k, 125000 or 0, got \"" + std::string(text) +
                       "\""};
  if (text.empty()) return expected;
  uint64_t multiplier = 1;
  if (text.back() == 'k' || text.back() == 'K') multiplier = 1000;
  if (text.back() == 'M' || text.back() == 'm') multiplier = 1'000'000;
  std::string_view digits = multiplier == 1 ? text : text.substr(0, text.size() - 1);
  uint64_t value = 0;
  const auto [end, problem] = std::from_chars(digits.data(), digits.data() + digits.size(), value);
  if (digits.empty() || digits.size() > 9 || problem != std::errc{} || end != digits.data() + digits.size()) {
    return expected;
  }
  if (value * multiplier > 1'000'000) return expected;  // classic CAN ends at 1 Mbit/s
  return static_cast<uint32_t>(value * multiplier);
}

// A single module is served only on the interfaces its firmware has.
Result<void> check_offered(const host::ModuleDescriptor& module, const EndpointPlan& plan) {
  const host::ModuleEndpoints& offered = module.endpoints;
  if ((!plan.tmcl_tcp.empty() && !offered.tmcl_tcp) || (!plan.tmcl_pty_link.empty() && !offered.tmcl_pty)) {
    return Error{std::string(module.name) + " has no TMCL interface" +
                 (offered.canopen ? " (its firmware speaks CANopen): use --can" : " on TCP or a pty")};
  }
  if (!plan.can.empty() && !offered.has_can()) return Error{std::string(module.name) + " has no CAN interface (--can)"};
  return {};
}

Result<EndpointPlan> check_endpoint_arguments(const ServeArguments& arguments, const ModulePlan& module) {
  EndpointPlan plan;
  Result<std::vector<TmclTcpPlan>> tcp =
      parse_each<TmclTcpPlan>(arguments.tcp_endpoints, [](const std::string& text, size_t) -> Result<TmclTcpPlan> {
        const Result<host::TmclEndpointArgument> argument = host::parse_tmcl_endpoint_argument(text);
        if (!argument) return argument.error_with_context("--tmcl-tcp: ");
        const Result<host::TcpEndpointSpec> spec = host::parse_tcp_endpoint(argument->address);
        if (!spec) return spec.error_with_context("--tmcl-tcp: ");
        return TmclTcpPlan{*spec, argument->echo};
      });
  if (!tcp) return Error{tcp.error()};
  plan.tmcl_tcp = std::move(*tcp);
  if (!arguments.pty_link.empty()) {
    const Result<host::TmclEndpointArgument> pty = host::parse_tmcl_endpoint_argument(arguments.pty_link);
    if (!pty) return pty.error_with_context("--tmcl-pty: ");
    plan.tmcl_pty_link = pty->address;
    plan.tmcl_pty_echo = pty->echo;
  }
  Result<std::vector<host::CanEndpointSpec>> can =
      parse_each<host::CanEndpointSpec>(arguments.can_endpoints, [](const std::string& text, size_t) {
        return with_context(host::parse_can_endpoint(text), "--can: ");
      });
  if (!can) return Error{can.error()};
  plan.can = std::move(*can);
  if (plan.tmcl_tcp.empty() && plan.tmcl_pty_link.empty() && plan.can.empty()) {
    // Nodes are on the bus; a single module where its descriptor puts it.
    if (module.nodes.empty() && module.descriptor.endpoints.default_endpoint == host::DefaultEndpoint::kTmclTcp) {
      plan.tmcl_tcp.push_back(TmclTcpPlan{});  // 127.0.0.1:5000
    } else {
      plan.can.push_back(host::CanEndpointSpec{});  // socketcand 127.0.0.1:29536
    }
  }
  Result<uint32_t> bit_rate = parse_bit_rate(arguments.can_bitrate);
  if (!bit_rate) return Error{bit_rate.error()};
  plan.can_bit_rate = *bit_rate;
  if (Result<void> combined = check_node_options(arguments); !combined) return Error{combined.error()};
  if (module.nodes.empty()) {
    if (Result<void> offered = check_offered(module.descriptor, plan); !offered) return Error{offered.error()};
  }
  // These watch the bus.
  if (plan.can.empty() && !arguments.can_capture.empty()) return Error{"--can-capture needs a CAN bus (--can)"};
  if (plan.can.empty() && arguments.can_stats_s > 0) return Error{"--can-stats needs a CAN bus (--can)"};
  plan.can_capture = arguments.can_capture;
  plan.can_stats_s = arguments.can_stats_s;
  if (!arguments.web_endpoint.empty()) {
    Result<host::web::WebEndpointSpec> web = host::web::parse_web_endpoint(arguments.web_endpoint, arguments.web_token);
    if (!web) return web.error_with_context("--web: ");
    plan.web = std::move(*web);
  } else if (!arguments.web_token.empty()) {
    return Error{"--web-token needs --web"};
  }
  return plan;
}

// Everything the user typed, checked before any file or socket is touched.
Result<ServePlan> check_arguments(const ServeArguments& arguments) {
  Result<ModulePlan> module = check_module_arguments(arguments);
  if (!module) return Error{module.error()};
  Result<EndpointPlan> endpoints = check_endpoint_arguments(arguments, *module);
  if (!endpoints) return Error{endpoints.error()};
  return ServePlan{std::move(*module), std::move(*endpoints)};
}

// --- The module, the bus and the endpoints ------------------------------------------------------

using NamedBusNode = std::pair<std::string, host::CanBusNode*>;

// What `serve` runs: one module, or with --node a group of them on one bus.
struct ServedModule {
  std::unique_ptr<host::VirtualModule> module;
  host::ModuleGroup* group = nullptr;  // the same object, when it is a group

  // The modules that join the CAN bus, with the names --can-stats gives them.
  std::vector<NamedBusNode> bus_nodes() const {
    if (group == nullptr) return {NamedBusNode{std::string(module->name()), module->can_node()}};
    std::vector<NamedBusNode> nodes;
    for (host::ModuleGroup::Member& member : group->members()) {
      nodes.emplace_back(member.name, member.module->can_node());
    }
    return nodes;
  }

  // The first lines on stdout: the module, or each node, with its firmware and EEPROM image.
  std::vector<std::string> banner_lines() const {
    if (group == nullptr) {
      return {"motwin: " + std::string(module->name()) + " (" + std::string(module->firmware_version()) +
              ") eeprom " + module->nvm_location()};
    }
    std::vector<std::string> lines;
    for (host::ModuleGroup::Member& member : group->members()) {
      lines.push_back("motwin: node " + member.name + " " + std::string(member.module->name()) + " (" +
                      std::string(member.module->firmware_version()) + ") eeprom " + member.module->nvm_location());
    }
    return lines;
  }
};

Result<ServedModule> make_served_module(const ModulePlan& plan) {
  if (plan.nodes.empty()) {
    Result<std::unique_ptr<host::VirtualModule>> module = plan.descriptor.make(plan.options);
    if (!module) return Error{module.error()};
    return ServedModule{std::move(*module)};
  }
  Result<std::unique_ptr<host::ModuleGroup>> group = host::ModuleGroup::make(plan.nodes, plan.options.state_dir);
  if (!group) return Error{group.error()};
  host::ModuleGroup* members = group->get();
  return ServedModule{std::move(*group), members};
}

// The virtual CAN bus, stamped with simulated time, with the modules and a capture on it. What
// joined leaves before the bus goes: the capture, then the modules (which outlive it). Endpoints
// on the bus must be closed before this goes.
class ServedCanBus {
 public:
  ServedCanBus(host::VirtualModule& clock, uint32_t bit_rate) : bus_([&clock] { return clock.sim_time_us(); }) {
    bus_.set_bit_rate(bit_rate);
  }
  ServedCanBus(const ServedCanBus&) = delete;
  ServedCanBus& operator=(const ServedCanBus&) = delete;
  ~ServedCanBus() {
    if (capture_id_ != 0) bus_.detach(capture_id_);
    capture_.reset();
    for (const auto& [name, node] : nodes_) node->disconnect();
  }

  void join(std::vector<NamedBusNode> nodes) {
    nodes_ = std::move(nodes);
    for (const auto& [name, node] : nodes_) node->connect(bus_);
  }
  // --can-capture FILE.
  Result<void> capture_to(const std::string& path) {
    Result<std::unique_ptr<host::CanCapture>> opened = host::CanCapture::open(path);
    if (!opened) return opened.error_with_context("--can-capture: ");
    capture_ = std::move(*opened);
    capture_id_ = bus_.attach(*capture_);
    return {};
  }

  host::CanBus& bus() { return bus_; }
  const std::vector<NamedBusNode>& nodes() const { return nodes_; }

 private:
  host::CanBus bus_;
  std::vector<NamedBusNode> nodes_;
  std::unique_ptr<host::CanCapture> capture_;
  host::CanBus::EndpointId capture_id_ = 0;
};

// An endpoint, open for as long as this lives, with its line for stdout ("endpoint tmcl-tcp ...").
struct OpenEndpoint {
  std::shared_ptr<void> endpoint;
  std::string line;
};

// Each kind of endpoint says where it is: an address, or a link and its device; a TMCL endpoint
// then its options.
std::string where(const host::TmclTcpServer& server) {
  return server.local_address() + host::describe_line_echo(server.echo());
}
std::string where(const host::SocketcandServer& server) { return server.local_address(); }
std::string where(const host::SlcanTcpServer& server) { return server.local_address(); }
std::string where(const host::SocketcanEndpoint& can) { return can.interface_name(); }
std::string where(const host::SocketcandClientEndpoint& client) { return client.where(); }
std::string where(const host::TmclPtyEndpoint& pty) {
  return pty.link_path() + " " + pty.device_path() + host::describe_line_echo(pty.echo());
}
std::string where(const host::SlcanPtyEndpoint& pty) { return pty.link_path() + " " + pty.device_path(); }

// `opened` with its line "endpoint KIND WHERE", or its failure with `context` in front.
template <class Endpoint>
Result<OpenEndpoint> keep_open(Result<std::unique_ptr<Endpoint>> opened, std::string_view kind,
                               const std::string& context) {
  if (!opened) return opened.error_with_context(context);
  std::string line = "endpoint " + std::string(kind) + " " + where(**opened);
  return OpenEndpoint{std::shared_ptr<Endpoint>(std::move(*opened)), std::move(line)};
}

Result<OpenEndpoint> open_can_endpoint(host::EventLoop& loop, host::CanBus& bus, const host::CanEndpointSpec& spec) {
  switch (spec.transport) {
    case host::CanTransport::kSlcanPty:
      return keep_open(host::SlcanPtyEndpoint::open(loop, bus, spec.device), "can-slcan-pty",
                       "--can slcan:" + spec.device + ": ");
    case host::CanTransport::kSocketcan:
      return keep_open(host::SocketcanEndpoint::open(loop, bus, spec.device), "can-socketcan", "--can: ");
    case host::CanTransport::kSlcanTcp:
      return keep_open(host::SlcanTcpServer::open(loop, bus, spec.tcp), "can-slcan-tcp", "--can: ");
    case host::CanTransport::kSocketcandClient:
      return keep_open(host::SocketcandClientEndpoint::open(loop, bus, {spec.tcp, spec.device}), "can-socketcand-client",
                       "--can: ");
    case host::CanTransport::kSocketcand:
      break;
  }
  return keep_open(host::SocketcandServer::open(loop, bus, spec.tcp), "can-socketcand", "--can: ");
}

// TMCL over TCP (--tmcl-tcp) and on a pseudo-terminal (--tmcl-pty).
Result<std::vector<OpenEndpoint>> open_tmcl_endpoints(host::HostRuntime& runtime, const EndpointPlan& plan) {
  std::vector<OpenEndpoint> endpoints;
  for (const TmclTcpPlan& tcp : plan.tmcl_tcp) {
    Result<OpenEndpoint> opened = keep_open(
        host::TmclTcpServer::open(runtime.loop(), runtime.service(), tcp.spec, host::log_to_stderr, tcp.echo),
        "tmcl-tcp", "");
    if (!opened) return Error{opened.error()};
    endpoints.push_back(std::move(*opened));
  }
  if (!plan.tmcl_pty_link.empty()) {
    Result<OpenEndpoint> opened =
        keep_open(host::TmclPtyEndpoint::open(runtime.loop(), runtime.service(), plan.tmcl_pty_link,
                                              host::log_to_stderr, plan.tmcl_pty_echo),
                  "tmcl-pty", "");
    if (!opened) return Error{opened.error()};
    endpoints.push_back(std::move(*opened));
  }
  return endpoints;
}

// The web console (--web): what it reaches, then its server. The console goes after the server.
struct WebEndpoint {
  std::unique_ptr<tools::web::WebConsole> console;
  std::unique_ptr<host::web::WebServer> server;
  ~WebEndpoint() { server.reset(); }
};
std::string where(const WebEndpoint& web) { return web.server->local_address(); }

// A CANopen node's ID as serve set it: its option, or the stored default (1).
uint8_t configured_node_id(uint8_t node_id) { return node_id != 0 ? node_id : 1; }

Result<OpenEndpoint> open_web_endpoint(host::HostRuntime& runtime, ServedCanBus& can, const ServedModule& served,
                                       const ModulePlan& module, const EndpointPlan& plan) {
  std::vector<tools::web::ConsoleTarget> targets;
  host::CanBus* bus = plan.can.empty() ? nullptr : &can.bus();
  if (served.group == nullptr) {
    const host::VirtualModule& single = *served.module;
    if (runtime.has_tmcl_service()) {
      targets.push_back(tools::web::tmcl_target(module.descriptor, std::string(single.name()),
                                                std::string(single.firmware_version()), module.options.firmware,
                                                served.module->engine().device().motor_count(), &runtime.service()));
    } else {
      targets.push_back(tools::web::canopen_target(module.descriptor, std::string(single.name()),
                                                   std::string(single.firmware_version()),
                                                   configured_node_id(module.options.node_id)));
    }
    targets.back().world = {&served.module->signals(), [&runtime](std::string_view signal, double value) {
                              return runtime.set_input_now(signal, value);
                            }};
  } else {
    for (size_t i = 0; i < module.nodes.size(); ++i) {
      const host::NodeSpec& spec = module.nodes[i];
      const host::ModuleGroup::Member& member = served.group->members()[i];
      const Result<host::ModuleDescriptor> node_module = host::node_module(spec);  // checked by parse_node_spec
      if (!node_module) return Error{node_module.error()};
      const host::ModuleDescriptor& descriptor = *node_module;
      const std::string firmware(member.module->firmware_version());
      targets.push_back(descriptor.canopen != nullptr
                            ? tools::web::canopen_target(descriptor, member.name, firmware,
                                                         configured_node_id(spec.node_id))
                            : tools::web::tmcl_target(descriptor, member.name, firmware, spec.firmware,
                                                      member.module->has_tmcl()
                                                          ? member.module->engine().device().motor_count()
                                                          : uint8_t{1},
                                                      nullptr,
                                                      bus != nullptr ? member.module->tmcl_can_node() : nullptr));
      targets.back().world.board = &member.module->signals();  // read only: a node takes no scenario
    }
  }
  auto web = std::make_unique<WebEndpoint>();
  web->console = std::make_unique<tools::web::WebConsole>(
      runtime.loop(), [&runtime] { return runtime.sim_time_us(); }, std::move(targets), bus);
  tools::web::WebConsole& console = *web->console;
  Result<std::unique_ptr<host::web::WebServer>> server = host::web::WebServer::open(
      runtime.loop(), *plan.web, [&console](host::web::WebConnection& connection) { return console.open_session(connection); });
  if (!server) return server.error_with_context("--web: ");
  web->server = std::move(*server);
  return keep_open(Result<std::unique_ptr<WebEndpoint>>(std::move(web)), "web", "");
}

// The endpoints of the plan in the order of their lines: TMCL over TCP and on a pty, then, once
// the modules are on the bus and its capture runs, the CAN endpoints. On a failure the ones
// already open close again.
Result<std::vector<OpenEndpoint>> open_can_and_tmcl_endpoints(host::HostRuntime& runtime, ServedCanBus& can,
                                                              const ServedModule& served, const EndpointPlan& plan) {
  Result<std::vector<OpenEndpoint>> endpoints = open_tmcl_endpoints(runtime, plan);
  if (!endpoints || plan.can.empty()) return endpoints;
  can.join(served.bus_nodes());
  if (!plan.can_capture.empty()) {
    if (Result<void> capture = can.capture_to(plan.can_capture); !capture) return Error{capture.error()};
  }
  for (const host::CanEndpointSpec& spec : plan.can) {
    Result<OpenEndpoint> opened = open_can_endpoint(runtime.loop(), can.bus(), spec);
    if (!opened) return Error{opened.error()};
    endpoints->push_back(std::move(*opened));
  }
  return endpoints;
}

// Then the web console, which reaches the modules through the TMCL service and the bus.
Result<std::vector<OpenEndpoint>> open_endpoints(host::HostRuntime& runtime, ServedCanBus& can,
                                                 const ServedModule& served, const ModulePlan& module,
                                                 const EndpointPlan& plan) {
  Result<std::vector<OpenEndpoint>> endpoints = open_can_and_tmcl_endpoints(runtime, can, served, plan);
  if (!endpoints || !plan.web) return endpoints;
  Result<OpenEndpoint> web = open_web_endpoint(runtime, can, served, module, plan);
  if (!web) return Error{web.error()};
  endpoints->push_back(std::move(*web));
  return endpoints;
}

// --- Reports while running ----------------------------------------------------------------------

using Report = std::shared_ptr<std::function<void()>>;

// Runs `report` every `period_us` for as long as the returned handle lives.
Report repeat_every(host::EventLoop& loop, uint64_t period_us, std::function<void()> report) {
  Report repeating = std::make_shared<std::function<void()>>();
  *repeating = [&loop, period_us, report = std::move(report), weak = std::weak_ptr(repeating)] {
    report();
    if (const Report again = weak.lock()) loop.add_timer_after(period_us, *again);
  };
  loop.add_timer_after(period_us, *repeating);
  return repeating;
}

// One `can-stats` line for the interval since `before` (`interval_us` of simulated time).
// Nodes that are or were off speed (or lost frames) follow, one " node NAME ..." part each.
std::string format_can_stats(host::CanBus& bus, const host::CanBusStats& before, uint64_t interval_us,
                             const std::vector<NamedBusNode>& nodes) {
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

// "output GPO0 1 at <sim seconds>" on stdout for each output change; on stderr, at most every
// kLagReportIntervalUs, that the simulation cannot keep up with --speed; and every
// `can_stats_s` a `can-stats` line. The reports stop when the returned handles go.
std::vector<Report> start_reports(host::HostRuntime& runtime, ServedCanBus& can, double can_stats_s) {
  runtime.set_output_listener([](const sim::OutputChange& change) {
    print_line("output " + std::string(change.signal) + " " + std::to_string(change.level) + " at " +
               format_sim_seconds(change.sim_time_us));
  });
  const auto report_lag = [&runtime, reported_lag_us = std::make_shared<uint64_t>(0)] {
    const uint64_t dropped_us = runtime.pacer().dropped_backlog_sim_us();
    if (dropped_us > *reported_lag_us) {
      std::fprintf(stderr, "motwin: the simulation cannot keep up with --speed %s; it now lags %.1f ms of sim time\n",
                   runtime.pacer().pacing().describe().c_str(), static_cast<double>(dropped_us) / 1000.0);
      *reported_lag_us = dropped_us;
    }
  };
  std::vector<Report> reports{repeat_every(runtime.loop(), kLagReportIntervalUs, report_lag)};
  if (can_stats_s > 0) {
    host::VirtualModule& module = runtime.module();
    // The bus totals and the simulated time of the previous line.
    auto previous = std::make_shared<std::pair<host::CanBusStats, uint64_t>>(can.bus().stats(), module.sim_time_us());
    const auto report_can_stats = [&can, &module, previous] {
      print_line(format_can_stats(can.bus(), previous->first, module.sim_time_us() - previous->second, can.nodes()));
      *previous = {can.bus().stats(), module.sim_time_us()};
    };
    reports.push_back(repeat_every(runtime.loop(), static_cast<uint64_t>(can_stats_s * 1e6), report_can_stats));
  }
  return reports;
}

// SIGINT or SIGTERM ends runtime.run() between two loop iterations.
void stop_on_shutdown_signals(host::HostRuntime& runtime, const ShutdownSignals& shutdown_signals) {
  runtime.loop().watch(shutdown_signals.fd(), POLLIN, [&runtime, &shutdown_signals](short) {
    signalfd_siginfo info{};
    while (::read(shutdown_signals.fd(), &info, sizeof(info)) == static_cast<ssize_t>(sizeof(info))) {
    }
    runtime.loop().request_stop();
  });
}

int run_serve(const ServeArguments& arguments) {
  std::setvbuf(stdout, nullptr, _IOLBF, 0);
  ShutdownSignals shutdown_signals;
  if (shutdown_signals.fd() < 0) return usage_error("cannot set up signal handling");
  Result<ServePlan> plan = check_arguments(arguments);
  if (!plan) return usage_error(plan.error());
  // The crash-point test hook, before any image is opened: opening may already write one.
  if (const Result<void> hook = host::install_persist_crash_hook_from_environment(); !hook) {
    return usage_error(hook.error());
  }
  Result<ServedModule> served = make_served_module(plan->module);
  if (!served) return usage_error(served.error());
  host::VirtualModule& module = *served->module;
  host::HostRuntime runtime(module, plan->module.pacing);
  if (plan->module.scenario) runtime.set_scenario(std::move(*plan->module.scenario));
  ServedCanBus can(module, plan->endpoints.can_bit_rate);
  // After the runtime and the bus: the endpoints close before them.
  Result<std::vector<OpenEndpoint>> endpoints = open_endpoints(runtime, can, *served, plan->module, plan->endpoints);
  if (!endpoints) return usage_error(endpoints.error());
  const std::vector<Report> reports = start_reports(runtime, can, plan->endpoints.can_stats_s);
  stop_on_shutdown_signals(runtime, shutdown_signals);

  for (const std::string& line : served->banner_lines()) print_line(line);
  for (const OpenEndpoint& endpoint : *endpoints) print_line(endpoint.line);
  runtime.start();
  print_line("ready");
  runtime.run();

  runtime.loop().unwatch(shutdown_signals.fd());
  endpoints->clear();
  return kExitSuccess;
}

// "Endpoints: --tmcl-tcp, ...; default ..." for a module's part of the help, after `indent`.
std::string endpoints_help(const host::ModuleEndpoints& endpoints, std::string_view indent = "  ") {
  std::vector<std::string> offered;
  if (endpoints.tmcl_tcp) offered.push_back("--tmcl-tcp");
  if (endpoints.tmcl_pty) offered.push_back("--tmcl-pty");
  if (endpoints.tmcl_can) offered.push_back("--can (TMCL on GP 71/70)");
  if (endpoints.canopen) offered.push_back("--can (CANopen)");
  std::string text = std::string(indent) + "Endpoints: ";
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
    if (!module.firmwares.empty()) {
      text += "  Firmware (--firmware):\n";
      for (const host::FirmwareGeneration& generation : module.firmwares) {
        text += "    " + std::string(generation.name) + " (" + std::string(generation.version) + "): " +
                std::string(generation.help) + "\n";
        // A generation that is another module to the host (another protocol): where it is served.
        if (generation.descriptor != nullptr) text += endpoints_help(generation.descriptor().endpoints, "      ");
      }
    }
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
                    "and serial (CANopen), boot-delay-ms and comm-boot-delay-ms (CANopen: as --boot-delay-ms), motor, firmware (as --firmware), receive-id and send-id (TMCL: GP 71/70, stored). Repeatable; the nodes speak "
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
                    "--tmcl-tcp or --tmcl-pty: 127.0.0.1:5000. ,echo after the address: every byte a client sends "
                    "comes back to it at once, before the reply, as an RS485 transceiver hands the host back what it "
                    "transmits (Zephyr's TMCM RS485 bus driver waits for each byte's echo)")
      ->type_name("HOST:PORT[,echo]")
      ->expected(1)
      ->multi_option_policy(CLI::MultiOptionPolicy::TakeAll);
  serve->add_option("--tmcl-pty", arguments->pty_link,
                    "Serve TMCL on a pseudo-terminal and make LINK a symbolic link to it (for pyserial and other "
                    "serial-port software; the baud rate, and GP 65, have no effect). ,echo after LINK: every byte "
                    "the client sends comes back at once, as on RS485 (see --tmcl-tcp); LINK has no comma")
      ->type_name("LINK[,echo]");
  serve->add_option("--can", arguments->can_endpoints,
                    "Put the module on a virtual CAN bus served as socketcand[:HOST]:PORT (python-can's "
                    "interface='socketcand'), slcan-tcp:[HOST:]PORT (interface='slcan', "
                    "channel='socket://HOST:PORT'), slcan:LINK (an SLCAN adapter on a pseudo-terminal, LINK a "
                    "symbolic link to it), socketcan:IFACE (a Linux CAN interface such as vcan0) or "
                    "socketcand-client:HOST:PORT:CHANNEL (join the bus of a socketcand server elsewhere: a socketcand "
                    "daemon on a gateway, another motwin serve); port 0 picks a free port. Repeatable: all share one "
                    "bus. Modules that start on the bus (" +
                        host::module_names([](const host::ModuleDescriptor& module) {
                          return module.endpoints.default_endpoint == host::DefaultEndpoint::kCanSocketcand;
                        }) +
                        ") default to socketcand:127.0.0.1:29536; TMCL modules (" +
                        host::module_names([](const host::ModuleDescriptor& module) { return module.endpoints.tmcl_can; }) +
                        ") answer TMCL on GP 71/70. See docs/canopen.md")
      ->type_name("socketcand:HOST:PORT|slcan-tcp:HOST:PORT|slcan:LINK|socketcan:IFACE|socketcand-client:HOST:PORT:CHANNEL")
      ->expected(1)
      ->multi_option_policy(CLI::MultiOptionPolicy::TakeAll);
  serve->add_option("--web", arguments->web_endpoint,
                    "Serve the web console on HOST:PORT (HTTP and WebSocket; open http://HOST:PORT/ in a browser): "
                    "the parameters or objects of every module, a direct-mode console, and a JSON protocol that "
                    "scripts speak too (docs/web-console.md). Port 0 picks a free port. A HOST other than loopback "
                    "needs --web-token")
      ->type_name("HOST:PORT");
  serve->add_option("--web-token", arguments->web_token,
                    "A secret the page and scripts must present (http://HOST:PORT/?token=TOKEN) before they may "
                    "talk to the modules; required with a --web address other than loopback")
      ->type_name("TOKEN");
  serve->add_option("--can-capture", arguments->can_capture,
                    "Write every frame of the CAN bus to FILE (simulated time): pcap with link type 227 when FILE "
                    "ends in .pcap (Wireshark, tshark), otherwise a candump -L log")
      ->type_name("FILE");
  serve->add_option("--node-id", arguments->node_id,
                    "CANopen node ID as the module's address switches would set it (1..127); without it the "
                    "stored node ID (default 1) applies")
      ->type_name("N")
      ->check(CLI::Range(1, 127));
  serve->add_option("--boot-delay-ms", arguments->boot_delay_ms,
                    "CANopen: restart time from power-up or NMT reset node to the boot-up message, in simulated "
                    "ms (default 300; the node answers nothing meanwhile). Applies to every CANopen --node "
                    "without its own boot-delay-ms key")
      ->type_name("MS")
      ->check(CLI::Range(0, static_cast<int>(host::kMaxBootDelayMs)));
  serve->add_option("--comm-boot-delay-ms", arguments->comm_boot_delay_ms,
                    "CANopen: restart time from NMT reset communication to the boot-up message, in simulated ms "
                    "(default 50)")
      ->type_name("MS")
      ->check(CLI::Range(0, static_cast<int>(host::kMaxBootDelayMs)));
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
  serve->add_option("--firmware", arguments->firmware,
                    "Firmware generation to emulate, for modules that have several (listed below, with the endpoints "
                    "of one that speaks another protocol); default: the module's first")
      ->type_name("VERSION");
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
    exit_status = run_serve(*arguments);
  });
}

}  // namespace motwin::cli
