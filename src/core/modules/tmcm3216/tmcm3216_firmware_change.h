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
    params::velocity(22, 0x20B6, kManufacturerAxisStride),        // high speed threshold: fullstep threshold speed
    params::velocity(23, 0x20B3, kManufacturerAxisStride),        // min DcStep speed
    params::same(27, 0x20B7, kManufacturerAxisStride),            // high speed chopper mode
    params::same(28, 0x20B8, kManufacturerAxisStride),            // high speed fullstep mode
    params::same(31, 0x20B9, kManufacturerAxisStride),            // power down ramp
    params::same(32, 0x20B4, kManufacturerAxisStride),            // DcStep time
    params::same(33, 0x20B5, kManufacturerAxisStride),            // DcStep StallGuard
    params::same(162, 0x2092, kManufacturerAxisStride),           // chopper blank time
    params::same(163, 0x2093, kManufacturerAxisStride),           // constant TOff mode: chopper mode
    params::same(164, 0x2094, kManufacturerAxisStride),           // disable fast decay comparator
    params::same(165, 0x2095, kManufacturerAxisStride),           // chopper hysteresis end
    params::same(166, 0x2096, kManufacturerAxisStride),           // chopper hysteresis start
    params::same(167, 0x2097, kManufacturerAxisStride),           // TOff: chopper off time
    params::same(168, 0x2098, kManufacturerAxisStride),           // smartEnergy current minimum
    params::same(169, 0x2099, kManufacturerAxisStride),           // smartEnergy current down step
    params::same(170, 0x209A, kManufacturerAxisStride),           // smartEnergy hysteresis
    params::same(171, 0x209B, kManufacturerAxisStride),           // smartEnergy current up step
    params::same(172, 0x209C, kManufacturerAxisStride),           // smartEnergy hysteresis start
    params::same(173, 0x209D, kManufacturerAxisStride),           // StallGuard2 filter enable
    params::same(174, 0x209E, kManufacturerAxisStride),           // StallGuard2 threshold
    params::same(178, 0x20A2, kManufacturerAxisStride),           // global current scaler
    params::same(179, 0x20A3, kManufacturerAxisStride),           // full scale current range
    params::velocity(181, 0x20A4, kManufacturerAxisStride),       // stop on stall
    params::velocity(182, 0x20A5, kManufacturerAxisStride),       // smartEnergy threshold speed
    params::velocity(186, 0x20B0, kManufacturerAxisStride),       // PWM threshold speed
    params::same(187, 0x20B1, kManufacturerAxisStride),           // PWM gradient
    params::same(188, 0x20B2, kManufacturerAxisStride),           // PWM amplitude
    params::velocity(194, 0x6099, kProfileAxisStride, 1),         // reference search speed: homing speed fast
    params::velocity(195, 0x6099, kProfileAxisStride, 2),         // reference switch speed: homing speed slow
    params::same(202, 0x2001, kManufacturerAxisStride),           // fullstep resolution
    params::same(210, 0x608F, kProfileAxisStride, 1),             // encoder resolution: encoder increments
    params::same(214, 0x2089, kManufacturerAxisStride),           // power down delay: setting delay
    params::same(221, 0x20A8, kManufacturerAxisStride),           // StallGuard4 threshold
    params::same(222, 0x20A9, kManufacturerAxisStride),           // StallGuard4 filter enable
    params::same(223, 0x20AA, kManufacturerAxisStride),           // StallGuard4 angle offset
    // clang-format on
};

}  // namespace motwin::modules::tmcm3216
