// What the TMCL modules on a simulated board share as virtual modules: the firmware `Device` on
// the simulated I/O and board, its EEPROM image (a file or memory), TMCL over CAN on GP 71 /
// GP 70 (core/tmcl/can_link.h), the tick loop and the steps of make(). A module is one
// instantiation (`using Tmcm1636VirtualModule = TmclSimModule<...>`) and its own make(), an
// explicit specialization in its folder: it chooses the motor, then power_up_on_board() opens
// eeprom_, builds board_, then device_ and can_, in that order. SimIo: the I/O a board over I/O
// keeps a reference to (the TMCM-1636's, the TMCM-142's); void for a board that holds its own (the
// TMCM-3216's), which then stamps output changes itself.
#pragma once

#include <cstdint>
#include <memory>
#include <optional>
#include <span>
#include <string>
#include <string_view>
#include <type_traits>
#include <utility>

#include "core/tmcl/engine.h"
#include "host/board_ticks.h"
#include "host/module_descriptor.h"
#include "host/module_eeprom.h"
#include "host/tmcl_can_node.h"
#include "host/virtual_module.h"

namespace motwin::host {

// kTickS is kTickUs in seconds, as the module's firmware spells it (see run_board_ticks).
template <typename DeviceT, typename SimIo, typename SimBoard, uint32_t kTickUs, double kTickS>
class TmclSimModule final : public VirtualModule {
 public:
  using Device = DeviceT;

  // Defined by each module (template <> ... ::make in src/host/modules/<module>/).
  static MakeModuleResult make(const ModuleOptions& options);

  // The inputs `--set` and scenario files address.
  static std::span<const sim::SignalInfo> signal_table() { return SimBoard::signal_table(); }

  TmclSimModule(const TmclSimModule&) = delete;
  TmclSimModule& operator=(const TmclSimModule&) = delete;

  // VirtualModule.
  std::string_view name() const override { return Device::kName; }
  // The generation the device was made with (command 136).
  std::string_view firmware_version() const override {
    return device_ ? std::string_view(device_->identity().version_string) : std::string_view(Device::kIdentity.version_string);
  }
  tmcl::TmclEngine& engine() override { return device_->engine(); }
  CanBusNode* can_node() override { return &*can_; }
  TmclCanNode* tmcl_can_node() override { return &*can_; }
  uint32_t tick_period_us() const override { return kTickUs; }
  void run_ticks(uint64_t count) override {
    run_board_ticks(count, tick_count_, kTickUs, kTickS, *board_, *device_, output_clock());
  }
  uint64_t tick_count() const override { return tick_count_; }
  board::NonVolatileMemory& nvm() override { return eeprom_.nvm(); }
  std::string nvm_location() const override { return eeprom_.location(); }
  sim::SignalBoard& signals() override { return *board_; }

  Device& device() { return *device_; }
  auto& io()
    requires(!std::is_void_v<SimIo>)
  {
    return io_;
  }
  SimBoard& board() { return *board_; }

 private:
  TmclSimModule() = default;

  // make() once the motor is chosen (`motor` empty: the ideal motor): opens the image (a new
  // one formatted by `format_image`), builds the board on the motor, sets the initial inputs,
  // lets `build_device` construct device_ (and do what the module needs around it), powers the
  // firmware up and adds TMCL over CAN. The module, or the error of an unusable image.
  // `firmware` is the running generation's version string, `firmware_update` what starting it
  // on another generation's image does and `take_over` what it does with another firmware's image
  // in that firmware's layout (ModuleEeprom::open).
  template <class Motor, class FormatImage, class BuildDevice>
  static MakeModuleResult power_up_on_board(const ModuleOptions& options, const std::optional<Motor>& motor,
                                            const FormatImage& format_image, const BuildDevice& build_device,
                                            std::string_view firmware = Device::kIdentity.version_string,
                                            const FirmwareUpdate& firmware_update = {},
                                            const FirmwareTakeOver& take_over = {}) {
    return power_up_on_built_board(
        options,
        [&motor](SimIo& io) { return motor ? std::make_unique<SimBoard>(io, *motor) : std::make_unique<SimBoard>(io); },
        format_image, build_device, firmware, firmware_update, take_over);
  }

  // The same with a board `build_board()` makes (`build_board(io)` with a SimIo): a board on
  // several motors or one that holds its own I/O.
  template <class BuildBoard, class FormatImage, class BuildDevice>
  static MakeModuleResult power_up_on_built_board(const ModuleOptions& options, const BuildBoard& build_board,
                                                  const FormatImage& format_image, const BuildDevice& build_device,
                                                  std::string_view firmware = Device::kIdentity.version_string,
                                                  const FirmwareUpdate& firmware_update = {},
                                                  const FirmwareTakeOver& take_over = {}) {
    std::unique_ptr<TmclSimModule> module(new TmclSimModule());
    const Result<void> eeprom =
        module->eeprom_.open(options, eeprom_identity_of<Device>(firmware), format_image, firmware_update, take_over);
    if (!eeprom) return Error{eeprom.error()};
    if constexpr (std::is_void_v<SimIo>) {
      module->board_ = build_board();
    } else {
      module->board_ = build_board(module->io_);
    }
    for (const InitialInput& input : options.initial_inputs) module->board_->set_input(input.signal, input.value);
    build_device(*module);
    module->device_->engine().power_up();
    module->can_.emplace(module->device_->engine());
    return MakeModuleResult(std::move(module));
  }

  auto& output_clock() { return output_clock_of<SimIo>(io_, *board_); }

  [[no_unique_address]] SimIoStorage<SimIo> io_;
  std::unique_ptr<SimBoard> board_;
  ModuleEeprom<Device::kNvmLayout.total_size> eeprom_;
  // Constructed once the image is chosen: the device keeps references to it, to io_ and the
  // board's power stage.
  std::optional<Device> device_;
  std::optional<TmclCanNode> can_;  // after device_: it refers to the engine
  uint64_t tick_count_ = 0;
};

}  // namespace motwin::host
