#include "host/modules/tmcm3216/tmcm3216_virtual_module.h"

#include <cstdlib>

#include "host/board_ticks.h"
#include "sim/stepper_motor_selection.h"

namespace motwin::host {

std::span<const sim::SignalInfo> Tmcm3216VirtualModule::signal_table() { return sim::Tmcm3216SimBoard::signal_table(); }

MakeModuleResult Tmcm3216VirtualModule::make(const ModuleOptions& options) {
  if (options.node_id > 127) return Error{"node ID " + std::to_string(options.node_id) + " is out of range (1..127)"};
  // The motor is checked before any file is touched.
  const Result<std::vector<sim::StepperMotorChoice>> motors =
      sim::resolve_stepper_motors(options.motor, sim::Tmcm3216SimBoard::kAxisCount);
  if (!motors) return Error{motors.error()};
  std::unique_ptr<Tmcm3216VirtualModule> module(new Tmcm3216VirtualModule());
  const Result<void> eeprom = module->eeprom_.open(options, eeprom_identity(), &Device::format_factory_image);
  if (!eeprom) return Error{eeprom.error()};
  modules::tmcm3216::Tmcm3216Config config;
  config.node_id_switches = options.node_id;
  config.serial_number = options.serial_number != 0 ? options.serial_number : 1;
  config.boot_delay_us = options.boot_delay_ms ? *options.boot_delay_ms * 1000u : Device::kBootDelayUs;
  config.communication_boot_delay_us = options.communication_boot_delay_ms
                                           ? *options.communication_boot_delay_ms * 1000u
                                           : Device::kCommunicationBootDelayUs;
  module->board_ = std::make_unique<sim::Tmcm3216SimBoard>(*motors);
  for (const InitialInput& input : options.initial_inputs) module->board_->set_input(input.signal, input.value);
  module->board_->before_tick();
  board::CanController& controller = *module;  // private base: reachable here only
  module->device_ = std::make_unique<Device>(module->eeprom_.nvm(), controller, module->board_->board(), config);
  // Switched on before any bus is connected and before `ready`: its restart time passes (the
  // services only: nothing moves before the boot-up) and its boot-up reaches nobody, as on a real
  // bus that a master joins later. Masters send an NMT reset to see one (docs/canopen.md
  // "Start-up timing").
  module->device_->power_up();
  module->device_->process(config.boot_delay_us);
  return MakeModuleResult(std::move(module));
}

Tmcm3216VirtualModule::~Tmcm3216VirtualModule() { disconnect(); }

tmcl::TmclEngine& Tmcm3216VirtualModule::engine() { std::abort(); }

void Tmcm3216VirtualModule::run_ticks(uint64_t count) {
  constexpr double kTickS = modules::tmcm3216::kTickUs * 1e-6;
  run_board_ticks(count, tick_count_, modules::tmcm3216::kTickUs, kTickS, *board_, *device_, *board_);
}

void Tmcm3216VirtualModule::connect(CanBus& bus) {
  disconnect();
  bus_ = &bus;
  bus_id_ = bus.attach(*this);
}

void Tmcm3216VirtualModule::disconnect() {
  if (bus_ != nullptr) bus_->detach(bus_id_);
  bus_ = nullptr;
  bus_id_ = 0;
}

void Tmcm3216VirtualModule::on_frame(const can::CanFrame& frame, uint64_t /*timestamp_us*/) {
  // The receive interrupt queues the frame; processing it at once (no simulated time passes)
  // answers an SDO request within the same bus delivery.
  device_->receive(frame);
  device_->process(0);
}

bool Tmcm3216VirtualModule::transmit(const can::CanFrame& frame) {
  if (bus_ != nullptr) bus_->send(bus_id_, frame);
  return true;
}

board::CanControllerStatus Tmcm3216VirtualModule::status() const {
  board::CanControllerStatus status;
  const CanNodeBusStats* node = bus_ != nullptr ? bus_->node_stats(bus_id_) : nullptr;
  if (node == nullptr) return status;  // on no bus: nothing to go wrong
  const bool bus_off = node->error_state == CanErrorState::kBusOff;
  status.error_state = bus_off ? board::CanErrorState::kBusOff
                       : node->error_state == CanErrorState::kErrorPassive ? board::CanErrorState::kErrorPassive
                                                                             : board::CanErrorState::kErrorActive;
  status.warning = node->warning();
  // The bus counts the times the node went bus-off; all but a bus-off still lasting have ended.
  status.bus_off_recoveries = static_cast<uint32_t>(node->bus_off_count - (bus_off ? 1 : 0));
  return status;
}

}  // namespace motwin::host
