// The TMCM-3216 with its TMCL firmware (docs/tmcm-3216-tmcl.md) as a virtual module: the
// firmware's three axes on the same simulated board as the CANopen firmware's, with its EEPROM
// image in a file or in memory and TMCL over TCP, a pty and CAN (GP 71 / GP 70), as every TMCL
// module is (host/tmcl_sim_module.h).
#pragma once

#include "core/modules/tmcm3216/tmcm3216_tmcl.h"
#include "host/module_descriptor.h"
#include "host/tmcl_sim_module.h"
#include "sim/modules/tmcm3216/tmcm3216_sim_board.h"

namespace motwin::host {

using Tmcm3216TmclVirtualModule = TmclSimModule<modules::tmcm3216::Tmcm3216Tmcl, void, sim::Tmcm3216SimBoard,
                                                modules::tmcm3216::kTickUs, modules::tmcm3216::kTickUs * 1e-6>;

// options.motor as the CANopen firmware's: "ideal" (default), a stepper preset or description
// file for all three axes, or one per axis, comma-separated (sim::resolve_stepper_motors).
template <>
MakeModuleResult Tmcm3216TmclVirtualModule::make(const ModuleOptions& options);

// `--firmware tmcl` of tmcm-3216 (tmcm3216_descriptor.cpp lists it).
ModuleDescriptor tmcm3216_tmcl_descriptor();

}  // namespace motwin::host
