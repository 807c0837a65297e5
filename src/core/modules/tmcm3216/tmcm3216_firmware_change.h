// The settings the TMCM-3216's two firmwares share (docs/tmcm-3216-tmcl.md "Changing firmware"):
// each TMCL axis parameter whose description names a CANopen object of the same meaning, with
// that object (axis n at + n x 0x200 in the manufacturer area, + n x 0x800 in the profile area).
// A firmware change on one state directory carries these over, in both directions; everything
// else starts at the new firmware's default. The TMCL firmware was built with the CANopen objects'
// units, so the rows are 1:1 unless the CANopen axis is set to the chip's units (208C = 0): then
// the velocity and acceleration rows convert. Adding a shared setting is one row.
#pragma once

#include <cstdint>

#include "core/cia402/trinamic_conventions.h"
#include "core/modules/tmcm3216/tmcm3216_manufacturer_objects.h"
#include "core/params/shared_setting.h"

namespace motwin::modules::tmcm3216 {

inline constexpr params::SharedAxisSetting kSharedAxisSettings[] = {
    // clang-format off
    params::velocity(4, 0x6081, kProfileAxisStride),              // max velocity: profile velocity
    params::acceleration(5, 0x6083, kProfileAxisStride),          // max acceleration: profile acceleration
    params::acceleration(17, 0x6084, kProfileAxisStride),         // max deceleration: profile deceleration
    params::velocity(20, 0x6082, kProfileAxisStride),             // stop velocity: end velocity
    params::same(6, 0x2003, kManufacturerAxisStride),             // max current
    params::same(7, 0x2004, kManufacturerAxisStride),             // standby current
    params::same(140, 0x2000, kManufacturerAxisStride),           // microstep resolution
    params::velocity(19, 0x2010, kManufacturerAxisStride),        // start velocity: VSTART
    params::acceleration(15, 0x2011, kManufacturerAxisStride),    // A1
    params::velocity(16, 0x2012, kManufacturerAxisStride),        // V1
    params::acceleration(18, 0x2013, kManufacturerAxisStride),    // D1
    params::same(21, 0x2015, kManufacturerAxisStride),            // ramp wait time (32 µs)
    params::acceleration(34, 0x2016, kManufacturerAxisStride),    // A2
    params::velocity(35, 0x2017, kManufacturerAxisStride),        // V2
    params::acceleration(36, 0x2018, kManufacturerAxisStride),    // D2
    params::bit(12, 0x2005, kManufacturerAxisStride, cia402::switch_parameter::kRightDisabled),
    params::bit(13, 0x2005, kManufacturerAxisStride, cia402::switch_parameter::kLeftDisabled),
    params::bit(24, 0x2005, kManufacturerAxisStride, cia402::switch_parameter::kRightInverted),
    params::bit(25, 0x2005, kManufacturerAxisStride, cia402::switch_parameter::kLeftInverted),
    // clang-format on
};

}  // namespace motwin::modules::tmcm3216
