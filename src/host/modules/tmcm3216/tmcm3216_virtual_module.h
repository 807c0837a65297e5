// The TMCM-3216 (CANopen firmware V1.04) as a virtual module: the module profile with its CAN
// controller on a virtual bus (host/can_bus.h), its NVM image in a file or in memory, and the
// simulated board (sim/modules/tmcm3216/tmcm3216_sim_board.h: three steppers, their sensors, the
// I/O), as every CANopen module is (host/canopen_sim_module.h). Each tick: the board senses, the
// firmware ticks, the motors advance by Device's tick. It has no TMCL interface.
#pragma once

#include "core/modules/tmcm3216/tmcm3216.h"
#include "host/canopen_sim_module.h"
#include "host/module_descriptor.h"
#include "sim/modules/tmcm3216/tmcm3216_sim_board.h"

namespace motwin::host {

using Tmcm3216VirtualModule = CanopenSimModule<modules::tmcm3216::Tmcm3216, sim::Tmcm3216SimBoard,
                                               modules::tmcm3216::kTickUs, modules::tmcm3216::kTickUs * 1e-6>;

// options.motor: "ideal" (default), a stepper preset or description file for all three axes, or
// one per axis, comma-separated (sim::resolve_stepper_motors).
template <>
MakeModuleResult Tmcm3216VirtualModule::make(const ModuleOptions& options);

}  // namespace motwin::host
