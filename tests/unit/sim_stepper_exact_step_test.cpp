// The stepper plant's default stepping (StepperPlant::kAdaptiveSubSteps: 1 or 2 steps per 50 µs
// tick, the back-EMF integrated exactly over each, the rotor by leapfrog) against the sub-step
// integrator it replaced (kReferenceSubSteps = 4) and a fine one (32 sub-steps), on the same
// moves; and StallGuard's load angle from the plant's sin and cos against atan2 and sin.
// The bounds and why: docs/stepper-motion.md "Hybrid stepper model".
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <cstdint>

#include "board/stepper_drive.h"
#include "core/motion/microstep_table.h"
#include "core/motion/s_ramp.h"
#include "sim/stallguard_model.h"
#include "sim/stepper_plant.h"

namespace motwin::sim {
namespace {

constexpr double kDt = 50e-6;
constexpr uint32_t kMicrosteps = 256;
constexpr double kMicrostepsPerRev = 200.0 * kMicrosteps;
constexpr int kFineSubSteps = 32;

// A driver at a fixed current following an S-ramp, as the modules' tick does it.
struct Axis {
  Axis(const StepperMotorDescription& motor, int sub_steps, int32_t run_current_ma, double velocity_rps, double supply)
      : plant(motor, sub_steps), current_ma(run_current_ma), supply_volt(supply) {
    config.max_velocity = velocity_rps * kMicrostepsPerRev;
    config.acceleration = 10.0 * kMicrostepsPerRev;
    drive.enabled = true;
  }
  void tick() {
    ramp.step(config, kDt);
    drive.electrical_angle = motion::electrical_angle_of(ramp.position(), kMicrosteps);
    const motion::CoilCurrents currents = motion::coil_currents(drive.electrical_angle, current_ma);
    drive.coil_a_ma = currents.coil_a_ma;
    drive.coil_b_ma = currents.coil_b_ma;
    plant.advance(drive, supply_volt, kDt);
  }

