// The TMCM-1636 as host, CLI and tools know it (host/module_descriptor.h).
#include "host/modules/tmcm1636/tmcm1636_virtual_module.h"
#include "host/tmcl_module_descriptor.h"
#include "sim/modules/tmcm1636/motor_description.h"

namespace motwin::host {

ModuleDescriptor tmcm1636_descriptor() {
  return tmcl_module_descriptor<Tmcm1636VirtualModule>({
      .product_name = "TMCM-1636",
      .summary = "TMCM-1636 1-axis BLDC/DC servo module, TMCL firmware 1636V109",
      .help = R"(TMCL (binary) over TCP, a pty and CAN. On a physical motor: FOC current, velocity and position
regulation, hall and encoder commutation, brake chopper and supply bus (docs/tmcm-1636-servo.md).)",
      .trace_parameters = {52, 42},  // actual position, actual velocity
      .motors = {[] { return ideal_and(sim::motor_preset_names()); },
                 R"(ideal (the axis follows its ramp exactly; fast, the default), a preset (a physical model driven
by the firmware's regulators; a new EEPROM image gets the preset's start-up settings) or a motor
description file (.json, docs/tmcm-1636-servo.md))"},
  });
}

}  // namespace motwin::host
