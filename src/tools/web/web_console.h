// The web console's protocol (docs/web-console.md, "Protocol"): JSON requests
// {"id":N,"op":"..."} from a page or a script, each answered by a reply with the same id, and
// "update" pushes of subscribed values. Everything the console does to a module goes the way a
// host's request goes: a TMCL module through its TmclHostService on a channel of the console's
// own (SAP, GAP, STAP ... and any instruction as `motwin tmcl` takes it), a CANopen node by SDO
// and NMT frames on the virtual bus. So the module's own range and access checks answer, and the
// page can do nothing a TMCL or CANopen host could not. No sockets here: the web server
// (host/web/web_server.h) hands messages in, and the unit tests do the same.
#pragma once

#include <cstdint>
#include <functional>
#include <memory>
#include <optional>
#include <string>
#include <string_view>
#include <vector>

#include "host/can_bus.h"
#include "host/event_loop.h"
#include "host/module_descriptor.h"
#include "host/module_listing.h"
#include "host/tmcl_host_service.h"
#include "host/web/web_server.h"
#include "tools/web/world_ops.h"

namespace motwin::host {
class TmclCanNode;
}  // namespace motwin::host

namespace motwin::tools::web {

// One module or node the console reaches.
struct ConsoleTarget {
  std::string name;              // "tmcm-1636", or the node's name with --node
  std::string module;            // the descriptor's name
  std::string product_name;      // "TMCM-1636"
  std::string firmware;          // "1636V109"
  host::ModuleParameterListing listing;
  host::TmclHostService* tmcl = nullptr;  // a TMCL module served directly
  host::TmclCanNode* tmcl_can = nullptr;  // or a TMCL module on the bus: reached by TMCL over CAN
  uint8_t module_address = 1;             // of its TMCL requests
  // Its motors (TMCL motor numbers 0..motor_count - 1, TmclDevice::motor_count(); a CANopen node:
  // the axes its dictionary lists). An axis parameter of a motor beyond them is refused.
  uint8_t motor_count = 1;
  std::optional<uint8_t> canopen_node_id;  // a CANopen node on the bus
  ConsoleWorld world;                      // its simulated world (ops "world", "world_set")
};

class WebConsole {
 public:
  static constexpr size_t kMaxPendingRequestsPerSession = 64;
  static constexpr size_t kMaxSubscribedItems = 64;
  static constexpr double kMaxUpdateRateHz = 100;
  // How long an SDO transfer may wait for the node's answer (wall time).
  static constexpr uint64_t kSdoTimeoutUs = 1'000'000;
  // The bus monitor (op "monitor"): a "frames" push every kMonitorPeriodUs (wall time) of at most
  // kMaxFramesPerMonitorPush frames; at most kMaxMonitorBufferedFrames wait (more are dropped and
  // counted), and none is pushed while the page leaves more than kMonitorMaxQueuedBytes unread.
  static constexpr uint64_t kMonitorPeriodUs = 100'000;
  static constexpr size_t kMaxFramesPerMonitorPush = 200;
  static constexpr size_t kMaxMonitorBufferedFrames = 1000;
  static constexpr size_t kMonitorMaxQueuedBytes = 64 * 1024;

  // `sim_time_us` stamps the pushes. `bus` is where CANopen targets are (nullptr: none).
  WebConsole(host::EventLoop& loop, std::function<uint64_t()> sim_time_us, std::vector<ConsoleTarget> targets,
             host::CanBus* bus);
  WebConsole(const WebConsole&) = delete;
  WebConsole& operator=(const WebConsole&) = delete;
  ~WebConsole();

  // A session for one page or script; it sends through `connection` until destroyed.
  std::unique_ptr<host::web::WebSessionHandler> open_session(host::web::WebConnection& connection);

  const std::vector<ConsoleTarget>& targets() const;

  class Impl;

 private:
  std::unique_ptr<Impl> impl_;
};

// The console's targets for `motwin serve`: the module itself (TMCL through `service`, or a
// CANopen node), or each node of a group. A TMCL module that is only a node of a bus is reached
// by TMCL over CAN through `can_node` (tmcl_can_port.h); without a bus, not at all. `motor_count`:
// the module's TmclDevice::motor_count().
ConsoleTarget tmcl_target(const host::ModuleDescriptor& descriptor, std::string name, std::string firmware,
                          std::string_view firmware_generation, uint8_t motor_count, host::TmclHostService* service,
                          host::TmclCanNode* can_node = nullptr);
ConsoleTarget canopen_target(const host::ModuleDescriptor& descriptor, std::string name, std::string firmware,
                             uint8_t node_id);

}  // namespace motwin::tools::web
