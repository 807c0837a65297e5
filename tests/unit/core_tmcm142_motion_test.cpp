// TMCM-142 motion on the ideal stepper: positioning through the microstep sequencer, run and
// standby current, limit switches (hard and soft stop), reference search modes 1..3 with the
// switches at known positions, and WAIT RFS in a program.
#include <cmath>
#include <string>

#include <gtest/gtest.h>

#include "core/modules/tmcm142/tmcm142_hardware.h"
#include "core/tmcl/ascii_link.h"
#include "support/tmcm142_rig.h"

namespace motwin::testing {
namespace {

constexpr uint8_t kOk = 100;

double coil_amplitude_ma(const board::StepperDrive& drive) {
  return std::hypot(static_cast<double>(drive.coil_a_ma), static_cast<double>(drive.coil_b_ma));
}

// Speeds in µsteps/s: unit mode 1, trapezoid corners (bows at their maximum).
void use_pps(Tmcm142Rig& rig, int32_t vmax, int32_t acceleration) {
  ASSERT_EQ(rig.sap(255, 1), kOk);
  ASSERT_EQ(rig.sap(4, vmax), kOk);
  ASSERT_EQ(rig.sap(5, acceleration), kOk);
  ASSERT_EQ(rig.sap(18, modules::tmcm142::kMaxBow), kOk);  // max. bow: trapezoid
}

TEST(Tmcm142Motion, moves_the_rotor_exactly_to_the_target_and_drops_to_standby_current) {
  Tmcm142Rig rig;
  use_pps(rig, 200000, 1000000);
  ASSERT_EQ(rig.command(4, 0, 0, 51200).status, kOk);  // MVP ABS: a quarter revolution
  rig.run_ms(20);
  EXPECT_EQ(rig.gap(8), 0);
  EXPECT_NEAR(coil_amplitude_ma(rig.stage.drive), 2625.0, 3.0);  // run current, AP 6 = 5
  const uint32_t ms = rig.run_until([&] { return rig.gap(8) == 1; }, 2000);
  EXPECT_LT(ms, 2000u);
  EXPECT_EQ(rig.gap(1), 51200);
  EXPECT_EQ(rig.gap(3), 0);
  EXPECT_NEAR(rig.rotor_microsteps(), 51200.0, 0.01);
  EXPECT_EQ(rig.gap(129) & 0b101, 0b101);  // position reached, velocity zero
  rig.run_ms(2100);                          // AP 20 = 200: 2 s at rest
  EXPECT_NEAR(coil_amplitude_ma(rig.stage.drive), 875.0, 3.0);  // standby, AP 7 = 1
  EXPECT_NEAR(rig.rotor_microsteps(), 51200.0, 0.01);
}

TEST(Tmcm142Motion, coarse_resolution_moves_whole_full_steps) {
  Tmcm142Rig rig;
  use_pps(rig, 2000, 20000);
  ASSERT_EQ(rig.sap(27, 11), kOk);  // full steps
  ASSERT_EQ(rig.command(4, 0, 0, 50).status, kOk);
  rig.run_until([&] { return rig.gap(8) == 1; }, 5000);
  EXPECT_EQ(rig.gap(1), 50);
  EXPECT_NEAR(rig.rotor_microsteps(), 50 * 1024.0, 0.01);  // a quarter revolution
  EXPECT_EQ(rig.stage.drive.electrical_angle % board::kElectricalAnglePerFullStep, 0u);
}

TEST(Tmcm142Motion, limit_switch_stops_at_once_and_lets_the_motor_leave) {
  Tmcm142Rig rig;
  use_pps(rig, 50000, 1000000);
  rig.place_limit_switches(-1e9, 20000);
  ASSERT_EQ(rig.command(1, 0, 0, 50000).status, kOk);  // ROR
  rig.run_ms(1000);
  EXPECT_EQ(rig.gap(10), 1);
  EXPECT_EQ(rig.gap(3), 0);
  // Detected one tick after the rotor passed the point: at most two ticks of travel beyond it.
  EXPECT_GE(rig.rotor_microsteps(), 20000.0);
  EXPECT_LE(rig.rotor_microsteps(), 20000.0 + 2 * 50000 * 50e-6 + 1);
  ASSERT_EQ(rig.command(2, 0, 0, 50000).status, kOk);  // ROL leaves the switch
  rig.run_ms(100);
  EXPECT_LT(rig.rotor_microsteps(), 19000.0);
  EXPECT_EQ(rig.gap(10), 0);
}

TEST(Tmcm142Motion, soft_stop_brakes_with_the_stop_deceleration) {
  Tmcm142Rig rig;
  use_pps(rig, 50000, 1000000);
  ASSERT_EQ(rig.sap(14, 32), kOk);     // soft stop
  ASSERT_EQ(rig.sap(15, 100000), kOk);  // µsteps/s²: 12500 µsteps to stop from 50000 µsteps/s
  rig.place_limit_switches(-1e9, 20000);
  ASSERT_EQ(rig.command(1, 0, 0, 50000).status, kOk);
  rig.run_ms(2000);
  EXPECT_EQ(rig.gap(3), 0);
  EXPECT_NEAR(rig.rotor_microsteps(), 20000.0 + 12500.0, 10.0);
}

TEST(Tmcm142Motion, disabled_switch_does_not_stop) {
  Tmcm142Rig rig;
  use_pps(rig, 50000, 1000000);
  ASSERT_EQ(rig.sap(12, 1), kOk);
  rig.place_limit_switches(-1e9, 20000);
  ASSERT_EQ(rig.command(4, 0, 0, 30000).status, kOk);
  rig.run_until([&] { return rig.gap(8) == 1; }, 2000);
  EXPECT_EQ(rig.gap(1), 30000);
  EXPECT_EQ(rig.gap(10), 1);
}

// Reference search speeds: fast 100000, slow 5000 µsteps/s (0.25 µstep per tick).
void prepare_search(Tmcm142Rig& rig, int32_t mode) {
  use_pps(rig, 100000, 2000000);
  ASSERT_EQ(rig.sap(193, mode), kOk);
  ASSERT_EQ(rig.sap(194, 100000), kOk);
  ASSERT_EQ(rig.sap(195, 5000), kOk);
}

uint32_t run_search(Tmcm142Rig& rig) {
  EXPECT_EQ(rig.command(13, 0, 0, 0).status, kOk);  // RFS START
  rig.run_ms(1);
  EXPECT_NE(rig.command(13, 2, 0, 0).value, 0);  // STATUS: running
  return rig.run_until([&] { return rig.command(13, 2, 0, 0).value == 0; }, 20000);
}

TEST(Tmcm142ReferenceSearch, mode_1_finds_the_left_switch) {
  Tmcm142Rig rig;
  prepare_search(rig, 1);
  rig.place_limit_switches(-30000, 40000);
  EXPECT_LT(run_search(rig), 20000u);
  EXPECT_EQ(rig.gap(1), 0);
  EXPECT_EQ(rig.gap(3), 0);
  EXPECT_EQ(rig.gap(8), 1);
  EXPECT_NEAR(rig.rotor_microsteps(), -30000.0, 1.0);
  // Measured from the switch, a later move lands at the same place.
  ASSERT_EQ(rig.command(4, 0, 0, 10000).status, kOk);
  rig.run_until([&] { return rig.gap(8) == 1; }, 2000);
  EXPECT_NEAR(rig.rotor_microsteps(), -20000.0, 1.0);
}

TEST(Tmcm142ReferenceSearch, mode_2_measures_the_travel_between_the_switches) {
  Tmcm142Rig rig;
  prepare_search(rig, 2);
  rig.place_limit_switches(-30000, 40000);
  EXPECT_LT(run_search(rig), 20000u);
  EXPECT_EQ(rig.gap(1), 0);
  EXPECT_NEAR(rig.rotor_microsteps(), -30000.0, 1.0);
  EXPECT_NEAR(rig.gap(196), 70000, 2);
}

TEST(Tmcm142ReferenceSearch, mode_3_references_the_centre_of_the_left_switch) {
  Tmcm142Rig rig;
  prepare_search(rig, 3);
  rig.place_limit_switches(-1e9, 40000);
  rig.place_left_cam(-36000, -30000);
  EXPECT_LT(run_search(rig), 20000u);
  EXPECT_EQ(rig.gap(1), 0);
  EXPECT_EQ(rig.gap(8), 1);
  EXPECT_NEAR(rig.rotor_microsteps(), -33000.0, 1.0);
  EXPECT_NEAR(rig.gap(196), 70000, 2);
}

TEST(Tmcm142ReferenceSearch, stop_ends_the_search_where_it_is) {
  Tmcm142Rig rig;
  prepare_search(rig, 1);
  rig.place_limit_switches(-300000, 40000);
  ASSERT_EQ(rig.command(13, 0, 0, 0).status, kOk);
  rig.run_ms(100);
  ASSERT_EQ(rig.command(13, 1, 0, 0).status, kOk);  // RFS STOP
  EXPECT_EQ(rig.command(13, 2, 0, 0).value, 0);
  rig.run_ms(200);
  EXPECT_EQ(rig.gap(3), 0);
  EXPECT_LT(rig.gap(1), -5000);
  // A motion command ends a search, too.
  ASSERT_EQ(rig.command(13, 0, 0, 0).status, kOk);
  rig.run_ms(10);
  ASSERT_EQ(rig.command(4, 1, 0, 0).status, kOk);  // MVP REL 0
  EXPECT_EQ(rig.command(13, 2, 0, 0).value, 0);
  EXPECT_EQ(rig.command(13, 3, 0, 0).status, 3);  // no such RFS type
  EXPECT_EQ(rig.command(13, 0, 1, 0).status, 4);  // motor 1
  ASSERT_EQ(rig.sap(195, 0), kOk);
  EXPECT_EQ(rig.command(13, 0, 0, 0).status, 4);  // a search at speed 0 would never end
  EXPECT_EQ(rig.command(13, 2, 0, 0).value, 0);
}

// Downloads instructions from address 0 (commands 132/133).
void download(Tmcm142Rig& rig, std::initializer_list<tmcl::Instruction> program) {
  ASSERT_EQ(rig.command(132, 0, 0, 0).status, kOk);
  for (const auto& in : program) ASSERT_EQ(rig.command(in.command, in.type, in.motor_bank, in.value).status, 101);
  ASSERT_EQ(rig.command(133, 0, 0, 0).status, kOk);
}

TEST(Tmcm142ReferenceSearch, a_program_waits_for_the_search_and_the_home_switch) {
  Tmcm142Rig rig;
  prepare_search(rig, 1);
  rig.place_limit_switches(-30000, 40000);
  auto config = rig.sensors.config();
  config.home = {true, 4000 / kMicrostepsPerRevolution, 6000 / kMicrostepsPerRevolution, true};
  rig.sensors.set_config(config);
  download(rig, {
      {13, 0, 0, 0},       // RFS START
      {27, 4, 0, 0},       // WAIT RFS
      {4, 0, 0, 60000},    // MVP ABS 60000: passes the home switch at 34000..36000
      {27, 2, 0, 0},       // WAIT REFSW
      {3, 0, 0, 0},        // MST
      {28, 0, 0, 0},       // STOP
  });
  ASSERT_EQ(rig.command(129, 1, 0, 0).status, kOk);
  rig.run_until([&] { return rig.ggp(128) == 0; }, 20000);
  rig.run_ms(500);
  EXPECT_EQ(rig.gap(3), 0);
  // Stopped (with the ramp) after the home switch at 34000 from the reference at -30000.
  EXPECT_GT(rig.gap(1), 34000);
  EXPECT_LT(rig.gap(1), 60000);
  EXPECT_NEAR(rig.rotor_microsteps(), rig.gap(1) - 30000.0, 1.0);
}

TEST(Tmcm142Motion, a_program_waits_for_a_limit_switch) {
  Tmcm142Rig rig;
  use_pps(rig, 50000, 1000000);
  rig.place_limit_switches(-1e9, 20000);
  download(rig, {
      {1, 0, 0, 50000},  // ROR
      {27, 3, 0, 0},     // WAIT LIMSW
      {6, 1, 0, 0},      // GAP 1 -> accumulator
      {35, 5, 2, 0},     // AGP 5, 2: user variable 5 = position at the switch
      {28, 0, 0, 0},     // STOP
  });
  ASSERT_EQ(rig.command(129, 1, 0, 0).status, kOk);
  rig.run_until([&] { return rig.ggp(128) == 0; }, 5000);
  EXPECT_EQ(rig.ggp(128), 0);
  EXPECT_NEAR(rig.ggp(5, 2), 20000, 10);
  EXPECT_EQ(rig.gap(10), 1);
}

// Lines typed at the module in ASCII mode without echo (GP 67 bit 5); returns the replies.
std::string type_lines(Tmcm142Rig& rig, tmcl::AsciiLink& link, const std::string& text) {
  std::string replies;
  for (const char c : text) {
    if (!link.push(static_cast<uint8_t>(c), tmcl::ascii_settings(rig.module))) continue;
    const tmcl::AsciiResponse response = tmcl::serve_ascii_command(rig.engine, link.command(), 1);
    replies.append(reinterpret_cast<const char*>(response.bytes), response.length);
  }
  return replies;
}

TEST(Tmcm142Ascii, a_session_homes_the_axis_and_moves_between_coordinates) {
  Tmcm142Rig rig;
  prepare_search(rig, 1);
  rig.place_limit_switches(-30000, 400000);
  ASSERT_EQ(rig.sgp(67, 0, 0x20), kOk);  // no echo, replies only
  EXPECT_EQ(rig.command(139, 0, 0, 0).status, kOk);  // the TMCM-142 has the ASCII interface
  tmcl::AsciiLink link;
  EXPECT_EQ(type_lines(rig, link, "ARFS START, 0\r"), "BA 100 0\r");
  rig.run_until([&] { return rig.command(13, 2, 0, 0).value == 0; }, 20000);
  EXPECT_EQ(type_lines(rig, link, "ARFS STATUS, 0\r"), "BA 100 0\r");
  EXPECT_EQ(type_lines(rig, link, "ASCO 1, 0, 12000\rASCO 2, 0, 3000\r"), "BA 100 12000\rBA 100 3000\r");
  EXPECT_EQ(type_lines(rig, link, "AMVP COORD, 0, 1\r"), "BA 100 1\r");
  rig.run_until([&] { return rig.gap(8) == 1; }, 5000);
  EXPECT_EQ(type_lines(rig, link, "AGAP 1, 0\r"), "BA 100 12000\r");
  EXPECT_NEAR(rig.rotor_microsteps(), -30000.0 + 12000.0, 1.0);
  EXPECT_EQ(type_lines(rig, link, "AMVP COORD, 0, 2\r"), "BA 100 2\r");
  rig.run_until([&] { return rig.gap(8) == 1; }, 5000);
  EXPECT_EQ(type_lines(rig, link, "ACCO 3, 0\rAGCO 3, 0\r"), "BA 100 0\rBA 100 3000\r");
  EXPECT_NEAR(rig.rotor_microsteps(), -30000.0 + 3000.0, 1.0);
}

}  // namespace
}  // namespace motwin::testing
