#include "host/modules/tmcm3216/tmcm3216_virtual_module.h"

#include "host/modules/tmcm3216/tmcm3216_firmware_change.h"
#include "host/zeroed_allocation.h"
#include "sim/stepper_motor_selection.h"

namespace motwin::host {

template <>
MakeModuleResult Tmcm3216VirtualModule::make(const ModuleOptions& options) {
  // The motor is checked before any file is touched.
  const Result<std::vector<sim::StepperMotorChoice>> motors =
      sim::resolve_stepper_motors(options.motor, sim::Tmcm3216SimBoard::kAxisCount);
  if (!motors) return Error{motors.error()};
  return power_up_on_bus(
      options, [&motors] { return std::make_unique<sim::Tmcm3216SimBoard>(*motors); },
      [](board::NonVolatileMemory& nvm, board::CanController& controller, sim::Tmcm3216SimBoard& board,
         const canopen::NodeConfig& config) {
        return make_unique_zeroed<Device>(nvm, controller, board.board(), config);
      },
      &Device::format_factory_image, &tmcm3216_canopen_image_from_tmcl);  // after the TMCL firmware
}

}  // namespace motwin::host
