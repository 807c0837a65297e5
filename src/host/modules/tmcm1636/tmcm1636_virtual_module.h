// The TMCM-1636 (firmware 1636V109) as a virtual module: the firmware's module profile on the
// simulated board, with its EEPROM image in a file or in memory.
#pragma once

#include "core/modules/tmcm1636/tmcm1636.h"
#include "host/module_descriptor.h"
#include "host/tmcl_sim_module.h"
#include "sim/modules/tmcm1636/tmcm1636_sim_board.h"
#include "sim/modules/tmcm1636/tmcm1636_sim_io.h"

namespace motwin::host {

using Tmcm1636VirtualModule =
    TmclSimModule<modules::tmcm1636::Tmcm1636, sim::Tmcm1636SimIo, sim::Tmcm1636SimBoard,
                  modules::tmcm1636::kControlTickUs, modules::tmcm1636::kControlTickUs * 1e-6>;

// The firmware generations (ModuleDescriptor::firmwares), 1.09 first, and the one a
// --firmware name chooses (empty: 1.09).
const std::vector<FirmwareGeneration>& tmcm1636_firmwares();
Result<modules::tmcm1636::Firmware> tmcm1636_firmware(std::string_view name);

// options.motor: "ideal" (default), a preset or a motor description file
// (sim/modules/tmcm1636/motor_description.h); options.firmware: a generation's name.
template <>
MakeModuleResult Tmcm1636VirtualModule::make(const ModuleOptions& options);

}  // namespace motwin::host
