// TMCM-3216 issue 7 leftovers on the simulated board: the enable signal of the shutdown switch
// (ENABLE, EMCY 5441), a full-step resolution (2001) other than 200 with a matching and a
// mismatching motor, and a motor per axis (`--motor nema17,ideal,nema23`).
#include <gtest/gtest.h>

#include <array>
#include <cmath>
#include <cstdint>
#include <filesystem>
#include <fstream>
#include <optional>
#include <string>
#include <vector>

#include "core/modules/tmcm3216/tmcm3216.h"
#include "host/modules/tmcm3216/tmcm3216_virtual_module.h"
#include "sim/scenario.h"
#include "sim/stepper_motor_selection.h"
#include "sim/stepper_plant.h"
#include "sim/modules/tmcm3216/tmcm3216_sim_board.h"
#include "support/tmcm3216_board_rig.h"

namespace motwin::sim {
namespace {

using Bytes = std::array<uint8_t, 8>;

struct Rig : testing::Tmcm3216BoardRig {
  using Tmcm3216BoardRig::Tmcm3216BoardRig;
  int64_t read(uint16_t index, uint8_t sub = 0) {
    canopen::ObjectRef ref;
    EXPECT_EQ(device->dictionary().find(index, sub, ref), canopen::SdoAbort::kNone) << std::hex << index;
    return ref.info == nullptr ? 0 : device->dictionary().value(ref);
  }
  void write(uint16_t index, uint8_t sub, int64_t value) {
    ASSERT_EQ(write_object(index, sub, value), canopen::SdoAbort::kNone) << std::hex << index;
  }
  // Axis n's CiA-402 objects are at + n x 0x800.
  void enable(uint8_t axis, int8_t mode) {
    const auto k = static_cast<uint16_t>(axis * 0x800);
    write(0x6060 + k, 0, mode);
    write(0x6040 + k, 0, 6);
    write(0x6040 + k, 0, 7);
    write(0x6040 + k, 0, 15);
    run_ms(1);
  }
  int64_t statusword(uint8_t axis) { return read(static_cast<uint16_t>(0x6041 + axis * 0x800)); }
};

void expect_frames(const std::vector<can::CanFrame>& frames, const std::vector<Bytes>& expected) {
  ASSERT_EQ(frames.size(), expected.size());
  for (size_t n = 0; n < frames.size(); ++n) {
    EXPECT_EQ(frames[n].dlc, 8);
    for (int i = 0; i < 8; ++i) EXPECT_EQ(frames[n].data[i], expected[n][i]) << "frame " << n << " byte " << i;
  }
}

// --- ENABLE: the shutdown switch -----------------------------------------------------------------

TEST(Tmcm3216SimInputs, EnableSignalIsClosedByDefaultAndGatesEveryDriver) {
  const SignalInfo* info = find_signal(Tmcm3216SimBoard::signal_table(), "enable");
  ASSERT_NE(info, nullptr);
  EXPECT_TRUE(info->whole_numbers_only);
  EXPECT_EQ(info->max, 1.0);
  Rig rig(StepperMotorDescription::nema17());
  EXPECT_EQ(*rig.board.read_signal("ENABLE"), 1.0);
  EXPECT_TRUE(rig.board.board().io.enable_input);
  rig.write(0x2005, 0, 3);  // no limit switches
  rig.enable(0, 1);
  rig.run_ms(20);
  EXPECT_GT(std::fabs(*rig.board.read_signal("AXIS0_COIL_A_A")) + std::fabs(*rig.board.read_signal("AXIS0_COIL_B_A")),
            0.5);
  rig.board.set_input("ENABLE", 0);
  EXPECT_EQ(*rig.board.read_signal("ENABLE"), 0.0);
  rig.tick();
  EXPECT_FALSE(rig.board.board().io.enable_input);
  rig.run_ms(5);
  // The hardware switches the bridges off: the coils carry no current.
  EXPECT_NEAR(*rig.board.read_signal("AXIS0_COIL_A_A"), 0.0, 1e-3);
  EXPECT_NEAR(*rig.board.read_signal("AXIS0_COIL_B_A"), 0.0, 1e-3);
}

TEST(Tmcm3216SimInputs, OpeningTheShutdownSwitchFaultsEveryAxisWithOneEmcy5441) {
  Rig rig;
  rig.nmt(0x01);  // operational
  rig.write(0x2005, 0, 3);
  rig.enable(0, 1);
  rig.enable(1, 3);
  rig.run_ms(2);
  rig.emergencies();
  ASSERT_EQ(rig.statusword(0) & 0x6F, 0x27);
  ASSERT_EQ(rig.statusword(2) & 0x4F, 0x40);

  rig.board.set_input("ENABLE", 0);
  rig.run_ms(20);
  // One message for the module: byte 2 = 255, 1001 = generic + device profile.
  expect_frames(rig.emergencies(), {{0x41, 0x54, 0x21, 0, 255, 0, 0, 0}});
  for (uint8_t axis = 0; axis < 3; ++axis) EXPECT_EQ(rig.statusword(axis) & 0x4F, 0x08) << "axis " << axis;
  EXPECT_EQ(rig.read(0x1001), 0x21);
  rig.run_ms(20);
  EXPECT_TRUE(rig.emergencies().empty()) << "an open switch that stays sends nothing more";

  // A fault reset while the switch is open: refused, the reason sent again.
  rig.write(0x6040, 0, 0x80);
  rig.run_ms(2);
  expect_frames(rig.emergencies(), {{0x41, 0x54, 0x21, 0, 255, 0, 0, 0}});
  EXPECT_EQ(rig.statusword(0) & 0x4F, 0x08);

  // Closed again: nothing is sent by itself; each axis leaves FAULT with its own reset.
  rig.write(0x6040, 0, 0x00);
  rig.board.set_input("ENABLE", 1);
  rig.run_ms(2);
  EXPECT_TRUE(rig.emergencies().empty());
  EXPECT_EQ(rig.statusword(0) & 0x4F, 0x08);
  rig.write(0x6040, 0, 0x80);
  rig.run_ms(2);
  expect_frames(rig.emergencies(), {{0x00, 0x00, 0x21, 0, 0, 0, 0, 0}});  // axes 1, 2 still in FAULT
  EXPECT_EQ(rig.statusword(0) & 0x4F, 0x40);
  for (uint8_t axis = 1; axis < 3; ++axis) {
    rig.write(static_cast<uint16_t>(0x6040 + axis * 0x800), 0, 0x80);
    rig.run_ms(2);
  }
  expect_frames(rig.emergencies(), {{0x00, 0x00, 0x21, 0, 1, 0, 0, 0}, {0x00, 0x00, 0x00, 0, 2, 0, 0, 0}});
  EXPECT_EQ(rig.read(0x1001), 0);
  // The axis runs again.
  rig.enable(0, 1);
  EXPECT_EQ(rig.statusword(0) & 0x6F, 0x27);
}

TEST(Tmcm3216SimInputs, ShutdownSwitchFromAScenarioAndAsInitialInput) {
  const Result<std::vector<ScenarioEvent>> parsed = parse_scenario("0.010 ENABLE 0\n0.030 ENABLE 1\n", "test", Tmcm3216SimBoard::signal_table());
  ASSERT_TRUE(parsed.ok()) << parsed.error();
  EXPECT_FALSE(parse_scenario("0 ENABLE 2\n", "test", Tmcm3216SimBoard::signal_table()).ok());

  host::ModuleOptions options;
  options.initial_inputs = {{"ENABLE", 0}};
  options.log = [](const std::string&) {};
  host::MakeModuleResult made = host::Tmcm3216VirtualModule::make(options);
  ASSERT_TRUE(made) << made.error();
  (*made)->run_ticks(40);
  auto& typed = static_cast<host::Tmcm3216VirtualModule&>(**made);
  EXPECT_FALSE(typed.board().board().io.enable_input);
  EXPECT_EQ(*(*made)->signals().read_signal("ENABLE"), 0.0);
}

// --- 2001: full steps per revolution -------------------------------------------------------------

// A 0.9-degree NEMA17: the same windings, 400 full steps per revolution.
StepperMotorDescription nema17_0_9_degree() {
  StepperMotorDescription motor = StepperMotorDescription::nema17();
  motor.name = "nema17-0.9deg";
  motor.full_steps_per_revolution = 400;
  return motor;
}

struct PpResult {
  int64_t position_usteps = 0;      // 6064 at the end
  int64_t demand_usteps = 0;        // 6062
  double rotor_revolutions = 0.0;   // what the shaft did
  double encoder_counts = 0.0;      // the sim's encoder (4000 counts per revolution)
  int64_t cruise_velocity_pps = 0;  // 606C in the middle of the move
  double cruise_rpm = 0.0;          // the shaft's mean speed over 0.5 s of cruising
  bool target_reached = false;
};

// A pp move of `target` microsteps at 25600 pps with 2001 = `full_steps` and the encoder as the
// position sensor (606A = 0, 608F = 4000 increments per revolution).
PpResult pp_move(Rig& rig, uint16_t full_steps, int32_t target) {
  PpResult result;
  rig.write(0x2005, 0, 3);
  rig.write(0x2001, 0, full_steps);
  rig.write(0x608F, 1, 4000);
  rig.write(0x606A, 0, 0);
  rig.write(0x6081, 0, 25600);
  rig.write(0x6083, 0, 102400);
  rig.write(0x6084, 0, 102400);
  rig.enable(0, 1);
  rig.run_ms(300);  // settled at the standing current
  const double start_rev = rig.board.rotor_revolutions(0);
  const double start_counts = *rig.board.read_signal("AXIS0_ENCODER_COUNT");
  rig.write(0x607A, 0, target);
  rig.write(0x6040, 0, 31);
  rig.write(0x6040, 0, 15);
  rig.run_ms(1500);  // 0.25 s ramp up, then cruising for 3.75 s
  result.cruise_velocity_pps = rig.read(0x606C);
  const double cruise_start_rev = rig.board.rotor_revolutions(0);
  rig.run_ms(500);  // a stepper's instantaneous speed rings around each step: take the mean
  result.cruise_rpm = (rig.board.rotor_revolutions(0) - cruise_start_rev) / 0.5 * 60.0;
  rig.run_ms(4000);
  result.target_reached = (rig.statusword(0) & 0x0400) != 0;
  result.position_usteps = rig.read(0x6064);
  result.demand_usteps = rig.read(0x6062);
  result.rotor_revolutions = rig.board.rotor_revolutions(0) - start_rev;
  result.encoder_counts = *rig.board.read_signal("AXIS0_ENCODER_COUNT") - start_counts;
  return result;
}

TEST(Tmcm3216SimInputs, FullStepResolution400MovesA09DegreeMotorOneRevolutionPer102400Microsteps) {
  const StepperMotorDescription motor = nema17_0_9_degree();
  ASSERT_LE(StepperPlant::step_number(motor, StepperPlant::kBoardTickS / StepperPlant::kFinestSubSteps),
            StepperPlant::kStableStepNumber);
  Rig rig(motor);
  const PpResult r = pp_move(rig, 400, 102400);
  EXPECT_TRUE(r.target_reached);
  EXPECT_EQ(r.demand_usteps, 102400);
  // 6064 from the encoder: 4000 counts are 400 x 256 microsteps, 25.6 microsteps a count.
  EXPECT_NEAR(static_cast<double>(r.position_usteps), 102400.0, 2 * 25.6);
  EXPECT_NEAR(r.rotor_revolutions, 1.0, 0.1 / 400) << "within a tenth of a full step";
  EXPECT_NEAR(r.encoder_counts, 4000.0, 2.0);
  // Velocities stay microsteps per second (208C = 181): 25600 pps is 0.25 rev/s of this motor.
  EXPECT_NEAR(static_cast<double>(r.cruise_velocity_pps), 25600.0, 25600.0 * 0.05);
  EXPECT_NEAR(r.cruise_rpm, 15.0, 0.75);
}

TEST(Tmcm3216SimInputs, FullStepResolutionThatMismatchesTheMotorOnlyScales) {
  // 2001 = 400 on a 1.8-degree motor: the driver still turns one electrical period per 4 full
  // steps, so the shaft turns twice as far as the firmware believes; the encoder scaled with
  // 2001 then reads twice the demand (a real module would run into its following error).
  Rig rig;  // ideal 200-step motors
  rig.write(0x6065, 0, 0);  // no following error check: the mismatch is shown, not faulted
  const PpResult r = pp_move(rig, 400, 51200);
  EXPECT_EQ(r.demand_usteps, 51200);
  EXPECT_NEAR(r.rotor_revolutions, 1.0, 1e-9);
  EXPECT_NEAR(r.encoder_counts, 4000.0, 1.0);
  EXPECT_NEAR(static_cast<double>(r.position_usteps), 102400.0, 2 * 25.6);
}

// --- --motor per axis ----------------------------------------------------------------------------

TEST(StepperMotorSelection, OneMotorForAllAxesOrOnePerAxis) {
  Result<std::vector<StepperMotorChoice>> all = resolve_stepper_motors("nema23", 3);
  ASSERT_TRUE(all.error().empty()) << all.error();
  ASSERT_EQ(all->size(), 3u);
  for (const auto& motor : *all) {
    ASSERT_TRUE(motor);
    EXPECT_EQ(motor->name, "nema23");
  }
  Result<std::vector<StepperMotorChoice>> ideal = resolve_stepper_motors("", 3);
  ASSERT_TRUE(ideal.error().empty());
  ASSERT_EQ(ideal->size(), 3u);
  EXPECT_FALSE((*ideal)[0] || (*ideal)[1] || (*ideal)[2]);

  Result<std::vector<StepperMotorChoice>> mixed = resolve_stepper_motors(" nema17, ideal ,nema23", 3);
  ASSERT_TRUE(mixed.error().empty()) << mixed.error();
  ASSERT_EQ(mixed->size(), 3u);
  ASSERT_TRUE((*mixed)[0]);
  EXPECT_EQ((*mixed)[0]->name, "nema17");
  EXPECT_FALSE((*mixed)[1]);
  ASSERT_TRUE((*mixed)[2]);
  EXPECT_EQ((*mixed)[2]->name, "nema23");

  // A description file as one item.
  const std::filesystem::path file = std::filesystem::temp_directory_path() / "motwin-sim3216-0.9deg.json";
  std::ofstream(file) << R"({"base": "nema17", "name": "fine", "full_steps_per_revolution": 400})";
  Result<std::vector<StepperMotorChoice>> with_file = resolve_stepper_motors("ideal,ideal," + file.string(), 3);
  ASSERT_TRUE(with_file.error().empty()) << with_file.error();
  ASSERT_TRUE((*with_file)[2]);
  EXPECT_EQ((*with_file)[2]->name, "fine");
  EXPECT_EQ((*with_file)[2]->full_steps_per_revolution, 400);
  std::filesystem::remove(file);
}

TEST(StepperMotorSelection, WrongCountEmptyOrUnknownItemIsAnErrorNamingIt) {
  // A failure resolves no motor at all: the Result holds no list.
  Result<std::vector<StepperMotorChoice>> two = resolve_stepper_motors("nema17,ideal", 3);
  EXPECT_FALSE(two.ok());
  EXPECT_NE(two.error().find("names 2 motors for 3 axes"), std::string::npos) << two.error();
  Result<std::vector<StepperMotorChoice>> four = resolve_stepper_motors("ideal,ideal,ideal,ideal", 3);
  EXPECT_NE(four.error().find("names 4 motors for 3 axes"), std::string::npos) << four.error();
  Result<std::vector<StepperMotorChoice>> unknown = resolve_stepper_motors("nema17,nema99,nema23", 3);
  EXPECT_FALSE(unknown.ok());
  EXPECT_NE(unknown.error().find("motor of axis 1: unknown stepper motor \"nema99\""), std::string::npos) << unknown.error();
  Result<std::vector<StepperMotorChoice>> empty = resolve_stepper_motors("nema17,,nema23", 3);
  EXPECT_NE(empty.error().find("motor of axis 1: empty name"), std::string::npos) << empty.error();
  Result<std::vector<StepperMotorChoice>> single = resolve_stepper_motors("nema99", 3);
  EXPECT_NE(single.error().find("unknown stepper motor \"nema99\""), std::string::npos) << single.error();
}

TEST(Tmcm3216SimInputs, BadMotorListTouchesNoFile) {
  const std::filesystem::path dir = std::filesystem::temp_directory_path() / "motwin-sim3216-bad-motor";
  std::filesystem::remove_all(dir);
  std::filesystem::create_directories(dir);
  host::ModuleOptions options;
  options.motor = "nema17,ideal";
  options.state_dir = dir;
  options.log = [](const std::string&) {};
  const host::MakeModuleResult made = host::Tmcm3216VirtualModule::make(options);
  EXPECT_FALSE(made);
  EXPECT_NE(made.error().find("names 2 motors for 3 axes"), std::string::npos) << made.error();
  EXPECT_TRUE(std::filesystem::is_empty(dir));
  std::filesystem::remove_all(dir);
}

TEST(Tmcm3216SimInputs, AxesWithDifferentMotorsBehaveDifferently) {
  host::ModuleOptions options;
  options.motor = "nema17,ideal,nema23";
  options.log = [](const std::string&) {};
  host::MakeModuleResult made = host::Tmcm3216VirtualModule::make(options);
  ASSERT_TRUE(made) << made.error();
  auto& module = static_cast<host::Tmcm3216VirtualModule&>(**made);
  Tmcm3216SimBoard& board = module.board();
  EXPECT_NE(board.plant(0), nullptr);
  EXPECT_EQ(board.plant(1), nullptr);
  ASSERT_NE(board.plant(2), nullptr);
  EXPECT_EQ(board.plant(2)->motor().name, "nema23");
  EXPECT_TRUE(module.signals().read_signal("AXIS0_COIL_A_A").has_value());
  EXPECT_FALSE(module.signals().read_signal("AXIS1_COIL_A_A").has_value());
  // The same load on each axis with the power stages off: the physical rotors turn under it (more
  // than detent and friction torque), the NEMA17 with its lighter rotor faster; the ideal one
  // ignores loads.
  for (const char* name : {"AXIS0_LOAD_TORQUE", "AXIS1_LOAD_TORQUE", "AXIS2_LOAD_TORQUE"}) board.set_input(name, -0.1);
  module.run_ticks(2000);  // 100 ms
  const double rev0 = board.rotor_revolutions(0);
  const double rev2 = board.rotor_revolutions(2);
  EXPECT_EQ(board.rotor_revolutions(1), 0.0);
  EXPECT_GT(rev0, 0.01);
  EXPECT_GT(rev2, 0.0);
  EXPECT_GT(rev0, 1.5 * rev2) << "the NEMA17's lighter rotor spins up faster";
}

}  // namespace
}  // namespace motwin::sim
