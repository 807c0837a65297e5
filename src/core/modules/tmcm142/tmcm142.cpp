#include "core/modules/tmcm142/tmcm142.h"

#include "core/tmcl/instruction.h"

namespace motwin::modules::tmcm142 {
namespace {

using tmcl::Status;

// GIO/SIO banks, as on the TMCM-1636.
constexpr uint8_t kIoBankDigitalInputs = 0;
constexpr uint8_t kIoBankAnalogInputs = 1;
constexpr uint8_t kIoBankDigitalOutputs = 2;

// RFS types (notes/tmcl.md).
constexpr uint8_t kRfsStart = 0;
constexpr uint8_t kRfsStop = 1;
constexpr uint8_t kRfsStatus = 2;

// The motor byte of `SCO n, 255, 0` / `GCO n, 255, 0`.
constexpr uint8_t kCoordinateEepromCopy = 255;

constexpr uint8_t kGpEepromMagic = 64;
constexpr uint8_t kGpEepromLock = 73;
constexpr uint8_t kApUnitMode = 255;

}  // namespace

Tmcm142::Tmcm142(board::NonVolatileMemory& nvm, board::StepperPowerStage& stage, board::Tmcm142Io& io)
    : ModuleStorage(nvm), stage_(stage), io_(io) {}

// Power-up: the live state and every setting back to the defaults, before the restore.
void Tmcm142::clear_ram_state() {
  axis_.reset_state();
  axis_.config = AxisConfig{};
  global_ = GlobalConfig{};
  eeprom_locked_ = false;
  coordinates_.fill(0);
  runtime_ = tmcl::TmclRuntime{};
  tick_timer_ms_ = 0;
  tick_fraction_ = 0;
}

// GP 64 other than the magic value: the parameter part of the image goes back to factory values
// before anything is restored. Then AP 255 first: the stored speeds are in its units.
void Tmcm142::before_axis_restore() {
  if (stored_value(kNvmLayout.global_parameter(kGpEepromMagic)) != kEepromMagic) restore_factory_defaults();
  const auto unit_mode = static_cast<UnitMode>(stored_value(kNvmLayout.axis_parameter(0, kApUnitMode)));
  if (unit_mode == UnitMode::kTmc457 || unit_mode == UnitMode::kMicrostepsPerSecond) axis_.config.unit_mode = unit_mode;
}

// GP 73 and, with GP 84 = 1, the coordinates come back from the image.
void Tmcm142::after_restore() {
  eeprom_locked_ = stored_value(kNvmLayout.global_parameter(kGpEepromLock)) == 1;
  if (global_.coordinate_storage == CoordinateStorage::kEeprom) {
    for (uint8_t n = 1; n < kCoordinateCount; ++n) load_coordinate(n);
  }
}

Status Tmcm142::set_eeprom_lock(int32_t code) {
  if (code != kLockCode && code != kUnlockCode) return Status::kInvalidValue;
  const bool locked = code == kLockCode;
  if (!store_value(kNvmLayout.global_parameter(kGpEepromLock), locked ? 1 : 0)) return Status::kEepromLocked;
  eeprom_locked_ = locked;
  return Status::kOk;
}

// xorshift32: deterministic, so a simulation replays exactly.
int32_t Tmcm142::next_random() {
  random_state_ ^= random_state_ << 13;
  random_state_ ^= random_state_ >> 17;
  random_state_ ^= random_state_ << 5;
  return static_cast<int32_t>(random_state_ & 0x7FFFFFFFu);
}

void Tmcm142::tick() {
  axis_.tick(stage_);
  if (axis_.take_deviation_event()) runtime_.error_flags |= tmcl::kErrorDeviation;
  ++tick_count_;
  if (++tick_fraction_ == kTicksPerMillisecond) {
    tick_fraction_ = 0;
    ++tick_timer_ms_;
  }
  engine_.tick(tick_count_ * kControlTickUs);
}

tmcl::SerialSettings Tmcm142::serial_settings() const {
  return tmcl::SerialSettings{static_cast<uint8_t>(global_.serial_address),
                              static_cast<uint8_t>(global_.serial_host_address),
                              static_cast<uint8_t>(global_.telegram_pause_ms)};
}

// ROR/ROL write the target speed (AP 2) in the units of AP 255.
Status Tmcm142::rotate(uint8_t motor, int32_t velocity) { return axis_parameters().write(*this, motor, 2, velocity); }

Status Tmcm142::stop(uint8_t /*motor*/) {
  axis_.stop();
  return Status::kOk;
}

// MVP ABS/REL/COORD write the target position (AP 0). REL is relative to the actual position and
// wraps at 32 bits like the position counter; COORD takes coordinate 0..20.
Status Tmcm142::move(uint8_t motor, uint8_t move_type, int32_t value) {
  switch (move_type) {
    case tmcl::move_type::kAbsolute:
      return axis_parameters().write(*this, motor, 0, value);
    case tmcl::move_type::kRelative: {
      const auto target = static_cast<int32_t>(static_cast<uint32_t>(axis_.actual_position()) + static_cast<uint32_t>(value));
      return axis_parameters().write(*this, motor, 0, target);
    }
    case tmcl::move_type::kCoordinate:
      if (value < 0 || value >= kCoordinateCount) return Status::kInvalidValue;
      return axis_parameters().write(*this, motor, 0, coordinates_[static_cast<size_t>(value)]);
    default:
      return Status::kWrongType;
  }
}

bool Tmcm142::position_reached(uint8_t /*motor*/) const { return axis_.position_reached(); }

bool Tmcm142::home_switch_active(uint8_t /*motor*/) const { return axis_.state.home_switch_active != 0; }

bool Tmcm142::stop_switch_active(uint8_t /*motor*/, bool left) const {
  return (left ? axis_.state.left_switch_active : axis_.state.right_switch_active) != 0;
}

bool Tmcm142::reference_search_running(uint8_t /*motor*/) const { return axis_.reference_search_running(); }

Status Tmcm142::reference_search(uint8_t motor, uint8_t type, int32_t& value) {
  if (motor >= kMotorCount) return Status::kInvalidValue;
  switch (type) {
    case kRfsStart:
      // A search at speed 0 would never end.
      if (axis_.config.reference_fast_pps <= 0.0 || axis_.config.reference_slow_pps <= 0.0) return Status::kInvalidValue;
      axis_.start_reference_search();
      return Status::kOk;
    case kRfsStop:
      axis_.stop_reference_search();
      return Status::kOk;
    case kRfsStatus:
      value = axis_.reference_search_running() ? 1 : 0;
      return Status::kOk;
    default:
      return Status::kWrongType;
  }
}

Status Tmcm142::store_coordinate(uint8_t number) {
  if (eeprom_locked_) return Status::kEepromLocked;
  return store_value(kNvmLayout.coordinate(0, number), coordinates_[number]) ? Status::kOk : Status::kEepromLocked;
}

void Tmcm142::load_coordinate(uint8_t number) { coordinates_[number] = stored_value(kNvmLayout.coordinate(0, number)); }

// SCO n, 0, position; SCO n, 255, 0 copies coordinate n (n = 0: all of 1..20) to the EEPROM.
// With GP 84 = 1 every change of coordinates 1..20 is stored at once; coordinate 0 lives in RAM.
Status Tmcm142::set_coordinate(uint8_t number, uint8_t motor, int32_t position) {
  if (number >= kCoordinateCount) return Status::kWrongType;
  if (motor == kCoordinateEepromCopy) {
    if (eeprom_locked_) return Status::kEepromLocked;
    for (uint8_t n = number == 0 ? 1 : number; n <= (number == 0 ? kCoordinateCount - 1 : number); ++n) {
      if (store_coordinate(n) != Status::kOk) return Status::kEepromLocked;
    }
    return Status::kOk;
  }
  if (motor >= kMotorCount) return Status::kInvalidValue;
  const bool stored = global_.coordinate_storage == CoordinateStorage::kEeprom && number != 0;
  if (stored && eeprom_locked_) return Status::kEepromLocked;
  const int32_t previous = coordinates_[number];
  coordinates_[number] = position;
  if (stored && store_coordinate(number) != Status::kOk) {
    coordinates_[number] = previous;
    return Status::kEepromLocked;
  }
  return Status::kOk;
}

// GCO n, 0 reads; GCO n, 255, 0 copies coordinate n (0: all of 1..20) back from the EEPROM.
Status Tmcm142::get_coordinate(uint8_t number, uint8_t motor, int32_t& position) {
  if (number >= kCoordinateCount) return Status::kWrongType;
  if (motor == kCoordinateEepromCopy) {
    if (number == 0) {
      for (uint8_t n = 1; n < kCoordinateCount; ++n) load_coordinate(n);
    } else {
      load_coordinate(number);
    }
    position = coordinates_[number];
    return Status::kOk;
  }
  if (motor >= kMotorCount) return Status::kInvalidValue;
  position = coordinates_[number];
  return Status::kOk;
}

// CCO n, 0: the actual position (AP 1) becomes coordinate n.
Status Tmcm142::capture_coordinate(uint8_t number, uint8_t motor) {
  if (motor >= kMotorCount) return number >= kCoordinateCount ? Status::kWrongType : Status::kInvalidValue;
  return set_coordinate(number, motor, axis_.actual_position());
}

Status Tmcm142::set_output(uint8_t port, uint8_t bank, int32_t value) {
  if (bank != kIoBankDigitalOutputs) return Status::kInvalidValue;
  if (port >= board::Tmcm142Io::kDigitalOutputCount) return Status::kWrongType;
  if (value != 0 && value != 1) return Status::kInvalidValue;
  io_.set_digital_output(port, value != 0);
  return Status::kOk;
}

Status Tmcm142::get_input(uint8_t port, uint8_t bank, int32_t& value) {
  switch (bank) {
    case kIoBankDigitalInputs:
      if (port >= board::Tmcm142Io::kDigitalInputCount) return Status::kWrongType;
      value = io_.digital_input(port) ? 1 : 0;
      return Status::kOk;
    case kIoBankAnalogInputs:
      if (port >= board::Tmcm142Io::kAnalogInputCount) return Status::kWrongType;
      value = io_.analog_input(port);
      return Status::kOk;
    case kIoBankDigitalOutputs:
      if (port >= board::Tmcm142Io::kDigitalOutputCount) return Status::kWrongType;
      value = io_.digital_output(port) ? 1 : 0;
      return Status::kOk;
    default:
      return Status::kInvalidValue;
  }
}

}  // namespace motwin::modules::tmcm142
