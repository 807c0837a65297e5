// Simulation speed of one TMCM-1636 axis as a real-time factor (simulated seconds per second of
// CPU time, one core): the full cascade (position P, velocity PI, FOC flux/torque PI, SVM) at the
// 50 µs tick on the motor plant (one exact current step per tick), sensors and supply bus. The
// baseline, measured in the same run, is the ideal motor (the axis follows its ramp, no
// regulators, no plant). Goal: at least 300x for the full cascade. The same motions driven by the
// CANopen firmware (canopen_*: the CiA-402 drive's profile generator ahead of the same cascade,
// the node's services once a millisecond) beside the TMCL firmware's (issue 31: within 10 %).
// See docs/benchmarks.md.
#include <benchmark/benchmark.h>

#include <cstring>
#include <memory>

#include "bench_support.h"
#include "../tests/unit/support/tmcm1636_rig.h"
#include "../tests/unit/support/tmcm1636_servo_rig.h"
#include "board/ram_non_volatile_memory.h"
#include "core/modules/tmcm1636/tmcm1636_canopen.h"
#include "host/canopen_dictionary_view.h"

namespace {

using motwin::testing::Tmcm1636Rig;
using motwin::testing::Tmcm1636ServoRig;

constexpr const char* kBaselineName = "ideal_motor_baseline";
constexpr double kGoalRealTimeFactor = 300.0;  // issue 18: position mode on a physical motor
constexpr uint64_t kTicksPerIteration = 20'000;  // one simulated second
constexpr double kSimSecondsPerIteration = kTicksPerIteration * motwin::modules::tmcm1636::kControlTickUs * 1e-6;

void report(benchmark::State& state) { motwin::bench::report_real_time_factor(state, kSimSecondsPerIteration); }

// Baseline: the ideal motor in velocity mode.
void ideal_motor(benchmark::State& state) {
  Tmcm1636Rig rig;
  rig.command(1, 0, 0, 2000);  // ROR 2000 rpm
  for (auto _ : state) {
    for (uint64_t i = 0; i < kTicksPerIteration; ++i) rig.module.tick();
    benchmark::DoNotOptimize(rig.module.axis().state.actual_position);
  }
  report(state);
}

// Velocity mode at 2000 rpm with a load: velocity PI, FOC, plant.
void servo_velocity(benchmark::State& state, const char* motor) {
  Tmcm1636ServoRig rig(Tmcm1636ServoRig::preset(motor));
  rig.ror(2000);
  rig.set("LOAD_TORQUE", 0.01);
  for (auto _ : state) {
    rig.run_ticks(kTicksPerIteration);
    benchmark::DoNotOptimize(rig.plant().speed_rad_s());
  }
  report(state);
}

// Position mode: MVP back and forth by 10 revolutions, so that the whole cascade and the ramp's
// braking point run (position P -> velocity PI -> FOC).
void servo_position(benchmark::State& state, const char* motor) {
  Tmcm1636ServoRig rig(Tmcm1636ServoRig::preset(motor));
  const int32_t distance = 10 * rig.gap(100);
  int32_t target = distance;
  for (auto _ : state) {
    rig.mvp(target);
    target = target == 0 ? distance : 0;
    rig.run_ticks(kTicksPerIteration);
    benchmark::DoNotOptimize(rig.plant().mechanical_angle_rad());
  }
  report(state);
}

// The CANopen firmware on the same board and preset, its objects written as an SDO download would
// (through the dictionary), NMT operational and the PDS at OPERATION ENABLED in `mode`.
struct CanopenServo {
  using Module = motwin::modules::tmcm1636::Tmcm1636Canopen;
  std::unique_ptr<motwin::board::RamNonVolatileMemory<Module::kNvmSize>> nvm =
      std::make_unique<motwin::board::RamNonVolatileMemory<Module::kNvmSize>>();
  motwin::host::NullCanController can;
  motwin::sim::Tmcm1636SimIo io;
  motwin::sim::Tmcm1636SimBoard board;
  Module module{*nvm, can, board.io()};

