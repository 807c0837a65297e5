// The stepper driver's microstep sine table: coil current targets for an electrical angle, as a
// driver chip's table of 1024 entries per quarter sine wave gives them (1024 microsteps per full
// step at the finest resolution). The table is computed at compile time; a lookup is an index
// and two multiplications.
#pragma once

#include <array>
#include <cstddef>
#include <cstdint>

#include "board/stepper_drive.h"

namespace motwin::motion {

inline constexpr int kMicrostepTableQuarter = 1024;  // entries per quarter wave (one full step)
inline constexpr int kMicrostepTableBits = 15;       // entries are sin x 2^15, 0..32768

namespace detail {

// sin(x) for 0 <= x <= pi/2 by its Taylor series, exact to double rounding (compile time only).
constexpr double taylor_sine(double x) {
  double term = x;
  double sum = x;
  for (int n = 1; n < 15; ++n) {
    term *= -x * x / static_cast<double>((2 * n) * (2 * n + 1));
    sum += term;
  }
  return sum;
}

constexpr std::array<uint16_t, kMicrostepTableQuarter + 1> make_quarter_sine() {
  std::array<uint16_t, kMicrostepTableQuarter + 1> table{};
  constexpr double kHalfPi = 1.5707963267948966;
  for (int i = 0; i <= kMicrostepTableQuarter; ++i) {
    const double value = taylor_sine(kHalfPi * i / kMicrostepTableQuarter) * (1 << kMicrostepTableBits);
    table[static_cast<size_t>(i)] = static_cast<uint16_t>(value + 0.5);
  }
  return table;
}

}  // namespace detail

// sin of (i / 1024) x 90°, scaled by 2^15, i = 0..1024. Defined once (microstep_table.cpp): as an
// inline variable every file that reads it kept a 2 KiB copy in the core's archive.
extern const std::array<uint16_t, kMicrostepTableQuarter + 1> kQuarterSine;

// Coil current targets (mA, signed) for an electrical angle (2^32 per electrical revolution,
// board/stepper_drive.h) at amplitude current_ma: coil A the cosine, coil B the sine.
struct CoilCurrents {
  int32_t coil_a_ma;
  int32_t coil_b_ma;
};

inline CoilCurrents coil_currents(uint32_t electrical_angle, int32_t current_ma) {
  // 4096 table steps per electrical revolution: the angle's top 12 bits.
  const uint32_t index = electrical_angle >> 20;
  const uint32_t quadrant = index >> 10;
  const uint32_t within = index & (kMicrostepTableQuarter - 1);
  const int64_t rising = kQuarterSine[within];
  const int64_t falling = kQuarterSine[kMicrostepTableQuarter - within];
  int64_t sine = 0;
  int64_t cosine = 0;
  switch (quadrant) {
    case 0: sine = rising; cosine = falling; break;
    case 1: sine = falling; cosine = -rising; break;
    case 2: sine = -rising; cosine = -falling; break;
    default: sine = -falling; cosine = rising; break;
  }
  // Rounded to the nearest mA, symmetric about zero.
  constexpr int64_t kHalf = int64_t{1} << (kMicrostepTableBits - 1);
  auto scale = [current_ma](int64_t entry) {
    const int64_t product = entry * current_ma;
    return static_cast<int32_t>(product >= 0 ? (product + kHalf) >> kMicrostepTableBits
                                             : -((-product + kHalf) >> kMicrostepTableBits));
  };
  return CoilCurrents{scale(cosine), scale(sine)};
}

// Electrical angle of a microstep position at a resolution of microsteps_per_full_step (1..1024,
// a power of 2): one full step is a quarter of the electrical revolution.
inline uint32_t electrical_angle_of(int64_t microstep_position, uint32_t microsteps_per_full_step) {
  const uint64_t per_microstep = board::kElectricalAnglePerFullStep / microsteps_per_full_step;
  return static_cast<uint32_t>(static_cast<uint64_t>(microstep_position) * per_microstep);
}

}  // namespace motwin::motion
