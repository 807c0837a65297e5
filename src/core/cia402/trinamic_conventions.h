// What Trinamic's CANopen drives share beyond CiA-402, the same on the TMCM-3216 and the
// TMCM-1636's CANopen firmware:
// - the switch parameters object 2005 (TMCM-3216 manual 4.2.6): which limit and home switches a
//   drive uses and which it inverts; the switches' electrical levels in, the switches the drive
//   sees active (its AxisInputs: left = negative limit, right = positive limit) out;
// - statusword bits 14 and 15, manufacturer-specific in CiA-402 (TMCM-3216 manual 6.1.2, the
//   TMCM-1690 manual for the servo family): the motor moves, the direction of its last motion.
#pragma once

#include <cstdint>

namespace motwin::cia402 {

namespace switch_parameter {
inline constexpr uint32_t kLeftDisabled = 1u << 0;  // the left switch is not used
inline constexpr uint32_t kRightDisabled = 1u << 1;
inline constexpr uint32_t kLeftInverted = 1u << 2;  // active while its level is low
inline constexpr uint32_t kRightInverted = 1u << 3;
inline constexpr uint32_t kHomeDisabled = 1u << 4;
inline constexpr uint32_t kHomeInverted = 1u << 5;
}  // namespace switch_parameter

struct Switches {
  bool left = false;
  bool right = false;
  bool home = false;
};

// `levels`: true = high. A level is active unless inverted; a switch not used reads inactive.
constexpr Switches active_switches(uint32_t parameters, const Switches& levels) {
  using namespace switch_parameter;
  const bool left = levels.left != ((parameters & kLeftInverted) != 0);
  const bool right = levels.right != ((parameters & kRightInverted) != 0);
  const bool home = levels.home != ((parameters & kHomeInverted) != 0);
  return Switches{left && (parameters & kLeftDisabled) == 0, right && (parameters & kRightDisabled) == 0,
                  home && (parameters & kHomeDisabled) == 0};
}

inline constexpr uint16_t kSwMotorActivity = 1u << 14;  // the motor moves
inline constexpr uint16_t kSwDirection = 1u << 15;      // direction of the last motion: 1 = negative

constexpr uint16_t trinamic_status_bits(bool motor_active, bool negative_direction) {
  return static_cast<uint16_t>((motor_active ? kSwMotorActivity : 0u) | (negative_direction ? kSwDirection : 0u));
}

}  // namespace motwin::cia402
