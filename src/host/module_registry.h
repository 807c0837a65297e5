// The modules `motwin serve --module NAME` can run. Adding a module (TMCM-142, TMCM-3216) means
// one VirtualModule implementation and one row in module_registry.cpp.
#pragma once

#include <filesystem>
#include <memory>
#include <optional>
#include <span>
#include <string>
#include <string_view>
#include <vector>

#include "host/eeprom_file.h"
#include "host/virtual_module.h"
#include "sim/signals.h"

namespace motwin::host {

struct InitialInput {
  std::string signal;
  double value;
};

struct ModuleOptions {
  // Directory of the EEPROM image file; nullopt keeps the image in memory (factory defaults).
  std::optional<std::filesystem::path> state_dir;
  // Input levels set before power-up (`--set`), already checked against input_signals.
  std::vector<InitialInput> initial_inputs;
  // The motor: "ideal" or empty (the axis follows its ramp exactly, the default), a preset name
  // or a motor description file (sim/modules/tmcm1636/motor_description.h, docs/tmcm-1636-servo.md).
  std::string motor;
  // CANopen node ID as address switches would set it (`--node-id`, 1..127); 0: the stored one.
  uint8_t node_id = 0;
  // CANopen identity 1018 sub 4; 0: the module's default (1). Distinct serials tell two
  // unconfigured modules apart in an LSS fastscan.
  uint32_t serial_number = 0;
  LogSink log = log_to_stderr;
};

struct MakeModuleResult {
  std::unique_ptr<VirtualModule> module;  // powered up and ready for its first tick
  std::string error;                      // when module is null
};

struct ModuleDescriptor {
  std::string_view name;     // "tmcm-1636"
  std::string_view summary;  // one line for --help
  std::span<const sim::SignalInfo> (*input_signals)();
  MakeModuleResult (*make)(const ModuleOptions& options);
};

std::span<const ModuleDescriptor> registered_modules();
// nullptr for an unknown name.
const ModuleDescriptor* find_module(std::string_view name);
// "tmcm-1636, ..." for messages.
std::string module_names();

// An unknown name or an unusable state directory gives an error, never an exception.
MakeModuleResult make_module(std::string_view name, const ModuleOptions& options);

}  // namespace motwin::host
