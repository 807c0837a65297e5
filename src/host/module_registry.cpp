#include "host/module_registry.h"

#include "host/modules/tmcm142/tmcm142_virtual_module.h"
#include "host/modules/tmcm1636/tmcm1636_virtual_module.h"
#include "host/modules/tmcm3216/tmcm3216_virtual_module.h"
#include "sim/modules/tmcm1636/tmcm1636_sim_board.h"

namespace motwin::host {
namespace {

constexpr ModuleDescriptor kModules[] = {
    {"tmcm-1636", "TMCM-1636 1-axis BLDC/DC servo module, TMCL firmware 1636V109", &sim::Tmcm1636SimBoard::signal_table,
     &Tmcm1636VirtualModule::make},
    {"tmcm-142", "TMCM-142 1-axis stepper module (TMC457: S-ramps, encoder, easyPID), TMCL firmware 142V1.06",
     &Tmcm142VirtualModule::signal_table, &Tmcm142VirtualModule::make},
    {"tmcm-3216", "TMCM-3216 3-axis stepper module, CANopen firmware V1.04 (CiA-402 drive: pp, pv, hm, csp, csv)",
     &Tmcm3216VirtualModule::signal_table, &Tmcm3216VirtualModule::make},
};

}  // namespace

std::span<const ModuleDescriptor> registered_modules() { return kModules; }

const ModuleDescriptor* find_module(std::string_view name) {
  for (const ModuleDescriptor& module : kModules) {
    if (module.name == name) return &module;
  }
  return nullptr;
}

std::string module_names() {
  std::string names;
  for (const ModuleDescriptor& module : kModules) {
    if (!names.empty()) names += ", ";
    names += module.name;
  }
  return names;
}

MakeModuleResult make_module(std::string_view name, const ModuleOptions& options) {
  const ModuleDescriptor* module = find_module(name);
  if (module == nullptr) {
    MakeModuleResult result;
    result.error = "unknown module \"" + std::string(name) + "\" (available: " + module_names() + ")";
    return result;
  }
  return module->make(options);
}

}  // namespace motwin::host