  CanopenServo(const char* motor, int8_t mode) : board(io, *motwin::sim::motor_preset(motor)) {
    Module::format_factory_image(nvm->mutable_data(), nvm->size());
    motwin::host::write_tmcm1636_canopen_startup_image(*motwin::sim::motor_preset(motor), nvm->mutable_data(),
                                                      nvm->size());
    module.axis().attach_power_stage(board.power_stage());
    module.power_up();
    // The TMCL cases' ramp: 2000 rpm/s (AP 44's default) both ways; positions in encoder steps.
    write(0x2058, 0, read(0x2080, 2));
    write(0x6081, 0, 4000);
    write(0x6083, 0, 2000);
    write(0x6084, 0, 2000);
    write(0x6060, 0, mode);
    for (const int64_t controlword : {0x06, 0x07, 0x0F}) write(0x6040, 0, controlword);
  }
  int64_t read(uint16_t index, uint8_t sub) {
    motwin::canopen::ObjectRef ref;
    module.dictionary().find(index, sub, ref);
    return module.dictionary().value(ref);
  }
  void write(uint16_t index, uint8_t sub, int64_t value) {
    motwin::canopen::ObjectRef ref;
    if (module.dictionary().find(index, sub, ref) != motwin::canopen::SdoAbort::kNone) std::abort();
    uint8_t bytes[4];
    motwin::canopen::encode_value(ref.info->type, value, bytes);
    if (module.dictionary().write(ref, bytes, motwin::canopen::type_size(ref.info->type)) !=
        motwin::canopen::SdoAbort::kNone) {
      std::abort();
    }
  }
  void run_ticks(uint64_t ticks) {
    for (uint64_t i = 0; i < ticks; ++i) {
      board.before_tick();
      module.tick();
      board.after_tick(Tmcm1636ServoRig::kTickS);
    }
  }
};

// servo_velocity's motion with the CANopen firmware in pv.
void canopen_velocity(benchmark::State& state, const char* motor) {
  CanopenServo servo(motor, 3);
  servo.write(0x60FF, 0, 2000);
  servo.board.set_input("LOAD_TORQUE", 0.01);
  for (auto _ : state) {
    servo.run_ticks(kTicksPerIteration);
    benchmark::DoNotOptimize(servo.board.plant()->speed_rad_s());
  }
  report(state);
}

// servo_position's motion with the CANopen firmware in pp: 10 revolutions back and forth.
void canopen_position(benchmark::State& state, const char* motor) {
  CanopenServo servo(motor, 1);
  const int64_t distance = 10 * servo.read(0x2080, 2);
  int64_t target = distance;
  for (auto _ : state) {
    servo.write(0x607A, 0, target);
    servo.write(0x6040, 0, 0x0F);
    servo.write(0x6040, 0, 0x3F);  // new set-point, at once
    target = target == 0 ? distance : 0;
    servo.run_ticks(kTicksPerIteration);
    benchmark::DoNotOptimize(servo.board.plant()->mechanical_angle_rad());
  }
  report(state);
}

}  // namespace

int main(int argc, char** argv) {
  benchmark::Initialize(&argc, argv);
  if (benchmark::ReportUnrecognizedArguments(argc, argv)) return 1;
  benchmark::RegisterBenchmark(kBaselineName, ideal_motor)->Unit(benchmark::kMillisecond);
  benchmark::RegisterBenchmark("servo_velocity/default-24v", servo_velocity, "default-24v")->Unit(benchmark::kMillisecond);
  benchmark::RegisterBenchmark("servo_position/default-24v", servo_position, "default-24v")->Unit(benchmark::kMillisecond);
  benchmark::RegisterBenchmark("servo_position/large-48v", servo_position, "large-48v")->Unit(benchmark::kMillisecond);
  benchmark::RegisterBenchmark("servo_velocity/dc-24v", servo_velocity, "dc-24v")->Unit(benchmark::kMillisecond);
  benchmark::RegisterBenchmark("canopen_velocity/default-24v", canopen_velocity, "default-24v")
      ->Unit(benchmark::kMillisecond);
  benchmark::RegisterBenchmark("canopen_position/default-24v", canopen_position, "default-24v")
      ->Unit(benchmark::kMillisecond);
  // Issue 31: the CANopen firmware within 10 % of the TMCL firmware on the same motion.
  motwin::bench::RealTimeFactorReporter reporter(
      {kBaselineName,
       "the ideal motor",
       kGoalRealTimeFactor,
       40,
       {{"canopen_velocity/default-24v", "servo_velocity/default-24v", "canopen/tmcl", 0.90},
        {"canopen_position/default-24v", "servo_position/default-24v", "canopen/tmcl", 0.90}}});
  benchmark::RunSpecifiedBenchmarks(&reporter);
  benchmark::Shutdown();
  return 0;
}
