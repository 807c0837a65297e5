#include "host/tmcm1636_virtual_module.h"

namespace motwin::host {

EepromImageIdentity Tmcm1636VirtualModule::eeprom_identity() {
  return EepromImageIdentity{std::string(Device::kName), Device::kNvmLayoutVersion, Device::kNvmLayout.total_size};
}

MakeModuleResult Tmcm1636VirtualModule::make(const ModuleOptions& options) {
  MakeModuleResult result;
  std::unique_ptr<Tmcm1636VirtualModule> module(new Tmcm1636VirtualModule());
  // The motor is checked before any file is touched.
  sim::MotorLoadResult motor = sim::resolve_motor(options.motor);
  if (!motor.error.empty()) {
    result.error = motor.error;
    return result;
  }
  // A physical motor's start-up settings go into a fresh image (docs/tmcm-1636-servo.md).
  const auto format_image = [&motor](uint8_t* image, size_t size) {
    Device::format_factory_image(image, size);
    if (motor.motor) sim::write_startup_parameters(*motor.motor, image, size);
  };
  if (options.state_dir) {
    EepromFile::OpenResult opened = EepromFile::open(*options.state_dir, eeprom_identity(), format_image, options.log);
    if (!opened.file) {
      result.error = opened.error;
      return result;
    }
    module->eeprom_file_ = std::move(opened.file);
    module->nvm_ = module->eeprom_file_.get();
  } else {
    module->memory_image_ = std::make_unique<MemoryImage>();
    format_image(module->memory_image_->mutable_data(), module->memory_image_->size());
    module->nvm_ = module->memory_image_.get();
  }
  module->board_ = motor.motor ? std::make_unique<sim::Tmcm1636SimBoard>(module->io_, *motor.motor)
                               : std::make_unique<sim::Tmcm1636SimBoard>(module->io_);
  if (motor.motor && module->eeprom_file_ && !sim::image_configures_motor(module->nvm_->data(), module->nvm_->size())) {
    options.log("motwin: the EEPROM image " + module->eeprom_file_->path().string() + " has motor type 0 (no motor); " +
                motor.motor->name + " start-up settings go into new images only (docs/tmcm-1636-servo.md)");
  }
  for (const InitialInput& input : options.initial_inputs) module->board_->set_input(input.signal, input.value);
  module->device_.emplace(*module->nvm_, module->io_);
  if (board::Tmcm1636PowerStage* stage = module->board_->power_stage()) module->device_->axis().attach_power_stage(stage);
  module->device_->engine().power_up();
  module->can_.emplace(module->device_->engine());
  result.module = std::move(module);
  return result;
}

void Tmcm1636VirtualModule::run_ticks(uint64_t count) {
  Device& device = *device_;
  sim::Tmcm1636SimBoard& sim_board = *board_;
  for (uint64_t i = 0; i < count; ++i) {
    // Output changes are stamped with the start of the tick that made them.
    io_.set_sim_time_us(tick_count_ * modules::tmcm1636::kControlTickUs);
    sim_board.before_tick();
    device.tick();
    sim_board.after_tick(modules::tmcm1636::kControlTickUs * 1e-6);
    ++tick_count_;
  }
  io_.set_sim_time_us(tick_count_ * modules::tmcm1636::kControlTickUs);
}

std::string Tmcm1636VirtualModule::nvm_location() const {
  return eeprom_file_ ? eeprom_file_->path().string() : "none";
}

}  // namespace motwin::host
