#include "host/modules/tmcm1636/tmcm1636_canopen_virtual_module.h"

#include "host/modules/tmcm1636/tmcm1636_firmware_change.h"
#include "host/modules/tmcm1636/tmcm1636_startup_image.h"

namespace motwin::host {

template <>
MakeModuleResult Tmcm1636CanopenVirtualModule::make(const ModuleOptions& options) {
  // The motor is checked before any file is touched.
  const Result<sim::MotorChoice> chosen = resolve_tmcm1636_motor(options.motor);
  if (!chosen) return Error{chosen.error()};
  const sim::MotorChoice& motor = *chosen;
  // A physical motor's start-up settings go into a fresh image (docs/tmcm-1636-servo.md).
  const auto format_image = [&motor](uint8_t* image, size_t size) {
    Device::format_factory_image(image, size);
    if (motor) write_tmcm1636_canopen_startup_image(*motor, image, size);
  };
  return power_up_on_bus(
      options,
      [&motor](sim::Tmcm1636SimIo& io) {
        return motor ? std::make_unique<sim::Tmcm1636SimBoard>(io, *motor) : std::make_unique<sim::Tmcm1636SimBoard>(io);
      },
      [](board::NonVolatileMemory& nvm, board::CanController& controller, sim::Tmcm1636SimBoard& board,
         const canopen::NodeConfig& config) {
        auto device = std::make_unique<Device>(nvm, controller, board.io(), config);
        if (board::Tmcm1636PowerStage* stage = board.power_stage()) device->axis().attach_power_stage(stage);
        return device;
      },
      format_image, &tmcm1636_canopen_image_from_tmcl);  // after either TMCL generation
}

}  // namespace motwin::host
