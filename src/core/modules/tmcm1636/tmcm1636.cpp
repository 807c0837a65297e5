#include "core/modules/tmcm1636/tmcm1636.h"

#include "core/tmcl/instruction.h"

namespace motwin::modules::tmcm1636 {
namespace {

using tmcl::Status;

// GIO/SIO banks (manual 2.6.13/2.6.14).
constexpr uint8_t kIoBankDigitalInputs = 0;
constexpr uint8_t kIoBankAnalogInputs = 1;
constexpr uint8_t kIoBankDigitalOutputs = 2;

}  // namespace

Tmcm1636::Tmcm1636(board::NonVolatileMemory& nvm, board::Tmcm1636Io& io) : ModuleStorage(nvm), io_(io) {}

// Power-up: the live state and every setting back to the defaults, before the restore.
void Tmcm1636::clear_ram_state() {
  axis_.reset_state();
  axis_.config = AxisConfig{};
  global_ = GlobalConfig{};
  runtime_ = tmcl::TmclRuntime{};
  tick_timer_ms_ = 0;
  tick_fraction_ = 0;
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
