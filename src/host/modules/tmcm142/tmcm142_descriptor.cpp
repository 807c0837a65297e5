// The TMCM-142 as host, CLI and tools know it (host/module_descriptor.h).
#include "host/modules/tmcm142/tmcm142_virtual_module.h"
#include "host/tmcl_module_descriptor.h"
#include "sim/stepper_motor_selection.h"

namespace motwin::host {

ModuleDescriptor tmcm142_descriptor() {
  return tmcl_module_descriptor<Tmcm142VirtualModule>({
      .product_name = "TMCM-142",
      .summary = "TMCM-142 1-axis stepper module (TMC457: S-ramps, encoder, easyPID), TMCL firmware 142V1.06",
      .help = R"(TMCL binary and ASCII (command 139) over TCP, a pty and CAN: S-shaped ramps, an ABN encoder with
the easyPID closed loop, limit switches, reference search and stored coordinates
(docs/tmcm-142.md). `motwin params` marks the parameters no public source numbers as
"[Motwin decision]".)",
      .trace_parameters = {1, 3},  // actual position, actual speed
      .motors = {[] { return ideal_and(sim::stepper_motor_preset_names()); },
                 R"(ideal (the rotor follows the field exactly, the default), a preset stepper or a stepper
description file (.json, docs/tmcm-142.md, "Motor"))"},
  });
}

}  // namespace motwin::host
