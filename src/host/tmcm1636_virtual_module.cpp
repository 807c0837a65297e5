#include "host/tmcm1636_virtual_module.h"

namespace motwin::host {

EepromImageIdentity Tmcm1636VirtualModule::eeprom_identity() {
  return EepromImageIdentity{std::string(Device::kName), Device::kNvmLayoutVersion, Device::kNvmLayout.total_size};
}

MakeModuleResult Tmcm1636VirtualModule::make(const ModuleOptions& options) {
  MakeModuleResult result;
  std::unique_ptr<Tmcm1636VirtualModule> module(new Tmcm1636VirtualModule());
  if (options.state_dir) {
    EepromFile::OpenResult opened =
        EepromFile::open(*options.state_dir, eeprom_identity(), &Device::format_factory_image, options.log);
    if (!opened.file) {
      result.error = opened.error;
      return result;
    }
    module->eeprom_file_ = std::move(opened.file);
    module->nvm_ = module->eeprom_file_.get();
  } else {
    module->memory_image_ = std::make_unique<MemoryImage>();
    Device::format_factory_image(module->memory_image_->mutable_data(), module->memory_image_->size());
    module->nvm_ = module->memory_image_.get();
  }
  for (const InitialInput& input : options.initial_inputs) module->io_.set_input(input.signal, input.value);
  module->device_.emplace(*module->nvm_, module->io_);
  module->device_->engine().power_up();
  result.module = std::move(module);
  return result;
}

void Tmcm1636VirtualModule::run_ticks(uint64_t count) {
  Device& device = *device_;
  for (uint64_t i = 0; i < count; ++i) {
    // Output changes are stamped with the start of the tick that made them.
    io_.set_sim_time_us(tick_count_ * modules::tmcm1636::kControlTickUs);
    device.tick();
    ++tick_count_;
  }
  io_.set_sim_time_us(tick_count_ * modules::tmcm1636::kControlTickUs);
}

std::string Tmcm1636VirtualModule::nvm_location() const {
  return eeprom_file_ ? eeprom_file_->path().string() : "none";
}

}  // namespace motwin::host
