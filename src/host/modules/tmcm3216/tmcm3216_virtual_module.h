// The TMCM-3216 (CANopen firmware V1.04) as a virtual module: the module profile with its CAN
// controller on a virtual bus (host/can_bus.h), its NVM image in a file or in memory, and the
// simulated board (sim/modules/tmcm3216/tmcm3216_sim_board.h: three steppers, their sensors, the I/O). Each tick:
// the board senses, the firmware ticks, the motors advance by Device's tick. It has no TMCL
// interface.
#pragma once

#include <memory>
#include <optional>

#include "board/can_controller.h"
#include "core/modules/tmcm3216/tmcm3216.h"
#include "host/can_bus.h"
#include "host/module_descriptor.h"
#include "host/module_eeprom.h"
#include "host/virtual_module.h"
#include "sim/signals.h"
#include "sim/modules/tmcm3216/tmcm3216_sim_board.h"

namespace motwin::host {

class Tmcm3216VirtualModule final : public VirtualModule, public CanBusNode, private board::CanController {
 public:
  using Device = modules::tmcm3216::Tmcm3216;

  static EepromImageIdentity eeprom_identity() { return eeprom_identity_of<Device>(); }
  static std::span<const sim::SignalInfo> signal_table();
  static MakeModuleResult make(const ModuleOptions& options);

  Tmcm3216VirtualModule(const Tmcm3216VirtualModule&) = delete;
  Tmcm3216VirtualModule& operator=(const Tmcm3216VirtualModule&) = delete;
  ~Tmcm3216VirtualModule() override;

  // VirtualModule.
  std::string_view name() const override { return Device::kName; }
  std::string_view firmware_version() const override { return Device::kFirmwareVersion; }
  [[noreturn]] tmcl::TmclEngine& engine() override;  // never called: has_tmcl() is false
  bool has_tmcl() const override { return false; }
  CanBusNode* can_node() override { return this; }
  uint32_t tick_period_us() const override { return modules::tmcm3216::kTickUs; }
  void run_ticks(uint64_t count) override;
  uint64_t tick_count() const override { return tick_count_; }
  board::NonVolatileMemory& nvm() override { return eeprom_.nvm(); }
  std::string nvm_location() const override { return eeprom_.location(); }
  sim::SignalBoard& signals() override { return *board_; }

  // CanBusNode.
  void connect(CanBus& bus) override;
  void disconnect() override;
  void on_frame(const can::CanFrame& frame, uint64_t timestamp_us) override;
  // The active bit rate (2707: 2704 at the last reset, or an LSS-activated one): the bus cuts
  // the node off while it differs from the bus's (host/can_bus.h).
  uint32_t controller_bit_rate() override { return uint32_t{device_->bit_rate_kbit()} * 1000u; }

  Device& device() { return *device_; }
  sim::Tmcm3216SimBoard& board() { return *board_; }

 private:
  Tmcm3216VirtualModule() = default;
  // board::CanController: what the firmware transmits goes onto the bus; its fault confinement
  // is the bus's view of the node (CanBus::node_stats: error counters, bus-off and recovery).
  bool transmit(const can::CanFrame& frame) override;
  board::CanControllerStatus status() const override;

  // Before device_: the device keeps a reference to its board seam.
  std::unique_ptr<sim::Tmcm3216SimBoard> board_;
  ModuleEeprom<nvm_image_size_of<Device>()> eeprom_;  // before device_, which keeps its nvm()
  std::unique_ptr<Device> device_;
  CanBus* bus_ = nullptr;
  CanBus::EndpointId bus_id_ = 0;
  uint64_t tick_count_ = 0;
};

}  // namespace motwin::host
