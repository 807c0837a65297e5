// Simulation speed of one stepper axis (the TMCM-142's, each of the TMCM-3216's) as a real-time
// factor (simulated seconds per second of CPU time, one core): per 50 µs tick the S-ramp, the
// microstep table and the motor (hybrid stepper plant with 1 or 2 steps per tick, or the ideal
// motor), and the encoder and switch sensors. The baseline, measured in the same run, is the S-ramp alone.
// Goal: well above 200x for the whole axis. See docs/benchmarks.md.
#include <benchmark/benchmark.h>

#include "bench_support.h"
#include "board/stepper_drive.h"
#include "core/motion/microstep_table.h"
#include "core/motion/s_ramp.h"
#include "sim/stepper_plant.h"

namespace {

namespace motion = motwin::motion;
namespace sim = motwin::sim;
namespace board = motwin::board;

constexpr const char* kBaselineName = "s_ramp_baseline";
constexpr double kGoalRealTimeFactor = 200.0;
constexpr double kTickS = 50e-6;
constexpr uint64_t kTicksPerIteration = 20'000;  // one simulated second
constexpr double kSimSecondsPerIteration = kTicksPerIteration * kTickS;
constexpr uint32_t kMicrosteps = 256;
constexpr double kMicrostepsPerRev = 200.0 * kMicrosteps;

// 5 rps, 20 rps², S-shaped; the target alternates between 0 and 8 revolutions every simulated
// second, so that every part of the ramp runs (S-curves, cruise, braking point, reversals).
motion::SRampConfig ramp_config() {
  motion::SRampConfig config;
  config.max_velocity = 5.0 * kMicrostepsPerRev;
  config.acceleration = 20.0 * kMicrostepsPerRev;
  config.deceleration = 20.0 * kMicrostepsPerRev;
  for (double& bow : config.bow) bow = 400.0 * kMicrostepsPerRev;
  return config;
}

void report(benchmark::State& state) { motwin::bench::report_real_time_factor(state, kSimSecondsPerIteration); }

int32_t next_target(int32_t target) { return target == 0 ? static_cast<int32_t>(8 * kMicrostepsPerRev) : 0; }

void s_ramp_alone(benchmark::State& state) {
  const motion::SRampConfig config = ramp_config();
  motion::SRamp ramp;
  int32_t target = 0;
  for (auto _ : state) {
    target = next_target(target);
    ramp.set_position_target(target);
    for (uint64_t i = 0; i < kTicksPerIteration; ++i) ramp.step(config, kTickS);
    benchmark::DoNotOptimize(ramp.position_q32());
  }
  report(state);
}

// The drive stage of a tick: the microstep counter as an electrical angle and the table's
// coil currents at the run current.
void drive_from(const motion::SRamp& ramp, board::StepperDrive& drive) {
  drive.electrical_angle = motion::electrical_angle_of(ramp.position(), kMicrosteps);
  const motion::CoilCurrents currents = motion::coil_currents(drive.electrical_angle, 1500);
  drive.coil_a_ma = currents.coil_a_ma;
  drive.coil_b_ma = currents.coil_b_ma;
}

sim::StepperSensorConfig sensor_config() {
  sim::StepperSensorConfig config;
  config.encoder.counts_per_revolution = 4000;
  config.encoder.index_revolutions = 0.3;
  config.left = {true, -1e300, -1.0, false};
  config.right = {true, 9.0, 1e300, false};
  config.home = {true, 0.0, 0.05, true};
  return config;
}

void ideal_axis(benchmark::State& state) {
  const motion::SRampConfig config = ramp_config();
  motion::SRamp ramp;
  sim::IdealStepper motor;
  sim::StepperSensors sensors(sensor_config());
  board::StepperPowerStage stage;
  stage.drive.enabled = true;
  int32_t target = 0;
  for (auto _ : state) {
    target = next_target(target);
    ramp.set_position_target(target);
    for (uint64_t i = 0; i < kTicksPerIteration; ++i) {
      sensors.sense(motor.position_revolutions(), stage.feedback);
      ramp.step(config, kTickS);
      drive_from(ramp, stage.drive);
      motor.advance(stage.drive, kTickS);
    }
    benchmark::DoNotOptimize(stage.feedback.encoder_count);
  }
  report(state);
}

void plant_axis(benchmark::State& state, sim::StepperMotorDescription motor_description) {
  const motion::SRampConfig config = ramp_config();
  motion::SRamp ramp;
  sim::StepperPlant plant(motor_description);
  plant.set_load_torque_nm(0.05);
  sim::StepperSensors sensors(sensor_config());
  board::StepperPowerStage stage;
  stage.drive.enabled = true;
  int32_t target = 0;
  for (auto _ : state) {
    target = next_target(target);
    ramp.set_position_target(target);
    for (uint64_t i = 0; i < kTicksPerIteration; ++i) {
      sensors.sense(plant.position_revolutions(), stage.feedback);
      ramp.step(config, kTickS);
      drive_from(ramp, stage.drive);
      plant.advance(stage.drive, stage.feedback.supply_millivolt * 1e-3, kTickS);
    }
    benchmark::DoNotOptimize(stage.feedback.encoder_count);
  }
  report(state);
}

}  // namespace

int main(int argc, char** argv) {
  benchmark::Initialize(&argc, argv);
  if (benchmark::ReportUnrecognizedArguments(argc, argv)) return 1;
  benchmark::RegisterBenchmark(kBaselineName, s_ramp_alone)->Unit(benchmark::kMillisecond);
  benchmark::RegisterBenchmark("ideal_motor_axis", ideal_axis)->Unit(benchmark::kMillisecond);
  benchmark::RegisterBenchmark("plant_axis/nema17", plant_axis, sim::StepperMotorDescription::nema17())
      ->Unit(benchmark::kMillisecond);
  benchmark::RegisterBenchmark("plant_axis/nema23", plant_axis, sim::StepperMotorDescription::nema23())
      ->Unit(benchmark::kMillisecond);
  motwin::bench::RealTimeFactorReporter reporter({kBaselineName, "the S-ramp alone", kGoalRealTimeFactor, 28});
  benchmark::RunSpecifiedBenchmarks(&reporter);
  benchmark::Shutdown();
  return 0;
}
