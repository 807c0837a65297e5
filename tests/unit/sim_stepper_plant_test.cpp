// The two-phase hybrid stepper model, the ideal motor and the motor-side sensors.
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <cstdint>

#include "board/stepper_drive.h"
#include "core/motion/microstep_table.h"
#include "core/motion/s_ramp.h"
#include "sim/stepper_plant.h"

namespace motwin::sim {
namespace {

constexpr double kDt = 50e-6;
constexpr double kPi = 3.14159265358979323846;
constexpr uint32_t kMicrosteps = 256;
constexpr double kMicrostepsPerRev = 200.0 * kMicrosteps;

// A driver at a fixed current following an S-ramp, as the module's tick does it.
struct Axis {
  explicit Axis(const StepperMotorDescription& motor, int32_t run_current_ma) : plant(motor), current_ma(run_current_ma) {
    drive.enabled = true;
    apply();
  }
  void apply() {
    drive.electrical_angle = motion::electrical_angle_of(ramp.position(), kMicrosteps);
    const motion::CoilCurrents currents = motion::coil_currents(drive.electrical_angle, current_ma);
    drive.coil_a_ma = currents.coil_a_ma;
    drive.coil_b_ma = currents.coil_b_ma;
  }
  void tick() {
    ramp.step(config, kDt);
    apply();
    plant.advance(drive, supply_volt, kDt);
  }
  void run(double seconds) {
    const auto ticks = static_cast<int64_t>(seconds / kDt + 0.5);
    for (int64_t i = 0; i < ticks; ++i) tick();
  }
  double commanded_revolutions() const { return ramp.position() / kMicrostepsPerRev; }
  // Rotor minus command, in full steps.
  double error_full_steps() const { return (plant.position_revolutions() - commanded_revolutions()) * 200.0; }

