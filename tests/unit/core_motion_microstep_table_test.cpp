// The driver's microstep sine table and the microstep-to-electrical-angle conversion.
#include <gtest/gtest.h>

#include <cmath>
#include <cstdint>

#include "core/motion/microstep_table.h"

namespace motwin::motion {
namespace {

TEST(MicrostepTable, quarter_table_entries) {
  EXPECT_EQ(kQuarterSine[0], 0);
  EXPECT_EQ(kQuarterSine[1024], 32768);
  EXPECT_EQ(kQuarterSine[512], 23170);  // sin 45° x 2^15 = 23170.475
  EXPECT_EQ(kQuarterSine[1], 50);       // sin(90° / 1024) x 2^15 = 50.27
  // Rising (flat only where neighbouring sines round to the same 15-bit value, near the top).
  EXPECT_GT(kQuarterSine[1000], kQuarterSine[999]);
  for (size_t i = 1; i < kQuarterSine.size(); ++i) EXPECT_GE(kQuarterSine[i], kQuarterSine[i - 1]) << i;
}

TEST(MicrostepTable, coil_currents_at_the_full_steps) {
  EXPECT_EQ(coil_currents(0, 1000).coil_a_ma, 1000);
  EXPECT_EQ(coil_currents(0, 1000).coil_b_ma, 0);
  EXPECT_EQ(coil_currents(1u << 30, 1000).coil_a_ma, 0);
  EXPECT_EQ(coil_currents(1u << 30, 1000).coil_b_ma, 1000);
  EXPECT_EQ(coil_currents(2u << 30, 1000).coil_a_ma, -1000);
  EXPECT_EQ(coil_currents(2u << 30, 1000).coil_b_ma, 0);
  EXPECT_EQ(coil_currents(3u << 30, 1000).coil_a_ma, 0);
  EXPECT_EQ(coil_currents(3u << 30, 1000).coil_b_ma, -1000);
  // Half steps: 2800 mA x sin 45° = 1979.9.
  EXPECT_EQ(coil_currents(1u << 29, 2800).coil_a_ma, 1980);
  EXPECT_EQ(coil_currents(1u << 29, 2800).coil_b_ma, 1980);
  EXPECT_EQ(coil_currents(5u << 29, 2800).coil_a_ma, -1980);
  EXPECT_EQ(coil_currents(5u << 29, 2800).coil_b_ma, -1980);
}

TEST(MicrostepTable, constant_amplitude_and_sine_shape_over_a_revolution) {
  for (uint32_t index = 0; index < 4096; ++index) {
    const uint32_t angle = index << 20;
    const CoilCurrents currents = coil_currents(angle, 2000);
    const double radians = index * (2.0 * 3.14159265358979323846 / 4096.0);
    // Rounded to mA from a table entry rounded to 2^-15: within 0.5 mA + 2000 mA x 2^-16.
    EXPECT_NEAR(currents.coil_a_ma, 2000.0 * std::cos(radians), 0.531) << index;
    EXPECT_NEAR(currents.coil_b_ma, 2000.0 * std::sin(radians), 0.531) << index;
    EXPECT_NEAR(std::hypot(currents.coil_a_ma, currents.coil_b_ma), 2000.0, 1.0) << index;
  }
}

TEST(MicrostepTable, angles_between_table_entries_use_the_entry_below) {
  const CoilCurrents at_entry = coil_currents(7u << 20, 1500);
  const CoilCurrents just_before_next = coil_currents((8u << 20) - 1, 1500);
  EXPECT_EQ(at_entry.coil_a_ma, just_before_next.coil_a_ma);
  EXPECT_EQ(at_entry.coil_b_ma, just_before_next.coil_b_ma);
  EXPECT_NE(coil_currents(8u << 20, 1500).coil_b_ma, at_entry.coil_b_ma);
}

TEST(MicrostepTable, electrical_angle_of_microstep_positions) {
  EXPECT_EQ(electrical_angle_of(1, 256), 1u << 22);
  EXPECT_EQ(electrical_angle_of(256, 256), 1u << 30);        // one full step
  EXPECT_EQ(electrical_angle_of(4 * 256, 256), 0u);          // one electrical revolution
  EXPECT_EQ(electrical_angle_of(-1, 1), 3u << 30);           // a full step back
  EXPECT_EQ(electrical_angle_of(1, 1024), 1u << 20);
  EXPECT_EQ(electrical_angle_of(-3, 16), (uint32_t{0} - (3u << 26)));
  // Far positions wrap without losing the phase.
  EXPECT_EQ(electrical_angle_of(int64_t{1} << 40, 1024), 0u);
  EXPECT_EQ(electrical_angle_of((int64_t{1} << 40) + 512, 1024), 1u << 29);
  EXPECT_EQ(electrical_angle_of(INT32_MIN, 256), 0u);
}

}  // namespace
}  // namespace motwin::motion
