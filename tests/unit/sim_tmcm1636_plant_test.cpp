// The motor plant and the motor descriptions on their own: electrical and mechanical equations,
// supply bus, sensors, presets and JSON files, and the motor signals of the simulated board.
#include <gtest/gtest.h>

#include <cmath>
#include <string>

#include "board/modules/tmcm1636/tmcm1636_power_stage.h"
#include "core/modules/tmcm1636/tmcm1636.h"
#include "host/modules/tmcm1636/tmcm1636_startup_image.h"
#include "sim/modules/tmcm1636/motor_description.h"
#include "sim/modules/tmcm1636/tmcm1636_plant.h"
#include "sim/modules/tmcm1636/tmcm1636_sim_board.h"
#include "sim/modules/tmcm1636/tmcm1636_sim_io.h"

namespace motwin::sim {
namespace {

constexpr double kTick = 50e-6;
constexpr double kPi = 3.14159265358979323846;

MotorDescription frictionless() {
  MotorDescription m = *motor_preset("default-24v");
  m.coulomb_friction_nm = 0.0;
  m.viscous_friction_nm_s = 0.0;
  return m;
}

// Duties of a voltage vector at a stationary electrical angle (no firmware): a DC current
// through the windings settles at V / R and pulls the rotor to that angle.
board::Tmcm1636Drive drive_towards(double angle_rad, double volts, double bus) {
  board::Tmcm1636Drive drive;
  drive.bridge_enabled = true;
  for (int k = 0; k < 3; ++k) {
    const double phase = volts * std::cos(angle_rad - k * 2.0 * kPi / 3.0);
    drive.duty[k] = static_cast<float>(0.5 + phase / bus);
  }
  return drive;
}

TEST(Tmcm1636Plant, a_stationary_voltage_vector_aligns_the_rotor) {
  MotorDescription m = frictionless();
  m.viscous_friction_nm_s = 1e-4;  // damping so that it settles
  Tmcm1636Plant plant(m);
  const board::Tmcm1636Drive drive = drive_towards(0.0, 0.4, 24.0);  // 1 A through 0.4 ohm
  for (int i = 0; i < 40000; ++i) plant.advance(drive, kTick);
  const double electrical = std::fmod(plant.mechanical_angle_rad() * m.pole_pairs, 2.0 * kPi);
  const double off = std::min(std::fabs(electrical), 2.0 * kPi - std::fabs(electrical));
  EXPECT_LT(off, 0.01) << "electrical angle " << electrical << " rad";
  EXPECT_NEAR(std::hypot(plant.id_amps(), plant.iq_amps()), 1.0, 0.01) << "V/R";
}

TEST(Tmcm1636Plant, open_bridge_carries_no_current_and_the_rotor_coasts) {
  MotorDescription m = frictionless();
  m.coulomb_friction_nm = 0.002;
  Tmcm1636Plant plant(m);
  plant.set_load_torque(-0.01);  // drives it forward
  board::Tmcm1636Drive off;
  for (int i = 0; i < 2000; ++i) plant.advance(off, kTick);
  EXPECT_EQ(plant.iq_amps(), 0.0);
  const double expected = (0.01 - 0.002) / m.rotor_inertia_kgm2 * 0.1;
  EXPECT_NEAR(plant.speed_rad_s(), expected, 1e-6 * expected + 1e-9) << "w = (T - Tc) t / J";
}

TEST(Tmcm1636Plant, static_friction_holds_a_small_load) {
  MotorDescription m = frictionless();
  m.coulomb_friction_nm = 0.01;
  Tmcm1636Plant plant(m);
  plant.set_load_torque(0.009);
  for (int i = 0; i < 2000; ++i) plant.advance(board::Tmcm1636Drive{}, kTick);
  EXPECT_EQ(plant.speed_rad_s(), 0.0);
}

TEST(Tmcm1636Plant, bus_charges_through_the_source_and_regeneration_lifts_it) {
  const MotorDescription m = frictionless();
  Tmcm1636Plant plant(m);
  plant.set_source_voltage(30.0);
  for (int i = 0; i < 40; ++i) plant.advance(board::Tmcm1636Drive{}, kTick);  // 2 ms = 43 RC
  EXPECT_NEAR(plant.bus_voltage(), 30.0, 0.05) << "R C = 47 us";
  plant.set_source_voltage(24.0);
  for (int i = 0; i < 200; ++i) plant.advance(board::Tmcm1636Drive{}, kTick);
  EXPECT_GT(plant.bus_voltage(), 29.0) << "the supply cannot sink: only the board's 0.6 W drains it";
  board::Tmcm1636Drive chopper;
  chopper.brake_chopper_on = true;
  plant.advance(chopper, kTick);
  for (int i = 0; i < 200; ++i) plant.advance(chopper, kTick);  // R C = 4.7 ms in the resistor
  EXPECT_NEAR(plant.bus_voltage(), 24.0, 0.3) << "the brake resistor takes it back to the supply";
}

TEST(Tmcm1636Plant, abn_counts_revolutions_and_latches_the_index) {
  MotorDescription m = frictionless();
  Tmcm1636Plant plant(m);
  plant.set_load_torque(-0.05);
  board::Tmcm1636Feedback feedback;
  uint32_t events = 0;
  double latched_at_turn = 0;
  for (int i = 0; i < 20000 && events < 3; ++i) {
    plant.advance(board::Tmcm1636Drive{}, kTick);
    plant.sense(feedback);
    if (feedback.abn_index_events != events) {
      events = feedback.abn_index_events;
      latched_at_turn = feedback.abn_index_count;
    }
  }
  ASSERT_EQ(events, 3u);
  // The index is at 200°, the rotor started at 40°: the pulses latch 160° + k * 360° of counts.
  EXPECT_NEAR(std::fmod(latched_at_turn, 4096.0), 160.0 / 360.0 * 4096.0, 1.0);
  const double counts = (plant.mechanical_angle_rad() - 40.0 / 180.0 * kPi) / (2.0 * kPi) * 4096.0;
  EXPECT_NEAR(feedback.abn_count, counts, 1.0);
}

TEST(Tmcm1636Plant, hall_states_follow_the_electrical_angle) {
  MotorDescription m = frictionless();
  m.initial_angle_deg = 0.0;
  Tmcm1636Plant plant(m);
  board::Tmcm1636Feedback feedback;
  plant.sense(feedback);
  EXPECT_EQ(feedback.hall, 5) << "sector 0 at electrical 0";
  plant.set_load_torque(-0.02);
  uint8_t previous = feedback.hall;
  int changes = 0;
  while (plant.mechanical_angle_rad() < 2.0 * kPi) {
    plant.advance(board::Tmcm1636Drive{}, kTick);
    plant.sense(feedback);
    if (feedback.hall != previous) ++changes;
    previous = feedback.hall;
  }
  EXPECT_EQ(changes, 24) << "6 per electrical turn, 4 pole pairs";
}

TEST(Tmcm1636Plant, adc_reads_the_phase_current_with_seeded_noise) {
  Tmcm1636Plant a(frictionless(), 42);
  Tmcm1636Plant b(frictionless(), 42);
  board::Tmcm1636Feedback fa;
  board::Tmcm1636Feedback fb;
  double sum = 0;
  for (int i = 0; i < 1000; ++i) {
    a.sense(fa);
    b.sense(fb);
    EXPECT_EQ(fa.adc_phase_a, fb.adc_phase_a);
    EXPECT_EQ(fa.adc_phase_a % 16, 0) << "12-bit ADC, left-aligned";
    sum += fa.adc_phase_a;
  }
  EXPECT_NEAR(sum / 1000.0, 32768.0, 2.0) << "zero current reads mid-scale";
}

TEST(MotorDescription, presets_have_their_documented_constants) {
  const MotorDescription d = *motor_preset("default-24v");
  EXPECT_NEAR(d.torque_constant(), 0.035, 1e-9);
  EXPECT_EQ(d.pole_pairs, 4);
  EXPECT_EQ(d.abn.counts_per_rev, 4096);
  const MotorDescription large = *motor_preset("large-48v");
  EXPECT_NEAR(large.resistance_ohm, 0.039, 1e-12);
  EXPECT_NEAR(large.inductance_q_h, 15.7e-6, 1e-12);
  EXPECT_EQ(large.pole_pairs, 7);
  EXPECT_NEAR(large.torque_constant(), 8.27 / 270.0, 1e-9);
  EXPECT_NEAR(large.rotor_inertia_kgm2, 1e-4, 1e-12);
  EXPECT_EQ(motor_preset("dc-24v")->kind, MotorKind::kDc);
  EXPECT_FALSE(motor_preset("nope"));
}

TEST(MotorDescription, json_round_trip_of_every_preset) {
  for (std::string_view name : motor_preset_names()) {
    const MotorDescription preset = *motor_preset(name);
    const Result<MotorDescription> parsed = parse_motor_description(motor_description_json(preset), "x.json");
    ASSERT_TRUE(parsed) << parsed.error();
    EXPECT_EQ(parsed->name, preset.name);
    EXPECT_DOUBLE_EQ(parsed->torque_constant(), preset.torque_constant());
    EXPECT_DOUBLE_EQ(parsed->resistance_ohm, preset.resistance_ohm);
    EXPECT_EQ(parsed->abn.counts_per_rev, preset.abn.counts_per_rev);
    EXPECT_EQ(parsed->axis_parameters.size(), preset.axis_parameters.size());
    EXPECT_EQ(parsed->startup, preset.startup);
  }
}

TEST(MotorDescription, a_user_file_with_kv_and_comments) {
  const Result<MotorDescription> parsed = parse_motor_description(R"({
    // a hobby outrunner
    "name": "my-motor", "type": "bldc", "pole_pairs": 7, "kv_rpm_per_v": 270,
    "resistance_ohm": 0.05, "inductance_h": 2e-5, "rotor_inertia_kgm2": 1e-4,
    "abn_encoder": {"counts_per_rev": 8192},
    "axis_parameters": {"10": 7, "100": 8192}
  })", "my.json");
  ASSERT_TRUE(parsed) << parsed.error();
  EXPECT_NEAR(parsed->torque_constant(), 8.27 / 270.0, 1e-12);
  EXPECT_DOUBLE_EQ(parsed->inductance_d_h, 2e-5);
  EXPECT_EQ(parsed->axis_parameters.size(), 2u);
}

// Found by fuzz/motor_description.cpp: JSON keys come sorted as text ("100" before "14"), and
// "05" is parameter 5 too. Start-up parameters apply in number order; a number given twice is an error.
TEST(MotorDescription, axis_parameters_in_number_order_and_each_number_once) {
  const Result<MotorDescription> parsed = parse_motor_description(
      R"({"flux_linkage_wb": 0.005, "axis_parameters": {"100": 8192, "25": 1, "14": 3, "05": 7}})", "p.json");
  ASSERT_TRUE(parsed) << parsed.error();
  const std::vector<std::pair<uint8_t, int32_t>> expected{{5, 7}, {14, 3}, {25, 1}, {100, 8192}};
  EXPECT_EQ(parsed->axis_parameters, expected);
  const Result<MotorDescription> again = parse_motor_description(motor_description_json(*parsed), "q.json");
  ASSERT_TRUE(again) << again.error();
  EXPECT_EQ(again->axis_parameters, expected);
  EXPECT_EQ(parse_motor_description(R"({"flux_linkage_wb": 0.005, "axis_parameters": {"5": 1, "05": 2}})", "r.json")
                .error(),
            "r.json: axis_parameters: parameter 5 is given twice");
}

// Found by the fuzz campaign: a torque constant or KV inside its own range can give a flux linkage
// outside flux_linkage_wb's, and the description was then written back in a form that did not load.
TEST(MotorDescription, a_derived_flux_linkage_stays_in_the_range_it_is_written_back_with) {
  EXPECT_EQ(parse_motor_description(R"({"pole_pairs": 2, "torque_constant_nm_per_a": 50.35})", "kt.json").error(),
            "kt.json: torque_constant_nm_per_a with 2 pole pairs gives a flux linkage of 16.7833 Wb; it must be from "
            "1e-06 to 10");
  EXPECT_EQ(parse_motor_description(R"({"pole_pairs": 200, "kv_rpm_per_v": 90000})", "kv.json").error(),
            "kv.json: kv_rpm_per_v with 200 pole pairs gives a flux linkage of 3.06296e-07 Wb; it must be from "
            "1e-06 to 10");
  const Result<MotorDescription> edge = parse_motor_description(R"({"pole_pairs": 2, "torque_constant_nm_per_a": 30})", "ok.json");
  ASSERT_TRUE(edge) << edge.error();
  const Result<MotorDescription> again = parse_motor_description(motor_description_json(*edge), "again.json");
  ASSERT_TRUE(again) << again.error();
  EXPECT_DOUBLE_EQ(again->flux_linkage_wb, 10.0);
}

TEST(MotorDescription, errors_name_the_file_and_the_problem) {
  EXPECT_EQ(parse_motor_description("{", "a.json").error(), "a.json: not valid JSON");
  EXPECT_EQ(parse_motor_description(R"({"pole_pairs": 4, "flux_linkage_wb": 0.005, "resistanse_ohm": 1})", "b.json").error(),
            "b.json: unknown key resistanse_ohm");
  EXPECT_EQ(parse_motor_description(R"({"pole_pairs": 0, "flux_linkage_wb": 0.005})", "c.json").error(),
            "c.json: pole_pairs must be from 1 to 255, got 0");
  EXPECT_EQ(parse_motor_description(R"({"flux_linkage_wb": 0.005, "axis_parameters": {"42": 1}})", "d.json",
                                    host::check_tmcm1636_axis_parameter)
                .error(),
            "d.json: axis_parameters: axis parameter 42 is not stored in the EEPROM");
  EXPECT_EQ(parse_motor_description(R"({"type": "dc"})", "e.json").error(), "e.json: a DC motor needs torque_constant_nm_per_a");
  EXPECT_EQ(resolve_motor("fast-one").error(),
            "unknown motor \"fast-one\" (expected ideal, default-24v, qbl4208-61-04-013, large-48v, dc-24v or a .json file)");
  EXPECT_FALSE(*resolve_motor("ideal"));
  EXPECT_TRUE(resolve_motor("ideal").error().empty());
}

// "preset": a bench motor as a preset with what differs (here an absolute encoder mounted),
// without copying the preset's figures.
TEST(MotorDescription, a_file_can_start_from_a_preset) {
  const MotorDescription preset = *motor_preset("qbl4208-61-04-013");
  const Result<MotorDescription> parsed = parse_motor_description(
      R"({"preset": "qbl4208-61-04-013", "absolute_encoder": {"bits": 12, "reversed": true},
          "startup": {"position_sensor": "absolute_encoder"}, "axis_parameters": {"160": 1}})",
      "amt20.json");
  ASSERT_TRUE(parsed) << parsed.error();
  EXPECT_EQ(parsed->name, "amt20.json");
  EXPECT_EQ(parsed->kind, MotorKind::kBldc);
  EXPECT_DOUBLE_EQ(parsed->torque_constant(), preset.torque_constant());
  EXPECT_DOUBLE_EQ(parsed->resistance_ohm, preset.resistance_ohm);
  EXPECT_EQ(parsed->hall.inverted, preset.hall.inverted);
  EXPECT_EQ(parsed->abn.reversed, preset.abn.reversed);
  EXPECT_TRUE(parsed->absolute.present);
  EXPECT_EQ(parsed->absolute.bits, 12);
  EXPECT_TRUE(parsed->absolute.reversed);
  ASSERT_TRUE(parsed->startup);
  EXPECT_EQ(parsed->startup->position_sensor, PositionSensor::kAbsoluteEncoder);
  EXPECT_EQ(parsed->startup->current_i, preset.startup->current_i) << "the other start-up settings stay";
  EXPECT_EQ(parsed->startup->hall_polarity_inverted, preset.startup->hall_polarity_inverted);
  const std::vector<std::pair<uint8_t, int32_t>> parameters{{160, 1}};
  EXPECT_EQ(parsed->axis_parameters, parameters);
  const Result<MotorDescription> dc = parse_motor_description(R"({"preset": "dc-24v", "resistance_ohm": 3})", "d.json");
  ASSERT_TRUE(dc) << dc.error();
  EXPECT_EQ(dc->kind, MotorKind::kDc);
  EXPECT_DOUBLE_EQ(dc->torque_constant(), motor_preset("dc-24v")->torque_constant());
  EXPECT_EQ(parse_motor_description(R"({"preset": "qbl"})", "u.json").error(), "u.json: unknown preset \"qbl\"");
}

