// The TMCM-142 (firmware 142V1.06) as a virtual module: the firmware's module profile on the
// simulated board (I/O, stepper, encoder, switches), with its EEPROM image in a file or in memory
// and TMCL over CAN on GP 71 / GP 70, as the TMCM-1636.
#pragma once

#include "core/modules/tmcm142/tmcm142.h"
#include "host/module_descriptor.h"
#include "host/tmcl_sim_module.h"
#include "sim/modules/tmcm142/tmcm142_sim_board.h"
#include "sim/modules/tmcm142/tmcm142_sim_io.h"

namespace motwin::host {

using Tmcm142VirtualModule = TmclSimModule<modules::tmcm142::Tmcm142, sim::Tmcm142SimIo, sim::Tmcm142SimBoard,
                                           modules::tmcm142::kControlTickUs, modules::tmcm142::kControlTickS>;

// options.motor: "ideal" (default), nema17, nema23 or a stepper description file
// (sim/stepper_motor_selection.h).
template <>
MakeModuleResult Tmcm142VirtualModule::make(const ModuleOptions& options);

}  // namespace motwin::host
