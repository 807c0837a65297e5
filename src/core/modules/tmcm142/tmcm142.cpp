#include "core/modules/tmcm142/tmcm142.h"

#include "core/tmcl/instruction.h"

namespace motwin::modules::tmcm142 {
namespace {

using tmcl::Status;

// RFS types (docs/tmcl-protocol.md "Code tables").
constexpr uint8_t kRfsStart = 0;
constexpr uint8_t kRfsStop = 1;
constexpr uint8_t kRfsStatus = 2;

// The motor byte of `SCO n, 255, 0` / `GCO n, 255, 0`.
constexpr uint8_t kCoordinateEepromCopy = 255;

constexpr uint8_t kGpEepromMagic = 64;
constexpr uint8_t kGpEepromLock = 73;
constexpr uint8_t kApUnitMode = 255;

}  // namespace

// Power-up: what the base clears, the EEPROM lock and the coordinates, before the restore.
void Tmcm142::clear_ram_state() {
  TmclModule::clear_ram_state();
  eeprom_locked_ = false;
  coordinates_.fill(0);
}

// GP 64 other than the magic value: the parameter part of the image goes back to factory values
// before anything is restored. Then AP 255 first: the stored speeds are in its units.
void Tmcm142::before_axis_restore() {
  if (stored_value(kNvmLayout.global_parameter(kGpEepromMagic)) != kEepromMagic) restore_factory_defaults();
  const auto unit_mode = static_cast<UnitMode>(stored_value(kNvmLayout.axis_parameter(0, kApUnitMode)));
  if (unit_mode == UnitMode::kTmc457 || unit_mode == UnitMode::kMicrostepsPerSecond) axis().config.unit_mode = unit_mode;
}

// GP 73 and, with GP 84 = 1, the coordinates come back from the image.
void Tmcm142::after_restore() {
  eeprom_locked_ = stored_value(kNvmLayout.global_parameter(kGpEepromLock)) == 1;
  if (global_config().coordinate_storage == CoordinateStorage::kEeprom) {
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

// MVP COORD moves to coordinate 0..20 (a write of the target position, AP 0); ABS and REL are
// the base's.
Status Tmcm142::move(uint8_t motor, uint8_t move_type, int32_t value) {
  if (move_type != tmcl::move_type::kCoordinate) return TmclModule::move(motor, move_type, value);
  if (value < 0 || value >= kCoordinateCount) return Status::kInvalidValue;
  return move_to(motor, coordinates_[static_cast<size_t>(value)]);
}

bool Tmcm142::reference_search_running(uint8_t /*motor*/) const { return axis().reference_search_running(); }

Status Tmcm142::reference_search(uint8_t motor, uint8_t type, int32_t& value) {
  if (motor >= kMotorCount) return Status::kInvalidValue;
  switch (type) {
    case kRfsStart:
      // A search at speed 0 would never end.
      if (axis().config.reference_fast_pps <= 0.0 || axis().config.reference_slow_pps <= 0.0) return Status::kInvalidValue;
      axis().start_reference_search();
      return Status::kOk;
    case kRfsStop:
      axis().stop_reference_search();
      return Status::kOk;
    case kRfsStatus:
      value = axis().reference_search_running() ? 1 : 0;
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
  const bool stored = global_config().coordinate_storage == CoordinateStorage::kEeprom && number != 0;
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
  return set_coordinate(number, motor, axis().actual_position());
}

}  // namespace motwin::modules::tmcm142
