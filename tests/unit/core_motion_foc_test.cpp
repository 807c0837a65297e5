// FOC arithmetic, PI regulators and the hall decoder of the core (core/motion/).
#include <gtest/gtest.h>

#include <cmath>

#include "core/motion/foc.h"
#include "core/motion/hall_decoder.h"
#include "core/motion/pi_regulator.h"

namespace motwin::motion {
namespace {

TEST(Foc, clarke_and_park_of_balanced_currents_give_a_constant_dq_vector) {
  // Phase currents of amplitude 2 A at electrical angle theta, q-axis aligned (id = 0, iq = 2).
  for (uint16_t angle : {uint16_t{0}, uint16_t{5000}, uint16_t{30000}, uint16_t{61000}}) {
    const float theta = angle * kAngleToRadians;
    const float ia = -2.0f * std::sin(theta);
    const float ib = -2.0f * std::sin(theta - kTwoPi / 3.0f);
    const Dq dq = park(clarke(ia, ib), sin_cos(angle));
    EXPECT_NEAR(dq.d, 0.0f, 1e-4f) << "angle " << angle;
    EXPECT_NEAR(dq.q, 2.0f, 1e-4f) << "angle " << angle;
  }
}

TEST(Foc, inverse_park_undoes_park) {
  const SinCos angle = sin_cos(12345);
  const AlphaBeta v = inverse_park(Dq{1.5f, -0.7f}, angle);
  const Dq back = park(v, angle);
  EXPECT_NEAR(back.d, 1.5f, 1e-5f);
  EXPECT_NEAR(back.q, -0.7f, 1e-5f);
}

TEST(Foc, rotate_matches_the_library_for_small_and_large_steps) {
  const SinCos start = sin_cos(20000);
  for (float delta : {0.01f, -0.2f, 0.45f, 1.3f}) {
    const SinCos rotated = rotate(start, delta);
    const float exact = 20000 * kAngleToRadians + delta;
    EXPECT_NEAR(rotated.sin, std::sin(exact), 2e-6f) << delta;
    EXPECT_NEAR(rotated.cos, std::cos(exact), 2e-6f) << delta;
  }
}

// SVM: the line-to-line voltages the duties make on the bus equal those of the requested vector,
// up to the linear limit Vbus / sqrt(3).
TEST(Foc, svm_makes_the_requested_line_voltages) {
  const float bus = 24.0f;
  for (uint16_t angle = 0; angle < 65000; angle += 6500) {
    const AlphaBeta v = inverse_park(Dq{0.0f, svm_voltage_limit(bus) * 0.99f}, sin_cos(angle));
    const Duties d = svm(v, bus);
    const float va = v.alpha;
    const float vb = -0.5f * v.alpha + 0.5f * kSqrt3 * v.beta;
    const float vc = -0.5f * v.alpha - 0.5f * kSqrt3 * v.beta;
    EXPECT_NEAR((d.a - d.b) * bus, va - vb, 1e-3f) << "angle " << angle;
    EXPECT_NEAR((d.b - d.c) * bus, vb - vc, 1e-3f) << "angle " << angle;
    for (float duty : {d.a, d.b, d.c}) {
      EXPECT_GE(duty, 0.0f);
      EXPECT_LE(duty, 1.0f);
    }
  }
}

TEST(PiRegulator, output_is_p_times_error_over_256_plus_i_times_sum_over_65536) {
  const PiConfig config{512, 65536};
  PiState state;
  EXPECT_FLOAT_EQ(pi_apply(config, state, 10, 1e6f), 2.0f * 10 + 10.0f);
  EXPECT_EQ(state.error_sum, 10);
  EXPECT_FLOAT_EQ(pi_apply(config, state, 5, 1e6f), 2.0f * 5 + 15.0f);
  EXPECT_EQ(state.error_sum, 15);
  EXPECT_EQ(state.error, 5);
}

TEST(PiRegulator, a_scale_sets_what_one_unit_of_p_and_of_i_is_worth) {
  const PiConfig config{1024, 262144};
  const PiScale scale{1.0f / 1024.0f, 1.0f / 262144.0f};
  PiState state;
  EXPECT_FLOAT_EQ(pi_apply(config, scale, state, 10, 1e6f), 10.0f + 10.0f);
  EXPECT_FLOAT_EQ(pi_apply(config, scale, state, 5, 1e6f), 5.0f + 15.0f);
  // The bound on the integral term follows the scale: I * sum * scale stays within the limit.
  for (int i = 0; i < 1000; ++i) pi_apply(config, scale, state, 10, 100.0f);
  EXPECT_LE(static_cast<double>(config.i) * scale.integral * state.error_sum, 100.0 + 1e-3);
  EXPECT_GT(static_cast<double>(config.i) * scale.integral * state.error_sum, 50.0);
}

TEST(PiRegulator, does_not_wind_up_while_limited) {
  const PiConfig config{256, 6554};
  PiState state;
  for (int i = 0; i < 10000; ++i) pi_apply(config, state, 1000, 100.0f);
  EXPECT_FLOAT_EQ(state.output, 100.0f);
  EXPECT_TRUE(state.limited);
  // The integral alone stays within the limit: one tick of opposite error leaves the limit.
  EXPECT_LE(static_cast<double>(config.i) * state.error_sum / 65536.0, 100.0 + 1e-3);
  const float after = pi_apply(config, state, -50, 100.0f);
  EXPECT_LT(after, 100.0f) << "recovers at once";
}

TEST(PiRegulator, zero_integral_gain_holds_the_sum_at_zero) {
  PiState state;
  pi_apply(PiConfig{100, 0}, state, 1000, 1e6f);
  EXPECT_EQ(state.error_sum, 0);
}

TEST(PiRegulator, vector_limit_keeps_the_direction) {
  const PiConfig config{256, 0};
  PiState d;
  PiState q;
  pi_apply_vector(config, d, q, 300, 400, 100.0f);
  EXPECT_NEAR(d.output, 60.0f, 1e-3f);
  EXPECT_NEAR(q.output, 80.0f, 1e-3f);
  EXPECT_TRUE(q.limited);
}

// Hall levels of the standard sequence 5, 1, 3, 2, 6, 4 (sectors 0..5).
constexpr uint8_t kSequence[6] = {5, 1, 3, 2, 6, 4};

TEST(HallDecoder, sector_centres_and_steps) {
  HallDecoder decoder;
  const HallConfig config;
  for (int i = 0; i < 13; ++i) {
    decoder.update(kSequence[i % 6], config);
    EXPECT_TRUE(decoder.valid());
    EXPECT_EQ(decoder.angle(), static_cast<uint16_t>((2 * (i % 6) + 1) * 65536 / 12)) << "sector " << i % 6;
  }
  EXPECT_EQ(decoder.steps(), 12);
  decoder.update(kSequence[5], config);
  EXPECT_EQ(decoder.steps(), 11) << "one sector back";
  EXPECT_TRUE(decoder.edge());
  EXPECT_EQ(decoder.edge_angle(), 0) << "the edge between sector 0 and 5";
}

TEST(HallDecoder, polarity_direction_and_offset) {
  HallDecoder decoder;
  const HallConfig config{true, true, false, 1000};
  decoder.update(static_cast<uint8_t>(~kSequence[1] & 7), config);
  EXPECT_EQ(decoder.angle(), static_cast<uint16_t>(65536 - 3 * 65536 / 12 + 1000));
  decoder.update(0, HallConfig{});
  EXPECT_FALSE(decoder.valid()) << "000 is not a hall state";
}

TEST(HallDecoder, interpolation_extrapolates_from_the_last_edge) {
  HallDecoder decoder;
  const HallConfig config{false, false, true, 0};
  // 100 ticks per sector, forward.
  for (int sector = 0; sector < 3; ++sector) {
    for (int tick = 0; tick < 100; ++tick) decoder.update(kSequence[sector], config);
  }
  decoder.update(kSequence[3], config);  // edge into sector 3 at 180°
  EXPECT_EQ(decoder.angle(), 32768);
  for (int tick = 0; tick < 50; ++tick) decoder.update(kSequence[3], config);
  EXPECT_NEAR(decoder.angle(), 32768 + 65536 / 12, 2) << "half a sector later";
}

}  // namespace
}  // namespace motwin::motion
