// The TMCM-1636 (firmware 1636V109) as a virtual module: the firmware's module profile on the
// simulated board, with its EEPROM image in a file or in memory.
#pragma once

#include "core/modules/tmcm1636/tmcm1636.h"
#include "host/module_registry.h"
#include "host/tmcl_sim_module.h"
#include "sim/modules/tmcm1636/tmcm1636_sim_board.h"
#include "sim/modules/tmcm1636/tmcm1636_sim_io.h"

namespace motwin::host {

using Tmcm1636SimModule = TmclSimModule<modules::tmcm1636::Tmcm1636, sim::Tmcm1636SimIo, sim::Tmcm1636SimBoard,
                                        modules::tmcm1636::kControlTickUs, modules::tmcm1636::kControlTickUs * 1e-6>;

class Tmcm1636VirtualModule final : public Tmcm1636SimModule {
 public:
  static MakeModuleResult make(const ModuleOptions& options);

 private:
  Tmcm1636VirtualModule() = default;
};

}  // namespace motwin::host
