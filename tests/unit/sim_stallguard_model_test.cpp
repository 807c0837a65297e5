// What the simulated driver's StallGuard2/4 measurement shows for the stepper plant, and the
// CoolStep and stop-on-stall logic closed around it.
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <cstdint>

#include "board/stepper_drive.h"
#include "core/motion/coolstep.h"
#include "core/motion/microstep_table.h"
#include "core/motion/stall_detector.h"
#include "core/motion/trapezoid_ramp.h"
#include "sim/stallguard_model.h"
#include "sim/stepper_plant.h"

namespace motwin::sim {
namespace {

constexpr double kDt = 50e-6;
constexpr uint32_t kMicrosteps = 256;
constexpr double kMicrostepsPerRev = 200.0 * kMicrosteps;
constexpr double kFullStepsPerRev = 200.0;
constexpr double kPi = 3.14159265358979323846;

// One axis as the TMCM-3216 runs it: a ramp feeds the driver's sequencer at a current scaled by
// CoolStep; the plant moves; the model measures; the detector watches.
struct Axis {
  explicit Axis(int32_t current_ma) : plant(StepperMotorDescription::nema17()), run_current_ma(current_ma) {
    drive.enabled = true;
    ramp_config.max_velocity = 2.0 * kMicrostepsPerRev;
    ramp_config.acceleration = 4.0 * kMicrostepsPerRev;
    apply(run_current_ma);
  }
  void apply(int32_t current_ma) {
    drive.electrical_angle = motion::electrical_angle_of(ramp.position(), kMicrosteps);
    const motion::CoilCurrents currents = motion::coil_currents(drive.electrical_angle, current_ma);
    drive.coil_a_ma = currents.coil_a_ma;
    drive.coil_b_ma = currents.coil_b_ma;
  }
  void tick() {
    // The firmware's tick: reads the last results, regulates, commands.
    const bool fresh = model.measurements() != seen_measurements;
    seen_measurements = model.measurements();
    const auto velocity = static_cast<int32_t>(ramp.velocity());
    int32_t current_ma = run_current_ma;
    if (use_coolstep) {
      coolstep.step(coolstep_config, {velocity, model.stallguard2_result(), fresh, settings.stealth_chop});
      current_ma = coolstep.scaled_current_ma(coolstep_config, run_current_ma);
    }
    if (detector.step(detector_config, {velocity, model.stallguard2_result(), model.stallguard4_result(), fresh,
                                        settings.stealth_chop})) {
      ramp.halt();
    }
    ramp.step(ramp_config, kDt);
    apply(current_ma);
    plant.advance(drive, 24.0, kDt);
    model.update(plant, drive, settings, kDt);
    ++ticks;
  }
  void run(double seconds) {
    const auto n = static_cast<int64_t>(seconds / kDt + 0.5);
    for (int64_t i = 0; i < n; ++i) tick();
  }
  void run_at(double rps) {
    ramp.set_velocity_target(rps * kMicrostepsPerRev);
  }
  // The mean of the SG2 results over `seconds` (one sample per new measurement).
  double mean_sg2(double seconds, int* samples = nullptr) {
    const auto n = static_cast<int64_t>(seconds / kDt + 0.5);
    double sum = 0.0;
    int count = 0;
    uint32_t last = model.measurements();
    for (int64_t i = 0; i < n; ++i) {
      tick();
      if (model.measurements() != last) {
        last = model.measurements();
        sum += model.stallguard2_result();
        ++count;
      }
    }
    if (samples != nullptr) *samples = count;
    return count > 0 ? sum / count : -1.0;
  }

