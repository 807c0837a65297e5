// The CiA-402 objects of one axis (6xxx; the TMCM-3216 manual's chapters 5-10 list the ones it
// implements), as the values a master wrote, in the objects' own units. The drive converts them
// to internal units (microsteps, microsteps/s, microsteps/s²) where it uses them, with the
// UnitScale its module gives (axis_drive.h), so that a unit choice applies to every velocity and
// acceleration object at once. A module's manufacturer objects are not here: they are the
// module's part of the drive (axis_drive.h, "The module's part").
#pragma once

#include <cstdint>
#include <limits>

namespace motwin::cia402 {

// 6060 / 6061 values.
enum class Mode : int8_t {
  kNone = 0,
  kProfilePosition = 1,
  kProfileVelocity = 3,
  kHoming = 6,
  kCyclicSyncPosition = 8,
  kCyclicSyncVelocity = 9,
  kCyclicSyncTorque = 10,
};
// 6502 bit of a mode: bit 0 pp, 2 pv, 5 hm, 7 csp, 8 csv, 9 cst (CiA-402: bit mode - 1).
constexpr uint32_t drive_mode_bit(Mode mode) { return 1u << (static_cast<int>(mode) - 1); }
// The modes the TMCM-3216 has (its 6502): pp, pv, hm, csp, csv.
inline constexpr uint32_t kSupportedDriveModes =
    drive_mode_bit(Mode::kProfilePosition) | drive_mode_bit(Mode::kProfileVelocity) | drive_mode_bit(Mode::kHoming) |
    drive_mode_bit(Mode::kCyclicSyncPosition) | drive_mode_bit(Mode::kCyclicSyncVelocity);
// A 6060 value a drive with the modes `supported` (6502 bits) accepts: 0 (no mode) or one of them.
constexpr bool supported_mode(uint32_t supported, int64_t value) {
  if (value == 0) return true;
  if (value < 1 || value > 32) return false;
  return (supported & (1u << (value - 1))) != 0;
}
constexpr bool supported_mode(int64_t value) { return supported_mode(kSupportedDriveModes, value); }

struct ProfileObjects {
  // Option codes 605A..605E.
  int16_t quick_stop_option = 2;
  int16_t shutdown_option = 0;
  int16_t disable_operation_option = 1;
  int16_t halt_option = 1;
  int16_t fault_reaction_option = 2;
  int8_t mode = 0;                                  // 6060
  int16_t sensor_selection = -1;                    // 606A: 0 encoder, -1 none
  uint32_t following_error_window = 0;              // 6065, µsteps; 0 = off
  uint32_t position_window = 0xFFFF'FFFF;           // 6067, µsteps; FFFFFFFF = off
  uint16_t position_window_time_ms = 0;             // 6068
  int32_t target_position = 0;                      // 607A
  int32_t home_offset = 0;                          // 607C
  int32_t software_limit_min = std::numeric_limits<int32_t>::min();  // 607D sub 1
  int32_t software_limit_max = std::numeric_limits<int32_t>::max();  // 607D sub 2
  // Velocities and accelerations in the object units (UnitScale). The manual's defaults of 6081,
  // 6083 and 6084 are 0, which would make its own examples (6.2, 7.2) stand still: see
  // docs/tmcm-3216-drive.md "Decisions".
  uint32_t profile_velocity = 51200;                // 6081
  uint32_t end_velocity = 0;                        // 6082
  uint32_t profile_acceleration = 51200;            // 6083
  uint32_t profile_deceleration = 51200;            // 6084
  uint32_t quick_stop_deceleration = 51200;         // 6085
  uint16_t positioning_option = 0;                  // 60F2 bits 0, 1
  int32_t target_velocity = 0;                      // 60FF
  int8_t homing_method = 0;                         // 6098
  uint32_t homing_speed_fast = 0;                   // 6099 sub 1
  uint32_t homing_speed_slow = 0;                   // 6099 sub 2
  uint32_t homing_acceleration = 0;                 // 609A; 0 = use 6083
  int32_t position_offset = 0;                      // 60B0
  int32_t velocity_offset = 0;                      // 60B1
  uint8_t interpolation_period = 1;                 // 60C2 sub 1
  int8_t interpolation_index = -3;                  // 60C2 sub 2: period = sub1 x 10^sub2 s
  uint32_t encoder_increments = 1;                  // 608F sub 1 (per motor revolution)
  // Torque (cst, where a module has it), in the module's torque unit (TMCM-1636: mA).
  int16_t target_torque = 0;                        // 6071
  uint16_t max_torque = 0;                          // 6072; 0 = no limit besides the motor's
  int16_t torque_offset = 0;                        // 60B2
  uint32_t max_profile_velocity = 0;                // 607F; 0 = no limit (objects a module lacks stay 0)
};

// A double in int32 range: the largest or smallest int32 beyond it (a cast would be undefined
// behaviour). 6099 and 609A/6083 take the whole UNSIGNED32 range (manual tables 260, 315, 317) and
// the module's units scale values further both ways.
inline int32_t saturate_to_int32(double value) {
  if (value >= static_cast<double>(std::numeric_limits<int32_t>::max())) return std::numeric_limits<int32_t>::max();
  if (value <= static_cast<double>(std::numeric_limits<int32_t>::min())) return std::numeric_limits<int32_t>::min();
  return static_cast<int32_t>(value);
}

// Object units -> internal units: what one unit of a velocity object (6081, 60FF, 6099, ...) and
// of an acceleration object (6083..6085, 609A) is in microsteps/s and microsteps/s². CiA-402
// leaves the units to the drive; the module decides them (AxisDrive's module part, units()).
// The default is 1:1.
struct UnitScale {
  double pps_per_velocity_unit = 1.0;
  double pps2_per_acceleration_unit = 1.0;

  double velocity_pps(double value) const { return value * pps_per_velocity_unit; }
  double acceleration_pps2(double value) const { return value * pps2_per_acceleration_unit; }
  // Internal velocity -> object units (606C), rounded towards zero; saturated where a small unit
  // makes a fast axis' value larger than 606C can hold (found by fuzzing: 4.2e11 units).
  int32_t velocity_value(double pps) const { return saturate_to_int32(pps / pps_per_velocity_unit); }
};

}  // namespace motwin::cia402
