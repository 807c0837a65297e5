#include "core/modules/tmcm1636/tmcm1636.h"

#include <cstring>

#include "core/tmcl/instruction.h"

namespace motwin::modules::tmcm1636 {
namespace {

using params::Access;
using params::has;
using tmcl::Status;

constexpr uint8_t kBankGlobal = 0;
constexpr uint8_t kBankUserVariables = 2;
// GIO/SIO banks (manual 2.6.13/2.6.14).
constexpr uint8_t kIoBankDigitalInputs = 0;
constexpr uint8_t kIoBankAnalogInputs = 1;
constexpr uint8_t kIoBankDigitalOutputs = 2;

constexpr Access kStoredMask = Access::kEeprom | Access::kAutoStore;

bool is_stored(const params::ParameterInfo& info) { return has(info.access, kStoredMask); }

}  // namespace

Tmcm1636::Tmcm1636(board::NonVolatileMemory& nvm, board::Tmcm1636Io& io) : nvm_(nvm), io_(io) {}

void Tmcm1636::format_factory_image(uint8_t* image, size_t size) {
  std::memset(image, 0, size);
  if (size < kNvmLayout.total_size) return;
  for (const auto& row : axis_parameters().rows()) {
    if (is_stored(row.info)) {
      tmcl::put_le32(image + kNvmLayout.axis_parameter(0, static_cast<uint8_t>(row.info.number)),
                     static_cast<int32_t>(row.info.default_value));
    }
  }
  for (const auto& row : global_parameters().rows()) {
    if (is_stored(row.info)) {
      tmcl::put_le32(image + kNvmLayout.global_parameter(static_cast<uint8_t>(row.info.number)),
                     static_cast<int32_t>(row.info.default_value));
    }
  }
  // An empty program memory holds STOP everywhere, so autostart (GP 77 = 1 by default) of a
  // module without a program stops at once.
  for (uint32_t address = 0; address < kNvmLayout.program_capacity; ++address) {
    tmcl::encode_program_record(tmcl::Instruction{tmcl::command::kStop, 0, 0, 0},
                                image + kNvmLayout.program_offset + address * tmcl::kProgramRecordBytes);
  }
}

bool Tmcm1636::store_value(uint32_t offset, int32_t value) {
  uint8_t bytes[4];
  tmcl::put_le32(bytes, value);
  last_store_failed_ = !nvm_.write(offset, bytes, sizeof bytes);
  return !last_store_failed_;
}

int32_t Tmcm1636::stored_value(uint32_t offset) const {
  if (nvm_.size() < offset + 4) return 0;
  return tmcl::get_le32(nvm_.data() + offset);
}

// Power-up (and command 255): RAM state cleared, every stored parameter restored from the
// EEPROM image. A stored value outside its row's range (an image from elsewhere) is skipped
// and the default kept, so a bad image can never put the module into an invalid state.
void Tmcm1636::power_up() {
  axis_.reset_state();
  axis_.config = AxisConfig{};
  global_ = GlobalConfig{};
  user_variables_.fill(0);
  runtime_ = tmcl::TmclRuntime{};
  tick_timer_ms_ = 0;
  tick_fraction_ = 0;
  if (nvm_.size() < kNvmLayout.total_size) return;
  for (const auto& row : axis_parameters().rows()) {
    if (!is_stored(row.info)) continue;
    const int32_t value = stored_value(kNvmLayout.axis_parameter(0, static_cast<uint8_t>(row.info.number)));
    if (params::in_range(row.info, value)) row.binding.set(*this, 0, value);
  }
  axis_.finish_restore();  // later writes are host commands (AP 15 starts encoder initialisation)
  for (const auto& row : global_parameters().rows()) {
    if (!is_stored(row.info)) continue;
    const int32_t value = stored_value(kNvmLayout.global_parameter(static_cast<uint8_t>(row.info.number)));
    if (params::in_range(row.info, value)) row.binding.set(*this, kBankGlobal, value);
  }
  if (global_.skip_user_variable_restore != 0) return;
  for (uint8_t i = 0; i < kStorableUserVariables; ++i) {
    user_variables_[i] = stored_value(kNvmLayout.user_variable(i));
  }
}

// Command 137: the parameter part of the image back to factory values; a stored TMCL program
// is kept (docs/decisions.md). The engine powers the module up afterwards.
void Tmcm1636::restore_factory_defaults() {
  static uint8_t image[kNvmLayout.total_size];
  format_factory_image(image, sizeof image);
  last_store_failed_ = !nvm_.write(0, image, kNvmLayout.program_offset);
}

void Tmcm1636::tick() {
  axis_.tick(io_, static_cast<double>(kControlTickUs) * 1e-6);
  ++tick_count_;
  if (++tick_fraction_ == kTicksPerMillisecond) {
    tick_fraction_ = 0;
    ++tick_timer_ms_;
  }
  engine_.tick(tick_count_ * kControlTickUs);
}

bool Tmcm1636::home_switch_active(uint8_t /*motor*/) const { return axis_.state.home_switch_active != 0; }

bool Tmcm1636::stop_switch_active(uint8_t /*motor*/, bool left) const {
  return (left ? axis_.state.left_switch_active : axis_.state.right_switch_active) != 0;
}

tmcl::SerialSettings Tmcm1636::serial_settings() const {
  return tmcl::SerialSettings{static_cast<uint8_t>(global_.serial_address),
                              static_cast<uint8_t>(global_.serial_host_address),
                              static_cast<uint8_t>(global_.telegram_pause_ms)};
}

// ROR/ROL write the target velocity (AP 40) in rpm: DESIGN.md errata.
Status Tmcm1636::rotate(uint8_t motor, int32_t velocity_rpm) {
  return axis_parameters().write(*this, motor, 40, velocity_rpm);
}

// MST: velocity mode, target velocity 0, stopping with the ramp.
Status Tmcm1636::stop(uint8_t /*motor*/) {
  axis_.set_target_velocity(0);
  return Status::kOk;
}

// MVP ABS/REL write the target position (AP 50). REL is relative to the actual position
// (manual 2.6.4) and wraps at 32 bits like the position counter.
Status Tmcm1636::move(uint8_t motor, uint8_t move_type, int32_t value) {
  switch (move_type) {
    case tmcl::move_type::kAbsolute:
      return axis_parameters().write(*this, motor, 50, value);
    case tmcl::move_type::kRelative: {
      const auto target = static_cast<int32_t>(static_cast<uint32_t>(axis_.state.actual_position) + static_cast<uint32_t>(value));
      return axis_parameters().write(*this, motor, 50, target);
    }
    default:
      return Status::kWrongType;
  }
}

bool Tmcm1636::position_reached(uint8_t /*motor*/) const { return axis_.position_reached(); }

Status Tmcm1636::set_axis_parameter(uint8_t number, uint8_t motor, int32_t value) {
  return axis_parameters().write(*this, motor, number, value);
}

Status Tmcm1636::get_axis_parameter(uint8_t number, uint8_t motor, int32_t& value) {
  return axis_parameters().read(*this, motor, number, value);
}

Status Tmcm1636::store_axis_parameter(uint8_t number, uint8_t motor) {
  const auto* row = axis_parameters().find(number);
  if (row == nullptr || !has(row->info.access, Access::kEeprom)) return Status::kWrongType;
  return store_value(kNvmLayout.axis_parameter(motor, number), row->binding.get(*this, motor)) ? Status::kOk
                                                                                                 : Status::kEepromLocked;
}

Status Tmcm1636::restore_axis_parameter(uint8_t number, uint8_t motor) {
  const auto* row = axis_parameters().find(number);
  if (row == nullptr || !has(row->info.access, Access::kEeprom)) return Status::kWrongType;
  const int32_t value = stored_value(kNvmLayout.axis_parameter(motor, number));
  if (!params::in_range(row->info, value)) return Status::kInvalidValue;
  return row->binding.set(*this, motor, value);
}

Status Tmcm1636::set_global_parameter(uint8_t number, uint8_t bank, int32_t value) {
  if (bank == kBankUserVariables) {
    user_variables_[number] = value;
    return Status::kOk;
  }
  if (bank != kBankGlobal) return Status::kInvalidValue;
  const auto* row = global_parameters().find(number);
  if (row == nullptr || !has(row->info.access, Access::kAutoStore)) return global_parameters().write(*this, bank, number, value);
  // Automatically stored (A): RAM and EEPROM change together or not at all.
  const int32_t previous = row->binding.get != nullptr ? row->binding.get(*this, bank) : 0;
  const Status status = global_parameters().write(*this, bank, number, value);
  if (status != Status::kOk) return status;
  if (!store_value(kNvmLayout.global_parameter(number), value)) {
    row->binding.set(*this, bank, previous);
    return Status::kEepromLocked;
  }
  return Status::kOk;
}

Status Tmcm1636::get_global_parameter(uint8_t number, uint8_t bank, int32_t& value) {
  if (bank == kBankUserVariables) {
    value = user_variables_[number];
    return Status::kOk;
  }
  if (bank != kBankGlobal) return Status::kInvalidValue;
  return global_parameters().read(*this, bank, number, value);
}

// STGP: user variables 0..55 (manual 4.2), and bank-0 parameters that are stored anyway.
Status Tmcm1636::store_global_parameter(uint8_t number, uint8_t bank) {
  if (bank == kBankUserVariables) {
    if (number >= kStorableUserVariables) return Status::kWrongType;
    return store_value(kNvmLayout.user_variable(number), user_variables_[number]) ? Status::kOk : Status::kEepromLocked;
  }
  if (bank != kBankGlobal) return Status::kInvalidValue;
  const auto* row = global_parameters().find(number);
  if (row == nullptr || !is_stored(row->info)) return Status::kWrongType;
  return store_value(kNvmLayout.global_parameter(number), row->binding.get(*this, bank)) ? Status::kOk
                                                                                          : Status::kEepromLocked;
}

Status Tmcm1636::restore_global_parameter(uint8_t number, uint8_t bank) {
  if (bank == kBankUserVariables) {
    if (number >= kStorableUserVariables) return Status::kWrongType;
    user_variables_[number] = stored_value(kNvmLayout.user_variable(number));
    return Status::kOk;
  }
  if (bank != kBankGlobal) return Status::kInvalidValue;
  const auto* row = global_parameters().find(number);
  if (row == nullptr || !is_stored(row->info)) return Status::kWrongType;
  const int32_t value = stored_value(kNvmLayout.global_parameter(number));
  if (!params::in_range(row->info, value)) return Status::kInvalidValue;
  return row->binding.set(*this, bank, value);
}

Status Tmcm1636::set_output(uint8_t port, uint8_t bank, int32_t value) {
  if (bank != kIoBankDigitalOutputs) return Status::kInvalidValue;
  if (port >= board::Tmcm1636Io::kDigitalOutputCount) return Status::kWrongType;
  if (value != 0 && value != 1) return Status::kInvalidValue;
  io_.set_digital_output(port, value != 0);
  return Status::kOk;
}

Status Tmcm1636::get_input(uint8_t port, uint8_t bank, int32_t& value) {
  switch (bank) {
    case kIoBankDigitalInputs:
      if (port >= board::Tmcm1636Io::kDigitalInputCount) return Status::kWrongType;
      value = io_.digital_input(port) ? 1 : 0;
      return Status::kOk;
    case kIoBankAnalogInputs:
      if (port >= board::Tmcm1636Io::kAnalogInputCount) return Status::kWrongType;
      value = io_.analog_input(port);
      return Status::kOk;
    case kIoBankDigitalOutputs:
      if (port >= board::Tmcm1636Io::kDigitalOutputCount) return Status::kWrongType;
      value = io_.digital_output(port) ? 1 : 0;
      return Status::kOk;
    default:
      return Status::kInvalidValue;
  }
}

}  // namespace motwin::modules::tmcm1636
