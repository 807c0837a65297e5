#include "host/modules/tmcm3216/tmcm3216_tmcl_virtual_module.h"

#include "host/modules/tmcm3216/tmcm3216_firmware_change.h"
#include "host/tmcl_module_descriptor.h"
#include "sim/stepper_motor_selection.h"

namespace motwin::host {

template <>
MakeModuleResult Tmcm3216TmclVirtualModule::make(const ModuleOptions& options) {
  // The motor is checked before any file is touched.
  const Result<std::vector<sim::StepperMotorChoice>> motors =
      sim::resolve_stepper_motors(options.motor, sim::Tmcm3216SimBoard::kAxisCount);
  if (!motors) return Error{motors.error()};
  const auto format_image = [](uint8_t* image, size_t size) { Device::format_factory_image(image, size); };
  return power_up_on_built_board(
      options, [&motors] { return std::make_unique<sim::Tmcm3216SimBoard>(*motors); }, format_image,
      [](Tmcm3216TmclVirtualModule& module) {
        // The firmware powers up seeing the switches and encoders as set.
        module.board_->before_tick();
        module.device_.emplace(module.eeprom_.nvm(), module.board_->board());
      },
      Device::kIdentity.version_string, {}, &tmcm3216_tmcl_image_from_canopen);  // after the CANopen firmware
}

ModuleDescriptor tmcm3216_tmcl_descriptor() {
  return tmcl_module_descriptor<Tmcm3216TmclVirtualModule>({
      .product_name = "TMCM-3216",
      .summary = "TMCM-3216 3-axis stepper module, TMCL firmware 3216V100 (--firmware tmcl)",
      .help = R"(TMCL (binary) over TCP, a pty and CAN, motors 0..2: the CANopen firmware's steppers and
EightPoint ramps driven by MVP/ROR/ROL/MST and axis parameters (docs/tmcm-3216-tmcl.md).)",
      .trace_parameters = {1, 3},  // actual position, actual velocity
      .motors = {[] { return ideal_and(sim::stepper_motor_preset_names()); },
                 R"(ideal (the rotor follows the field exactly, the default), a preset stepper or a stepper
description file (.json, docs/tmcm-142.md, "Motor") for all three axes, or a comma-separated
list, one per axis, e.g. nema17,ideal,nema23)"},
  });
}

}  // namespace motwin::host
