// The TMCM-1636 servo cascade on the physical motor models (issue 4): torque, velocity and
// position regulation, commutation modes, encoder initialisation, regeneration and the brake
// chopper, reference switches, driver enable, brake, protections, determinism. Every test asserts
// numbers and prints the figure it checks when it fails.
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <cstdlib>
#include <cstring>
#include <vector>

#include "support/tmcm1636_servo_rig.h"

namespace motwin::testing {
namespace {

namespace flag = modules::tmcm1636::status_flag;

constexpr double kPi = 3.14159265358979323846;

sim::MotorDescription default_motor() { return Tmcm1636ServoRig::preset("default-24v"); }

// Distance of two counts on a circle of `period` counts.
double circular_distance(double a, double b, double period) {
  double d = std::fmod(a - b, period);
  if (d < 0) d += period;
  return std::min(d, period - d);
}

// --- Torque (current) regulation --------------------------------------------------------------

// The q current commanded with AP 30 accelerates the rotor at T/J of the model. Without friction
// in the model, T/J is exactly 1.5 p lambda iq / J (J: rotor plus a load of 5e-5 kg m^2, so that
// the back-EMF does not ramp faster than a current loop follows). Commutation on the absolute
// encoder with its offset given (AP 161 = 1): the test measures the current loop, not an angle
// error.
TEST(Tmcm1636Servo, torque_mode_accelerates_at_torque_over_inertia) {
  sim::MotorDescription motor = default_motor();
  motor.coulomb_friction_nm = 0.0;
  motor.viscous_friction_nm_s = 0.0;
  motor.absolute = {true, 14, 0.0, false};
  Tmcm1636ServoRig rig(motor);
  rig.set("LOAD_INERTIA", 5e-5);
  const double inertia = rig.plant().total_inertia_kgm2();
  ASSERT_EQ(rig.sap(160, 2), 100);  // AMT23, 14 bits
  ASSERT_EQ(rig.sap(161, 1), 100);  // use the offset
  ASSERT_EQ(rig.sap(163, static_cast<int32_t>(rig.plant().absolute_reading_at_electrical_zero())), 100);
  ASSERT_EQ(rig.sap(15, 4), 100);
  rig.run_ms(5);
  for (const int32_t current_ma : {500, 1500, -1000}) {
    ASSERT_EQ(rig.sap(30, current_ma), 100);
    rig.run_ms(5);  // current loop settles
    const double w0 = rig.plant().speed_rad_s();
    rig.run_ms(20);
    const double w1 = rig.plant().speed_rad_s();
    const double measured = (w1 - w0) / 0.020;
    const double expected = motor.torque_constant() * current_ma * 1e-3 / inertia;
    EXPECT_NEAR(measured, expected, 0.05 * std::fabs(expected))
        << "iq " << current_ma << " mA: measured " << measured << " rad/s^2, T/J " << expected;
    EXPECT_NEAR(rig.gap(31), current_ma, 60) << "AP 31 actual torque";
    EXPECT_NEAR(rig.gap(33), 0, 60) << "AP 33 actual flux";
    EXPECT_TRUE(rig.gap(156) & flag::kTorqueMode);
  }
}

TEST(Tmcm1636Servo, torque_is_limited_by_max_current) {
  sim::MotorDescription motor = default_motor();
  Tmcm1636ServoRig rig(motor);
  rig.sap(11, 800);
  rig.sap(30, 3000);
  rig.run_ms(10);
  EXPECT_NEAR(rig.plant().iq_amps() * 1000.0, 800.0, 120.0) << "q current clipped at AP 11 (hall commutation)";
  EXPECT_TRUE(rig.gap(156) & flag::kCurrentLimit);
}

// --- Velocity regulation ----------------------------------------------------------------------

// A step 0 -> 2000 rpm (ramp off) with the default motor's documented gains: settles within
// ±1 % in less than 40 ms with less than 5 % overshoot (docs/tmcm-1636-servo.md).
TEST(Tmcm1636Servo, velocity_step_settles_with_documented_gains) {
  Tmcm1636ServoRig rig(default_motor());
  rig.sap(45, 0);
  rig.ror(2000);
  double peak = 0.0;
  double last_outside_ms = 0.0;
  for (int tick = 1; tick <= 4000; ++tick) {
    rig.tick();
    const double speed = rig.speed_rpm();
    peak = std::max(peak, speed);
    if (std::fabs(speed - 2000.0) > 20.0) last_outside_ms = tick * 0.05;
  }
  const double overshoot = (peak - 2000.0) / 2000.0 * 100.0;
  EXPECT_LT(last_outside_ms, 40.0) << "settling time to ±1 %: " << last_outside_ms << " ms";
  EXPECT_LT(overshoot, 5.0) << "overshoot " << overshoot << " %";
  EXPECT_NEAR(rig.gap(42), 2000, 10) << "AP 42";
  rig.run_ms(1000);  // loops are counted per simulated second
  EXPECT_EQ(rig.gap(232), 20000) << "velocity loops per second";
  EXPECT_EQ(rig.gap(231), 20000) << "torque loops per second";
  EXPECT_EQ(rig.gap(230), 20000) << "main loops per second";
}

TEST(Tmcm1636Servo, velocity_ramp_shapes_the_acceleration) {
  Tmcm1636ServoRig rig(default_motor());
  rig.sap(44, 10000);  // rpm/s
  rig.ror(2000);
  rig.run_ms(100);
  EXPECT_NEAR(rig.speed_rpm(), 1000.0, 40.0) << "half-way up the 10000 rpm/s ramp";
  EXPECT_NEAR(rig.gap(41), 1000, 5) << "AP 41 ramp velocity";
  rig.run_ms(200);
  EXPECT_NEAR(rig.speed_rpm(), 2000.0, 20.0);
}

TEST(Tmcm1636Servo, zero_velocity_gains_do_not_move_the_motor) {
  Tmcm1636ServoRig rig(default_motor());
  rig.sap(72, 0);
  rig.sap(73, 0);
  const double start = rig.plant().position_revolutions();
  rig.ror(2000);
  rig.run_ms(500);
  EXPECT_LT(std::fabs(rig.speed_rpm()), 0.5) << "speed " << rig.speed_rpm() << " rpm";
  EXPECT_LT(std::fabs(rig.plant().position_revolutions() - start) * 360.0, 0.5) << "degrees moved";
  EXPECT_EQ(rig.gap(77), 0) << "velocity error sum held at 0 with I = 0";
  EXPECT_GT(rig.gap(80), 900) << "velocity error (the ramp is at 1000 rpm)";
}

// A load step of 0.03 N m (85 % of the default 2 A torque) at constant speed: the I term brings
// the speed back; with I = 0 the P term alone leaves a steady error of T / (Kt P).
TEST(Tmcm1636Servo, load_step_is_rejected_by_the_integral_term) {
  for (const bool with_integral : {true, false}) {
    Tmcm1636ServoRig rig(default_motor());
    if (!with_integral) rig.sap(73, 0);
    rig.sap(44, 20000);
    rig.ror(1000);
    rig.run_ms(400);
    rig.set("LOAD_TORQUE", 0.03);
    double dip = 1000.0;
    for (int i = 0; i < 6000; ++i) {
      rig.tick();
      dip = std::min(dip, rig.speed_rpm());
    }
    const double error = 1000.0 - rig.speed_rpm();
    if (with_integral) {
      EXPECT_LT(std::fabs(error), 5.0) << "steady error with I: " << error << " rpm (dip to " << dip << ")";
      EXPECT_GT(1000.0 - dip, 20.0) << "the step is felt: dip to " << dip << " rpm";
      EXPECT_NEAR(rig.gap(31), 0.03 / default_motor().torque_constant() * 1000.0 + 150.0, 120.0) << "AP 31 carries the load";
    } else {
      EXPECT_GT(error, 100.0) << "steady error with P only: " << error << " rpm";
    }
  }
}

// --- Position regulation ----------------------------------------------------------------------

TEST(Tmcm1636Servo, mvp_reaches_the_target_with_and_without_ramp) {
  for (const int32_t ramp : {1, 0}) {
    Tmcm1636ServoRig rig(default_motor());
    rig.sap(45, ramp);
    const int32_t target = 5 * 4096 + 123;
    ASSERT_EQ(rig.mvp(target), 100);
    rig.run_ms(5);
    EXPECT_EQ(rig.gap(55), 0);
    const double ms = rig.run_until([&] { return rig.gap(55) == 1; }, 10000);
    EXPECT_LT(ms, 10000) << "position reached (ramp " << ramp << ")";
    EXPECT_LE(std::abs(rig.gap(52) - target), rig.gap(53)) << "AP 52 " << rig.gap(52) << " (ramp " << ramp << ")";
    rig.run_ms(300);
    EXPECT_LE(std::abs(rig.gap(52) - target), 5) << "holds: AP 52 " << rig.gap(52) << " (ramp " << ramp << ")";
    EXPECT_EQ(rig.gap(55), 1);
    EXPECT_TRUE(rig.gap(156) & flag::kPositionReached);
    // The encoder counts what the rotor did: 5 revolutions and 123 counts.
    const double moved = rig.plant().position_revolutions() - default_motor().initial_angle_deg / 360.0;
    EXPECT_NEAR(moved * 4096.0, target, 6.0) << "rotor moved " << moved << " rev (ramp " << ramp << ")";
    if (ramp == 1) {
      // With the ramp, the move takes about the ramp's time (2000 rpm/s, 4000 rpm max).
      const double revs = target / 4096.0;
      const double ramp_ms = 2.0 * std::sqrt(revs / (2000.0 / 60.0)) * 1000.0;
      EXPECT_NEAR(ms, ramp_ms, 0.15 * ramp_ms) << "move time vs the ramp's " << ramp_ms << " ms";
    }
  }
}

// --- Trinamic's reference motor -------------------------------------------------------------

sim::MotorDescription reference_motor() { return Tmcm1636ServoRig::preset("qbl4208-61-04-013"); }

// Wired as on Trinamic's setup: the start-up image holds hall polarity 1 and encoder direction 1
// (the examples' settings), and with them hall commutation, ABN initialised from the halls and a
// position move work as on the bench.
TEST(Tmcm1636ReferenceMotor, the_examples_sensor_settings_are_the_right_ones) {
  Tmcm1636ServoRig rig(reference_motor());
  EXPECT_EQ(rig.gap(90), 1);
  EXPECT_EQ(rig.gap(91), 0);
  EXPECT_EQ(rig.gap(101), 1);
  rig.sap(45, 0);
  rig.ror(1500);
  rig.run_ms(500);
  EXPECT_NEAR(rig.speed_rpm(), 1500.0, 20.0) << "hall commutation with AP 90 = 1";
  EXPECT_NEAR(rig.gap(42), 1500, 30) << "encoder velocity counts forward with AP 101 = 1";
  rig.ror(0);
  rig.run_ms(300);
  ASSERT_EQ(rig.sap(15, 3), 100);  // ABN commutation, initialised from the halls (AP 102 = 2)
  rig.ror(1000);
  const double init_ms = rig.run_until([&] { return rig.gap(103) == 0; }, 2000);
  EXPECT_LT(init_ms, 2000);
  rig.run_ms(500);
  EXPECT_NEAR(rig.speed_rpm(), 1000.0, 15.0) << "ABN commutation after the initialisation";
  rig.ror(0);
  rig.run_ms(300);
  const int32_t target = rig.gap(52) + 5 * 4096;
  ASSERT_EQ(rig.mvp(target), 100);
  const double ms = rig.run_until([&] { return rig.gap(55) == 1; }, 10000);
  EXPECT_LT(ms, 10000) << "position reached";
  rig.run_ms(300);
  EXPECT_LE(std::abs(rig.gap(52) - target), 5) << "holds: AP 52 " << rig.gap(52);
}

// The other settings are wrong the way they are on a bench: hall polarity 0 commutates 180° off,
// encoder direction 0 counts backwards, so the velocity the regulator sees has the wrong sign.
TEST(Tmcm1636ReferenceMotor, the_default_sensor_settings_are_wrong_for_its_wiring) {
  {
    Tmcm1636ServoRig rig(reference_motor());
    rig.sap(45, 0);
    rig.sap(90, 0);
    rig.ror(1500);
    rig.run_ms(500);
    EXPECT_GT(std::fabs(rig.speed_rpm() - 1500.0), 500.0) << "AP 90 = 0: " << rig.speed_rpm() << " rpm";
  }
  {
    Tmcm1636ServoRig rig(reference_motor());
    rig.sap(45, 0);
    rig.sap(101, 0);
    rig.ror(1500);
    rig.run_ms(500);
    EXPECT_GT(std::fabs(rig.speed_rpm() - 1500.0), 500.0) << "AP 101 = 0: " << rig.speed_rpm() << " rpm";
  }
}

// --- Commutation modes -----------------------------------------------------------------------

TEST(Tmcm1636Servo, open_loop_turns_the_motor_at_the_commanded_speed) {
  Tmcm1636ServoRig rig(default_motor());
  rig.sap(15, 1);
  rig.sap(12, 1500);
  rig.ror(300);
  rig.run_ms(1000);
  std::vector<double> speeds;
  for (int i = 0; i < 100; ++i) {
    rig.run_ms(2);
    speeds.push_back(rig.speed_rpm());
  }
  double mean = 0;
  for (double s : speeds) mean += s;
  mean /= static_cast<double>(speeds.size());
  EXPECT_NEAR(mean, 300.0, 3.0) << "mean rotor speed";
  EXPECT_NEAR(rig.gap(42), 300, 6) << "AP 42 from the encoder (the open-loop rotor swings about the field)";
  EXPECT_NE(rig.gap(16), 0) << "AP 16 open-loop angle moves";
  EXPECT_NEAR(rig.plant().id_amps(), 1.5, 0.3) << "open-loop current as flux current";
}

TEST(Tmcm1636Servo, hall_commutation_turns_the_motor_at_the_commanded_speed) {
  for (const int32_t interpolation : {1, 0}) {
    Tmcm1636ServoRig rig(default_motor());
    rig.sap(92, interpolation);
    rig.ror(1500);
    rig.run_ms(800);
    double mean = 0;
    for (int i = 0; i < 100; ++i) {
      rig.run_ms(2);
      mean += rig.speed_rpm() / 100.0;
    }
    EXPECT_NEAR(mean, 1500.0, 15.0) << "hall interpolation " << interpolation;
    EXPECT_EQ(rig.gap(15), 2);
    EXPECT_FALSE(rig.gap(156) & flag::kHallError);
  }
}

// Wrong hall settings show: inverted polarity without AP 90 commutates 180° off.
TEST(Tmcm1636Servo, hall_polarity_mismatch_does_not_run) {
  sim::MotorDescription motor = default_motor();
  motor.hall.inverted = true;
  Tmcm1636ServoRig rig(motor);
  rig.sap(45, 0);
  rig.ror(1500);
  rig.run_ms(500);
  EXPECT_GT(std::fabs(rig.speed_rpm() - 1500.0), 500.0) << "speed " << rig.speed_rpm();
  Tmcm1636ServoRig fixed(motor);
  fixed.sap(45, 0);
  fixed.sap(90, 1);
  fixed.ror(1500);
  fixed.run_ms(500);
  EXPECT_NEAR(fixed.speed_rpm(), 1500.0, 20.0) << "with AP 90 = 1";
}

// ABN commutation restored at power-up without an initialisation: the counter starts wherever
// the rotor is, the offset is stale, and the motor does not follow its command (here it runs
// away backwards: 160° electrical off). SAP 15, 0, 3 initialises, then it works.
TEST(Tmcm1636Servo, abn_before_initialisation_misbehaves_and_works_after) {
  sim::MotorDescription motor = default_motor();
  motor.startup->commutation = sim::CommutationSensor::kAbnEncoder;  // AP 15 = 3
  Tmcm1636ServoRig rig(motor);
  rig.sap(44, 20000);
  EXPECT_EQ(rig.gap(15), 3);
  EXPECT_EQ(rig.gap(103), 0) << "no initialisation at power-up";
  EXPECT_FALSE(rig.gap(156) & flag::kEncoderInitialised);
  rig.ror(1000);
  rig.run_ms(500);
  EXPECT_GT(std::fabs(rig.speed_rpm() - 1000.0), 300.0) << "uninitialised ABN: " << rig.speed_rpm() << " rpm";
  rig.ror(0);
  rig.sap(255, 0);
  rig.run_ms(3000);  // coast to a stop
  rig.sap(255, 1);
  ASSERT_EQ(rig.sap(15, 3), 100);  // initialise ("use hall", the preset's AP 102 = 2)
  rig.ror(500);
  const double ms = rig.run_until([&] { return rig.gap(103) == 0; }, 2000);
  EXPECT_LT(ms, 2000);
  EXPECT_TRUE(rig.gap(156) & flag::kEncoderInitialised);
  rig.ror(1000);
  rig.run_ms(500);
  EXPECT_NEAR(rig.speed_rpm(), 1000.0, 10.0) << "after initialisation";
}

struct InitCase {
  int32_t mode;
  const char* name;
};

// Where a forced field leaves the rotor: Coulomb friction holds it off the field angle by up to
// asin(Tc / (Kt I)) electrical; in counts of a motor with `counts_per_electrical_turn`.
double friction_angle_counts(const sim::MotorDescription& m, double amps, double counts_per_electrical_turn) {
  return std::asin(m.coulomb_friction_nm / (m.torque_constant() * amps)) / (2.0 * kPi) * counts_per_electrical_turn;
}

// Each init mode finds the offset of the model: the count at electrical angle 0 (mode 0 and 2,
// counted from power-up) or its distance from the N pulse (mode 1). Forced-field modes are off by
// at most the friction angle; "use hall" by the motion of one tick at the edge.
TEST(Tmcm1636Servo, each_encoder_init_mode_finds_the_model_offset) {
  const sim::MotorDescription motor = default_motor();
  const double period = 4096.0 / 4;
  const double friction = friction_angle_counts(motor, 2.0, period);
  for (const InitCase c : {InitCase{0, "estimate"}, InitCase{1, "N channel"}, InitCase{2, "hall"}}) {
    Tmcm1636ServoRig rig(motor);
    rig.sap(44, 20000);
    rig.sap(12, 2000);
    rig.sap(102, c.mode);
    rig.sap(104, 600);
    rig.sap(105, 60);
    ASSERT_EQ(rig.sap(15, 3), 100);
    EXPECT_NE(rig.gap(103), 0) << c.name << ": init started";
    if (c.mode == 2) rig.ror(300);  // the hall edge comes with motion
    const double ms = rig.run_until([&] { return rig.gap(103) == 0; }, 5000);
    ASSERT_LT(ms, 5000) << c.name << ": init state " << rig.gap(103);
    const double tolerance = c.mode == 2 ? 300.0 / 60.0 * 4096.0 * 50e-6 + 1.0 : friction + 2.0;
    const double expected = c.mode == 1 ? rig.plant().abn_count_at_electrical_zero() - rig.plant().abn_count_at_index()
                                        : rig.plant().abn_count_at_electrical_zero();
    const double found = rig.gap(106);
    EXPECT_LE(circular_distance(found, expected, period), tolerance)
        << c.name << ": AP 106 " << found << ", model " << std::fmod(expected + 40960.0, period) << " (mod " << period << ")";
    rig.ror(2000);
    rig.run_ms(400);
    EXPECT_NEAR(rig.speed_rpm(), 2000.0, 20.0) << c.name << ": runs on the ABN encoder after init";
  }
}

TEST(Tmcm1636Servo, absolute_encoder_estimate_finds_the_model_offset) {
  sim::MotorDescription motor = default_motor();
  motor.absolute = {true, 12, 77.0, false};
  Tmcm1636ServoRig rig(motor);
  rig.sap(44, 20000);
  rig.sap(12, 2000);
  rig.sap(160, 1);
  rig.sap(161, 0);
  rig.sap(104, 600);
  ASSERT_EQ(rig.sap(15, 4), 100);
  const double ms = rig.run_until([&] { return rig.gap(103) == 0; }, 3000);
  ASSERT_LT(ms, 3000);
  const double period = 65536.0 / 4;
  const double expected = rig.plant().absolute_reading_at_electrical_zero();
  const double tolerance = friction_angle_counts(motor, 2.0, period) + 16.0;  // plus one 12-bit step
  EXPECT_LE(circular_distance(rig.gap(163), expected, period), tolerance)
      << "AP 163 " << rig.gap(163) << ", model " << expected << " (mod " << period << ", 16 bits per revolution)";
  EXPECT_TRUE(rig.gap(156) & flag::kAbsoluteEncoderReady);
  rig.ror(1500);
  rig.run_ms(400);
  EXPECT_NEAR(rig.speed_rpm(), 1500.0, 15.0);
}

TEST(Tmcm1636Servo, clear_on_null_zeroes_the_position_at_the_n_pulse) {
  Tmcm1636ServoRig rig(default_motor());
  rig.sap(108, 1);  // once
  rig.sap(107, 1);
  rig.ror(600);
  rig.run_ms(300);  // the N pulse at 200° passes within the first revolution
  const int32_t since = rig.gap(52);
  const double revolutions = rig.plant().position_revolutions() - 200.0 / 360.0;
  EXPECT_NEAR(since, revolutions * 4096.0, 8.0) << "counted from the N pulse";
  rig.run_ms(300);  // more pulses pass; clear once keeps counting
  EXPECT_GT(rig.gap(52), 4096);
}

// --- Supply, regeneration, brake chopper --------------------------------------------------------

// Braking a high-inertia load from 3000 rpm returns energy to the bus (15 J into 470 uF): without
// the chopper the bus rises far above the supply (until the overvoltage trip); with it
// (AP 140..142) the bus stays at the limit and the energy goes into the brake resistor.
TEST(Tmcm1636Servo, regeneration_raises_the_bus_until_the_brake_chopper_engages) {
  for (const bool chopper : {false, true}) {
    Tmcm1636ServoRig rig(default_motor());
    rig.set("LOAD_INERTIA", 3e-4);
    rig.sap(44, 1500);
    rig.sap(140, 1);  // spinning up: any overshoot regenerates too
    rig.sap(141, 260);
    rig.sap(142, 5);
    rig.ror(3000);
    rig.run_ms(3000);
    ASSERT_NEAR(rig.speed_rpm(), 3000.0, 30.0);
    rig.sap(140, chopper ? 1 : 0);
    rig.sap(44, 100000);
    rig.mst();
    double peak = 0.0;
    bool chopper_seen = false;
    double volts_when_engaged = 0.0;
    for (int i = 0; i < 20 * 1500; ++i) {
      rig.tick();
      peak = std::max(peak, rig.plant().bus_voltage());
      if (!chopper_seen && rig.gap(144) != 0) {
        chopper_seen = true;
        volts_when_engaged = rig.gap(220) / 10.0;
      }
    }
    if (chopper) {
      EXPECT_TRUE(chopper_seen);
      EXPECT_GE(volts_when_engaged, 26.0) << "engaged at " << volts_when_engaged << " V";
      EXPECT_LT(peak, 27.0) << "peak bus " << peak << " V with the chopper";
      EXPECT_GT(rig.plant().chopper_energy_j(), 1.0) << "energy into the brake resistor";
    } else {
      EXPECT_FALSE(chopper_seen);
      EXPECT_GT(peak, 30.0) << "peak bus " << peak << " V without the chopper";
      EXPECT_TRUE(rig.gap(156) & flag::kOvervoltage) << "the bus reached the overvoltage trip";
    }
  }
}

TEST(Tmcm1636Servo, undervoltage_switches_the_bridge_off) {
  Tmcm1636ServoRig rig(default_motor());
  rig.sap(44, 20000);
  rig.ror(1000);
  rig.run_ms(200);
  rig.set("VSUPPLY", 6.0);
  rig.run_ms(1000);  // the bus capacitance discharges into the motor and the board
  EXPECT_TRUE(rig.gap(156) & flag::kUndervoltage);
  EXPECT_FALSE(rig.gap(156) & flag::kPowerStageOn);
  EXPECT_EQ(rig.plant().iq_amps(), 0.0);
  rig.set("VSUPPLY", 24.0);
  rig.run_ms(300);
  EXPECT_NEAR(rig.speed_rpm(), 1000.0, 15.0) << "back on";
}

TEST(Tmcm1636Servo, overtemperature_switches_the_bridge_off_until_the_driver_cools) {
  Tmcm1636ServoRig rig(default_motor());
  rig.sap(30, 500);
  rig.run_ms(10);
  rig.set("TEMP", 105.0);  // ambient: the driver reads a little more
  rig.run_ms(5);
  EXPECT_GE(rig.gap(221), 105) << "AP 221";
  EXPECT_TRUE(rig.gap(156) & flag::kOvertemperature);
  EXPECT_EQ(rig.plant().iq_amps(), 0.0);
  rig.set("TEMP", 95.0);
  rig.run_ms(5);
  EXPECT_TRUE(rig.gap(156) & flag::kOvertemperature) << "hysteresis: clears below 90 °C";
  rig.set("TEMP", 80.0);
  rig.run_ms(5);
  EXPECT_FALSE(rig.gap(156) & flag::kOvertemperature);
  EXPECT_TRUE(rig.gap(156) & flag::kPowerStageOn);
}

// --- Reference switches, driver enable, brake -------------------------------------------------

TEST(Tmcm1636Servo, reference_switch_stops_the_motor) {
  Tmcm1636ServoRig rig(default_motor());
  rig.set("REF_R_AT", 3.0);  // rotor revolutions
  rig.sap(209, 1);
  rig.sap(210, 1);  // high active
  rig.ror(1000);
  rig.run_ms(1000);
  EXPECT_EQ(rig.gap(211), 1);
  EXPECT_LT(std::fabs(rig.speed_rpm()), 1.0) << "stopped: " << rig.speed_rpm() << " rpm";
  const double stopped = rig.plant().position_revolutions();
  EXPECT_GT(stopped, 3.0);
  EXPECT_LT(stopped, 3.1) << "stops within 0.1 revolution past the switch";
  EXPECT_TRUE(rig.gap(156) & flag::kRightSwitchStop);
  rig.run_ms(200);
  EXPECT_NEAR(rig.plant().position_revolutions(), stopped, 0.01) << "stays";
  rig.command(2, 0, 0, 500);  // ROL: away from the switch
  rig.run_ms(500);
  EXPECT_LT(rig.plant().position_revolutions(), 3.0);
  EXPECT_EQ(rig.gap(211), 0);
}

TEST(Tmcm1636Servo, disabled_driver_removes_torque) {
  Tmcm1636ServoRig rig(default_motor());
  rig.sap(44, 20000);
  rig.ror(2000);
  rig.run_ms(300);
  ASSERT_NEAR(rig.speed_rpm(), 2000.0, 20.0);
  rig.sap(255, 0);
  rig.run_ticks(2);  // the PWM of the tick before still applies once
  EXPECT_EQ(rig.plant().iq_amps(), 0.0);
  EXPECT_EQ(rig.plant().electromagnetic_torque_nm(), 0.0);
  EXPECT_FALSE(rig.gap(156) & flag::kPowerStageOn);
  // It coasts: only friction decelerates it.
  const sim::MotorDescription m = default_motor();
  const double w0 = rig.plant().speed_rad_s();
  rig.run_ms(50);
  const double decel = (w0 - rig.plant().speed_rad_s()) / 0.05;
  const double friction_decel = (m.coulomb_friction_nm + m.viscous_friction_nm_s * w0) / m.rotor_inertia_kgm2;
  EXPECT_NEAR(decel, friction_decel, 0.1 * friction_decel) << "coasting deceleration";
  rig.sap(255, 1);
  rig.run_ms(1000);  // the ramp takes over from the coasting speed
  EXPECT_NEAR(rig.speed_rpm(), 2000.0, 20.0) << "back under control";
}

TEST(Tmcm1636Servo, brake_output_releases_and_holds_the_brake) {
  sim::MotorDescription motor = default_motor();
  motor.brake = {true, 0.5, 50.0, 8.0, 0.015};
  Tmcm1636ServoRig rig(motor);
  rig.sap(44, 20000);
  rig.ror(1000);
  rig.run_ms(300);
  EXPECT_LT(std::fabs(rig.speed_rpm()), 1.0) << "the closed brake holds against the motor";
  EXPECT_EQ(rig.board.read_signal("BRAKE_ENGAGED"), 1.0);
  rig.sap(120, 1);  // release: 75 % for 80 ms, then 11 %
  rig.run_ms(20);
  EXPECT_EQ(rig.board.read_signal("BRAKE_ENGAGED"), 0.0) << "released within 20 ms";
  rig.run_ms(500);
  EXPECT_NEAR(rig.speed_rpm(), 1000.0, 15.0) << "held open at 11 %";
  EXPECT_TRUE(rig.gap(156) & flag::kBrakeReleased);
  rig.sap(122, 5);  // holding duty below the brake's drop-out level
  rig.run_ms(200);
  EXPECT_EQ(rig.board.read_signal("BRAKE_ENGAGED"), 1.0) << "5 % cannot hold it open";
  rig.sap(120, 0);
  rig.sap(122, 11);
  rig.sap(124, 1);  // brake function disabled: the output stays off
  rig.sap(120, 1);
  rig.run_ms(100);
  EXPECT_EQ(rig.board.read_signal("BRAKE_ENGAGED"), 1.0);
}

// --- Measurements and the DC motor ------------------------------------------------------------

TEST(Tmcm1636Servo, adc_readings_and_supply_follow_the_board) {
  Tmcm1636ServoRig rig(default_motor());
  rig.run_ms(10);
  EXPECT_NEAR(rig.gap(0), 32768, 48) << "AP 0 raw at zero current";
  EXPECT_NEAR(rig.gap(2), 0, 48) << "AP 2";
  EXPECT_EQ(rig.gap(4), -rig.gap(2) - rig.gap(3));
  EXPECT_NEAR(rig.gap(220), 240, 1) << "AP 220";
  EXPECT_NEAR(rig.gap(221), 25, 2) << "AP 221 near ambient";
  rig.set("BLOCKED", 1);
  rig.sap(30, 1500);
  rig.run_ms(5);
  const double a = rig.gap(2);
  const double b = rig.gap(3);
  const double c = rig.gap(4);
  const double amplitude = std::hypot(rig.plant().id_amps(), rig.plant().iq_amps()) * 1000.0;
  EXPECT_NEAR(std::sqrt((a * a + b * b + c * c) * 2.0 / 3.0), amplitude, 50.0) << "phase current amplitude";
  EXPECT_NEAR(amplitude, 1500.0, 60.0) << "regulated to AP 30 on a blocked rotor";
}

TEST(Tmcm1636Servo, dc_motor_follows_torque_and_velocity_commands) {
  const sim::MotorDescription motor = Tmcm1636ServoRig::preset("dc-24v");
  Tmcm1636ServoRig rig(motor);
  rig.sap(30, 1000);
  rig.run_ms(5);
  const double w0 = rig.plant().speed_rad_s();
  rig.run_ms(20);
  const double measured = (rig.plant().speed_rad_s() - w0) / 0.02;
  const double mid = 0.5 * (w0 + rig.plant().speed_rad_s());
  const double expected =
      (motor.torque_constant() * 1.0 - motor.coulomb_friction_nm - motor.viscous_friction_nm_s * mid) / motor.rotor_inertia_kgm2;
  EXPECT_NEAR(measured, expected, 0.05 * expected) << "DC torque mode, T/J";
  rig.sap(45, 0);
  rig.ror(1500);
  rig.run_ms(300);
  EXPECT_NEAR(rig.speed_rpm(), 1500.0, 15.0) << "DC velocity mode";
  rig.mvp(0);
  rig.sap(45, 1);
  rig.run_until([&] { return rig.gap(55) == 1; }, 5000);
  EXPECT_LE(std::abs(rig.gap(52)), 5) << "DC position mode";
}

TEST(Tmcm1636Servo, no_motor_type_or_disabled_commutation_gives_no_torque) {
  for (const auto& [type, mode] : {std::pair{0, 2}, std::pair{3, 0}}) {
    Tmcm1636ServoRig rig(default_motor());
    rig.sap(14, type);
    rig.sap(15, mode);
    rig.sap(30, 1000);
    rig.run_ms(100);
    EXPECT_EQ(rig.plant().iq_amps(), 0.0) << "motor type " << type << ", commutation " << mode;
    EXPECT_LT(std::fabs(rig.speed_rpm()), 0.1);
  }
}

// --- Determinism ------------------------------------------------------------------------------

// The same commands and scenario inputs give bit-identical traces (noise included: it is seeded).
TEST(Tmcm1636Servo, the_same_scenario_twice_gives_bit_identical_traces) {
  auto run = [] {
    Tmcm1636ServoRig rig(default_motor());
    std::vector<double> trace;
    rig.ror(1500);
    for (int ms = 0; ms < 1500; ++ms) {
      if (ms == 300) rig.set("LOAD_TORQUE", 0.02);
      if (ms == 600) rig.set("VSUPPLY", 20.0);
      if (ms == 800) rig.mvp(20000);
      if (ms == 1200) rig.set("LOAD_TORQUE", -0.01);
      rig.run_ms(1);
      trace.push_back(rig.plant().mechanical_angle_rad());
      trace.push_back(rig.plant().iq_amps());
      trace.push_back(rig.plant().bus_voltage());
      trace.push_back(rig.gap(52));
      trace.push_back(rig.gap(31));
    }
    return trace;
  };
  const std::vector<double> first = run();
  const std::vector<double> second = run();
  ASSERT_EQ(first.size(), second.size());
  size_t differences = 0;
  for (size_t i = 0; i < first.size(); ++i) {
    if (std::memcmp(&first[i], &second[i], sizeof(double)) != 0) ++differences;
  }
  EXPECT_EQ(differences, 0u) << "values differing between two runs";
}

}  // namespace
}  // namespace motwin::testing
