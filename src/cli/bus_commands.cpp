// `motwin candump` and `motwin lss`: client commands on a socketcand endpoint (docs/canopen.md).
//   candump  prints `candump -L` lines "(SEC.USEC) can0 ID#DATA" (the server's timestamps: for
//            Motwin simulated time) until --count frames, the end of the connection (exit 0) or
//            --timeout seconds without a frame (exit 0 without --count, 1 before --count frames).
//   lss      one CiA-305 master service per call (tools/lss_client.h); the slave keeps its LSS
//            state between calls, so `lss switch-global configuration` then `lss set-node-id 5`
//            then `lss store` works as a sequence of commands. Exit status 0; 1 when a slave
//            refused (its error code on stderr) or fastscan found nobody.
// Both: 2 for bad arguments, no connection or no answer.
#include <charconv>
#include <cstdio>
#include <iostream>
#include <memory>
#include <optional>
#include <string>
#include <string_view>

#include "cli/bus_connection.h"
#include "cli/cli_errors.h"
#include "cli/commands.h"
#include "host/can_capture.h"
#include "tools/lss_client.h"

namespace motwin::cli {
namespace {

// Decimal or 0x hexadecimal, 32 bits.
std::optional<uint32_t> parse_number(std::string_view text) {
  const bool hex = text.size() > 2 && text[0] == '0' && (text[1] == 'x' || text[1] == 'X');
  const std::string_view digits = hex ? text.substr(2) : text;
  uint32_t value = 0;
  const auto [end, problem] = std::from_chars(digits.data(), digits.data() + digits.size(), value, hex ? 16 : 10);
  if (digits.empty() || digits.size() > (hex ? 8u : 10u) || problem != std::errc{} ||
      end != digits.data() + digits.size()) {
    return std::nullopt;
  }
  return value;
}

std::string hex32(uint32_t value) {
  char text[16];
  std::snprintf(text, sizeof(text), "0x%08X", value);
  return text;
}

int report(const tools::LssResult& result) {
  if (result.ok) return kExitSuccess;
  print_error(result.error);
  return result.error_code != 0 ? kExitModuleError : kExitUsageError;
}

struct LssOptions {
  std::string can = kDefaultCanEndpoint;
  double timeout_s = 1.0;
  std::string state;
  std::vector<std::string> identity;
  int node_id = 0;
  uint32_t bit_rate_kbit = 0;
  int delay_ms = 0;
  std::string what;
  int fastscan_node_id = 0;
  bool fastscan_store = false;
  double step_timeout_s = 0.05;
};

// Runs `body` on a connected master; sets exit_status.
template <typename Body>
void with_master(const LssOptions& options, int& exit_status, Body body) {
  const Result<std::unique_ptr<tools::SocketcandClient>> bus = connect_can(options.can);
  if (!bus) {
    exit_status = usage_error(bus.error());
    return;
  }
  tools::LssMaster master(**bus, static_cast<int>(options.timeout_s * 1000));
  exit_status = body(master);
}

struct CandumpOptions {
  std::string can = kDefaultCanEndpoint;
  int count = 0;
  double timeout_s = 0;
  std::string channel = "can0";
};

// Prints frames until --count of them, the end of the connection or --timeout; the exit status.
int dump_frames(tools::SocketcandClient& bus, const CandumpOptions& options) {
  std::setvbuf(stdout, nullptr, _IOLBF, 0);
  int received = 0;
  // Without a timeout, wait in slices so that a closed connection is noticed.
  const int slice_ms = options.timeout_s > 0 ? static_cast<int>(options.timeout_s * 1000) : 1000;
  while (options.count == 0 || received < options.count) {
    const std::optional<tools::ReceivedFrame> frame = bus.receive_stamped(slice_ms);
    if (!frame) {
      if (!bus.connected()) break;
      if (options.timeout_s > 0) return options.count == 0 ? kExitSuccess : kExitModuleError;
      continue;
    }
    std::cout << host::format_candump_line(frame->frame, frame->timestamp_us, options.channel) << '\n' << std::flush;
    ++received;
  }
  return kExitSuccess;
}

}  // namespace

void add_candump_command(CLI::App& app, int& exit_status) {
  auto options = std::make_shared<CandumpOptions>();
  CLI::App* candump = app.add_subcommand("candump", "Print the frames of a CAN bus as candump -L log lines");
  candump->add_option("--can", options->can, "Bus endpoint")->type_name("socketcand:HOST:PORT")->capture_default_str();
  candump->add_option("--count", options->count, "Stop after N frames (0: no limit)")->type_name("N")->check(CLI::NonNegativeNumber);
  candump->add_option("--timeout", options->timeout_s, "Stop after SECONDS without a frame (0: never)")
      ->type_name("SECONDS")
      ->check(CLI::NonNegativeNumber);
  candump->add_option("--channel", options->channel, "Interface name written in each line")->capture_default_str();
  candump->footer(
      "Lines: \"(SEC.USEC) can0 601#4000100000000000\" with the server's timestamps (Motwin: simulated time), "
      "readable by canplayer and python-can. Exit status 0 when --count frames arrived or the connection ended, "
      "1 when --timeout passed before --count frames, 2 when the endpoint cannot be reached.");
  candump->callback([options, &exit_status] {
    const Result<std::unique_ptr<tools::SocketcandClient>> bus = connect_can(options->can);
    exit_status = bus ? dump_frames(**bus, *options) : usage_error(bus.error());
  });
}

void add_lss_command(CLI::App& app, int& exit_status) {
  auto options = std::make_shared<LssOptions>();
  CLI::App* lss = app.add_subcommand("lss", "CiA-305 LSS master: configure node IDs and bit rates of CANopen slaves");
  lss->require_subcommand(1);
  lss->add_option("--can", options->can, "Bus endpoint")->type_name("socketcand:HOST:PORT")->capture_default_str();
  lss->add_option("--timeout", options->timeout_s, "Seconds to wait for a slave's answer")->capture_default_str();

  CLI::App* global = lss->add_subcommand("switch-global", "Switch state global: every slave to waiting or configuration");
  global->add_option("state", options->state, "waiting or configuration")
      ->required()
      ->check(CLI::IsMember({"waiting", "configuration"}));
  global->callback([options, &exit_status] {
    with_master(*options, exit_status,
                [&](tools::LssMaster& master) { return report(master.switch_global(options->state == "configuration")); });
  });

  CLI::App* selective = lss->add_subcommand("switch-selective", "Switch state selective: the slave with this identity "
                                                                "(1018 sub 1-4) to configuration");
  selective->add_option("identity", options->identity, "VENDOR PRODUCT REVISION SERIAL (decimal or 0x..)")
      ->required()
      ->expected(4);
  selective->callback([options, &exit_status] {
    std::optional<uint32_t> parts[4];
    for (size_t i = 0; i < 4; ++i) parts[i] = parse_number(options->identity[i]);
    if (!parts[0] || !parts[1] || !parts[2] || !parts[3]) {
      exit_status = usage_error("expected VENDOR PRODUCT REVISION SERIAL as numbers");
      return;
    }
    with_master(*options, exit_status, [&](tools::LssMaster& master) {
      return report(master.switch_selective({*parts[0], *parts[1], *parts[2], *parts[3]}));
    });
  });

  CLI::App* node_id = lss->add_subcommand("set-node-id", "Configure node ID (1..127, 255 unconfigured) of the slave in "
                                                         "configuration state; it applies at its next reset");
  node_id->add_option("node", options->node_id, "Node ID")->required()->check(CLI::Range(1, 127) | CLI::IsMember({255}));
  node_id->callback([options, &exit_status] {
    with_master(*options, exit_status, [&](tools::LssMaster& master) {
      return report(master.configure_node_id(static_cast<uint8_t>(options->node_id)));
    });
  });

  CLI::App* bit_rate = lss->add_subcommand("set-bitrate", "Configure bit timing (CiA-305 table 0) of the slave in "
                                                          "configuration state");
  bit_rate->add_option("kbit", options->bit_rate_kbit, "1000, 800, 500, 250, 125, 50, 20 or 10")->required();
  bit_rate->callback([options, &exit_status] {
    const std::optional<uint8_t> index = tools::LssMaster::bit_timing_index(options->bit_rate_kbit);
    if (!index) {
      exit_status =
          usage_error("bit rate " + std::to_string(options->bit_rate_kbit) + " kbit/s is not in CiA-305 table 0");
      return;
    }
    with_master(*options, exit_status, [&](tools::LssMaster& master) { return report(master.configure_bit_timing(*index)); });
  });

  CLI::App* activate = lss->add_subcommand("activate-bitrate", "Activate bit timing after a switch delay");
  activate->add_option("delay_ms", options->delay_ms, "Switch delay in ms")->required()->check(CLI::Range(0, 65535));
  activate->callback([options, &exit_status] {
    with_master(*options, exit_status, [&](tools::LssMaster& master) {
      return report(master.activate_bit_timing(static_cast<uint16_t>(options->delay_ms)));
    });
  });

  CLI::App* store = lss->add_subcommand("store", "Store the configured node ID and bit timing in the slave");
  store->callback([options, &exit_status] {
    with_master(*options, exit_status, [&](tools::LssMaster& master) { return report(master.store_configuration()); });
  });

  CLI::App* inquire = lss->add_subcommand("inquire", "Inquire the identity or node ID of the slave in configuration state");
  inquire->add_option("what", options->what, "vendor, product, revision, serial, node-id or all")
      ->required()
      ->check(CLI::IsMember({"vendor", "product", "revision", "serial", "node-id", "all"}));
  inquire->callback([options, &exit_status] {
    with_master(*options, exit_status, [&](tools::LssMaster& master) {
      const std::pair<const char*, uint8_t> items[] = {
          {"vendor", 0x5A}, {"product", 0x5B}, {"revision", 0x5C}, {"serial", 0x5D}, {"node-id", 0x5E}};
      std::string line;
      for (const auto& [name, command] : items) {
        if (options->what != "all" && options->what != name) continue;
        const tools::LssResult result = master.inquire(command);
        if (!result.ok) return report(result);
        const std::string value = command == 0x5E ? std::to_string(result.value) : hex32(result.value);
        line += (line.empty() ? "" : " ") + (options->what == "all" ? std::string(name) + " " : std::string()) + value;
      }
      std::cout << line << '\n';
      return kExitSuccess;
    });
  });

  CLI::App* fastscan = lss->add_subcommand("fastscan", "Find an unconfigured slave (node ID 255) by its identity; it is "
                                                       "left in configuration state");
  fastscan->add_option("--node-id", options->fastscan_node_id, "Then configure this node ID (1..127)")
      ->check(CLI::Range(1, 127));
  fastscan->add_flag("--store", options->fastscan_store, "With --node-id: also store it in the slave");
  fastscan->add_option("--step-timeout", options->step_timeout_s,
                       "Seconds to wait for an answer to each of the ~130 probes (silence means 1)")
      ->capture_default_str();
  fastscan->callback([options, &exit_status] {
    with_master(*options, exit_status, [&](tools::LssMaster& master) {
      const Result<tools::LssIdentityNumbers> found = master.fastscan(static_cast<int>(options->step_timeout_s * 1000));
      if (!found) {
        print_error(found.error());
        return kExitModuleError;
      }
      std::cout << "vendor " << hex32(found->vendor_id) << " product " << hex32(found->product_code) << " revision "
                << hex32(found->revision_number) << " serial " << hex32(found->serial_number) << '\n';
      if (options->fastscan_node_id == 0) return kExitSuccess;
      if (const int status = report(master.configure_node_id(static_cast<uint8_t>(options->fastscan_node_id)));
          status != kExitSuccess) {
        return status;
      }
      if (options->fastscan_store) {
        if (const int status = report(master.store_configuration()); status != kExitSuccess) return status;
      }
      // Back to waiting: the slave takes the new node ID and boots with it.
      return report(master.switch_global(false));
    });
  });
}

}  // namespace motwin::cli
