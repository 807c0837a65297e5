// The TMCM-3216's part of its CiA-402 drives (cia402::AxisDrive's template parameter, see
// "The module's part" in core/cia402/axis_drive.h): the manufacturer objects of an axis that shape
// the drive (the EightPoint ramp objects 2010..2018 and the velocity dimension 208C, manual
// 4.2.10-4.2.20), the EMCY codes of manual table 365 for the drive's events, and the statusword
// bits 14 and 15 (motor activity, direction; manual 6.1.2). The rows that bind the objects are in
// tmcm3216_profile_objects.h (add_ramp_rows).
#pragma once

#include <cstdint>

#include "board/stepper_drive.h"
#include "core/cia402/axis_drive.h"
#include "core/cia402/trinamic_conventions.h"
#include "core/modules/tmcm3216/tmcm3216_emergencies.h"
#include "core/modules/tmcm3216/tmcm3216_stepper.h"
#include "core/motion/eight_point_ramp.h"

namespace motwin::modules::tmcm3216 {

// 208C values.
inline constexpr uint8_t kVelocityDimensionInternal = 0;
inline constexpr uint8_t kVelocityDimensionPps = 181;
// 208E values (read-only, follow 208C).
inline constexpr uint8_t kAccelerationDimensionInternal = 0;
inline constexpr uint8_t kAccelerationDimensionPps2 = 179;

// Statusword bits 14 and 15, manufacturer-specific in CiA-402 (manual 6.1.2).
using cia402::kSwDirection;
using cia402::kSwMotorActivity;

// The 2102 flags with which the driver cannot run the motor (table 365: the driver is switched
// off): the drive's power-stage fault (cia402::AxisInputs::power_stage_fault).
inline constexpr uint8_t kDriverFaultFlags = board::kDriverOvercurrentA | board::kDriverOvercurrentB |
                                             board::kDriverOvercurrentHighSide | board::kDriverOvertemperature |
                                             board::kDriverUndervoltage;

struct Tmcm3216DriveObjects {
  // In 208C units (velocities) and 208E units (accelerations), as written.
  uint32_t start_velocity = 0;  // 2010 VSTART
  uint32_t a1 = 0;              // 2011
  uint32_t v1 = 0;              // 2012
  uint32_t d1 = 0;              // 2013
  uint16_t ramp_wait_time = 0;  // 2015, 32 µs units
  uint32_t a2 = 0;              // 2016
  uint32_t v2 = 0;              // 2017
  uint32_t d2 = 0;              // 2018
  uint8_t velocity_dimension = kVelocityDimensionPps;  // 208C

  // 208C = 181: pps and pps/s; 0: the driver chip's register units (TMC: v = v_reg x fCLK / 2^24,
  // a = a_reg x fCLK² / 2^41).
  cia402::UnitScale units() const {
    if (velocity_dimension != kVelocityDimensionInternal) return cia402::UnitScale{};
    return cia402::UnitScale{kDriverClockHz / 16777216.0, kDriverClockHz * kDriverClockHz / 2199023255552.0};
  }

  // The EightPoint segments on top of the profile objects' trapezoid (manual 1.5).
  void shape_profile(motion::EightPointConfig& profile, const cia402::UnitScale& u) const {
    profile.vstart_pps = u.velocity_pps(start_velocity);
    profile.a1_pps2 = u.acceleration_pps2(a1);
    profile.v1_pps = u.velocity_pps(v1);
    profile.a2_pps2 = u.acceleration_pps2(a2);
    profile.v2_pps = u.velocity_pps(v2);
    profile.d2_pps2 = u.acceleration_pps2(d2);
    profile.d1_pps2 = u.acceleration_pps2(d1);
    profile.tzerowait_us = static_cast<uint32_t>(ramp_wait_time) * 32u;
    // The manual's defaults have D1 = D2 = 0 with V1 = V2 = 0: a plain trapezoid. The segments
    // that are not in use brake with DMAX (docs/tmcm-3216-drive.md, "Decisions").
    if (profile.v1_pps == 0.0 && profile.d1_pps2 == 0.0) profile.d1_pps2 = profile.dmax_pps2;
    if (profile.v2_pps == 0.0 && profile.d2_pps2 == 0.0) profile.d2_pps2 = profile.dmax_pps2;
  }

  // Table 365's code and additional byte 1 for each drive event.
  static constexpr cia402::AxisEmergency emergency(cia402::DriveEvent event) {
    using cia402::DriveEvent;
    switch (event) {
      case DriveEvent::kFaultReset: return {kEmcyFaultReset, 0};
      case DriveEvent::kFollowingError: return {kEmcyFollowingError, 0};
      case DriveEvent::kStall: return {kEmcyStallGuard, 0};
      case DriveEvent::kSoftwareLimitPositive: return {kEmcyLimit, 1};
      case DriveEvent::kSoftwareLimitNegative: return {kEmcyLimit, 2};
      case DriveEvent::kLimitSwitchPositive: return {kEmcyLimit, 3};
      case DriveEvent::kLimitSwitchNegative: return {kEmcyLimit, 4};
    }
    return {};
  }

  // pp, pv, hm, csp, csv (6502); every homing method of cia402::Homing (manual table 296).
  static constexpr uint32_t kSupportedModes = cia402::kSupportedDriveModes;
  static constexpr bool supports_homing_method(int8_t) { return true; }
  // A stepper: the ramp is the motion.
  static constexpr bool kServo = false;

  static constexpr uint16_t manufacturer_status_bits(bool motor_active, bool negative_direction) {
    return cia402::trinamic_status_bits(motor_active, negative_direction);
  }
};

// One axis of the module: the generic drive with the module's part.
using Tmcm3216Drive = cia402::AxisDrive<Tmcm3216DriveObjects>;

}  // namespace motwin::modules::tmcm3216

