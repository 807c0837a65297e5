#include "core/modules/tmcm142/tmcm142.h"

#include "core/tmcl/instruction.h"

namespace motwin::modules::tmcm142 {
namespace {

using tmcl::Status;

// The motor byte of `SCO n, 255, 0` / `GCO n, 255, 0`.
constexpr uint8_t kCoordinateEepromCopy = 255;

constexpr uint8_t kGpEepromMagic = 64;
constexpr uint8_t kGpEepromLock = 73;
constexpr uint8_t kApUnitMode = 255;

}  // namespace

// Layout 1 -> 2 (docs/tmcm-142.md "EEPROM image"): the slots are the parameter numbers, so the
// values of the renumbered settings move, the slots whose meaning changed get the new meaning's
// factory value, and the rows new in layout 2 start at their defaults.
bool Tmcm142::migrate_image(uint32_t from_layout_version, uint8_t* image, size_t size) {
  constexpr tmcl::NvmLayout layout = kNvmLayout;
  if (from_layout_version != 1 || size != layout.total_size) return false;
  const auto axis_slot = [&](uint8_t number) { return image + layout.axis_parameter(0, number); };
  // The stored axis rows of layout 1; every other stored row of layout 2 is new.
  constexpr uint8_t kLayout1AxisRows[] = {4,  5,  6,  7,  12, 13, 14,  15,  16,  17,  18,  19,  27, 30,
                                          31, 32, 33, 35, 37, 40, 42, 46, 193, 194, 195, 212, 214, 255};
  constexpr uint8_t kLayout1BowSlots[] = {16, 17, 18, 19};
  constexpr uint8_t kLayout1EncoderDirection = 46;
  constexpr uint8_t kLayout1StandbyDelay = 214;

  // One bow for the four: the gentlest of the stored ones, so no change of acceleration becomes
  // harsher than it was set.
  int32_t bow = kMaxBow;
  bool any_bow = false;
  for (const uint8_t slot : kLayout1BowSlots) {
    const int32_t value = tmcl::get_le32(axis_slot(slot));
    if (value < 1 || value > kMaxBow) continue;
    if (!any_bow || value < bow) bow = value;
    any_bow = true;
  }
  const int32_t encoder_reversed = tmcl::get_le32(axis_slot(kLayout1EncoderDirection)) == 1 ? encoder_mode::kReverse : 0;
  const int32_t standby_delay = tmcl::get_le32(axis_slot(kLayout1StandbyDelay));

  for (const auto& row : axis_parameters().rows()) {
    if (!tmcl::is_stored_parameter(row.info)) continue;
    bool in_layout1 = false;
    for (const uint8_t number : kLayout1AxisRows) in_layout1 = in_layout1 || number == row.info.number;
    if (!in_layout1 || row.info.number == 17 || row.info.number == 18 || row.info.number == 19) {
      tmcl::put_le32(axis_slot(static_cast<uint8_t>(row.info.number)), static_cast<int32_t>(row.info.default_value));
    }
  }
  // Slots no stored row of layout 2 reads any more: cleared, as a factory image has them.
  tmcl::put_le32(axis_slot(16), 0);
  tmcl::put_le32(axis_slot(kLayout1EncoderDirection), 0);
  tmcl::put_le32(axis_slot(kLayout1StandbyDelay), 0);
  constexpr uint8_t kMaxBowRow = 18, kStandbyDelayRow = 20, kEncoderModeRow = 43;
  if (any_bow) tmcl::put_le32(axis_slot(kMaxBowRow), bow);
  tmcl::put_le32(axis_slot(kStandbyDelayRow), standby_delay);
  tmcl::put_le32(axis_slot(kEncoderModeRow), encoder_reversed);

  constexpr uint8_t kLayout2NewGlobals[] = {68, 81, 82, 83, 87};
  for (const uint8_t number : kLayout2NewGlobals) {
    const auto* row = global_parameters().find(number);
    if (row != nullptr) tmcl::put_le32(image + layout.global_parameter(number), static_cast<int32_t>(row->info.default_value));
  }
  return true;
}

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