  StepperPlant plant;
  StallGuardModel model;
  StallGuardSettings settings;
  motion::TrapezoidRamp ramp;
  motion::TrapezoidRampConfig ramp_config;
  board::StepperDrive drive;
  int32_t run_current_ma;
  bool use_coolstep = false;
  motion::CoolStep coolstep;
  motion::CoolStepConfig coolstep_config;
  motion::StallDetector detector;
  motion::StallDetectorConfig detector_config;
  uint32_t seen_measurements = 0;
  int64_t ticks = 0;
};

// The reading the model's formula gives for a steady load at the motor (N m) and current (A).
double expected_sg2(double load_nm, double current_a, double velocity_rps) {
  const StepperMotorDescription motor = StepperMotorDescription::nema17();
  const double omega = 2.0 * 3.14159265358979323846 * velocity_rps;
  const double torque = load_nm + motor.friction_torque_nm + motor.viscous_friction_nm_s * omega;
  return 1023.0 * (1.0 - torque / (motor.torque_constant_nm_per_a * current_a));
}

// A sequencer moving at a fixed number of ticks per full step with a set load angle: exact
// inputs for the formula.
struct Sequencer {
  board::StepperDrive drive;
  StallGuardModel model;
  StallGuardSettings settings;
  int ticks_per_full_step = 16;  // 1250 full steps/s at 50 µs (a power of 2: exact steps)
  int direction = 1;
  double field_rad = 0.0;  // continuous
  Sequencer() {
    drive.enabled = true;
    drive.coil_a_ma = 1000;
    update(0.0);  // establishes the start
  }
  // The rotor sits load_angle_rad behind the field.
  void update(double load_angle_rad, bool current = true) {
    model.update_with_angles(drive, load_angle_rad, field_rad - load_angle_rad, current, settings, kDt);
  }
  void tick(double load_angle_rad, bool current = true) {
    const uint32_t per_tick = board::kElectricalAnglePerFullStep / static_cast<uint32_t>(ticks_per_full_step);
    drive.electrical_angle += direction > 0 ? per_tick : 0u - per_tick;
    field_rad += direction * (kPi / 2.0) / ticks_per_full_step;
    update(load_angle_rad, current);
  }
  // Runs whole full steps at a load angle (rad); returns the number of new results.
  uint32_t full_steps(int count, double load_angle_rad) {
    const uint32_t before = model.measurements();
    for (int i = 0; i < count * ticks_per_full_step; ++i) tick(load_angle_rad);
    return model.measurements() - before;
  }
};

const double kFifthLoad = std::asin(0.2);  // the load angle that uses 20 % of the available torque

TEST(StallGuardModel, reading_is_the_torque_reserve_of_each_full_step) {
  Sequencer seq;
  EXPECT_EQ(seq.full_steps(1, kFifthLoad), 1u);
  EXPECT_EQ(seq.model.stallguard2_result(), 818);  // round(1023 x 0.8)
  EXPECT_NEAR(seq.model.last_full_steps_per_s(), 1250.0, 1e-6);
  EXPECT_NEAR(seq.model.last_load_fraction(), 0.2, 1e-9);
  // No load: full scale; 90 % load: 102.
  seq.full_steps(1, 0.0);
  EXPECT_EQ(seq.model.stallguard2_result(), 1023);
  seq.full_steps(1, std::asin(0.9));
  EXPECT_EQ(seq.model.stallguard2_result(), 102);
  // Moving backwards, the load angle's sign turns: negative is load; positive is a load that
  // pulls along (no reserve used) and reads full scale. The reversal on a full step measures
  // after a full step back, not at once.
  seq.full_steps(1, 0.0);
  seq.direction = -1;
  EXPECT_EQ(seq.full_steps(1, -kFifthLoad), 1u);
  EXPECT_EQ(seq.model.stallguard2_result(), 818);
  seq.full_steps(1, kFifthLoad);
  EXPECT_EQ(seq.model.stallguard2_result(), 1023);
  // Past 90° the rotor slips: 0, whatever the mean.
  seq.direction = 1;
  seq.full_steps(1, kPi / 2.0);
  EXPECT_EQ(seq.model.stallguard2_result(), 0);
  seq.full_steps(1, 0.75 * kPi);
  EXPECT_EQ(seq.model.stallguard2_result(), 0);
  // StallGuard4 was not measured in SpreadCycle.
  EXPECT_EQ(seq.model.stallguard4_result(), 0);
}

TEST(StallGuardModel, a_rotor_that_does_not_turn_with_the_field_reads_zero) {
  Sequencer seq;
  seq.full_steps(4, 0.0);
  ASSERT_EQ(seq.model.stallguard2_result(), 1023);
  // The rotor stands while the field turns a whole electrical revolution: in the last quarter the
  // angle is small again (the field comes round behind it) but the rotor has not turned.
  const double rotor = seq.field_rad;
  const uint32_t per_tick = board::kElectricalAnglePerFullStep / 16;
  for (int step = 0; step < 4; ++step) {
    for (int i = 0; i < 16; ++i) {
      seq.drive.electrical_angle += per_tick;
      seq.field_rad += kPi / 32.0;
      seq.model.update_with_angles(seq.drive, seq.field_rad - rotor, rotor, true, seq.settings, kDt);
    }
    // 0..90°: the mean of sin is 2/π (0.667 sampled at the tick ends): 340; then past 90°;
    // then the rotor has turned less than half as far as the field over four steps.
    EXPECT_EQ(seq.model.stallguard2_result(), step == 0 ? 340 : 0) << step;
  }
  // Turning again with the field, a revolution behind: once the four-step ratio is back above 1/2.
  seq.full_steps(1, 2.0 * kPi);
  EXPECT_EQ(seq.model.stallguard2_result(), 0);
  seq.full_steps(2, 2.0 * kPi);
  EXPECT_EQ(seq.model.stallguard2_result(), 1023);
}

TEST(StallGuardModel, threshold_sgt_offsets_the_reading_by_16_per_step) {
  Sequencer seq;
  seq.settings.stallguard2_threshold = 4;
  seq.full_steps(1, kFifthLoad);
  EXPECT_EQ(seq.model.stallguard2_result(), 818 + 64);
  seq.settings.stallguard2_threshold = -10;
  seq.full_steps(1, kFifthLoad);
  EXPECT_EQ(seq.model.stallguard2_result(), 818 - 160);
  // Very sensitive: 20 % load already reads 0; insensitive: even a slipping rotor reads 1008.
  seq.settings.stallguard2_threshold = -63;
  seq.full_steps(1, kFifthLoad);
  EXPECT_EQ(seq.model.stallguard2_result(), 0);
  seq.settings.stallguard2_threshold = 63;
  seq.full_steps(1, kPi);
  EXPECT_EQ(seq.model.stallguard2_result(), 1008);
  seq.full_steps(1, 0.0);
  EXPECT_EQ(seq.model.stallguard2_result(), 1023);  // clamped
}

TEST(StallGuardModel, filter_209D_gives_one_mean_per_four_full_steps) {
  Sequencer seq;
  seq.settings.stallguard2_filter = true;
  EXPECT_EQ(seq.full_steps(3, 0.0), 0u);
  EXPECT_EQ(seq.model.stallguard2_result(), 0);
  EXPECT_EQ(seq.full_steps(1, kPi / 2.0), 1u);  // 1023, 1023, 1023, 0
  EXPECT_EQ(seq.model.stallguard2_result(), 767);  // (3069 + 2) / 4
  EXPECT_EQ(seq.full_steps(8, kFifthLoad), 2u);
  EXPECT_EQ(seq.model.stallguard2_result(), 818);
  seq.settings.stallguard2_filter = false;
  EXPECT_EQ(seq.full_steps(8, 0.0), 8u);
}

TEST(StallGuardModel, low_speed_fades_the_reading_towards_zero) {
  Sequencer seq;
  seq.ticks_per_full_step = 512;  // 39.06 full steps/s: 0.78 of the fade speed 50
  seq.full_steps(1, 0.0);
  EXPECT_NEAR(seq.model.last_full_steps_per_s(), 39.0625, 1e-9);
  EXPECT_EQ(seq.model.stallguard2_result(), 799);  // round(1023 x 0.78125)
  seq.ticks_per_full_step = 2048;  // 9.77 full steps/s
  seq.full_steps(1, 0.0);
  EXPECT_EQ(seq.model.stallguard2_result(), 200);
  seq.ticks_per_full_step = 256;  // 78 full steps/s: full reading
  seq.full_steps(1, 0.0);
  EXPECT_EQ(seq.model.stallguard2_result(), 1023);
}

TEST(StallGuardModel, standstill_holds_the_value_and_a_disabled_driver_reads_zero) {
  Sequencer seq;
  seq.full_steps(2, kFifthLoad);
  const uint32_t count = seq.model.measurements();
  ASSERT_EQ(count, 2u);
  for (int i = 0; i < 20000; ++i) seq.update(0.0);
  EXPECT_EQ(seq.model.measurements(), count);
  EXPECT_EQ(seq.model.stallguard2_result(), 818);
  // Dithering about a full-step position: no result.
  for (int i = 0; i < 10; ++i) {
    seq.direction = -1;
    seq.tick(0.0);
    seq.direction = 1;
    seq.tick(0.0);
  }
  EXPECT_EQ(seq.model.measurements(), count);
  // Moving on after the pause: the 20 ms of it that count, the 1 ms of dithering and the step's
  // 16 ticks: 1 / 21.8 ms.
  EXPECT_EQ(seq.full_steps(1, 0.0), 1u);
  EXPECT_NEAR(seq.model.last_full_steps_per_s(), 1.0 / 0.0218, 1e-6);
  EXPECT_EQ(seq.model.stallguard2_result(), 939);  // round(1023 x 45.87 / 50)
  seq.full_steps(1, kFifthLoad);
  seq.drive.enabled = false;
  seq.update(0.0);
  EXPECT_EQ(seq.model.stallguard2_result(), 0);
  EXPECT_EQ(seq.model.stallguard4_result(), 0);
  EXPECT_EQ(seq.model.measurements(), count + 2);
  // Enabled again, the first full step measures from there.
  seq.drive.enabled = true;
  seq.update(0.0);
  EXPECT_EQ(seq.full_steps(1, 0.0), 1u);
  EXPECT_EQ(seq.model.stallguard2_result(), 1023);
}

TEST(StallGuardModel, no_coil_current_reads_zero) {
  Sequencer seq;
  seq.full_steps(1, 0.0);
  EXPECT_EQ(seq.model.stallguard2_result(), 1023);
  for (int i = 0; i < 16; ++i) seq.tick(0.0, false);
  EXPECT_EQ(seq.model.stallguard2_result(), 0);
}

TEST(StallGuardModel, stealthchop_measures_stallguard4_with_its_filter) {
  Sequencer seq;
  seq.full_steps(1, kFifthLoad);
  ASSERT_EQ(seq.model.stallguard2_result(), 818);
  seq.settings.stealth_chop = true;
  EXPECT_EQ(seq.full_steps(1, 0.0), 1u);
  EXPECT_EQ(seq.model.stallguard4_result(), 510);
  EXPECT_EQ(seq.model.stallguard2_result(), 818);  // holds
  seq.full_steps(1, kFifthLoad);
  EXPECT_EQ(seq.model.stallguard4_result(), 408);  // round(510 x 0.8)
  seq.settings.stealth_chop = false;
  seq.full_steps(1, 0.0);
  seq.settings.stealth_chop = true;
  // 20A9: the mean of the last four results, from each result on.
  seq.settings.stallguard4_filter = true;
  EXPECT_EQ(seq.full_steps(1, 0.0), 1u);  // history restarted after SpreadCycle: 510
  EXPECT_EQ(seq.model.stallguard4_result(), 510);
  EXPECT_EQ(seq.full_steps(1, kPi / 2.0), 1u);  // 510, 0
  EXPECT_EQ(seq.model.stallguard4_result(), 255);
  seq.full_steps(1, kPi / 2.0);                  // 510, 0, 0
  EXPECT_EQ(seq.model.stallguard4_result(), 170);
  seq.full_steps(1, kFifthLoad);                 // 510, 0, 0, 408
  EXPECT_EQ(seq.model.stallguard4_result(), 230);  // (918 + 2) / 4
  seq.full_steps(1, kFifthLoad);                 // 0, 0, 408, 408
  EXPECT_EQ(seq.model.stallguard4_result(), 204);
}

TEST(StallGuardModel, ideal_motor_reads_full_scale_while_moving) {
  StallGuardModel model;
  StallGuardSettings settings;
  board::StepperDrive drive;
  drive.enabled = true;
  drive.coil_a_ma = 1000;
  int results = 0;
  for (int i = 0; i < 200; ++i) {
    const uint32_t before = model.measurements();
    model.update_ideal(drive, settings, kDt);
    results += static_cast<int>(model.measurements() - before);
    drive.electrical_angle += board::kElectricalAnglePerFullStep / 10;
  }
  EXPECT_EQ(results, 19);  // every tenth tick (the first only establishes the start)
  EXPECT_EQ(model.stallguard2_result(), 1023);
}

// --- With the physical motor -----------------------------------------------------------------

TEST(StallGuardModel, plant_reading_falls_linearly_with_the_load) {
  // NEMA17 at 1.5 A (0.405 N m), 2 rps: expected 1023 (1 - (load + friction) / K I).
  double previous = 1024.0;
  double readings[4] = {};
  const double loads[4] = {0.0, 0.1, 0.2, 0.3};
  for (int i = 0; i < 4; ++i) {
    Axis axis(1500);
    axis.plant.set_load_torque_nm(loads[i]);
    axis.run_at(2.0);
    axis.run(1.0);
    int samples = 0;
    readings[i] = axis.mean_sg2(0.5, &samples);
    EXPECT_EQ(samples, 200) << loads[i];  // 400 full steps/s
    EXPECT_NEAR(readings[i], expected_sg2(loads[i], 1.5, 2.0), 30.0) << loads[i];
    EXPECT_LT(readings[i], previous);
    previous = readings[i];
  }
  EXPECT_GT(readings[0], 950.0);  // light load: high
  // Slope: 1023 counts per K I = 2526 counts per N m, within 3 %.
  const double slope = (readings[0] - readings[3]) / 0.3;
  EXPECT_NEAR(slope, 1023.0 / 0.405, 0.03 * 1023.0 / 0.405);
}

TEST(StallGuardModel, plant_less_current_less_reserve) {
  Axis full(1500);
  full.plant.set_load_torque_nm(0.1);
  full.run_at(2.0);
  full.run(1.0);
  Axis half(750);
  half.plant.set_load_torque_nm(0.1);
  half.run_at(2.0);
  half.run(1.0);
  const double at_full = full.mean_sg2(0.5);
  const double at_half = half.mean_sg2(0.5);
  EXPECT_NEAR(at_half, expected_sg2(0.1, 0.75, 2.0), 30.0);
  EXPECT_LT(at_half, at_full - 200.0);
}

TEST(StallGuardModel, blocked_rotor_reads_zero_within_three_full_steps) {
  Axis axis(1500);
  axis.run_at(2.0);
  axis.run(1.0);
  ASSERT_GT(axis.model.stallguard2_result(), 900);
  axis.plant.set_blocked(true);
  const uint32_t start = axis.model.measurements();
  while (axis.model.stallguard2_result() != 0 && axis.model.measurements() - start < 10) axis.tick();
  EXPECT_EQ(axis.model.stallguard2_result(), 0);
  EXPECT_LE(axis.model.measurements() - start, 3u);
  // And it stays there while the field turns over the blocked rotor.
  int nonzero = 0;
  const uint32_t from = axis.model.measurements();
  while (axis.model.measurements() - from < 100) {
    axis.tick();
    if (axis.model.stallguard2_result() != 0) ++nonzero;
  }
  EXPECT_EQ(nonzero, 0);
}

TEST(StallGuardModel, overload_pulls_out_and_reads_zero) {
  // 0.34 N m at 2 rps is beyond what the NEMA17 at 1.5 A pulls through its start: it stalls.
  Axis axis(1500);
  axis.plant.set_load_torque_nm(0.34);
  axis.run_at(2.0);
  axis.run(1.0);
  const double lag_full_steps = axis.plant.position_revolutions() * kFullStepsPerRev - axis.ramp.position() / 256.0;
  ASSERT_LT(lag_full_steps, -100.0);  // really stalled
  EXPECT_EQ(axis.mean_sg2(0.2), 0.0);
}

TEST(StallGuardModel, stop_on_stall_halts_a_blocked_axis_above_the_threshold_speed) {
  Axis axis(1500);
  axis.detector_config.stop_velocity_pps = static_cast<uint32_t>(kMicrostepsPerRev);  // 1 rps
  axis.run_at(2.0);
  axis.run(1.0);
  EXPECT_FALSE(axis.detector.stalled());  // accelerating through the threshold with light load
  axis.plant.set_blocked(true);
  const int64_t blocked_at = axis.ticks;
  while (!axis.detector.stalled() && axis.ticks - blocked_at < 2000) axis.tick();
  ASSERT_TRUE(axis.detector.stalled());
  // Three full steps at 400 full steps/s plus a tick: within 7.5 ms.
  EXPECT_LE(axis.ticks - blocked_at, 151);
  EXPECT_EQ(axis.detector.stall_velocity_pps(), static_cast<int32_t>(2 * kMicrostepsPerRev));
  axis.run(0.01);
  EXPECT_EQ(axis.ramp.velocity(), 0.0);

  // Below the threshold a blocked rotor is not a stall.
  Axis slow(1500);
  slow.detector_config.stop_velocity_pps = static_cast<uint32_t>(kMicrostepsPerRev);
  slow.run_at(0.5);
  slow.run(0.2);
  slow.plant.set_blocked(true);
  slow.run(1.0);
  EXPECT_EQ(slow.model.stallguard2_result(), 0);
  EXPECT_FALSE(slow.detector.stalled());
}

TEST(StallGuardModel, coolstep_lowers_the_current_at_light_load_and_raises_it_under_load) {
  // Settings as the manual advises for CoolStep: filtered StallGuard2 (209D = 1), a lower
  // threshold of 6 x 32 = 192 (209C), upper (6 + 4 + 1) x 32 = 352 (209A = 4), +4 steps up
  // (209B = 2), one step down per 8 high results (2099 = 1), floor 1/2 (2098 = 0), above 1 rps.
  struct Point {
    double load_nm;
    int min_scale;
    int max_scale;
  };
  // The scale that keeps SG in 192..352 (reserve 19..34 %) for the load plus friction:
  // I = torque / (K (1 - reserve)); scale = 32 I / 1.5 A - 1.
  const Point points[] = {{0.0, 15, 15}, {0.1, 15, 15}, {0.2, 20, 24}, {0.25, 25, 29}};
  for (const Point& point : points) {
    Axis axis(1500);
    axis.use_coolstep = true;
    axis.settings.stallguard2_filter = true;
    axis.coolstep_config.run_current_scale = 31;
    axis.coolstep_config.hysteresis_start = 6;
    axis.coolstep_config.hysteresis = 4;
    axis.coolstep_config.up_step = 2;
    axis.coolstep_config.down_step = 1;
    axis.coolstep_config.threshold_velocity_pps = static_cast<uint32_t>(kMicrostepsPerRev);
    axis.run_at(2.0);
    axis.run(2.0);
    // Light load first: down to the floor, half the run current (one step per 32 full steps:
    // 16 steps in 1.3 s).
    EXPECT_TRUE(axis.coolstep.active());
    EXPECT_EQ(axis.coolstep.current_scale(), 15);
    EXPECT_EQ(axis.coolstep.scaled_current_ma(axis.coolstep_config, 1500), 750);
    EXPECT_NEAR(std::hypot(axis.plant.coil_a_current_a(), axis.plant.coil_b_current_a()), 0.75, 0.01);
    // The load rises over 0.5 s; CoolStep follows it.
    for (int i = 1; i <= 10000; ++i) {
      axis.plant.set_load_torque_nm(point.load_nm * i / 10000.0);
      axis.tick();
    }
    axis.run(1.0);
    int min_scale = 31;
    int max_scale = 0;
    int outside_band = 0;
    int samples = 0;
    uint32_t last = axis.model.measurements();
    for (int i = 0; i < 20000; ++i) {  // 1 s: 100 filtered results
      axis.tick();
      if (axis.model.measurements() == last) continue;
      last = axis.model.measurements();
      ++samples;
      const uint16_t sg = axis.model.stallguard2_result();
      if (point.min_scale > 15 && (sg < 192 || sg >= 352)) ++outside_band;
      min_scale = std::min<int>(min_scale, axis.coolstep.current_scale());
      max_scale = std::max<int>(max_scale, axis.coolstep.current_scale());
    }
    EXPECT_EQ(samples, 100) << point.load_nm;
    EXPECT_GE(min_scale, point.min_scale) << point.load_nm;
    EXPECT_LE(max_scale, point.max_scale) << point.load_nm;
    EXPECT_LE(outside_band, 5) << point.load_nm;
    const double lag_full_steps = axis.plant.position_revolutions() * kFullStepsPerRev - axis.ramp.position() / 256.0;
    EXPECT_GT(lag_full_steps, -1.0) << point.load_nm;  // no step lost
    if (point.load_nm < 0.25) continue;
    // Unloaded again: back down to the floor; stopped: the run current.
    axis.plant.set_load_torque_nm(0.0);
    axis.run(1.5);
    EXPECT_EQ(axis.coolstep.current_scale(), 15);
    axis.run_at(0.0);
    axis.run(1.0);
    EXPECT_FALSE(axis.coolstep.active());
    EXPECT_EQ(axis.coolstep.current_scale(), 31);
    EXPECT_NEAR(std::hypot(axis.plant.coil_a_current_a(), axis.plant.coil_b_current_a()), 1.5, 0.01);
  }
}

}  // namespace
}  // namespace motwin::sim