  StepperPlant plant;
  motion::SRamp ramp;
  motion::SRampConfig config{kMicrostepsPerRev * 1.0, kMicrostepsPerRev * 10.0, 0.0, {0, 0, 0, 0}};
  board::StepperDrive drive;
  int32_t current_ma;
  double supply_volt = 24.0;
};

TEST(StepperPlant, presets) {
  const StepperMotorDescription nema17 = StepperMotorDescription::nema17();
  EXPECT_DOUBLE_EQ(nema17.resistance_ohm, 1.5);
  EXPECT_DOUBLE_EQ(nema17.inductance_h, 2.8e-3);
  EXPECT_DOUBLE_EQ(nema17.torque_constant_nm_per_a, 0.27);
  EXPECT_DOUBLE_EQ(nema17.detent_torque_nm, 0.022);
  EXPECT_DOUBLE_EQ(nema17.rotor_inertia_kg_m2, 5.4e-6);
  EXPECT_DOUBLE_EQ(nema17.friction_torque_nm, 0.017);
  const StepperMotorDescription nema23 = StepperMotorDescription::nema23();
  EXPECT_DOUBLE_EQ(nema23.rated_current_a, 2.8);
  EXPECT_NEAR(nema23.holding_torque_nm(), 1.0, 1e-12);
  EXPECT_EQ(nema23.full_steps_per_revolution, 200);
}

// Holds a load ramped up slowly at rest; returns the final rotor position (revolutions).
double hold_against(const StepperMotorDescription& motor, int32_t current_ma, double load_nm) {
  Axis axis(motor, current_ma);
  axis.run(0.05);
  const int ramp_ticks = 8000;  // 0.4 s: slow against the rotor's resonance
  for (int i = 0; i < ramp_ticks; ++i) {
    axis.plant.set_load_torque_nm(load_nm * (i + 1) / ramp_ticks);
    axis.tick();
  }
  axis.run(0.2);
  return axis.plant.position_revolutions();
}

TEST(StepperPlant, holding_torque_is_k_times_i) {
  const StepperMotorDescription motor = StepperMotorDescription::nema17();
  const double holding = motor.torque_constant_nm_per_a * 1.5;  // 0.405 N m at 1500 mA
  const double margin = motor.friction_torque_nm + motor.detent_torque_nm;
  // Below: holds, with the load angle of K I sin(angle) = load (within friction and detent).
  for (double fraction : {0.25, 0.5, 0.75, 0.9}) {
    const double load = fraction * holding;
    const double position = hold_against(motor, 1500, load);
    const double load_angle = -position * 50.0 * 2.0 * kPi;  // electrical, rad (the load pulls back)
    EXPECT_LT(load_angle, kPi / 2.0) << fraction;
    EXPECT_GE(holding * std::sin(load_angle), load - margin) << fraction;
    EXPECT_LE(holding * std::sin(std::min(load_angle, kPi / 2.0)), load + margin) << fraction;
  }
  // The threshold where it lets go: between K I - detent and K I + friction + detent.
  double threshold = 0.0;
  for (double load = 0.8 * holding; load < 1.3 * holding; load += 0.01 * holding) {
    if (hold_against(motor, 1500, load) < -4.0 / 200.0) {
      threshold = load;
      break;
    }
  }
  EXPECT_GT(threshold, holding - motor.detent_torque_nm);
  EXPECT_LT(threshold, holding + margin + 0.01 * holding);
  // Half the current, half the holding torque.
  EXPECT_GT(hold_against(motor, 750, 0.45 * holding), -1.0 / 200.0);
  EXPECT_LT(hold_against(motor, 750, 0.6 * holding), -4.0 / 200.0);
}

TEST(StepperPlant, rotor_follows_a_slow_ramp_within_the_load_angle) {
  Axis axis(StepperMotorDescription::nema17(), 1500);
  axis.config.bow[0] = axis.config.bow[1] = axis.config.bow[2] = axis.config.bow[3] = kMicrostepsPerRev * 200.0;
  axis.ramp.set_position_target(static_cast<int32_t>(3 * kMicrostepsPerRev));  // 3 revolutions at 1 rps
  double worst = 0.0;
  for (int i = 0; i < 100000 && !axis.ramp.position_reached(); ++i) {
    axis.tick();
    worst = std::max(worst, std::fabs(axis.error_full_steps()));
  }
  ASSERT_TRUE(axis.ramp.position_reached());
  // Never a full step (90° electrical is one full step) behind or ahead.
  EXPECT_LT(worst, 1.0);
  axis.run(0.3);
  EXPECT_NEAR(axis.plant.position_revolutions(), 3.0, 0.1 / 200.0);
  // With a load the rotor lags by the load angle: asin(0.2 / 0.405) = 29.6° = 0.33 full steps.
  axis.plant.set_load_torque_nm(0.2);
  axis.ramp.set_position_target(0);
  double lag_sum = 0.0;
  int lag_samples = 0;
  for (int i = 0; i < 100000 && !axis.ramp.position_reached(); ++i) {
    axis.tick();
    if (axis.ramp.velocity_reached()) {
      lag_sum += axis.error_full_steps();
      ++lag_samples;
    }
  }
  ASSERT_GT(lag_samples, 1000);
  const double lag = lag_sum / lag_samples;  // the load pulls towards negative positions: ahead
  EXPECT_GT(lag, -0.45);
  EXPECT_LT(lag, -0.2);
}

TEST(StepperPlant, blocked_rotor_loses_every_step) {
  Axis axis(StepperMotorDescription::nema17(), 1500);
  axis.config.max_velocity = 2 * kMicrostepsPerRev;
  StepperSensors sensors;  // 4000 counts per revolution
  board::StepperFeedback feedback;
  sensors.sense(axis.plant.position_revolutions(), feedback);
  axis.run(0.05);
  axis.plant.set_blocked(true);
  axis.ramp.set_position_target(static_cast<int32_t>(10 * kMicrostepsPerRev));
  for (int i = 0; i < 200000 && !axis.ramp.position_reached(); ++i) axis.tick();
  ASSERT_TRUE(axis.ramp.position_reached());
  sensors.sense(axis.plant.position_revolutions(), feedback);
  EXPECT_EQ(feedback.encoder_count, 0);
  EXPECT_EQ(axis.plant.velocity_rps(), 0.0);
  // Steps lost: command minus encoder, in encoder counts.
  const double commanded_counts = axis.commanded_revolutions() * 4000.0;
  EXPECT_EQ(commanded_counts - feedback.encoder_count, 40000.0);
}

TEST(StepperPlant, a_stall_loses_whole_electrical_periods) {
  Axis axis(StepperMotorDescription::nema17(), 1500);
  axis.ramp.set_position_target(static_cast<int32_t>(2 * kMicrostepsPerRev));  // 2 revolutions at 1 rps
  axis.run(0.5);
  axis.plant.set_blocked(true);  // an obstacle for 0.3 s
  axis.run(0.3);
  axis.plant.set_blocked(false);
  for (int i = 0; i < 200000 && !axis.ramp.position_reached(); ++i) axis.tick();
  axis.run(0.5);
  // The rotor stays behind by a whole number of electrical periods (4 full steps each).
  const double behind = -axis.error_full_steps();
  EXPECT_GE(behind, 4.0 - 0.2);
  const double periods = behind / 4.0;
  EXPECT_NEAR(periods, std::round(periods), 0.05) << behind;
  EXPECT_NEAR(axis.plant.velocity_rps(), 0.0, 1e-3);
}

TEST(StepperPlant, supply_limits_the_current_at_speed) {
  // The voltage needed grows with back-EMF (K w) and reactance (w_e L): at 20 rps the coils no
  // longer reach 1.5 A from 24 V.
  auto current_at = [](double rps) {
    Axis axis(StepperMotorDescription::nema17(), 1500);
    axis.config.max_velocity = rps * kMicrostepsPerRev;
    axis.config.acceleration = 40.0 * kMicrostepsPerRev;
    axis.ramp.set_velocity_target(rps * kMicrostepsPerRev);
    axis.run(rps / 40.0 + 0.2);
    double peak = 0.0;
    for (int i = 0; i < 4000; ++i) {
      axis.tick();
      peak = std::max(peak, std::hypot(axis.plant.coil_a_current_a(), axis.plant.coil_b_current_a()));
    }
    EXPECT_NEAR(axis.plant.velocity_rps(), rps, 0.2 * rps) << rps;  // still running in step
    return peak;
  };
  const double slow = current_at(2.0);
  const double fast = current_at(20.0);
  EXPECT_NEAR(slow, 1.5, 0.03);
  EXPECT_LT(fast, 0.6 * slow);
  // At 48 V the same speed gets more current.
  Axis strong(StepperMotorDescription::nema17(), 1500);
  strong.supply_volt = 48.0;
  strong.config.max_velocity = 20.0 * kMicrostepsPerRev;
  strong.config.acceleration = 40.0 * kMicrostepsPerRev;
  strong.ramp.set_velocity_target(20.0 * kMicrostepsPerRev);
  strong.run(0.7);
  double peak = 0.0;
  for (int i = 0; i < 4000; ++i) {
    strong.tick();
    peak = std::max(peak, std::hypot(strong.plant.coil_a_current_a(), strong.plant.coil_b_current_a()));
  }
  EXPECT_GT(peak, 1.5 * fast);
}

TEST(StepperPlant, torque_falls_with_speed_so_a_load_stalls_it_fast_but_not_slow) {
  auto steps_lost = [](double rps) {
    Axis axis(StepperMotorDescription::nema17(), 1500);
    axis.plant.set_load_torque_nm(0.25);  // pulls towards negative positions: positive moves lift it
    axis.run(0.1);
    const double start = axis.plant.position_revolutions() - axis.commanded_revolutions();
    axis.config.max_velocity = rps * kMicrostepsPerRev;
    axis.config.acceleration = 20.0 * kMicrostepsPerRev;
    axis.ramp.set_position_target(static_cast<int32_t>(std::round(rps * 1.0 * kMicrostepsPerRev)));
    for (int i = 0; i < 400000 && !axis.ramp.position_reached(); ++i) axis.tick();
    axis.run(0.3);
    return -(axis.plant.position_revolutions() - axis.commanded_revolutions() - start) * 200.0;
  };
  // 0.25 N m is 62 % of the holding torque: carried at 2 and 10 rps; at 25 rps the current
  // (and torque) left is too small, the rotor falls out of step and the load pulls it back.
  EXPECT_LT(std::fabs(steps_lost(2.0)), 0.5);
  EXPECT_LT(std::fabs(steps_lost(10.0)), 0.5);
  EXPECT_GT(steps_lost(25.0), 4.0);
}

TEST(StepperPlant, disabled_drive_lets_the_currents_decay_and_the_rotor_coast) {
  Axis axis(StepperMotorDescription::nema17(), 1500);
  axis.run(0.05);
  EXPECT_NEAR(axis.plant.coil_a_current_a(), 1.5, 1e-9);
  axis.drive.enabled = false;
  for (int i = 0; i < 20; ++i) axis.plant.advance(axis.drive, 24.0, kDt);  // 1 ms
  EXPECT_EQ(axis.plant.coil_a_current_a(), 0.0);
  EXPECT_EQ(axis.plant.coil_b_current_a(), 0.0);
  // Unpowered, the detent and friction still hold a small load...
  axis.plant.set_load_torque_nm(0.02);
  for (int i = 0; i < 4000; ++i) axis.plant.advance(axis.drive, 24.0, kDt);
  EXPECT_GT(axis.plant.position_revolutions(), -1.0 / 200.0);
  // ...but not a larger one: it turns away.
  axis.plant.set_load_torque_nm(0.1);
  for (int i = 0; i < 4000; ++i) axis.plant.advance(axis.drive, 24.0, kDt);
  EXPECT_LT(axis.plant.position_revolutions(), -1.0);
}

TEST(StepperPlant, load_inertia_slows_the_response) {
  // Same load step, more inertia: the rotor takes longer to reach its new load angle.
  auto deflection_after = [](double inertia, double seconds) {
    Axis axis(StepperMotorDescription::nema17(), 1500);
    axis.plant.set_load_inertia_kg_m2(inertia);
    axis.run(0.01);
    axis.plant.set_load_torque_nm(0.1);
    axis.run(seconds);
    return -axis.plant.position_revolutions();
  };
  const double light = deflection_after(0.0, 0.0005);
  const double heavy = deflection_after(100 * 5.4e-6, 0.0005);
  EXPECT_GT(light, 3.0 * heavy);
  EXPECT_GT(heavy, 0.0);
}

// --- IdealStepper ----------------------------------------------------------------------------

TEST(IdealStepper, unwraps_in_both_directions) {
  IdealStepper motor;
  board::StepperDrive drive;
  drive.enabled = true;
  // Forward by almost a quarter revolution of the field per tick, across many wraps.
  const uint32_t per_tick = (1u << 30) - 12345;
  for (int i = 0; i < 1000; ++i) {
    drive.electrical_angle += per_tick;
    motor.advance(drive, kDt);
  }
  const double expected_forward = 1000.0 * per_tick / 4294967296.0 * 4.0 / 200.0;
  EXPECT_NEAR(motor.position_revolutions(), expected_forward, 1e-12);
  EXPECT_EQ(motor.electrical_position(), int64_t{1000} * per_tick);
  EXPECT_NEAR(motor.velocity_rps(), per_tick / 4294967296.0 * 4.0 / 200.0 / kDt, 1e-9);
  // Backward twice as far.
  for (int i = 0; i < 2000; ++i) {
    drive.electrical_angle -= per_tick;
    motor.advance(drive, kDt);
  }
  EXPECT_EQ(motor.electrical_position(), -int64_t{1000} * per_tick);
  EXPECT_LT(motor.velocity_rps(), 0.0);
}

TEST(IdealStepper, disabled_it_stays_and_snaps_to_the_nearest_equilibrium) {
  IdealStepper motor;
  board::StepperDrive drive;
  drive.enabled = true;
  drive.electrical_angle = 5u << 28;  // 1.25 full steps
  motor.advance(drive, kDt);
  EXPECT_EQ(motor.electrical_position(), int64_t{5} << 28);
  drive.enabled = false;
  drive.electrical_angle += 3u << 30;  // the field moves 3 full steps while off
  motor.advance(drive, kDt);
  EXPECT_EQ(motor.electrical_position(), int64_t{5} << 28);
  EXPECT_EQ(motor.velocity_rps(), 0.0);
  drive.enabled = true;  // the nearest equilibrium is one full step back
  motor.advance(drive, kDt);
  EXPECT_EQ(motor.electrical_position(), (int64_t{5} << 28) - (int64_t{1} << 30));
  motor.set_position_revolutions(-2.5);
  EXPECT_DOUBLE_EQ(motor.position_revolutions(), -2.5);
  EXPECT_EQ(motor.electrical_position(), -int64_t{125} * (int64_t{1} << 32));
}

// --- StepperSensors ----------------------------------------------------------------------------

TEST(StepperSensors, encoder_counts_are_exact) {
  StepperSensorConfig config;
  config.encoder.counts_per_revolution = 4000;
  StepperSensors sensors(config);
  board::StepperFeedback feedback;
  sensors.sense(1.2345, feedback);
  EXPECT_EQ(feedback.encoder_count, 4938);  // floor(4938.0)
  sensors.sense(-0.0001, feedback);
  EXPECT_EQ(feedback.encoder_count, -1);  // floor(-0.4)
  sensors.sense(-3.0, feedback);
  EXPECT_EQ(feedback.encoder_count, -12000);
  config.encoder.reversed = true;
  sensors.set_config(config);
  sensors.sense(1.2345, feedback);
  EXPECT_EQ(feedback.encoder_count, -4938);
  // The 32-bit counter wraps.
  config.encoder.reversed = false;
  sensors.set_config(config);
  EXPECT_EQ(sensors.encoder_count_at(536871.0), static_cast<int32_t>(static_cast<uint32_t>(int64_t{2147484000})));
}

TEST(StepperSensors, index_pulse_once_per_revolution_latches_the_count) {
  StepperSensorConfig config;
  config.encoder.counts_per_revolution = 4000;
  config.encoder.index_revolutions = 0.25;
  StepperSensors sensors(config);
  board::StepperFeedback feedback;
  sensors.sense(0.0, feedback);
  EXPECT_EQ(feedback.encoder_index_events, 0u);
  for (double position = 0.0; position <= 2.3; position += 0.001) sensors.sense(position, feedback);
  // Crossed 0.25, 1.25 and 2.25.
  EXPECT_EQ(feedback.encoder_index_events, 3u);
  EXPECT_EQ(feedback.encoder_index_count, 9000);
  for (double position = 2.3; position >= 1.0; position -= 0.001) sensors.sense(position, feedback);
  // Back over 2.25 and 1.25.
  EXPECT_EQ(feedback.encoder_index_events, 5u);
  EXPECT_EQ(feedback.encoder_index_count, 5000);
  // A jump over several revolutions in one call counts each of them.
  sensors.sense(5.5, feedback);  // 1.25 (again), 2.25, 3.25, 4.25, 5.25
  EXPECT_EQ(feedback.encoder_index_events, 10u);
  EXPECT_EQ(feedback.encoder_index_count, 21000);
}

// hfuzz finding: a diverged plant's rotor position (1e19 revolutions, inf, NaN) was converted to
// int64 (undefined behaviour). Counts wrap at 32 bits for any finite position; a position that
// is not a number counts 0, crosses no index pulse and presses no switch.
TEST(StepperSensors, huge_and_non_finite_positions_are_defined) {
  StepperSensorConfig config;
  config.encoder.counts_per_revolution = 4000;
  config.home = {true, 1.0, 1e300, false};  // active low: pressed reads 0
  StepperSensors sensors(config);
  // 2^62 revolutions x 4000 is a multiple of 2^32; 2^31 + 0.25 revolutions leaves 1000.
  EXPECT_EQ(sensors.encoder_count_at(std::ldexp(1.0, 62)), 0);
  EXPECT_EQ(sensors.encoder_count_at(-std::ldexp(1.0, 62)), 0);
  EXPECT_EQ(sensors.encoder_count_at(std::ldexp(1.0, 31) + 0.25), 1000);
  EXPECT_EQ(sensors.encoder_count_at(1e300), sensors.encoder_count_at(1e300));
  EXPECT_EQ(sensors.encoder_count_at(HUGE_VAL), 0);
  EXPECT_EQ(sensors.encoder_count_at(std::nan("")), 0);
  board::StepperFeedback feedback;
  sensors.sense(0.5, feedback);
  EXPECT_EQ(feedback.encoder_count, 2000);
  EXPECT_EQ(feedback.switches, 0b100);
  sensors.sense(std::nan(""), feedback);
  EXPECT_EQ(feedback.encoder_count, 0);
  EXPECT_EQ(feedback.encoder_index_events, 0u);
  EXPECT_EQ(feedback.switches, 0b100) << "released";
  sensors.sense(1e25, feedback);  // a runaway: the turn count saturates instead of overflowing
  EXPECT_EQ(feedback.encoder_count, sensors.encoder_count_at(1e25));
  EXPECT_EQ(feedback.switches, 0b000);
  sensors.sense(-1e25, feedback);
  EXPECT_EQ(feedback.encoder_count, sensors.encoder_count_at(-1e25));
  sensors.sense(0.5, feedback);
  EXPECT_EQ(feedback.encoder_count, 2000);
}

// The stability bound the stepper JSON parser applies: the presets lie far inside it, and a
// rotor just above the smallest stable inertia holds its position at the stiffest current.
TEST(StepperPlant, rotor_integration_is_stable_above_the_minimum_inertia) {
  const double h = kDt / StepperPlant::kFinestSubSteps;
  EXPECT_LT(StepperPlant::step_number(StepperMotorDescription::nema17(), h), 0.06);
  EXPECT_LT(StepperPlant::step_number(StepperMotorDescription::nema23(), h), 0.03);
  StepperMotorDescription light = StepperMotorDescription::nema23();
  light.rotor_inertia_kg_m2 = StepperPlant::min_stable_inertia_kg_m2(light, h);
  EXPECT_NEAR(StepperPlant::step_number(light, h), StepperPlant::kStableStepNumber, 1e-9);
  light.rotor_inertia_kg_m2 *= 1.01;
  StepperPlant plant(light);
  board::StepperDrive drive;
  drive.enabled = true;
  drive.coil_a_ma = 7000;  // holding at electrical angle 0 with the assumed peak current
  plant.set_position_revolutions(0.001);  // 0.2 full steps off the equilibrium
  double largest = 0;
  for (int i = 0; i < 2000; ++i) {
    plant.advance(drive, 48.0, kDt);
    largest = std::max(largest, std::fabs(plant.position_revolutions()));
  }
  EXPECT_LE(largest, 0.0011) << "no growth beyond the start";
  EXPECT_LT(std::fabs(plant.position_revolutions()), 0.0002) << "settles towards 0";
}

TEST(StepperSensors, switches_at_their_positions_with_polarity) {
  StepperSensorConfig config;
  config.right = {true, 5.0, 1e300, true};    // pressed from 5 revolutions on, reads 1
  config.left = {true, -1e300, -5.0, false};  // pressed up to -5 revolutions, reads 0 (active low)
  config.home = {true, 1.0, 1.1, true};
  StepperSensors sensors(config);
  board::StepperFeedback feedback;
  sensors.sense(0.0, feedback);
  EXPECT_EQ(feedback.switches, 0b010);  // left released reads 1
  sensors.sense(5.0, feedback);
  EXPECT_EQ(feedback.switches, 0b011);
  sensors.sense(4.9999, feedback);
  EXPECT_EQ(feedback.switches, 0b010);
  sensors.sense(1.05, feedback);
  EXPECT_EQ(feedback.switches, 0b110);
  sensors.sense(-6.0, feedback);
  EXPECT_EQ(feedback.switches, 0b000);
  // Absent switches read released.
  StepperSensors none;
  none.sense(100.0, feedback);
  EXPECT_EQ(feedback.switches, 0);
}

}  // namespace
}  // namespace motwin::sim
