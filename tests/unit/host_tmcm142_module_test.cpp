// The virtual TMCM-142 (`motwin serve --module tmcm-142`): motor selection, the board signals
// (I/O, switch windows, encoder configuration, obstacle) as the firmware sees them, and what
// a limit switch does to the target of a move. Positions: 204800 microsteps per revolution.
#include <gtest/gtest.h>

#include <cstdio>
#include <cstdlib>
#include <cstring>
#include <fstream>
#include <string>
#include <vector>

#include "host/host_runtime.h"
#include "host/module_registry.h"
#include "host/modules/tmcm142/tmcm142_virtual_module.h"
#include "sim/scenario.h"
#include "sim/stepper_motor_selection.h"

namespace motwin::host {
namespace {

constexpr uint8_t kMvp = 4, kSap = 5, kGap = 6, kRfs = 13, kSio = 14, kGio = 15;
constexpr int32_t kRev = 204800;

struct Made {
  MakeModuleResult result;
  Tmcm142VirtualModule& module() { return static_cast<Tmcm142VirtualModule&>(**result); }
};

Made make(const std::string& motor = "ideal", std::vector<InitialInput> inputs = {}) {
  ModuleOptions options;
  options.motor = motor;
  options.initial_inputs = std::move(inputs);
  options.log = [](const std::string&) {};
  return Made{make_module("tmcm-142", options)};
}

tmcl::CommandResult execute(VirtualModule& module, uint8_t command, uint8_t type, int32_t value, uint8_t bank = 0) {
  return module.engine().execute(tmcl::Instruction{command, type, bank, value}, tmcl::Origin::kHost, 1);
}
int32_t gap(VirtualModule& module, uint8_t number) { return execute(module, kGap, number, 0).value; }
void sap(VirtualModule& module, uint8_t number, int32_t value) {
  ASSERT_EQ(execute(module, kSap, number, value).status, tmcl::Status::kOk) << "SAP " << int{number};
}
void run_ms(VirtualModule& module, uint64_t ms) { module.run_ticks(ms * 20); }
// Runs until AP 8 (position reached) or max_ms.
void run_until_reached(VirtualModule& module, uint64_t max_ms) {
  for (uint64_t ms = 0; ms < max_ms && gap(module, 8) == 0; ++ms) run_ms(module, 1);
}

TEST(Tmcm142Module, the_default_motor_is_ideal_and_presets_and_files_are_steppers) {
  Made ideal = make("");
  ASSERT_TRUE(ideal.result) << ideal.result.error();
  EXPECT_EQ((*ideal.result)->firmware_version(), "142V1.06");
  EXPECT_EQ((*ideal.result)->tick_period_us(), 50u);
  EXPECT_EQ(ideal.module().board().plant(), nullptr);
  Made nema17 = make("nema17");
  ASSERT_TRUE(nema17.result) << nema17.result.error();
  ASSERT_NE(nema17.module().board().plant(), nullptr);
  EXPECT_DOUBLE_EQ(nema17.module().board().plant()->motor().rated_current_a, 1.5);

  Made servo_preset = make("default-24v");
  EXPECT_FALSE(servo_preset.result);
  EXPECT_NE(servo_preset.result.error().find("unknown stepper motor \"default-24v\""), std::string::npos)
      << servo_preset.result.error();
}

TEST(Tmcm142Module, stepper_description_files_start_from_a_preset_and_check_every_key) {
  const Result<sim::StepperMotorDescription> good = sim::parse_stepper_motor_description(
      R"({"name": "my-motor", "base": "nema17", "rated_current_a": 2.0, "full_steps_per_revolution": 400})", "m.json");
  ASSERT_TRUE(good) << good.error();
  EXPECT_EQ(good->name, "my-motor");
  EXPECT_DOUBLE_EQ(good->rated_current_a, 2.0);
  EXPECT_EQ(good->full_steps_per_revolution, 400);
  EXPECT_DOUBLE_EQ(good->resistance_ohm, 1.5) << "from the nema17 base";
  EXPECT_EQ(sim::parse_stepper_motor_description(R"({"resistance": 1})", "m.json").error(),
            "m.json: unknown key \"resistance\"");
  EXPECT_EQ(sim::parse_stepper_motor_description(R"({"inductance_h": 0})", "m.json").error(),
            "m.json: \"inductance_h\" must be a number from 1e-06 to 10");
  EXPECT_EQ(sim::parse_stepper_motor_description(R"({"full_steps_per_revolution": 201})", "m.json").error(),
            "m.json: \"full_steps_per_revolution\" must be a multiple of 4 from 4 to 4000");
  EXPECT_EQ(sim::parse_stepper_motor_description("[1]", "m.json").error(), "m.json: expected a JSON object");
  // A preset from a file is the ideal motor's counterpart of --motor nema23.
  const Result<sim::StepperMotorChoice> preset = sim::resolve_stepper_motor("nema23");
  ASSERT_TRUE(preset && *preset);
  EXPECT_EQ((*preset)->name, "nema23");
  EXPECT_FALSE(*sim::resolve_stepper_motor("ideal"));
  EXPECT_TRUE(sim::resolve_stepper_motor("ideal").error().empty());
}

// hfuzz finding: any positive number was taken, and a light or stiff rotor made the plant's
// explicit integration diverge (rotor at 1e19 revolutions, NaN). Every key has a physical range,
// and a motor whose rotor integration would be unstable is refused, naming the key and its bound.
TEST(Tmcm142Module, stepper_description_keys_are_bounded_and_unstable_motors_refused) {
  auto error_of = [](const char* json) { return sim::parse_stepper_motor_description(json, "m.json").error(); };
  EXPECT_EQ(error_of(R"({"rotor_inertia_kg_m2": 1e-300})"), "m.json: \"rotor_inertia_kg_m2\" must be a number from 1e-08 to 1");
  EXPECT_EQ(error_of(R"({"rotor_inertia_kg_m2": 1e-9})"), "m.json: \"rotor_inertia_kg_m2\" must be a number from 1e-08 to 1");
  EXPECT_EQ(error_of(R"({"torque_constant_nm_per_a": 1000})"),
            "m.json: \"torque_constant_nm_per_a\" must be a number from 0.001 to 20");
  EXPECT_EQ(error_of(R"({"resistance_ohm": 1e9})"), "m.json: \"resistance_ohm\" must be a number from 0.01 to 1000");
  EXPECT_EQ(error_of(R"({"detent_torque_nm": -1})"), "m.json: \"detent_torque_nm\" must be a number from 0 to 10");
  EXPECT_EQ(error_of(R"({"viscous_friction_nm_s": "x"})"), "m.json: \"viscous_friction_nm_s\" must be a number from 0 to 10");
  EXPECT_TRUE(error_of(R"({"detent_torque_nm": 0, "friction_torque_nm": 0, "viscous_friction_nm_s": 0})").empty());
  // In range but unstable: the NEMA23 (Kt 0.357, 7 A peak assumed, 50 pole pairs) needs about
  // 1.17e-7 kg m^2 at 12.5 us sub-steps.
  const sim::StepperMotorDescription nema23 = sim::StepperMotorDescription::nema23();
  const double min_inertia = sim::StepperPlant::min_stable_inertia_kg_m2(nema23, 12.5e-6);
  EXPECT_NEAR(min_inertia, 1.1706e-7, 0.0001e-7);
  const std::string unstable = error_of(R"({"rotor_inertia_kg_m2": 1e-7})");
  EXPECT_EQ(unstable.rfind("m.json: \"rotor_inertia_kg_m2\" must be at least 1.17056e-07 for", 0), 0u) << unstable;
  EXPECT_NE(unstable.find("12.5 us"), std::string::npos) << unstable;
  EXPECT_TRUE(error_of(R"({"rotor_inertia_kg_m2": 1.2e-7})").empty());
  // A stiffer motor needs more inertia: 4000 full steps (1000 pole pairs) at the preset's inertia.
  EXPECT_TRUE(error_of(R"({"full_steps_per_revolution": 4000})").empty());
  EXPECT_FALSE(error_of(R"({"full_steps_per_revolution": 4000, "rotor_inertia_kg_m2": 1e-6})").empty());
  // The CLI (--motor FILE.json) reports the parser's error.
  const std::string path = ::testing::TempDir() + "hfix-unstable-motor.json";
  {
    std::ofstream file(path);
    file << R"({"base": "nema23", "rotor_inertia_kg_m2": 1e-7})";
  }
  Made made = make(path);
  EXPECT_FALSE(made.result);
  EXPECT_NE(made.result.error().find("\"rotor_inertia_kg_m2\" must be at least"), std::string::npos) << made.result.error();
  std::remove(path.c_str());
}

TEST(Tmcm142Module, io_signals_reach_gio_and_sio_reaches_the_output_log) {
  Made made = make("ideal", {{"IN7", 1}, {"AIN2", 2047}, {"AIN1", 2048}, {"IN0", 1}});
  VirtualModule& m = **made.result;
  std::vector<int32_t> digital;
  for (uint8_t port = 0; port < 9; ++port) digital.push_back(execute(m, kGio, port, 0, 0).value);
  EXPECT_EQ(digital, (std::vector<int32_t>{1, 1, 0, 0, 0, 0, 0, 1, 0})) << "IN1 from AIN1 at half scale";
  EXPECT_EQ(execute(m, kGio, 0, 0, 1).value, 4095) << "IN0 = 1 drives the pin to full scale";
  EXPECT_EQ(execute(m, kGio, 2, 0, 1).value, 2047);
  m.signals().set_input("AIN0", 100);
  EXPECT_EQ(execute(m, kGio, 0, 0, 0).value, 0) << "an analog count sets the digital level too";
  run_ms(m, 10);
  ASSERT_EQ(execute(m, kSio, 1, 1, 2).status, tmcl::Status::kOk);
  std::vector<sim::OutputChange> changes;
  m.signals().take_output_changes(changes);
  ASSERT_EQ(changes.size(), 1u);
  EXPECT_EQ(changes[0].signal, "OUT1");
  EXPECT_EQ(changes[0].level, 1);
  EXPECT_EQ(changes[0].sim_time_us, 10'000u);
  EXPECT_EQ(m.signals().read_signal("out1"), 1.0);
}

TEST(Tmcm142Module, switch_windows_follow_the_rotor_and_a_level_by_name_takes_over) {
  Made made = make();
  sim::Tmcm142SimBoard& board = made.module().board();
  board.set_input("REF_L_FROM", 0.25);  // a cam closed from 0.25 to 0.5 rev
  board.set_input("REF_L_TO", 0.5);
  board.set_input("REF_H_AT", 1.0);
  EXPECT_EQ(board.read_signal("REF_L_FROM"), 0.25);
  EXPECT_EQ(board.read_signal("REF_L_TO"), 0.5);
  EXPECT_EQ(board.read_signal("REF_L_AT"), 0.5) << "the left switch's AT is its upper bound";
  EXPECT_EQ(board.read_signal("REF_H_TO"), std::nullopt) << "no upper bound";
  const std::vector<std::pair<double, uint8_t>> expected = {{0.0, 0}, {0.3, 2}, {0.49, 2}, {0.6, 0}, {1.2, 4}};
  for (const auto& [position, switches] : expected) {
    board.set_rotor_revolutions(position);
    EXPECT_EQ(board.power_stage().feedback.switches, switches) << "at " << position << " rev";
  }
  board.set_input("REF_H", 0);
  EXPECT_EQ(board.power_stage().feedback.switches & 4, 4) << "until the next sample";
  board.before_tick();
  EXPECT_EQ(board.power_stage().feedback.switches, 0) << "REF_H = 0 by name replaces the window";
  EXPECT_EQ(board.read_signal("REF_H_AT"), std::nullopt);
  board.set_input("REF_R", 1);
  board.before_tick();
  EXPECT_EQ(board.power_stage().feedback.switches, 1);
  EXPECT_EQ(board.read_signal("REF_R"), 1.0);
}

// The limit-switch decision (docs/tmcm-142.md): a hard stop at a switch makes the stop point the
// target, so AP 0 = AP 1 and AP 8 = 1 (WAIT POS ends); a soft stop (AP 14 bit 5) decelerates with
// AP 15 past the switch and leaves the axis at rest in velocity mode, target unchanged.
TEST(Tmcm142Module, a_limit_switch_hard_stop_makes_the_stop_point_the_target) {
  Made made = make();
  VirtualModule& m = **made.result;
  m.signals().set_input("REF_R_AT", 0.5);
  ASSERT_EQ(execute(m, kMvp, 0, kRev).status, tmcl::Status::kOk);
  run_ms(m, 2000);
  const int32_t stop = gap(m, 1);
  EXPECT_GE(stop, kRev / 2);
  EXPECT_LE(stop, kRev / 2 + 20) << "at most two ticks at 1 rev/s past the switch";
  EXPECT_EQ(gap(m, 0), stop);
  EXPECT_EQ(gap(m, 8), 1);
  EXPECT_EQ(gap(m, 10), 1) << "right switch active";
  EXPECT_EQ(gap(m, 128), 0) << "still position mode";
  // A move further right is refused by the switch at once; a move away runs.
  ASSERT_EQ(execute(m, kMvp, 0, kRev).status, tmcl::Status::kOk);
  run_ms(m, 100);
  EXPECT_LE(gap(m, 1), stop + 20);
  ASSERT_EQ(execute(m, kMvp, 0, 0).status, tmcl::Status::kOk);
  run_until_reached(m, 3000);
  EXPECT_EQ(gap(m, 1), 0);
}

TEST(Tmcm142Module, a_limit_switch_soft_stop_decelerates_past_the_switch) {
  Made made = make();
  VirtualModule& m = **made.result;
  m.signals().set_input("REF_R_AT", 0.5);
  sap(m, 14, 32);     // soft stop
  sap(m, 15, 140730);  // 2.05e6 µsteps/s², ten times AP 5: the switch is reached at about 1 rev/s
  ASSERT_EQ(execute(m, kMvp, 0, kRev).status, tmcl::Status::kOk);
  run_ms(m, 2000);
  const int32_t stop = gap(m, 1);
  // v²/2a is 0.05 rev; the S-shaped onset of the deceleration (max. bow 1000) adds about 0.14 s of it.
  EXPECT_GT(stop, kRev / 2 + kRev / 20);
  EXPECT_LT(stop, kRev / 2 + kRev / 4);
  EXPECT_EQ(gap(m, 3), 0);
  EXPECT_EQ(gap(m, 0), kRev) << "target kept";
  EXPECT_EQ(gap(m, 8), 0);
  EXPECT_EQ(gap(m, 128), 2) << "velocity mode at 0";
}

TEST(Tmcm142Module, reference_search_mode_2_measures_the_switch_distance_placed_by_signals) {
  Made made = make();
  VirtualModule& m = **made.result;
  const Result<std::vector<sim::ScenarioEvent>> scenario =
      sim::parse_scenario("0 REF_R_AT 1.0\n0 REF_L_AT -0.5\n", "rfs.scn", m.signals().input_signals());
  ASSERT_TRUE(scenario.ok()) << scenario.error();
  sim::ScenarioPlayer player(*scenario, m.signals());
  player.apply_due(0);
  sap(m, 193, 2);
  int32_t status = 0;
  ASSERT_EQ(execute(m, kRfs, 0, 0).status, tmcl::Status::kOk);
  for (int ms = 0; ms < 20000; ++ms) {
    run_ms(m, 1);
    status = execute(m, kRfs, 2, 0).value;
    if (status == 0) break;
  }
  EXPECT_EQ(status, 0);
  EXPECT_EQ(gap(m, 1), 0);
  EXPECT_NEAR(gap(m, 196), 1.5 * kRev, 2.0) << "right minus left switching point";
  EXPECT_NEAR(*m.signals().read_signal("POSITION_REV"), -0.5, 2.0 / kRev) << "the rotor at the left switch";
}

// RFS mode 3 with the left switch as a cam (a window): the centre of its two switching points
// becomes 0; AP 196 measures from the cam's right edge to the right limit switch.
TEST(Tmcm142Module, reference_search_mode_3_homes_on_the_centre_of_a_cam_window) {
  Made made = make("ideal", {{"REF_R_AT", 1.0}, {"REF_L_FROM", -0.5}, {"REF_L_TO", -0.4}});
  VirtualModule& m = **made.result;
  sap(m, 193, 3);
  ASSERT_EQ(execute(m, kRfs, 0, 0).status, tmcl::Status::kOk);
  int32_t status = 1;
  for (int ms = 0; ms < 30000 && status != 0; ++ms) {
    run_ms(m, 1);
    status = execute(m, kRfs, 2, 0).value;
  }
  EXPECT_EQ(status, 0);
  EXPECT_EQ(gap(m, 1), 0);
  EXPECT_NEAR(*m.signals().read_signal("POSITION_REV"), -0.45, 2.0 / kRev) << "centre of the cam";
  EXPECT_NEAR(gap(m, 196), 1.4 * kRev, 2.0) << "right switch minus the cam's right edge";
  EXPECT_EQ(gap(m, 11), 1) << "the cam is closed at its centre";
}

// A scenario through the host runtime on the physical motor: the same run gives the same rotor
// trace bit for bit, whatever the tick batching.
TEST(Tmcm142Module, scenario_runs_on_the_physical_motor_are_bit_identical) {
  auto run = [](uint64_t batch) {
    Made made = make("nema23");
    VirtualModule& m = **made.result;
    HostRuntime runtime(m, Pacing::fast());
    const Result<std::vector<sim::ScenarioEvent>> scenario = sim::parse_scenario(
        "0.2 LOAD_TORQUE 0.5\n0.4 VSUPPLY 12\n0.6 BLOCKED 1\n0.7 BLOCKED 0\n", "load.scn", m.signals().input_signals());
    EXPECT_TRUE(scenario.ok()) << scenario.error();
    runtime.set_scenario(*scenario);
    runtime.start();
    EXPECT_EQ(execute(m, kMvp, 0, 2 * kRev).status, tmcl::Status::kOk);
    std::vector<double> trace;
    for (uint64_t done = 0; done < 24'000; done += batch) {
      runtime.advance_ticks(batch);
      trace.push_back(*m.signals().read_signal("POSITION_REV"));
    }
    trace.push_back(gap(m, 41));
    trace.push_back(gap(m, 1));
    return trace;
  };
  const std::vector<double> first = run(40);
  const std::vector<double> again = run(40);
  ASSERT_EQ(again.size(), first.size());
  EXPECT_EQ(std::memcmp(again.data(), first.data(), first.size() * sizeof(double)), 0) << "bit-identical";
  const std::vector<double> other_batching = run(400);
  for (size_t i = 0; i + 2 < other_batching.size(); ++i) {
    ASSERT_EQ(std::memcmp(&other_batching[i], &first[(i + 1) * 10 - 1], sizeof(double)), 0) << "sample " << i;
  }
  EXPECT_EQ(other_batching[other_batching.size() - 2], first[first.size() - 2]);
  // The 100 ms obstacle lost steps: the rotor is whole electrical periods (4096 µsteps each)
  // behind the ramp's position, beyond the load angle (under 1024 µsteps).
  const double ramp_microsteps = first.back();
  const double rotor_microsteps = first[first.size() - 3] * kRev;
  EXPECT_GT(ramp_microsteps - rotor_microsteps, 4096.0 - 1024.0)
      << "ramp " << ramp_microsteps << ", rotor " << rotor_microsteps;
}

TEST(Tmcm142Module, the_index_pulse_is_where_the_signal_puts_it_and_setting_it_is_no_crossing) {
  Made made = make();
  sim::Tmcm142SimBoard& board = made.module().board();
  const board::StepperFeedback& feedback = board.power_stage().feedback;
  board.set_input("ENCODER_INDEX_AT", 0.3);
  board.before_tick();
  EXPECT_EQ(feedback.encoder_index_events, 0u) << "moving the index is not a crossing";
  board.set_rotor_revolutions(0.35);
  EXPECT_EQ(feedback.encoder_index_events, 1u);
  EXPECT_EQ(feedback.encoder_index_count, 1200) << "0.3 rev of 4000 counts";
  board.set_input("ENCODER_INDEX_AT", 0.5);
  board.before_tick();
  EXPECT_EQ(feedback.encoder_index_events, 1u) << "the count carries on";
  EXPECT_EQ(feedback.encoder_index_count, 1200);
  board.set_rotor_revolutions(1.6);
  EXPECT_EQ(feedback.encoder_index_events, 3u) << "0.5 and 1.5 rev crossed";
  EXPECT_EQ(feedback.encoder_index_count, 6000);
  EXPECT_EQ(feedback.encoder_count, 6400);
}

TEST(Tmcm142Module, encoder_resolution_and_direction_come_from_the_signals) {
  Made made = make("ideal", {{"ENCODER_CPR", 1000}, {"ENCODER_REVERSED", 1}});
  VirtualModule& m = **made.result;
  sap(m, 42, 13421773);  // 204.8 µsteps per count: 1000 counts per revolution
  sap(m, 43, 1);         // and count the other way (encoder mode bit 0), as the encoder is reversed
  ASSERT_EQ(execute(m, kMvp, 0, kRev).status, tmcl::Status::kOk);
  run_until_reached(m, 3000);
  EXPECT_EQ(gap(m, 1), kRev);
  EXPECT_NEAR(gap(m, 41), kRev, 205);
  EXPECT_EQ(m.signals().read_signal("ENCODER_COUNT"), -1000.0);
  // A faulty encoder stops counting: the deviation check sees the motor run away from it.
  m.signals().set_input("ENCODER_FAULT", 1);
  sap(m, 212, 5000);
  ASSERT_EQ(execute(m, kMvp, 0, 2 * kRev).status, tmcl::Status::kOk);
  run_ms(m, 2000);
  EXPECT_EQ(m.signals().read_signal("ENCODER_COUNT"), -1000.0);
  EXPECT_GT(gap(m, 1), kRev + 5000);
  EXPECT_LT(gap(m, 1), kRev + 5000 + 300);
  EXPECT_EQ(gap(m, 207), 2) << "stopped by the encoder deviation";
}

TEST(Tmcm142Module, an_overload_loses_steps_on_the_physical_motor_only) {
  for (const char* motor : {"ideal", "nema23"}) {
    Made made = make(motor, {{"LOAD_TORQUE", 2.0}});  // twice the NEMA23's holding torque
    VirtualModule& m = **made.result;
    ASSERT_EQ(execute(m, kMvp, 0, kRev).status, tmcl::Status::kOk);
    run_until_reached(m, 3000);
    EXPECT_EQ(gap(m, 1), kRev) << motor << ": the ramp arrives either way";
    const double rotor = *m.signals().read_signal("POSITION_REV");
    if (std::string(motor) == "ideal") {
      EXPECT_DOUBLE_EQ(rotor, 1.0);
    } else {
      EXPECT_LT(rotor, 0.0) << "the weight pulls the rotor back, step by step lost";
      EXPECT_LT(gap(m, 41), 0);
    }
  }
}

}  // namespace
}  // namespace motwin::host
