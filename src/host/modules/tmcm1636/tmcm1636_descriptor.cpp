// The TMCM-1636 as host, CLI and tools know it (host/module_descriptor.h).
#include "host/modules/tmcm1636/tmcm1636_canopen_virtual_module.h"
#include "host/modules/tmcm1636/tmcm1636_virtual_module.h"
#include "host/tmcl_module_descriptor.h"
#include "sim/modules/tmcm1636/motor_description.h"

namespace motwin::host {
namespace {

using modules::tmcm1636::Firmware;
using modules::tmcm1636::Tmcm1636;

ModuleParameterListing listing_v109() { return tmcl_parameter_listing<Tmcm1636>(Tmcm1636::axis_parameters(Firmware::kV109)); }
ModuleParameterListing listing_v113() { return tmcl_parameter_listing<Tmcm1636>(Tmcm1636::axis_parameters(Firmware::kV113)); }

}  // namespace

const std::vector<FirmwareGeneration>& tmcm1636_firmwares() {
  static const std::vector<FirmwareGeneration> generations = {
      {"1.09", Tmcm1636::identity_of(Firmware::kV109).version_string,
       "TMCL firmware V1.09 as its manual describes it (the default)", &listing_v109},
      {"1.13", Tmcm1636::identity_of(Firmware::kV113).version_string,
       "the later revision PyTrinamic's TMCM1636 class targets: AP 13, 26, 56, 94, 109, 165..167 added, AP 7 gone",
       &listing_v113},
      {.name = "canopen",
       .version = modules::tmcm1636::Tmcm1636Canopen::kFirmwareVersion,
       .help = "the CANopen firmware V1.12 (CiA-301/402, Trinamic's EDS): a CANopen node instead of TMCL",
       .descriptor = &tmcm1636_canopen_descriptor},
  };
  return generations;
}

Result<Firmware> tmcm1636_firmware(std::string_view name) {
  if (name.empty() || name == tmcm1636_firmwares()[0].name) return Firmware::kV109;
  if (name == tmcm1636_firmwares()[1].name) return Firmware::kV113;
  std::string names;
  for (const FirmwareGeneration& generation : tmcm1636_firmwares()) names += (names.empty() ? "" : ", ") + std::string(generation.name);
  return Error{"unknown firmware \"" + std::string(name) + "\" for tmcm-1636 (choices: " + names + ")"};
}

ModuleDescriptor tmcm1636_descriptor() {
  return tmcl_module_descriptor<Tmcm1636VirtualModule>({
      .product_name = "TMCM-1636",
      .summary = "TMCM-1636 1-axis BLDC/DC servo module, TMCL firmware 1636V109 (or 1636V113: --firmware 1.13; CANopen: --firmware canopen)",
      .help = R"(TMCL (binary) over TCP, a pty and CAN. On a physical motor: FOC current, velocity and position
regulation, hall and encoder commutation, brake chopper and supply bus (docs/tmcm-1636-servo.md).)",
      .trace_parameters = {52, 42},  // actual position, actual velocity
      .motors = {[] { return ideal_and(sim::motor_preset_names()); },
                 R"(ideal (the axis follows its ramp exactly; fast, the default), a preset (a physical model driven
by the firmware's regulators; a new EEPROM image gets the preset's start-up settings) or a motor
description file (.json, docs/tmcm-1636-servo.md))"},
      .firmwares = tmcm1636_firmwares(),
  });
}

}  // namespace motwin::host
