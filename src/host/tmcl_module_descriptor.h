// The descriptor of a TMCL module on a simulated board (host/tmcl_sim_module.h): what follows
// from its classes is filled in here the same way for every such module (name, firmware, signals,
// make(), endpoints, parameter listing); the module gives the rest in its own words.
#pragma once

#include <cstdint>
#include <string_view>
#include <vector>

#include "host/module_descriptor.h"
#include "host/module_listing.h"

namespace motwin::host {

struct TmclModuleText {
  std::string_view product_name;
  std::string_view summary;
  std::string_view help;
  std::vector<uint8_t> trace_parameters;  // actual position and velocity
  MotorChoices motors;
  std::vector<FirmwareGeneration> firmwares = {};  // ModuleDescriptor::firmwares
};

// `Module` derives from TmclSimModule and has a static make().
template <class Module>
ModuleDescriptor tmcl_module_descriptor(const TmclModuleText& text) {
  using Device = typename Module::Device;
  return ModuleDescriptor{
      .name = Device::kName,
      .product_name = text.product_name,
      .summary = text.summary,
      .firmware = Device::kIdentity.version_string,
      .help = text.help,
      .input_signals = &Module::signal_table,
      .make = &Module::make,
      // Every TMCL module serves TCP, a pty and TMCL over CAN (GP 71/70), TCP by default.
      .endpoints = {.tmcl_tcp = true, .tmcl_pty = true, .tmcl_can = true},
      .trace_parameters = text.trace_parameters,
      .motors = text.motors,
      .listing = &tmcl_parameter_listing<Device>,
      .firmwares = text.firmwares,
  };
}

}  // namespace motwin::host
