// What the TMCL modules on a simulated board (TMCM-1636, TMCM-142) share as virtual modules: the
// firmware `Device` on the simulated I/O and board, its EEPROM image (a file or memory), TMCL
// over CAN on GP 71 / GP 70 (core/tmcl/can_link.h) and the tick loop. Each module's make()
// chooses the motor, opens eeprom_, builds board_, then device_ and can_, in that order.
#pragma once

#include <cstdint>
#include <memory>
#include <optional>
#include <string>
#include <string_view>

#include "core/tmcl/engine.h"
#include "host/board_ticks.h"
#include "host/module_eeprom.h"
#include "host/tmcl_can_node.h"
#include "host/virtual_module.h"

namespace motwin::host {

// kTickS is kTickUs in seconds, as the module's firmware spells it (see run_board_ticks).
template <typename DeviceT, typename SimIo, typename SimBoard, uint32_t kTickUs, double kTickS>
class TmclSimModule : public VirtualModule {
 public:
  using Device = DeviceT;

  static EepromImageIdentity eeprom_identity() { return eeprom_identity_of<Device>(); }

  TmclSimModule(const TmclSimModule&) = delete;
  TmclSimModule& operator=(const TmclSimModule&) = delete;

  // VirtualModule.
  std::string_view name() const override { return Device::kName; }
  std::string_view firmware_version() const override { return Device::kIdentity.version_string; }
  tmcl::TmclEngine& engine() override { return device_->engine(); }
  CanBusNode* can_node() override { return &*can_; }
  TmclCanNode* tmcl_can_node() override { return &*can_; }
  uint32_t tick_period_us() const override { return kTickUs; }
  void run_ticks(uint64_t count) override {
    run_board_ticks(count, tick_count_, kTickUs, kTickS, *board_, *device_, io_);
  }
  uint64_t tick_count() const override { return tick_count_; }
  board::NonVolatileMemory& nvm() override { return eeprom_.nvm(); }
  std::string nvm_location() const override { return eeprom_.location(); }
  sim::SignalBoard& signals() override { return *board_; }

  Device& device() { return *device_; }
  SimIo& io() { return io_; }
  SimBoard& board() { return *board_; }

 protected:
  TmclSimModule() = default;

  SimIo io_;
  std::unique_ptr<SimBoard> board_;
  ModuleEeprom<Device::kNvmLayout.total_size> eeprom_;
  // Constructed once the image is chosen: the device keeps references to it, to io_ and the
  // board's power stage.
  std::optional<Device> device_;
  std::optional<TmclCanNode> can_;  // after device_: it refers to the engine
  uint64_t tick_count_ = 0;
};

}  // namespace motwin::host