// Start-up settings are named values in the motor's units; numbered firmware parameters are
// kept as given unless the caller checks them for its firmware (the host does).
TEST(MotorDescription, startup_settings_are_named_values_of_the_file) {
  const Result<MotorDescription> parsed = parse_motor_description(
      R"({"flux_linkage_wb": 0.005, "startup": {"max_current_ma": 1500, "commutation": "abn_encoder",
          "hall_interpolation": false, "brake_chopper_voltage_v": 30.5}, "axis_parameters": {"42": 1}})",
      "s.json");
  ASSERT_TRUE(parsed) << parsed.error();
  ASSERT_TRUE(parsed->startup);
  const StartupSettings& startup = *parsed->startup;
  EXPECT_EQ(startup.max_current_ma, 1500);
  EXPECT_EQ(startup.commutation, CommutationSensor::kAbnEncoder);
  EXPECT_EQ(startup.hall_interpolation, false);
  EXPECT_EQ(startup.brake_chopper_voltage_v, 30.5);
  EXPECT_FALSE(startup.open_loop_current_ma);
  EXPECT_FALSE(startup.encoder_alignment);
  const std::vector<std::pair<uint8_t, int32_t>> kept{{42, 1}};
  EXPECT_EQ(parsed->axis_parameters, kept) << "no firmware check: the motor keeps the number";
  const Result<MotorDescription> again = parse_motor_description(motor_description_json(*parsed), "t.json");
  ASSERT_TRUE(again) << again.error();
  EXPECT_EQ(again->startup, parsed->startup);

  EXPECT_FALSE(parse_motor_description(R"({"flux_linkage_wb": 0.005})", "n.json")->startup);
  EXPECT_TRUE(parse_motor_description(R"({"flux_linkage_wb": 0.005, "startup": {}})", "n.json")->startup);
  EXPECT_EQ(parse_motor_description(R"({"flux_linkage_wb": 0.005, "startup": {"commutation": "hal"}})", "e.json").error(),
            "e.json: startup.commutation must be one of \"open_loop\", \"hall\", \"abn_encoder\", "
            "\"absolute_encoder\", got \"hal\"");
  EXPECT_EQ(parse_motor_description(R"({"flux_linkage_wb": 0.005, "startup": {"max_current": 1}})", "f.json").error(),
            "f.json: unknown key startup.max_current");
  EXPECT_EQ(parse_motor_description(R"({"flux_linkage_wb": 0.005, "startup": {"current_p": -1}})", "g.json").error(),
            "g.json: startup.current_p must be from 0 to 2.14748e+09, got -1");
  EXPECT_EQ(parse_motor_description(R"({"flux_linkage_wb": 0.005, "axis_parameters": {"256": 1}})", "h.json").error(),
            "h.json: axis_parameters: axis parameter 256 does not exist");
}

