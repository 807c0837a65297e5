// The simulated TMCM-3216 board (sim/modules/tmcm3216/tmcm3216_sim_board.h) driven by the core's stepper axes:
// motion of the ideal and the physical motors, switch windows, encoder and index polarity, a
// blocked axis losing steps with StallGuard falling, driver faults, brake, I/O and signals.
#include <gtest/gtest.h>

#include <array>
#include <cmath>
#include <cstdint>
#include <cstdio>
#include <vector>

#include "core/modules/tmcm3216/tmcm3216.h"
#include "core/modules/tmcm3216/tmcm3216_io.h"
#include "core/modules/tmcm3216/tmcm3216_stepper.h"
#include "sim/scenario.h"
#include "sim/stepper_plant.h"
#include "sim/modules/tmcm3216/tmcm3216_sim_board.h"
#include "host/modules/tmcm3216/tmcm3216_virtual_module.h"

namespace motwin::sim {
namespace {

using modules::tmcm3216::StepperDemand;
using modules::tmcm3216::Tmcm3216GeneralIo;
using modules::tmcm3216::Tmcm3216Stepper;

constexpr uint32_t kTickUs = 50;
constexpr double kTickS = kTickUs * 1e-6;
constexpr double kMicrostepsPerRev = 200.0 * 256.0;

// The three core axes and the I/O on the sim board, ticked the way the module does it. Each axis
// runs at a constant velocity (microsteps/s, with a fractional accumulator) when told to.
struct Rig {
  Tmcm3216SimBoard board;
  std::array<Tmcm3216Stepper, 3> steppers;
  std::array<StepperDemand, 3> demands;
  std::array<double, 3> velocity_pps{};
  std::array<double, 3> position_exact{};
  Tmcm3216GeneralIo io;

  Rig() = default;
  explicit Rig(const StepperMotorDescription& motor, int sub_steps = StepperPlant::kDefaultSubSteps)
      : board(motor, sub_steps) {}

