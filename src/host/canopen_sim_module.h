// What the CANopen modules on a simulated board share as virtual modules, as host/tmcl_sim_module.h
// is for the TMCL ones: the firmware `Device` (a canopen::Node inside) on its simulated board,
// its storage image (a file or memory), its CAN controller as a node of the virtual bus, the
// node's configuration from the ModuleOptions, the start-up and the tick loop. A module is one
// instantiation (`using Tmcm3216VirtualModule = CanopenSimModule<...>`) and its own make(), an
// explicit specialization in its folder: it checks what is its own (the motor), then
// power_up_on_bus() opens the image, builds the board and the device and lets the restart pass.
//
// What Device provides: kName, kFirmwareVersion, kBootDelayUs, kCommunicationBootDelayUs, the
// identity eeprom_identity_of<Device>() reads (kNvmLayoutVersion, kNvmSize), format_factory_image,
// power_up(), receive(frame), process(elapsed_us), tick() and bit_rate_kbit().
#pragma once

#include <cstdint>
#include <cstdlib>
#include <memory>
#include <span>
#include <string>
#include <string_view>
#include <type_traits>
#include <utility>

#include "board/can_controller.h"
#include "board/non_volatile_memory.h"
#include "core/canopen/node.h"
#include "host/board_ticks.h"
#include "host/can_bus.h"
#include "host/module_descriptor.h"
#include "host/module_eeprom.h"
#include "host/virtual_module.h"
#include "types/result.h"

namespace motwin::host {

// A CANopen module's end of the virtual bus: where its controller transmits, and the controller's
// fault confinement as the bus sees the node (CanBus::node_stats: error counters, bus-off and
// recovery). On no bus it sends nothing and nothing goes wrong. Detaches when it goes.
class CanopenBusAttachment {
 public:
  CanopenBusAttachment() = default;
  CanopenBusAttachment(const CanopenBusAttachment&) = delete;
  CanopenBusAttachment& operator=(const CanopenBusAttachment&) = delete;
  ~CanopenBusAttachment() { detach(); }

  void attach(CanBus& bus, CanBusEndpoint& node);
  void detach();
  void send(const can::CanFrame& frame);
  board::CanControllerStatus controller_status() const;

 private:
  CanBus* bus_ = nullptr;
  CanBus::EndpointId id_ = 0;
};

// The node's configuration as `serve` gives it (docs/canopen.md "Start-up timing"): --node-id as
// the address switches would set it, the serial number (1018 sub 4, default 1) and the restart
// times, the module's own (`boot_delay_us`, `communication_boot_delay_us`) unless given. A node
// ID above 127 is an error.
Result<canopen::NodeConfig> canopen_node_config(const ModuleOptions& options, uint32_t boot_delay_us,
                                                uint32_t communication_boot_delay_us);

// kTickS is kTickUs in seconds, as the module's firmware spells it (see run_board_ticks). SimIo:
// the I/O a board over I/O keeps a reference to (sim::SimBoardOverIo, the TMCM-1636's); void for
// a board that holds its own (the TMCM-3216's). The I/O, else the board, stamps output changes.
template <typename DeviceT, typename SimBoard, uint32_t kTickUs, double kTickS, typename SimIo = void>
class CanopenSimModule final : public VirtualModule, public CanBusNode, private board::CanController {
 public:
  using Device = DeviceT;

  // Defined by each module (template <> ... ::make in src/host/modules/<module>/).
  static MakeModuleResult make(const ModuleOptions& options);

  // The inputs `--set` and scenario files address.
  static std::span<const sim::SignalInfo> signal_table() { return SimBoard::signal_table(); }
  static EepromImageIdentity eeprom_identity() { return eeprom_identity_of<Device>(); }

  CanopenSimModule(const CanopenSimModule&) = delete;
  CanopenSimModule& operator=(const CanopenSimModule&) = delete;

