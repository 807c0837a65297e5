// A virtual module as the host runtime sees it, whatever the module: a name, a TMCL engine,
// a control tick, an EEPROM image and named board signals. Module-specific code lives behind
// make_module() (module_registry.h); the event loop, transports and `motwin serve` only use
// this interface.
#pragma once

#include <cstdint>
#include <optional>
#include <span>
#include <string>
#include <string_view>
#include <vector>

#include "board/non_volatile_memory.h"
#include "core/tmcl/engine.h"
#include "sim/signals.h"

namespace motwin::host {

class CanBusNode;
class TmclCanNode;

class VirtualModule {
 public:
  virtual ~VirtualModule() = default;

  virtual std::string_view name() const = 0;              // "tmcm-1636"
  virtual std::string_view firmware_version() const = 0;  // "1636V109"
  // Only called when has_tmcl(): a module whose firmware speaks no TMCL (the TMCM-3216 CANopen
  // firmware) gets no TMCL service and no TMCL endpoints.
  virtual tmcl::TmclEngine& engine() = 0;
  virtual bool has_tmcl() const { return true; }
  // The module's CAN controller as a node of a virtual bus (host/can_bus.h); nullptr: none.
  virtual CanBusNode* can_node() { return nullptr; }
  // The same node when it speaks TMCL over CAN (host/tmcl_can_node.h), so that the host runtime
  // can route its command 138 replies; nullptr otherwise.
  virtual TmclCanNode* tmcl_can_node() { return nullptr; }

  // Fixed simulation step of the module (TMCM-1636: 50 µs).
  virtual uint32_t tick_period_us() const = 0;
  // Runs `count` ticks; one virtual call per batch keeps the per-tick path free of them.
  virtual void run_ticks(uint64_t count) = 0;
  void tick() { run_ticks(1); }
  // Ticks run since start-up (not reset by command 255, which restarts the firmware only).
  virtual uint64_t tick_count() const = 0;
  uint64_t sim_time_us() const { return tick_count() * tick_period_us(); }

  virtual board::NonVolatileMemory& nvm() = 0;
  // Path of the EEPROM image file, or "none" when it is kept in memory only.
  virtual std::string nvm_location() const = 0;

  // Inputs to set (--set, scenario files) and outputs to log.
  virtual sim::SignalBoard& signals() = 0;
};

// The signal board of a module (or group) with no inputs or outputs to offer.
class NoSignalBoard final : public sim::SignalBoard {
 public:
  std::span<const sim::SignalInfo> input_signals() const override { return {}; }
  void set_input(std::string_view, double) override {}
  std::optional<double> read_signal(std::string_view) const override { return std::nullopt; }
  void take_output_changes(std::vector<sim::OutputChange>&) override {}
};

}  // namespace motwin::host