  StepperPlant plant;
  motion::SRamp ramp;
  motion::SRampConfig config;
  board::StepperDrive drive;
  int32_t current_ma;
  double supply_volt;
};

struct Deviation {
  double position_full_steps = 0.0;
  double velocity_rps = 0.0;
  double current_a = 0.0;
  double final_position_full_steps = 0.0;
};

// A move of 10 revolutions and back with a load, the default stepping against `sub_steps`.
Deviation move(const StepperMotorDescription& motor, int sub_steps, double velocity_rps, double supply,
               int32_t current_ma) {
  Axis fast(motor, StepperPlant::kAdaptiveSubSteps, current_ma, velocity_rps, supply);
  Axis reference(motor, sub_steps, current_ma, velocity_rps, supply);
  Deviation worst;
  for (Axis* axis : {&fast, &reference}) axis->plant.set_load_torque_nm(0.2 * motor.holding_torque_nm());
  for (int32_t target : {static_cast<int32_t>(10 * kMicrostepsPerRev), 0}) {
    fast.ramp.set_position_target(target);
    reference.ramp.set_position_target(target);
    const int ticks = static_cast<int>((10.0 / velocity_rps + 0.5) / kDt);
    for (int i = 0; i < ticks; ++i) {
      fast.tick();
      reference.tick();
      worst.position_full_steps =
          std::max(worst.position_full_steps,
                   200.0 * std::fabs(fast.plant.position_revolutions() - reference.plant.position_revolutions()));
      worst.velocity_rps =
          std::max(worst.velocity_rps, std::fabs(fast.plant.velocity_rps() - reference.plant.velocity_rps()));
      worst.current_a = std::max({worst.current_a,
                                  std::fabs(fast.plant.coil_a_current_a() - reference.plant.coil_a_current_a()),
                                  std::fabs(fast.plant.coil_b_current_a() - reference.plant.coil_b_current_a())});
    }
  }
  worst.final_position_full_steps =
      200.0 * std::fabs(fast.plant.position_revolutions() - reference.plant.position_revolutions());
  return worst;
}

// The rotor rings at its resonance (a few hundred hertz, barely damped) whenever the ramp changes
// its acceleration, so any two integrations drift apart in phase within that ringing, today's
// 4 sub-steps against 32 as much as the new stepping: what is bounded is the rotor's difference
// (below 0.3 full steps, far inside the 4 full steps of a lost electrical period; at rest on the
// target below 0.002), the speed within the ringing (below 2 rps) and the coil currents (the
// chopper holds them on target at 24 V; at 12 V and 5 rps the back-EMF limits them: below
// 0.2 A of 1.5 A).
TEST(StepperExactStep, moves_match_the_fine_sub_steps) {
  struct Case {
    const char* name;
    StepperMotorDescription motor;
    double velocity_rps;
    double supply;
    int32_t current_ma;
  };
  const Case cases[] = {
      {"nema17 2 rps 24 V", StepperMotorDescription::nema17(), 2.0, 24.0, 1500},
      {"nema17 5 rps 12 V (back-EMF limited)", StepperMotorDescription::nema17(), 5.0, 12.0, 1500},
      {"nema23 3 rps 24 V", StepperMotorDescription::nema23(), 3.0, 24.0, 2800},
  };
  for (const Case& c : cases) {
    SCOPED_TRACE(c.name);
    const Deviation fine = move(c.motor, kFineSubSteps, c.velocity_rps, c.supply, c.current_ma);
    const Deviation today = move(c.motor, StepperPlant::kReferenceSubSteps, c.velocity_rps, c.supply, c.current_ma);
    // Measured (this commit): 0.02 / 0.08 / 0.19 full steps, 0.18 / 0.76 / 1.33 rps, 0.14 A in the
    // back-EMF-limited case; today's 4 sub-steps lie as far from the fine ones.
    EXPECT_LT(fine.position_full_steps, 0.3) << "rotor vs 32 sub-steps, full steps";
    EXPECT_LT(fine.final_position_full_steps, 0.002) << "at rest on the target";
    EXPECT_LT(fine.velocity_rps, 2.0) << "within the ringing";
    EXPECT_LT(fine.current_a, 0.2);
    EXPECT_LT(today.position_full_steps, 0.3) << "rotor vs today's 4 sub-steps, full steps";
    EXPECT_LT(today.final_position_full_steps, 0.002);
    EXPECT_LT(today.velocity_rps, 2.0);
    EXPECT_LT(today.current_a, 0.2);
  }
}

// StallGuard's load angle from sin and cos (no atan2, no sin per tick; the plant's pair rotated
// between exact ones every millisecond) equals the angle path up to rounding: the results agree
// exactly, the load fractions within 1e-9, over a loaded run, a stall and an open bridge.
TEST(StepperExactStep, stallguard_from_sin_and_cos_equals_the_angle_path) {
  Axis axis(StepperMotorDescription::nema17(), StepperPlant::kAdaptiveSubSteps, 1500, 3.0, 24.0);
  axis.ramp.set_position_target(static_cast<int32_t>(20 * kMicrostepsPerRev));
  StallGuardModel from_sin_cos;
  StallGuardModel from_angles;
  StallGuardSettings settings;
  int results = 0;
  for (int i = 0; i < 60000; ++i) {
    if (i == 20000) axis.plant.set_load_torque_nm(0.25);
    if (i == 30000) axis.plant.set_blocked(true);
    if (i == 40000) axis.drive.enabled = false;
    if (i == 41000) {
      axis.drive.enabled = true;
      axis.plant.set_blocked(false);
      axis.plant.set_load_torque_nm(0.0);
    }
    axis.tick();
    from_sin_cos.update(axis.plant, axis.drive, settings, kDt);
    const double ia = axis.plant.coil_a_current_a();
    const double ib = axis.plant.coil_b_current_a();
    const bool present = std::hypot(ia, ib) > 1e-3;
    const double rotor = axis.plant.electrical_angle_rad();
    from_angles.update_with_angles(axis.drive, (present ? std::atan2(ib, ia) : 0.0) - rotor, rotor, present, settings,
                                   kDt);
    ASSERT_EQ(from_sin_cos.stallguard2_result(), from_angles.stallguard2_result()) << "tick " << i;
    ASSERT_EQ(from_sin_cos.measurements(), from_angles.measurements()) << "tick " << i;
    ASSERT_NEAR(from_sin_cos.last_load_fraction(), from_angles.last_load_fraction(), 1e-9) << "tick " << i;
    results = static_cast<int>(from_sin_cos.measurements());
  }
  EXPECT_GT(results, 100);
}

// The adaptive choice: the presets take 2 (NEMA17) and 1 (NEMA23) steps per tick; a light rotor
// takes up to 4, the reference's count, whose stability the motor check guarantees.
TEST(StepperExactStep, adaptive_sub_steps_follow_the_step_number) {
  board::StepperDrive drive;
  StepperPlant nema17(StepperMotorDescription::nema17());
  nema17.advance(drive, 24.0, kDt);
  EXPECT_EQ(nema17.sub_steps(), 2);
  StepperPlant nema23(StepperMotorDescription::nema23());
  nema23.advance(drive, 24.0, kDt);
  EXPECT_EQ(nema23.sub_steps(), 1);
  StepperMotorDescription light = StepperMotorDescription::nema17();
  light.rotor_inertia_kg_m2 = StepperPlant::min_stable_inertia_kg_m2(light, kDt / StepperPlant::kFinestSubSteps);
  StepperPlant light_plant(light);
  light_plant.advance(drive, 24.0, kDt);
  EXPECT_EQ(light_plant.sub_steps(), 4);
  // A load inertia lowers the step number: the same motor needs fewer steps.
  nema17.set_load_inertia_kg_m2(10 * StepperMotorDescription::nema17().rotor_inertia_kg_m2);
  nema17.advance(drive, 24.0, kDt);
  EXPECT_EQ(nema17.sub_steps(), 1);
  for (StepperPlant* p : {&nema17, &nema23, &light_plant}) {
    EXPECT_LE(StepperPlant::step_number(p->motor(), kDt / p->sub_steps()), StepperPlant::kStableStepNumber + 1e-9);
  }
}

}  // namespace
}  // namespace motwin::sim
