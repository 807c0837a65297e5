// The modules Motwin knows: one row per module in module_registry.cpp, each row the module's
// descriptor (host/module_descriptor.h). `serve`, `run`, `params`, `eds`, the help texts and the
// module group learn every module from here; adding a module is its own folders plus one row
// (docs/host-runtime.md, "Adding a module").
#pragma once

#include <span>
#include <string>
#include <string_view>

#include "host/module_descriptor.h"

namespace motwin::host {

std::span<const ModuleDescriptor> registered_modules();
// nullptr for an unknown name.
const ModuleDescriptor* find_module(std::string_view name);
// The same, ignoring case ("TMCM-1636"), for commands that always have: `motwin params`.
const ModuleDescriptor* find_module_ignoring_case(std::string_view name);
// "tmcm-1636, ..." for messages; with a filter, the modules it keeps.
std::string module_names();
std::string module_names(bool (*keep)(const ModuleDescriptor&));
// The first registered module the filter keeps (nullptr: none), e.g. the default of a command.
const ModuleDescriptor* first_module(bool (*keep)(const ModuleDescriptor&));

// Filters for the two functions above.
inline bool has_tmcl(const ModuleDescriptor& module) { return module.endpoints.has_tmcl(); }
inline bool has_canopen_dictionary(const ModuleDescriptor& module) { return module.canopen != nullptr; }

// The descriptor of the module `name` running `firmware` (with_firmware; empty: its default), or
// why there is none: an unknown module, naming the registered ones, or an unknown firmware.
Result<ModuleDescriptor> find_module_with_firmware(std::string_view name, std::string_view firmware);

// The module running options.firmware. An unknown name or firmware, or an unusable state
// directory, gives an error, never an exception.
MakeModuleResult make_module(std::string_view name, const ModuleOptions& options);

}  // namespace motwin::host
