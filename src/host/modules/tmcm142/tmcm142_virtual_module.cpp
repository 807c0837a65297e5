#include "host/modules/tmcm142/tmcm142_virtual_module.h"

#include "sim/stepper_motor_selection.h"

namespace motwin::host {

MakeModuleResult Tmcm142VirtualModule::make(const ModuleOptions& options) {
  MakeModuleResult result;
  std::unique_ptr<Tmcm142VirtualModule> module(new Tmcm142VirtualModule());
  // The motor is checked before any file is touched.
  sim::StepperMotorChoice motor = sim::resolve_stepper_motor(options.motor);
  if (!motor.error.empty()) {
    result.error = "tmcm-142: " + motor.error;
    return result;
  }
  // The factory image is the same whatever the motor: AP 6/7 are set by the user, as on the
  // real module (docs/tmcm-142.md, "Motor").
  const auto format_image = [](uint8_t* image, size_t size) { Device::format_factory_image(image, size); };
  if (!module->eeprom_.open(options, eeprom_identity(), format_image, result.error)) return result;
  module->board_ = motor.motor ? std::make_unique<sim::Tmcm142SimBoard>(module->io_, *motor.motor)
                               : std::make_unique<sim::Tmcm142SimBoard>(module->io_);
  for (const InitialInput& input : options.initial_inputs) module->board_->set_input(input.signal, input.value);
  module->board_->before_tick();  // the firmware powers up seeing the switches and encoder as set
  module->device_.emplace(module->eeprom_.nvm(), module->board_->power_stage(), module->io_);
  module->device_->engine().power_up();
  module->can_.emplace(module->device_->engine());
  result.module = std::move(module);
  return result;
}

}  // namespace motwin::host
