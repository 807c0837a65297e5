// The TMCM-1636 (firmware 1636V109) as a virtual module: the firmware's module profile on the
// simulated board, with its EEPROM image in a file or in memory.
#pragma once

#include <memory>
#include <optional>

#include "board/ram_non_volatile_memory.h"
#include "core/modules/tmcm1636/tmcm1636.h"
#include "core/tmcl/engine.h"
#include "host/eeprom_file.h"
#include "host/module_registry.h"
#include "host/tmcl_can_node.h"
#include "host/virtual_module.h"
#include "sim/tmcm1636_sim_board.h"
#include "sim/tmcm1636_sim_io.h"

namespace motwin::host {

class Tmcm1636VirtualModule final : public VirtualModule {
 public:
  using Device = modules::tmcm1636::Tmcm1636;
  using MemoryImage = board::RamNonVolatileMemory<Device::kNvmLayout.total_size>;

  static EepromImageIdentity eeprom_identity();
  static MakeModuleResult make(const ModuleOptions& options);

  Tmcm1636VirtualModule(const Tmcm1636VirtualModule&) = delete;
  Tmcm1636VirtualModule& operator=(const Tmcm1636VirtualModule&) = delete;

  // VirtualModule.
  std::string_view name() const override { return Device::kName; }
  std::string_view firmware_version() const override { return Device::kIdentity.version_string; }
  tmcl::TmclEngine& engine() override { return device_->engine(); }
  // TMCL over CAN on GP 71 / GP 70 (core/tmcl/can_link.h).
  CanBusNode* can_node() override { return &*can_; }
  TmclCanNode* tmcl_can_node() override { return &*can_; }
  uint32_t tick_period_us() const override { return modules::tmcm1636::kControlTickUs; }
  void run_ticks(uint64_t count) override;
  uint64_t tick_count() const override { return tick_count_; }
  board::NonVolatileMemory& nvm() override { return *nvm_; }
  std::string nvm_location() const override;
  sim::SignalBoard& signals() override { return *board_; }

  Device& device() { return *device_; }
  sim::Tmcm1636SimIo& io() { return io_; }
  // The I/O plus, unless the motor is ideal, the motor plant.
  sim::Tmcm1636SimBoard& board() { return *board_; }

 private:
  Tmcm1636VirtualModule() = default;

  sim::Tmcm1636SimIo io_;
  std::unique_ptr<sim::Tmcm1636SimBoard> board_;
  std::unique_ptr<EepromFile> eeprom_file_;
  std::unique_ptr<MemoryImage> memory_image_;
  board::NonVolatileMemory* nvm_ = nullptr;
  // Constructed once the image is chosen: the device keeps references to it and to io_.
  std::optional<Device> device_;
  std::optional<TmclCanNode> can_;  // after device_: it refers to the engine
  uint64_t tick_count_ = 0;
};

}  // namespace motwin::host
