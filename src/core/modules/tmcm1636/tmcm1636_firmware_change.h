// The settings the TMCM-1636's TMCL firmware (1.09, 1.13) and its CANopen firmware (V1.12) share
// (docs/tmcm-1636-canopen.md "Changing firmware"): the manufacturer objects that are bound to the
// same field of the axis as the TMCL axis parameter (tmcm1636_canopen_objects.cpp names the APs),
// so every row is the same number in both. One axis: no stride. A row whose AP the running TMCL
// generation lacks (AP 56 and 165..167 on 1.09) is refused by it and keeps its default.
#pragma once

#include "core/params/shared_setting.h"

namespace motwin::modules::tmcm1636 {

inline constexpr params::SharedAxisSetting kSharedAxisSettings[] = {
    // clang-format off
    params::same(11, 0x2003, 0),       // max current, mA
    params::same(12, 0x2004, 0),       // open loop current, mA
    params::same(140, 0x2006, 0, 1),   // brake chopper enable
    params::same(141, 0x2006, 0, 2),   // brake chopper voltage limit, 0.1 V
    params::same(142, 0x2006, 0, 3),   // brake chopper hysteresis, 0.1 V
    params::same(70, 0x2041, 0, 1),    // torque P
    params::same(71, 0x2041, 0, 2),    // torque I
    params::same(72, 0x2042, 0, 1),    // velocity P
    params::same(73, 0x2042, 0, 2),    // velocity I
    params::same(26, 0x2042, 0, 5),    // velocity sensor selection
    params::same(74, 0x2043, 0, 1),    // position P
    params::same(25, 0x2043, 0, 3),    // commutation mode in position mode
    params::same(14, 0x2050, 0),       // motor type
    params::same(15, 0x2055, 0),       // commutation mode
    params::same(10, 0x2056, 0),       // motor pole pairs
    params::same(13, 0x2057, 0),       // motor direction
    params::same(56, 0x2058, 0),       // position scaler
    params::same(5, 0x2060, 0, 3),     // ADC I0 offset
    params::same(6, 0x2060, 0, 4),     // ADC I1 offset
    params::same(90, 0x2070, 0, 1),    // hall polarity
    params::same(91, 0x2070, 0, 2),    // hall direction
    params::same(92, 0x2070, 0, 3),    // hall interpolation
    params::same(93, 0x2070, 0, 4),    // hall phi_e offset
    params::same(101, 0x2080, 0, 1),   // encoder direction
    params::same(100, 0x2080, 0, 2),   // encoder steps
    params::same(102, 0x2080, 0, 3),   // encoder init mode
    params::same(160, 0x2085, 0, 1),   // absolute encoder type
    params::same(162, 0x2085, 0, 2),   // absolute encoder direction
    params::same(161, 0x2085, 0, 3),   // absolute encoder init
    params::same(163, 0x2085, 0, 4),   // absolute encoder offset
    params::same(165, 0x2085, 0, 5),   // absolute encoder data length
    params::same(166, 0x2085, 0, 6),   // absolute encoder position start
    params::same(167, 0x2085, 0, 7),   // absolute encoder position length
    // clang-format on
};

}  // namespace motwin::modules::tmcm1636
