#include "host/modules/tmcm1636/tmcm1636_virtual_module.h"

#include "host/modules/tmcm1636/tmcm1636_firmware_change.h"
#include "host/modules/tmcm1636/tmcm1636_startup_image.h"

namespace motwin::host {

template <>
MakeModuleResult Tmcm1636VirtualModule::make(const ModuleOptions& options) {
  // The firmware and the motor are checked before any file is touched.
  const Result<modules::tmcm1636::Firmware> firmware = tmcm1636_firmware(options.firmware);
  if (!firmware) return Error{firmware.error()};
  const modules::tmcm1636::Firmware generation = *firmware;
  const Result<sim::MotorChoice> chosen = resolve_tmcm1636_motor(options.motor);
  if (!chosen) return Error{chosen.error()};
  const sim::MotorChoice& motor = *chosen;
  // A physical motor's start-up settings go into a fresh image (docs/tmcm-1636-servo.md).
  const auto format_image = [&motor, generation](uint8_t* image, size_t size) {
    Device::format_factory_image(image, size, Device::axis_parameters(generation));
    if (motor) write_tmcm1636_startup_image(*motor, image, size);
  };
  const auto build_device = [&](Tmcm1636VirtualModule& module) {
    board::NonVolatileMemory& nvm = module.eeprom_.nvm();
    if (motor && module.eeprom_.file() && !tmcm1636_image_configures_motor(nvm.data(), nvm.size())) {
      options.log("motwin: the EEPROM image " + module.eeprom_.location() + " has motor type 0 (no motor); " +
                  motor->name + " start-up settings go into new images only (docs/tmcm-1636-servo.md)");
    }
    module.device_.emplace(nvm, module.io_, generation);
    if (board::Tmcm1636PowerStage* stage = module.board_->power_stage()) module.device_->axis().attach_power_stage(stage);
  };
  // An image another generation wrote: the rows this one adds get their defaults (a firmware
  // update, docs/tmcm-1636.md "EEPROM image and firmware changes"); a version Motwin does not
  // know (a later Motwin's) is taken as it is.
  const auto firmware_update = [generation, &options](std::string_view previous, board::NonVolatileMemory& nvm) {
    for (const modules::tmcm1636::Firmware known : {modules::tmcm1636::Firmware::kV109, modules::tmcm1636::Firmware::kV113}) {
      if (Device::identity_of(known).version_string != previous) continue;
      if (!Device::update_image_for_firmware(nvm, Device::axis_parameters(known), Device::axis_parameters(generation))) {
        options.log("motwin: the EEPROM image could not be updated; the firmware's rows keep what is stored");
      }
      return;
    }
  };
  // The CANopen firmware's image: its shared settings (docs/tmcm-1636-canopen.md "Changing firmware").
  return power_up_on_board(options, motor, format_image, build_device,
                           Device::identity_of(generation).version_string, firmware_update,
                           tmcm1636_tmcl_take_over(generation));
}

}  // namespace motwin::host
