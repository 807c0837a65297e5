// Several virtual modules on one CAN bus in one process (`motwin serve --node ...`): the group is
// itself a VirtualModule, so the host runtime paces it like a single module. Its tick is the
// greatest common divisor of the members' ticks (all 50 µs today; the gcd keeps any mix exact) and
// each member runs the ticks that bring it up to the group's simulated time, so every member
// and the bus share one clock. Members speak on the bus only: no TMCL over TCP or a pty, no
// input signals (docs/canopen.md, "Several modules on one bus").
#pragma once

#include <memory>
#include <optional>
#include <string>
#include <vector>

#include "host/module_registry.h"
#include "host/virtual_module.h"
#include "types/result.h"

namespace motwin::host {

// One `--node MODULE[:KEY=VALUE,...]` option.
struct NodeSpec {
  std::string module;        // "tmcm-3216"
  std::string name;          // state subdirectory; default "<module>-<position>"
  uint8_t node_id = 0;       // node-id=N (CANopen modules)
  uint32_t serial_number = 0;  // serial=N (CANopen identity 1018 sub 4)
  std::string motor;         // motor=NAME|FILE (TMCM-1636)
  std::string firmware;      // firmware=NAME (ModuleDescriptor::firmwares; empty: the default)
  int32_t receive_id = -1;   // receive-id=N (TMCL modules: GP 71 at start-up)
  int32_t send_id = -1;      // send-id=N (GP 70)
  // boot-delay-ms=N, comm-boot-delay-ms=N (CANopen modules: ModuleOptions); nullopt: serve's
  // --boot-delay-ms / --comm-boot-delay-ms, or the module's default.
  std::optional<uint32_t> boot_delay_ms;
  std::optional<uint32_t> communication_boot_delay_ms;
};

// The longest restart time `boot-delay-ms` and `--boot-delay-ms` take (one minute).
inline constexpr long kMaxBootDelayMs = 60'000;

// "tmcm-3216:node-id=2,name=left". `position` (1-based) names an unnamed node. An unknown module
// or key, or a value out of range, is an error.
Result<NodeSpec> parse_node_spec(std::string_view text, size_t position);

// The descriptor of the module a node runs: its module with its firmware (with_firmware), which
// may be another protocol's (a CANopen generation of a TMCL module).
Result<ModuleDescriptor> node_module(const NodeSpec& spec);

class ModuleGroup final : public VirtualModule {
 public:
  struct Member {
    std::string name;
    std::unique_ptr<VirtualModule> module;
  };

  // Builds each member (its EEPROM image in <state_dir>/<name>/ when state_dir is set). Two
  // nodes with one name are refused. TMCL modules get the CAN IDs of their spec.
  static Result<std::unique_ptr<ModuleGroup>> make(const std::vector<NodeSpec>& specs,
                                                   const std::optional<std::filesystem::path>& state_dir,
                                                   LogSink log = log_to_stderr);

  std::string_view name() const override { return "bus"; }
  std::string_view firmware_version() const override { return ""; }
  tmcl::TmclEngine& engine() override;  // never called: has_tmcl() is false
  bool has_tmcl() const override { return false; }
  uint32_t tick_period_us() const override { return tick_period_us_; }
  void run_ticks(uint64_t count) override;
  uint64_t tick_count() const override { return tick_count_; }
  board::NonVolatileMemory& nvm() override { return members_.front().module->nvm(); }
  std::string nvm_location() const override;
  sim::SignalBoard& signals() override { return signals_; }

  std::vector<Member>& members() { return members_; }

 private:
  ModuleGroup() = default;

  std::vector<Member> members_;
  std::vector<sim::OutputChange> discarded_outputs_;
  NoSignalBoard signals_;
  uint32_t tick_period_us_ = 1;
  uint64_t tick_count_ = 0;
};

}  // namespace motwin::host