  // VirtualModule.
  std::string_view name() const override { return Device::kName; }
  std::string_view firmware_version() const override { return Device::kFirmwareVersion; }
  [[noreturn]] tmcl::TmclEngine& engine() override { std::abort(); }  // never called: has_tmcl() is false
  bool has_tmcl() const override { return false; }
  CanBusNode* can_node() override { return this; }
  uint32_t tick_period_us() const override { return kTickUs; }
  void run_ticks(uint64_t count) override {
    run_board_ticks(count, tick_count_, kTickUs, kTickS, *board_, *device_, output_clock());
  }
  uint64_t tick_count() const override { return tick_count_; }
  board::NonVolatileMemory& nvm() override { return eeprom_.nvm(); }
  std::string nvm_location() const override { return eeprom_.location(); }
  sim::SignalBoard& signals() override { return *board_; }

  // CanBusNode.
  void connect(CanBus& bus) override { bus_.attach(bus, *this); }
  void disconnect() override { bus_.detach(); }
  void on_frame(const can::CanFrame& frame, uint64_t /*timestamp_us*/) override {
    // The receive interrupt queues the frame; processing it at once (no simulated time passes)
    // answers an SDO request within the same bus delivery.
    device_->receive(frame);
    device_->process(0);
  }
  // The active bit rate (2707: 2704 at the last reset, or an LSS-activated one): the bus cuts
  // the node off while it differs from the bus's (host/can_bus.h).
  uint32_t controller_bit_rate() override { return uint32_t{device_->bit_rate_kbit()} * 1000u; }

  Device& device() { return *device_; }
  SimBoard& board() { return *board_; }
  auto& io()
    requires(!std::is_void_v<SimIo>)
  {
    return io_;
  }

 private:
  CanopenSimModule() = default;

  // make() once its own options are checked: opens the image (a new one formatted by
  // `format_image`), builds the board with `build_board()` (`build_board(io)` with a SimIo), sets
  // the initial inputs and samples them, constructs the device with `build_device(nvm, controller,
  // board, config)` (a std::unique_ptr<Device>) and powers it up. Switched on before any bus is
  // connected and before `ready`: its restart time passes (the services only: nothing moves
  // before the boot-up) and its boot-up reaches nobody, as on a real bus that a master joins
  // later. Masters send an NMT reset to see one (docs/canopen.md "Start-up timing"). `take_over`:
  // what the module does with another firmware's image in that firmware's layout (ModuleEeprom::open).
  template <class BuildBoard, class BuildDevice>
  static MakeModuleResult power_up_on_bus(const ModuleOptions& options, const BuildBoard& build_board,
                                          const BuildDevice& build_device,
                                          const FactoryImageFormatter& format_image = &Device::format_factory_image,
                                          const FirmwareTakeOver& take_over = {}) {
    const Result<canopen::NodeConfig> config =
        canopen_node_config(options, Device::kBootDelayUs, Device::kCommunicationBootDelayUs);
    if (!config) return Error{config.error()};
    std::unique_ptr<CanopenSimModule> module(new CanopenSimModule());
    const Result<void> eeprom = module->eeprom_.open(options, eeprom_identity(), format_image, {}, take_over);
    if (!eeprom) return Error{eeprom.error()};
    if constexpr (std::is_void_v<SimIo>) {
      module->board_ = build_board();
    } else {
      module->board_ = build_board(module->io_);
    }
    for (const InitialInput& input : options.initial_inputs) module->board_->set_input(input.signal, input.value);
    module->board_->before_tick();
    board::CanController& controller = *module;  // private base: reachable here only
    module->device_ = build_device(module->eeprom_.nvm(), controller, *module->board_, *config);
    module->device_->power_up();
    module->device_->process(config->boot_delay_us);
    return MakeModuleResult(std::move(module));
  }

  // board::CanController: what the firmware transmits goes onto the bus.
  bool transmit(const can::CanFrame& frame) override {
    bus_.send(frame);
    return true;
  }
  board::CanControllerStatus status() const override { return bus_.controller_status(); }

  auto& output_clock() { return output_clock_of<SimIo>(io_, *board_); }

  // Before board_, which may keep a reference to it.
  [[no_unique_address]] SimIoStorage<SimIo> io_;
  // Before device_: the device keeps a reference to its board seam.
  std::unique_ptr<SimBoard> board_;
  ModuleEeprom<nvm_image_size_of<Device>()> eeprom_;  // before device_, which keeps its nvm()
  std::unique_ptr<Device> device_;
  CanopenBusAttachment bus_;  // after device_: leaves the bus first
  uint64_t tick_count_ = 0;
};

}  // namespace motwin::host
