// Everything the host runtime, the CLI and the tools know about a module, in one place: its
// names, firmware identity, input signals, make(), endpoints, motors, help, parameter or object
// listing and, for a CANopen module, what its EDS says. Each module defines its descriptor in its
// own folder (src/host/modules/<module>/<module>_descriptor.cpp); host/module_registry.cpp lists
// them, one row each. Nothing outside those files names a module (docs/host-runtime.md, "Adding
// a module"; tests/unit/host_module_descriptor_test.cpp checks both).
#pragma once

#include <cstdint>
#include <filesystem>
#include <memory>
#include <optional>
#include <span>
#include <string>
#include <string_view>
#include <vector>

#include "host/canopen_dictionary_view.h"
#include "host/eeprom_file.h"
#include "host/module_listing.h"
#include "host/virtual_module.h"
#include "sim/signals.h"
#include "types/result.h"

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
  // The motor: "ideal" or empty (the axis follows its ramp exactly, the default), or one of the
  // module's MotorChoices (a preset name or a motor description file).
  std::string motor;
  // CANopen node ID as address switches would set it (`--node-id`, 1..127); 0: the stored one.
  uint8_t node_id = 0;
  // The firmware generation (`--firmware`, ModuleDescriptor::firmwares); empty: the default.
  std::string firmware;
  // CANopen identity 1018 sub 4; 0: the module's default (1). Distinct serials tell two
  // unconfigured modules apart in an LSS fastscan.
  uint32_t serial_number = 0;
  // CANopen restart times in ms (`--boot-delay-ms`, `--comm-boot-delay-ms`): from power-up or NMT
  // reset node, and from NMT reset communication, to the boot-up; nullopt: the module's default
  // (docs/canopen.md "Start-up timing").
  std::optional<uint32_t> boot_delay_ms;
  std::optional<uint32_t> communication_boot_delay_ms;
  LogSink log = log_to_stderr;
};

// What make() gives: the module, powered up and ready for its first tick (never null), or why
// it cannot run (an unknown motor, an unusable state directory, ...).
using MakeModuleResult = Result<std::unique_ptr<VirtualModule>>;

// Where `motwin serve` puts a module when no endpoint option is given.
enum class DefaultEndpoint : uint8_t {
  kTmclTcp,        // TMCL over TCP on 127.0.0.1:5000
  kCanSocketcand,  // the CAN bus as a socketcand server on 127.0.0.1:29536
};

// The endpoints a module offers (`motwin serve`, docs/host-runtime.md).
struct ModuleEndpoints {
  bool tmcl_tcp = false;  // --tmcl-tcp
  bool tmcl_pty = false;  // --tmcl-pty: a serial port (TMCL binary, and ASCII where the firmware has it)
  bool tmcl_can = false;  // --can: TMCL over CAN (GP 71/70)
  bool canopen = false;   // --can: a CANopen node (`motwin sdo`, `motwin eds`)
  DefaultEndpoint default_endpoint = DefaultEndpoint::kTmclTcp;

  // A TMCL engine: `motwin run`, `motwin tmcl`.
  bool has_tmcl() const { return tmcl_tcp || tmcl_pty || tmcl_can; }
  bool has_can() const { return tmcl_can || canopen; }
};

// What `--motor` takes for a module besides a motor description file.
struct MotorChoices {
  // "ideal" first (the default), then the presets.
  std::vector<std::string_view> (*names)();
  std::string_view help;  // a paragraph for `serve --help`: what a preset is, the file format, per-axis lists
};

// "ideal" followed by a simulation's preset names: MotorChoices::names of most modules.
inline std::vector<std::string_view> ideal_and(std::vector<std::string_view> presets) {
  presets.insert(presets.begin(), "ideal");
  return presets;
}

// The EDS of a CANopen module: its identity and its objects at factory defaults.
struct CanopenDescription {
  CanopenIdentity identity;
  CanopenDictionaryView (*dictionary)();
};

struct ModuleDescriptor;

