// The TMCM-142 (firmware 142V1.06) as a virtual module: the firmware's module profile on the
// simulated board (I/O, stepper, encoder, switches), with its EEPROM image in a file or in memory
// and TMCL over CAN on GP 71 / GP 70, as the TMCM-1636.
#pragma once

#include <span>

#include "core/modules/tmcm142/tmcm142.h"
#include "host/module_registry.h"
#include "host/tmcl_sim_module.h"
#include "sim/modules/tmcm142/tmcm142_sim_board.h"
#include "sim/modules/tmcm142/tmcm142_sim_io.h"

namespace motwin::host {

using Tmcm142SimModule = TmclSimModule<modules::tmcm142::Tmcm142, sim::Tmcm142SimIo, sim::Tmcm142SimBoard,
                                       modules::tmcm142::kControlTickUs, modules::tmcm142::kControlTickS>;

class Tmcm142VirtualModule final : public Tmcm142SimModule {
 public:
  static std::span<const sim::SignalInfo> signal_table() { return sim::Tmcm142SimBoard::signal_table(); }
  // options.motor: "ideal" (default), nema17, nema23 or a stepper description file
  // (sim/stepper_motor_selection.h).
  static MakeModuleResult make(const ModuleOptions& options);

 private:
  Tmcm142VirtualModule() = default;
};

}  // namespace motwin::host