TEST(MotorDescription, startup_parameters_go_into_a_fresh_image) {
  using modules::tmcm1636::Tmcm1636;
  std::vector<uint8_t> image(Tmcm1636::kNvmLayout.total_size);
  Tmcm1636::format_factory_image(image.data(), image.size());
  EXPECT_FALSE(host::tmcm1636_image_configures_motor(image.data(), image.size()));
  host::write_tmcm1636_startup_image(*motor_preset("default-24v"), image.data(), image.size());
  EXPECT_TRUE(host::tmcm1636_image_configures_motor(image.data(), image.size()));
  EXPECT_EQ(tmcl::get_le32(image.data() + Tmcm1636::kNvmLayout.axis_parameter(0, 100)), 4096);
  EXPECT_EQ(tmcl::get_le32(image.data() + Tmcm1636::kNvmLayout.axis_parameter(0, 15)), 2);
}

TEST(Tmcm1636SimBoard, motor_signals_reach_the_plant_and_switches_follow_the_rotor) {
  Tmcm1636SimIo io;
  Tmcm1636SimBoard board(io, frictionless());
  EXPECT_EQ(board.input_signals().size(), Tmcm1636SimIo::signal_table().size() + 9);
  board.set_input("LOAD_TORQUE", -0.02);
  board.set_input("REF_R_AT", 0.5);
  EXPECT_EQ(board.read_signal("LOAD_TORQUE"), -0.02);
  for (int i = 0; i < 4000; ++i) {
    board.before_tick();
    board.after_tick(kTick);
  }
  board.before_tick();
  EXPECT_GT(*board.read_signal("POSITION_REV"), 0.5);
  EXPECT_TRUE(io.reference_switch_level(board::ReferenceSwitch::kRight));
  EXPECT_EQ(board.power_stage()->feedback.reference_switches & 1, 1);
  board.set_input("REF_R", 0);  // a level by name takes the switch back
  board.before_tick();
  EXPECT_FALSE(io.reference_switch_level(board::ReferenceSwitch::kRight));
  // VSUPPLY stays the source voltage; ADC_VM reads the bus.
  board.set_input("VSUPPLY", 30);
  EXPECT_EQ(board.read_signal("VSUPPLY"), 30.0);
}

