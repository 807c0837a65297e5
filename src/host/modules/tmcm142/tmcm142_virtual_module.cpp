#include "host/modules/tmcm142/tmcm142_virtual_module.h"

#include "sim/stepper_motor_selection.h"

namespace motwin::host {

template <>
MakeModuleResult Tmcm142VirtualModule::make(const ModuleOptions& options) {
  // The motor is checked before any file is touched.
  const Result<sim::StepperMotorChoice> motor = sim::resolve_stepper_motor(options.motor);
  if (!motor) return motor.error_with_context(std::string(Device::kName) + ": ");
  // The factory image is the same whatever the motor: AP 6/7 are set by the user, as on the
  // real module (docs/tmcm-142.md, "Motor").
  const auto format_image = [](uint8_t* image, size_t size) { Device::format_factory_image(image, size); };
  return power_up_on_board(options, *motor, format_image, [](Tmcm142VirtualModule& module) {
    // The firmware powers up seeing the switches and encoder as set.
    module.board_->before_tick();
    module.device_.emplace(module.eeprom_.nvm(), module.board_->power_stage(), module.io_);
  });
}

}  // namespace motwin::host
