// The one row per module. The first row is the default module of `serve` and `run`.
#include "host/module_registry.h"

#include <cctype>

namespace motwin::host {

// Each module's descriptor, defined in its own folder: src/host/modules/<module>/<module>_descriptor.cpp.
ModuleDescriptor tmcm1636_descriptor();
ModuleDescriptor tmcm142_descriptor();
ModuleDescriptor tmcm3216_descriptor();

namespace {

bool equals_ignoring_case(std::string_view a, std::string_view b) {
  if (a.size() != b.size()) return false;
  for (size_t i = 0; i < a.size(); ++i) {
    if (std::tolower(static_cast<unsigned char>(a[i])) != std::tolower(static_cast<unsigned char>(b[i]))) return false;
  }
  return true;
}

bool any_module(const ModuleDescriptor&) { return true; }

}  // namespace

std::span<const ModuleDescriptor> registered_modules() {
  // Built on first use: the rows come from other translation units.
  static const ModuleDescriptor kModules[] = {
      tmcm1636_descriptor(),
      tmcm142_descriptor(),
      tmcm3216_descriptor(),
  };
  return kModules;
}

const ModuleDescriptor* find_module(std::string_view name) {
  for (const ModuleDescriptor& module : registered_modules()) {
    if (module.name == name) return &module;
  }
  return nullptr;
}

const ModuleDescriptor* find_module_ignoring_case(std::string_view name) {
  for (const ModuleDescriptor& module : registered_modules()) {
    if (equals_ignoring_case(module.name, name)) return &module;
  }
  return nullptr;
}

std::string module_names() { return module_names(&any_module); }

std::string module_names(bool (*keep)(const ModuleDescriptor&)) {
  std::string names;
  for (const ModuleDescriptor& module : registered_modules()) {
    if (!keep(module)) continue;
    if (!names.empty()) names += ", ";
    names += module.name;
  }
  return names;
}

const ModuleDescriptor* first_module(bool (*keep)(const ModuleDescriptor&)) {
  for (const ModuleDescriptor& module : registered_modules()) {
    if (keep(module)) return &module;
  }
  return nullptr;
}

Result<ModuleDescriptor> find_module_with_firmware(std::string_view name, std::string_view firmware) {
  const ModuleDescriptor* module = find_module(name);
  if (module == nullptr) {
    return Error{"unknown module \"" + std::string(name) + "\" (available: " + module_names() + ")"};
  }
  return with_firmware(*module, firmware);
}

MakeModuleResult make_module(std::string_view name, const ModuleOptions& options) {
  const Result<ModuleDescriptor> module = find_module_with_firmware(name, options.firmware);
  if (!module) return Error{module.error()};
  return module->make(options);
}

}  // namespace motwin::host