// REF_AT_LEVEL 0: switches placed on the rotor's path pull their inputs low when pressed and
// read high elsewhere, the wiring of low-active switches (AP 210 bit = 0).
TEST(Tmcm1636SimBoard, switches_at_positions_can_pull_their_inputs_low) {
  Tmcm1636SimIo io;
  Tmcm1636SimBoard board(io, frictionless());
  board.set_input("REF_AT_LEVEL", 0);
  board.set_input("REF_L_AT", 100.0);  // pressed: the rotor is below
  board.set_input("REF_R_AT", 100.0);  // free: the rotor has not reached it
  board.before_tick();
  EXPECT_EQ(board.read_signal("REF_AT_LEVEL"), 0.0);
  EXPECT_FALSE(io.reference_switch_level(board::ReferenceSwitch::kLeft));
  EXPECT_TRUE(io.reference_switch_level(board::ReferenceSwitch::kRight));
  EXPECT_EQ(board.power_stage()->feedback.reference_switches & 3, 1);
  board.set_input("REF_AT_LEVEL", 1);
  board.before_tick();
  EXPECT_EQ(board.power_stage()->feedback.reference_switches & 3, 2);
}

TEST(Tmcm1636SimBoard, the_ideal_motor_accepts_the_motor_signals_without_effect) {
  Tmcm1636SimIo io;
  Tmcm1636SimBoard board(io);
  EXPECT_EQ(board.power_stage(), nullptr);
  board.set_input("LOAD_TORQUE", 1.0);
  board.before_tick();
  board.after_tick(kTick);
  EXPECT_EQ(board.read_signal("SPEED_RPM"), std::nullopt);
  EXPECT_EQ(board.read_signal("LOAD_TORQUE"), 1.0);
}

}  // namespace
}  // namespace motwin::sim
