// The TMCM-1636 with its CANopen firmware (V1.12, `--firmware canopen`) as a virtual module: the
// firmware's module profile (core/modules/tmcm1636/tmcm1636_canopen.h) on the same simulated
// board as the TMCL firmware (sim/modules/tmcm1636/tmcm1636_sim_board.h: the motor plant behind the
// power stage, the I/O), a node of the virtual CAN bus as every CANopen module is
// (host/canopen_sim_module.h). It has no TMCL interface.
#pragma once

#include "core/modules/tmcm1636/tmcm1636_canopen.h"
#include "host/canopen_sim_module.h"
#include "host/module_descriptor.h"
#include "sim/modules/tmcm1636/tmcm1636_sim_board.h"
#include "sim/modules/tmcm1636/tmcm1636_sim_io.h"

namespace motwin::host {

using Tmcm1636CanopenVirtualModule =
    CanopenSimModule<modules::tmcm1636::Tmcm1636Canopen, sim::Tmcm1636SimBoard, modules::tmcm1636::kControlTickUs,
                     modules::tmcm1636::kControlTickUs * 1e-6, sim::Tmcm1636SimIo>;

// options.motor: "ideal" (default), a preset or a motor description file, as for the TMCL
// firmware; a physical motor's start-up settings go into a fresh image as objects.
template <>
MakeModuleResult Tmcm1636CanopenVirtualModule::make(const ModuleOptions& options);

// The descriptor `--firmware canopen` of tmcm-1636 chooses.
ModuleDescriptor tmcm1636_canopen_descriptor();

}  // namespace motwin::host
