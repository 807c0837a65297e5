// The TMCM-1636 CANopen firmware's part of its CiA-402 drive (cia402::AxisDrive's template
// parameter, see "The module's part" in core/cia402/axis_drive.h): a servo (the regulators of
// Tmcm1636Axis follow the demand, the measured motion is the actual one), velocities in rpm and
// accelerations in rpm/s of the shaft, positions in 2058 units (position scaler: units per
// revolution), the profile generator in its plain trapezoid form (6081, 6083, 6084; 6084 = 0
// brakes with 6083), modes pp, pv, hm, csp, csv and cst, homing methods 17, 18, 19, 21 and 35
// (PyTrinamic's homing example lists them), statusword bits 14 and 15 and the EMCY codes of the
// Trinamic servo firmware family (docs/tmcm-1636-canopen.md).
#pragma once

#include <cstdint>

#include "core/cia402/axis_drive.h"
#include "core/cia402/trinamic_conventions.h"
#include "core/motion/eight_point_ramp.h"

namespace motwin::modules::tmcm1636 {

// EMCY codes of the drive's events (docs/tmcm-1636-canopen.md "Emergencies").
inline constexpr uint16_t kCanopenEmcyFaultReset = 0x0000;
inline constexpr uint16_t kCanopenEmcyFollowingError = 0x8611;
inline constexpr uint16_t kCanopenEmcyLimit = 0xFF01;  // additional byte 1: 1/2 software limit, 3/4 switch
inline constexpr uint16_t kCanopenEmcyGeneric = 0x1000;
// The power stage's protections (the axis' status flags): the family's undervoltage and
// overtemperature codes, CiA-402's DC link overvoltage (docs/tmcm-1636-canopen.md "Emergencies").
inline constexpr uint16_t kCanopenEmcyUndervoltage = 0xFF00;
inline constexpr uint16_t kCanopenEmcyOvervoltage = 0x3210;
inline constexpr uint16_t kCanopenEmcyOvertemperature = 0x4310;

struct Tmcm1636DriveObjects {
  // 2058 (the module sets it with the axis' setting): the drive's velocities are in 2058 units per
  // second, so 606C, 60FF, 6081, 6099 are rpm and 6083, 6084, 6085, 609A rpm/s.
  void set_position_scaler(int32_t units_per_revolution) {
    const double units_per_rpm = static_cast<double>(units_per_revolution) / 60.0;
    scale = cia402::UnitScale{units_per_rpm, units_per_rpm};
  }
  // Derived once per 2058 write, not per use: the drive asks for it several times a tick.
  cia402::UnitScale scale{65536.0 / 60.0, 65536.0 / 60.0};

  cia402::UnitScale units() const { return scale; }
  // The profile objects' trapezoid as it is, but a 6084 of 0 (the EDS's default, which
  // PyTrinamic's pp example leaves) brakes with 6083: the example's move ends on its target.
  void shape_profile(motion::EightPointConfig& profile, const cia402::UnitScale&) const {
    if (profile.dmax_pps2 == 0.0) profile.dmax_pps2 = profile.d1_pps2 = profile.d2_pps2 = profile.amax_pps2;
  }

  static constexpr cia402::AxisEmergency emergency(cia402::DriveEvent event) {
    using cia402::DriveEvent;
    switch (event) {
      case DriveEvent::kFaultReset: return {kCanopenEmcyFaultReset, 0};
      case DriveEvent::kFollowingError: return {kCanopenEmcyFollowingError, 0};
      case DriveEvent::kStall: return {kCanopenEmcyGeneric, 0};  // a servo has no stall input
      case DriveEvent::kSoftwareLimitPositive: return {kCanopenEmcyLimit, 1};
      case DriveEvent::kSoftwareLimitNegative: return {kCanopenEmcyLimit, 2};
      case DriveEvent::kLimitSwitchPositive: return {kCanopenEmcyLimit, 3};
      case DriveEvent::kLimitSwitchNegative: return {kCanopenEmcyLimit, 4};
    }
    return {};
  }
  // Bits 14 and 15 as every Trinamic drive's.
  static constexpr uint16_t manufacturer_status_bits(bool motor_active, bool negative_direction) {
    return cia402::trinamic_status_bits(motor_active, negative_direction);
  }

  // 6502 = 0x3A5.
  static constexpr uint32_t kSupportedModes =
      cia402::drive_mode_bit(cia402::Mode::kProfilePosition) | cia402::drive_mode_bit(cia402::Mode::kProfileVelocity) |
      cia402::drive_mode_bit(cia402::Mode::kHoming) | cia402::drive_mode_bit(cia402::Mode::kCyclicSyncPosition) |
      cia402::drive_mode_bit(cia402::Mode::kCyclicSyncVelocity) | cia402::drive_mode_bit(cia402::Mode::kCyclicSyncTorque);
  static constexpr bool supports_homing_method(int8_t method) {
    return method == 0 || method == 17 || method == 18 || method == 19 || method == 21 || method == 35;
  }
  static constexpr bool kServo = true;
};

// The axis' drive.
using Tmcm1636Drive = cia402::AxisDrive<Tmcm1636DriveObjects>;

}  // namespace motwin::modules::tmcm1636

