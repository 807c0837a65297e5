// Fixed facts of the TMCM-142 as its firmware sees them: the control tick, the TMC457's clock
// and the conversions between its internal units and microsteps per second (AP 255), the
// current scale of AP 6/7 and the microstep resolution codes of AP 27. All Motwin decisions
// where the public sources are silent (docs/tmcm-142.md "Units").
#pragma once

#include <cmath>
#include <cstdint>

namespace motwin::modules::tmcm142 {

// One control tick: ramp, encoder, easyPID and driver outputs every 50 µs (as the TMCM-1636).
inline constexpr uint32_t kControlTickUs = 50;
inline constexpr uint32_t kTicksPerMillisecond = 1000 / kControlTickUs;
inline constexpr double kControlTickS = kControlTickUs * 1e-6;

// TMC457 clock. Velocity v [µsteps/s] = v_reg * fCLK / 2^32, so 2^31 internal units are 32e6
// µsteps/s (the manual's range 0..31999999 in unit mode 1).
inline constexpr double kClockHz = 64e6;
inline constexpr double kPpsPerVelocityUnit = kClockHz / 4294967296.0;                       // 0.0149 µsteps/s
// Acceleration a [µsteps/s²] = a_reg * fCLK² / 2^48 (14.55 µsteps/s² per unit).
inline constexpr double kPps2PerAccelerationUnit = kClockHz * kClockHz / 281474976710656.0;
// Bow (jerk) b [µsteps/s³] = b_reg * fCLK³ / 2^64 (14211 µsteps/s³ per unit). Always in these
// units: unit mode 1 converts velocities and accelerations only.
inline constexpr double kPps3PerBowUnit = kClockHz * kClockHz * kClockHz / 18446744073709551616.0;
// The easyPID integrates at fCLK / 128 on the chip: this many of its samples per control tick.
inline constexpr double kPidSamplesPerTick = kControlTickS * kClockHz / 128.0;  // 25
// And samples the D part every pid_d_clkdiv * 128 clocks (0 = 256).
inline constexpr double kPidDClockS = 128.0 / kClockHz;  // 2 µs per divider step

inline constexpr int64_t kMaxVelocityInternal = 2147483647;
inline constexpr int64_t kMaxVelocityPps = 31999999;
inline constexpr int64_t kMaxAccelerationInternal = 16777215;
// The same limit in µsteps/s² (unit mode 1): 16777215 internal units.
inline constexpr int64_t kMaxAccelerationPps2 = 244140610;  // floor(16777215 * 14.5519...)
inline constexpr int64_t kMaxBow = 16777215;  // the maximum bow: unlimited jerk (trapezoid corner)

// AP 6/7: 16 steps of the module's 7 A peak coil current; code c gives (c + 1) * 7000 / 16 mA.
inline constexpr int32_t kPeakCurrentMa = 7000;
constexpr int32_t current_ma_of_code(int32_t code) { return (code + 1) * kPeakCurrentMa / 16; }

// AP 27: code c selects 2^(11 - c) microsteps per full step. Code 0 (2048) is refused: the
// driver's sine table has 1024 entries per full step (the manual's "up to 1024").
inline constexpr int32_t kFinestResolutionCode = 1;
inline constexpr int32_t kCoarsestResolutionCode = 11;
constexpr uint32_t microsteps_of_code(int32_t code) { return uint32_t{1} << (11 - code); }

inline double round_half_away(double v) { return std::round(v); }

}  // namespace motwin::modules::tmcm142