  void enable(uint8_t axis) {
    demands[axis].power_enabled = true;
    demands[axis].brake_released_request = true;
    demands[axis].switch_on_disabled = false;
  }
  void tick() {
    board.before_tick();
    io.sample(board.board().io);
    bool brake_control[3];
    uint8_t brake_duty[3];
    for (uint8_t a = 0; a < 3; ++a) {
      position_exact[a] += velocity_pps[a] * kTickS;
      demands[a].position_usteps = static_cast<int32_t>(std::llround(position_exact[a]));
      demands[a].velocity_pps = static_cast<int32_t>(velocity_pps[a]);
      steppers[a].tick(board.board().axes[a], demands[a], kTickUs);
      brake_control[a] = steppers[a].brake_control();
      brake_duty[a] = steppers[a].brake_duty();
    }
    io.drive(board.board().io, brake_control, brake_duty);
    board.after_tick(kTickS);
  }
  void run_ms(double ms) {
    const auto ticks = static_cast<uint64_t>(std::llround(ms * 1000.0 / kTickUs));
    for (uint64_t i = 0; i < ticks; ++i) tick();
  }
};

TEST(Tmcm3216SimBoard, IdealMotorsFollowTheirAxesExactly) {
  Rig rig;
  for (uint8_t a = 0; a < 3; ++a) rig.enable(a);
  rig.steppers[0].objects.encoder_increments = 4000;
  rig.tick();  // the axes take their first demand as where they are
  rig.velocity_pps = {51200.0, -25600.0, 0.0};
  rig.run_ms(1000);
  rig.velocity_pps = {0.0, 0.0, 0.0};
  rig.run_ms(1);
  EXPECT_EQ(rig.demands[0].position_usteps, 51200);
  EXPECT_DOUBLE_EQ(rig.board.rotor_revolutions(0), 1.0);
  EXPECT_DOUBLE_EQ(rig.board.rotor_revolutions(1), -0.5);
  EXPECT_DOUBLE_EQ(rig.board.rotor_revolutions(2), 0.0);
  EXPECT_EQ(rig.steppers[0].encoder_count(), 4000);
  EXPECT_EQ(rig.steppers[0].encoder_position(), 51200);
  EXPECT_EQ(*rig.board.read_signal("AXIS1_ENCODER_COUNT"), -2000);
}

TEST(Tmcm3216SimBoard, SwitchWindowsAndLevelsPerAxis) {
  Rig rig;
  rig.enable(1);
  rig.board.set_input("AXIS1_REF_R_AT", 0.25);
  rig.board.set_input("AXIS1_REF_H_FROM", 0.1);
  rig.board.set_input("AXIS1_REF_H_TO", 0.2);
  rig.board.set_input("AXIS2_REF_L", 1);
  rig.tick();
  EXPECT_EQ(rig.board.board().axes[1].feedback.switches, 0);
  EXPECT_EQ(rig.board.board().axes[2].feedback.switches, 0b010);
  EXPECT_TRUE(rig.steppers[2].switches().left);
  // Forward at 1/4 revolution per second: home from 0.1 to 0.2 revolutions, right limit from 0.25.
  rig.velocity_pps[1] = kMicrostepsPerRev / 4;
  rig.run_ms(500);  // 0.125 rev
  EXPECT_TRUE(rig.steppers[1].switches().home);
  EXPECT_FALSE(rig.steppers[1].switches().right);
  rig.run_ms(400);  // 0.225 rev
  EXPECT_FALSE(rig.steppers[1].switches().home);
  rig.run_ms(200);  // 0.275 rev
  EXPECT_TRUE(rig.steppers[1].switches().right);
  EXPECT_EQ(*rig.board.read_signal("AXIS1_REF_R"), 1.0);
  EXPECT_EQ(*rig.board.read_signal("AXIS1_REF_R_AT"), 0.25);
}

TEST(Tmcm3216SimBoard, IndexPulsesNeedTheMatchingPolarity) {
  Rig rig;
  rig.enable(0);
  rig.board.set_input("AXIS0_ENCODER_INDEX_AT", 0.5);
  rig.tick();
  rig.velocity_pps[0] = kMicrostepsPerRev;  // 1 rev/s
  rig.run_ms(600);
  EXPECT_EQ(rig.steppers[0].index_events(), 1u);
  // The N pulse at 0.5 rev = 25600 µsteps, latched within one tick's motion (2.56 µsteps).
  EXPECT_NEAR(rig.steppers[0].index_position(), 25600, 3);
  // An active-low N channel with 200B sub 1 = 0: the interface sees no pulse.
  rig.board.set_input("AXIS0_ENCODER_INDEX_ACTIVE_LOW", 1);
  rig.run_ms(1000);
  EXPECT_EQ(rig.steppers[0].index_events(), 1u);
  // 200B sub 1 = 1 (the core writes it to the interface): seen again.
  rig.steppers[0].objects.encoder_index_inverted = 1;
  rig.run_ms(1000);
  EXPECT_EQ(rig.steppers[0].index_events(), 2u);
  EXPECT_NEAR(rig.steppers[0].index_position(), 2.5 * kMicrostepsPerRev, 3);
}

TEST(Tmcm3216SimBoard, BlockedAxisLosesStepsAndStallGuardFalls) {
  Rig rig(StepperMotorDescription::nema17());
  rig.enable(0);
  rig.enable(1);
  for (uint8_t a = 0; a < 2; ++a) {
    rig.steppers[a].objects.run_current = 255;  // 3000 mA peak range x 32/32
    rig.steppers[a].objects.current_range = 1;  // 2 A peak: NEMA17 rated 1.5 A
    rig.steppers[a].objects.stop_on_stall_velocity = 1000;
    rig.steppers[a].objects.encoder_increments = 4000;
  }
  rig.run_ms(20);
  // Both at 2 rev/s (400 full steps/s); axis 1 runs into an obstacle after 300 ms.
  rig.velocity_pps = {2 * kMicrostepsPerRev, 2 * kMicrostepsPerRev, 0.0};
  rig.run_ms(300);
  const uint16_t free_running_sg = rig.steppers[1].load_value();
  EXPECT_GT(free_running_sg, 300);
  EXPECT_FALSE(rig.steppers[1].stall_detected());
  rig.board.set_input("AXIS1_BLOCKED", 1);
  const double blocked_at = rig.board.rotor_revolutions(1);
  rig.run_ms(200);
  // The free axis followed its demand; the blocked one stayed put while the field ran on.
  EXPECT_NEAR(rig.board.rotor_revolutions(0) * kMicrostepsPerRev, rig.demands[0].position_usteps, 256 * 2);
  EXPECT_NEAR(rig.board.rotor_revolutions(1), blocked_at, 1e-9);
  const double lost_usteps = rig.demands[1].position_usteps - rig.steppers[1].encoder_position();
  EXPECT_GT(lost_usteps, 0.19 * kMicrostepsPerRev * 2 - 512);
  EXPECT_GT(rig.steppers[0].load_value(), 300);
  EXPECT_LT(rig.steppers[1].load_value(), 50);
  EXPECT_EQ(rig.steppers[1].load_value(), *rig.board.read_signal("AXIS1_SG2"));
  EXPECT_TRUE(rig.steppers[1].stall_detected());
  EXPECT_FALSE(rig.steppers[0].stall_detected());
  std::printf("free-running SG2 %u, blocked SG2 %u, steps lost %.0f µsteps\n", free_running_sg,
              rig.steppers[1].load_value(), lost_usteps);
}

TEST(Tmcm3216SimBoard, CoolStepLowersTheCurrentUnloadedAndRaisesItUnderLoad) {
  Rig rig(StepperMotorDescription::nema17());
  rig.enable(0);
  Tmcm3216Stepper& axis = rig.steppers[0];
  axis.objects.run_current = 120;  // CS 15: 3000 x 16 / 32 = 1500 mA
  axis.objects.coolstep_hysteresis_start = 6;  // SEMIN: raise below 192
  axis.objects.coolstep_hysteresis = 4;        // SEMAX: lower from 352 on
  axis.objects.coolstep_up_step = 2;
  axis.objects.coolstep_down_step = 1;
  axis.objects.stallguard2_filter = 1;
  axis.objects.coolstep_threshold_velocity = 10000;
  axis.objects.encoder_increments = 4000;
  rig.run_ms(10);
  rig.velocity_pps[0] = 2 * kMicrostepsPerRev;
  rig.run_ms(1000);
  EXPECT_TRUE(axis.coolstep_active());
  EXPECT_EQ(axis.current_scale(), 7);  // the floor: half the run current (2098 = 0)
  EXPECT_EQ(axis.current_ma(), 750);
  // 0.15 N m and about 0.0175 N m of friction against K = 0.27 N m/A: the floor's 750 mA still
  // holds it (at SG ~ 120); SG inside 192..352 needs 0.76..0.95 A: CS 8..9.
  rig.board.set_input("AXIS0_LOAD_TORQUE", 0.15);
  rig.run_ms(1000);
  EXPECT_GE(axis.current_scale(), 8);
  EXPECT_LE(axis.current_scale(), 9);
  const double lag_usteps = rig.demands[0].position_usteps - axis.encoder_position();
  EXPECT_LT(std::fabs(lag_usteps), 256.0);  // no step lost: less than the load angle's full step
  std::printf("CoolStep under 0.15 N m: CS %u, load value %u, lag %.0f µsteps\n", axis.current_scale(),
              axis.load_value(), lag_usteps);
  // Stopped: CoolStep is off, the run current is back until the standby delay.
  rig.velocity_pps[0] = 0.0;
  rig.run_ms(10);
  EXPECT_FALSE(axis.coolstep_active());
  EXPECT_EQ(axis.current_ma(), 1500);
}

TEST(Tmcm3216SimBoard, DriverFaultsAreFlaggedAndCutTheBridges) {
  Rig rig(StepperMotorDescription::nema17());
  rig.enable(2);
  rig.run_ms(5);
  EXPECT_GT(std::fabs(*rig.board.read_signal("AXIS2_COIL_A_A")), 1.0);
  rig.board.set_input("AXIS2_OPEN_COIL_A", 1);
  rig.run_ms(5);
  EXPECT_EQ(rig.steppers[2].driver_error_flags(), board::kDriverOpenLoadA);
  EXPECT_NEAR(*rig.board.read_signal("AXIS2_COIL_A_A"), 0.0, 1e-3);
  rig.board.set_input("AXIS2_OPEN_COIL_A", 0);
  rig.board.set_input("AXIS2_SHORT", 1);
  rig.board.set_input("AXIS2_DRIVER_TEMP", 130);
  rig.run_ms(5);
  EXPECT_EQ(rig.steppers[2].driver_error_flags(),
            board::kDriverOvercurrentA | board::kDriverOvercurrentB | board::kDriverTemperatureWarning);
  EXPECT_NEAR(*rig.board.read_signal("AXIS2_COIL_A_A"), 0.0, 1e-3);
  rig.board.set_input("AXIS2_SHORT", 0);
  rig.board.set_input("AXIS2_DRIVER_TEMP", 150);
  rig.board.set_input("VSUPPLY", 7.5);
  rig.run_ms(1);
  EXPECT_EQ(rig.steppers[2].driver_error_flags(),
            board::kDriverOvertemperature | board::kDriverTemperatureWarning | board::kDriverUndervoltage);
}

TEST(Tmcm3216SimBoard, BrakeHoldsTheRotorUntilItsOutputCarriesCurrent) {
  Rig rig(StepperMotorDescription::nema17());
  rig.board.set_input("AXIS0_BRAKE", 1);
  rig.steppers[0].objects.brake_release_current = 200;
  rig.steppers[0].objects.enable_drive_delay_ms = 10;
  rig.tick();
  EXPECT_EQ(*rig.board.read_signal("AXIS0_BRAKE_ENGAGED"), 1.0);
  rig.enable(0);
  rig.velocity_pps[0] = kMicrostepsPerRev;  // the demand runs at once; the brake opens after 10 ms
  rig.run_ms(9.9);
  EXPECT_EQ(*rig.board.read_signal("AXIS0_BRAKE_ENGAGED"), 1.0);
  EXPECT_DOUBLE_EQ(rig.board.rotor_revolutions(0), 0.0);
  rig.run_ms(0.2);
  EXPECT_EQ(*rig.board.read_signal("BRAKE0"), 200.0);
  EXPECT_EQ(*rig.board.read_signal("AXIS0_BRAKE_ENGAGED"), 0.0);
  std::vector<OutputChange> changes;
  rig.board.take_output_changes(changes);
  ASSERT_FALSE(changes.empty());
  EXPECT_EQ(changes.back().signal, "BRAKE0");
  EXPECT_EQ(changes.back().level, 200);
}

TEST(Tmcm3216SimBoard, DioPinsAnalogInputsAndOutputLog) {
  Rig rig;
  rig.io.io_mode = 0x0103;  // DIO0 push-pull output, DIO1 high-side output, DIO2/3 inputs
  rig.io.output_mask = 0x000F0000;
  rig.io.write_outputs(0x00010000);
  rig.board.set_input("DIO1", 1);  // pulled up outside
  rig.board.set_input("DIO2", 1);
  rig.board.set_input("AIN1", 2048);
  rig.board.set_sim_time_us(500);
  rig.tick();
  rig.tick();
  EXPECT_EQ(*rig.board.read_signal("DIO0"), 1.0);
  EXPECT_EQ(*rig.board.read_signal("DIO1"), 1.0);  // high-side off: the pull-up wins
  EXPECT_EQ(rig.io.digital_inputs(), 0x00070000u);
  EXPECT_EQ(rig.io.analog_input(1), 2048);
  std::vector<OutputChange> changes;
  rig.board.take_output_changes(changes);
  ASSERT_EQ(changes.size(), 2u);  // DIO0 and DIO1 (an output pin pulled high) went to 1
  EXPECT_EQ(changes[0].signal, "DIO0");
  EXPECT_EQ(changes[0].sim_time_us, 500u);
  rig.io.write_outputs(0);
  rig.board.set_input("DIO1", 0);
  rig.tick();
  EXPECT_EQ(*rig.board.read_signal("DIO0"), 0.0);
  EXPECT_EQ(*rig.board.read_signal("DIO1"), 0.0);
}

TEST(Tmcm3216SimBoard, SignalTableAndScenarioFiles) {
  const auto table = Tmcm3216SimBoard::signal_table();
  EXPECT_NE(find_signal(table, "axis2_load_torque"), nullptr);
  EXPECT_NE(find_signal(table, "AXIS0_REF_L"), nullptr);
  EXPECT_NE(find_signal(table, "VSUPPLY"), nullptr);
  EXPECT_EQ(find_signal(table, "AXIS3_REF_L"), nullptr);
  const Result<std::vector<ScenarioEvent>> parsed =
      parse_scenario("0.001 AXIS1_REF_L 1\n0.002 axis0_load_torque 0.1\n0.003 VSUPPLY 12\n", "test", table);
  ASSERT_TRUE(parsed.ok()) << parsed.error();
  Rig rig;
  ScenarioPlayer player(*parsed, rig.board);
  EXPECT_EQ(player.apply_due(2000), 2u);
  EXPECT_EQ(*rig.board.read_signal("AXIS1_REF_L"), 0.0);  // seen at the next sample
  rig.tick();
  EXPECT_EQ(*rig.board.read_signal("AXIS1_REF_L"), 1.0);
  EXPECT_EQ(*rig.board.read_signal("AXIS0_LOAD_TORQUE"), 0.1);
  EXPECT_EQ(player.apply_due(3000), 1u);
  EXPECT_EQ(*rig.board.read_signal("VSUPPLY"), 12.0);
  const Result<std::vector<ScenarioEvent>> bad = parse_scenario("0 AXIS0_BRAKE 2\n", "test", table);
  EXPECT_FALSE(bad.ok());
}

TEST(Tmcm3216VirtualModule, BoardSignalsMotorChoiceAndTick) {
  host::ModuleOptions options;
  options.motor = "nema17";
  options.initial_inputs = {{"AXIS1_REF_L", 1}, {"VSUPPLY", 36}};
  options.log = [](const std::string&) {};
  host::MakeModuleResult made = host::Tmcm3216VirtualModule::make(options);
  ASSERT_TRUE(made) << made.error();
  host::VirtualModule& module = **made;
  EXPECT_EQ(module.tick_period_us(), modules::tmcm3216::kTickUs);
  module.run_ticks(20);
  EXPECT_EQ(module.sim_time_us(), 20u * modules::tmcm3216::kTickUs);
  EXPECT_EQ(*module.signals().read_signal("AXIS1_REF_L"), 1.0);
  EXPECT_EQ(*module.signals().read_signal("VSUPPLY"), 36.0);
  EXPECT_TRUE(module.signals().read_signal("AXIS0_COIL_A_A").has_value());  // a physical motor
  EXPECT_EQ(host::Tmcm3216VirtualModule::signal_table().size(), Tmcm3216SimBoard::signal_table().size());
  auto& typed = static_cast<host::Tmcm3216VirtualModule&>(module);
  EXPECT_EQ(typed.board().board().axes[1].feedback.switches, 0b010);
  EXPECT_EQ(typed.board().board().io.supply_millivolt, 36000);

  options.motor = "no-such-motor";
  EXPECT_FALSE(host::Tmcm3216VirtualModule::make(options).ok());
}

}  // namespace
}  // namespace motwin::sim