// One generation of a module's firmware that `--firmware` chooses (docs/host-runtime.md "Adding
// a module"): the same module with another identity and row set, chosen when it is made, or a
// firmware that speaks another protocol (the TMCM-1636's CANopen firmware beside its TMCL ones),
// which brings the whole descriptor of the module running it.
struct FirmwareGeneration {
  std::string_view name;     // as --firmware takes it: "1.13"
  std::string_view version;  // as `serve` prints it (command 136): "1636V113"
  std::string_view help;     // one line for `serve --help`
  // `motwin params --firmware NAME`: this generation's parameters (unused with `descriptor`).
  ModuleParameterListing (*listing)() = nullptr;
  // A firmware with other endpoints, another protocol or another virtual module: the descriptor
  // of the module running it (make, endpoints, canopen, listing, help, summary, firmware = version,
  // motors, trace parameters). Its `name` is the module's, so `--module` still finds it; its
  // make() is given ModuleOptions::firmware as the user wrote it (this generation's name) and
  // need not read it. nullptr: the module's own descriptor with this identity and listing.
  ModuleDescriptor (*descriptor)() = nullptr;
};

struct ModuleDescriptor {
  std::string_view name;          // as --module takes it: "tmcm-1636"
  std::string_view product_name;  // as the manuals write it: "TMCM-1636"
  std::string_view summary;       // one line for --help
  std::string_view firmware;      // as `serve` prints it: "1636V109" (the default generation's)
  std::string_view help;          // a paragraph for `serve --help`
  std::span<const sim::SignalInfo> (*input_signals)();
  MakeModuleResult (*make)(const ModuleOptions& options);
  ModuleEndpoints endpoints;
  // The axis parameters `motwin run` traces by default (actual position and velocity); empty
  // for a module without TMCL.
  std::vector<uint8_t> trace_parameters = {};
  MotorChoices motors;
  // `motwin params`: the parameters of a TMCL module or the objects of a CANopen module.
  ModuleParameterListing (*listing)();
  // nullptr: no CANopen object dictionary (`motwin eds` refuses the module).
  const CanopenDescription* canopen = nullptr;
  // The firmware generations `--firmware` chooses from, the default (`firmware`) first; empty for
  // a module with one firmware.
  std::vector<FirmwareGeneration> firmwares = {};
};

// "1.09, 1.13": the names --firmware takes for a module (its one version string when it has no
// generations).
inline std::string firmware_names(const ModuleDescriptor& module) {
  if (module.firmwares.empty()) return std::string(module.firmware);
  std::string names;
  for (const FirmwareGeneration& generation : module.firmwares) {
    if (!names.empty()) names += ", ";
    names += std::string(generation.name);
  }
  return names;
}

// The generation `--firmware NAME` chooses: nullptr for the default (NAME empty, or a module
// without generations given its one version), an error naming the choices otherwise.
inline Result<const FirmwareGeneration*> find_firmware(const ModuleDescriptor& module, std::string_view name) {
  if (name.empty()) return static_cast<const FirmwareGeneration*>(nullptr);
  if (module.firmwares.empty()) {
    if (name == module.firmware) return static_cast<const FirmwareGeneration*>(nullptr);
    return Error{"--firmware " + std::string(name) + ": " + std::string(module.name) + " has one firmware, " +
                 std::string(module.firmware)};
  }
  // By its name, or by the version string `serve` prints for it ("CANopen V1.04", "1636V113").
  for (const FirmwareGeneration& generation : module.firmwares) {
    if (generation.name == name || generation.version == name) return &generation;
  }
  return Error{"unknown firmware \"" + std::string(name) + "\" for " + std::string(module.name) +
               " (choices: " + firmware_names(module) + ")"};
}

// The descriptor of `module` running the firmware `--firmware NAME` chooses (NAME as find_firmware
// takes it, with its errors): a generation's own descriptor when it brings one, otherwise the
// module with the generation's version string and listing (make() reads ModuleOptions::firmware).
// A value, not a pointer: a generation's descriptor is built when asked for.
inline Result<ModuleDescriptor> with_firmware(const ModuleDescriptor& module, std::string_view name) {
  const Result<const FirmwareGeneration*> found = find_firmware(module, name);
  if (!found) return Error{found.error()};
  const FirmwareGeneration* generation = *found;
  if (generation == nullptr) return module;
  if (generation->descriptor != nullptr) return generation->descriptor();
  ModuleDescriptor running = module;
  running.firmware = generation->version;
  if (generation->listing != nullptr) running.listing = generation->listing;
  return running;
}

// `motwin params`: the parameters or objects of a module's firmware generation.
inline Result<ModuleParameterListing> firmware_listing(const ModuleDescriptor& module, std::string_view name) {
  const Result<ModuleDescriptor> running = with_firmware(module, name);
  if (!running) return Error{running.error()};
  return running->listing();
}

}  // namespace motwin::host
