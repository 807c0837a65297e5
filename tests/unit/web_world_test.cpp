// The web console's World ops (tools/web/world_ops.h) without sockets: "world" lists a module's
// scenario signals with ranges, units and values and draws its axes; "world_set" sets one the way
// a scenario event is applied (HostRuntime::set_input_now), and the module sees it in its own
// parameters over TMCL; bad requests change nothing.
#include <gtest/gtest.h>

#include <cmath>
#include <cstring>
#include <memory>
#include <string>
#include <vector>

#include <nlohmann/json.hpp>

#include "host/host_runtime.h"
#include "host/module_registry.h"
#include "support/web_console_rig.h"
#include "tools/web/web_console.h"

namespace motwin::tools::web {
namespace {

using Json = nlohmann::json;

// A console on one TMCL module whose world is set as `motwin serve --web` sets it. World ops
// reply at once; TMCL requests when the module has served them.
class WorldRig : public motwin::testing::WebConsoleRig {
 public:
  explicit WorldRig(const char* module_name, const char* motor = "ideal")
      : WebConsoleRig(module_name, motwin::testing::WebConsoleRigSetup().with_motor(motor).with_target_adapter(
                                       [](WebConsoleRig& rig, ConsoleTarget& target) {
                                         target.world = {&rig.module().signals(),
                                                         [&rig](std::string_view signal, double value) {
                                                           return rig.runtime().set_input_now(signal, value);
                                                         }};
                                       })) {}

  int64_t gap(int number) {
    const Json reply = ask({{"op", "get"}, {"number", number}, {"axis", 0}});
    EXPECT_EQ(reply["ok"], true) << reply.dump();
    return reply.value("value", int64_t{-1});
  }
  Json world() { return ask({{"op", "world"}}); }
  double signal_value(const char* name) {
    const Json values = ask({{"op", "world"}, {"values_only", true}})["values"];
    return values.value(name, Json(nullptr)).is_number() ? values[name].get<double>() : NAN;
  }
  void run_for_ms(uint64_t ms) { run_for_us(ms * 1000); }
};

const Json* signal_named(const Json& world, const std::string& name) {
  for (const Json& signal : world["signals"]) {
    if (signal["name"] == name) return &signal;
  }
  return nullptr;
}

TEST(WebWorld, world_lists_the_scenario_signals_with_range_unit_and_value_and_the_axis) {
  WorldRig rig("tmcm-142");
  const Json world = rig.world();
  ASSERT_EQ(world["ok"], true) << world.dump();
  EXPECT_EQ(world["settable"], true);
  EXPECT_EQ(world["signals"].size(), rig.module().signals().input_signals().size());
  const Json* supply = signal_named(world, "VSUPPLY");
  ASSERT_NE(supply, nullptr);
  EXPECT_EQ((*supply)["unit"], "V");
  EXPECT_EQ((*supply)["min"], 0);
  EXPECT_EQ((*supply)["max"], 80);
  EXPECT_EQ((*supply)["whole"], false);
  EXPECT_EQ((*supply)["value"], 24);
  const Json* left = signal_named(world, "REF_L");
  ASSERT_NE(left, nullptr);
  EXPECT_EQ((*left)["whole"], true);
  EXPECT_EQ((*left)["value"], 0);
  EXPECT_EQ((*signal_named(world, "REF_L_AT"))["unit"], "rev");
  EXPECT_TRUE((*signal_named(world, "REF_L_AT"))["value"].is_null()) << "no switch position set";
  ASSERT_EQ(world["axes"].size(), 1u);
  EXPECT_EQ(world["axes"][0]["prefix"], "");
  EXPECT_EQ(world["axes"][0]["position_rev"], 0.0);
}

TEST(WebWorld, the_tmcm3216_has_three_axes_by_their_signal_prefix) {
  host::MakeModuleResult made = motwin::testing::make_quiet_module("tmcm-3216");
  ASSERT_TRUE(made) << made.error();
  const ConsoleWorld world{&(*made)->signals(), {}};
  const Result<Json> reply = world_op("world", Json{{"op", "world"}}, 0, world, 0);
  ASSERT_TRUE(reply) << reply.error();
  ASSERT_EQ((*reply)["axes"].size(), 3u);
  EXPECT_EQ((*reply)["axes"][2]["prefix"], "AXIS2_");
  EXPECT_EQ((*reply)["axes"][2]["position_rev"], 0.0);
  EXPECT_EQ((*reply)["settable"], false);
  // A board no scenario reaches (a node of a --node bus) is read, never set.
  const Result<Json> refused = world_op("world_set", Json{{"signal", "VSUPPLY"}, {"value", 12}}, 0, world, 0);
  ASSERT_FALSE(refused);
  EXPECT_NE(refused.error().find("not set from here"), std::string::npos);
  EXPECT_EQ((*made)->signals().read_signal("VSUPPLY"), 24.0);
}

TEST(WebWorld, closing_the_left_switch_of_a_tmcm142_shows_in_its_own_switch_parameters) {
  WorldRig rig("tmcm-142");
  EXPECT_EQ(rig.gap(11), 0);
  const Json set = rig.ask({{"op", "world_set"}, {"signal", "ref_l"}, {"value", 1}});
  ASSERT_EQ(set["ok"], true) << set.dump();
  EXPECT_EQ(set["signal"], "REF_L");
  EXPECT_EQ(set["value"], 1);
  rig.run_for_ms(1);
  EXPECT_EQ(rig.gap(11), 1) << "AP 11: left endstop";
  EXPECT_EQ(rig.gap(9) & 2, 2) << "AP 9 bit 1: left limit switch";
  EXPECT_EQ(rig.signal_value("REF_L"), 1.0);
  ASSERT_EQ(rig.ask({{"op", "world_set"}, {"signal", "REF_L"}, {"value", 0}})["ok"], true);
  rig.run_for_ms(1);
  EXPECT_EQ(rig.gap(11), 0);
}

TEST(WebWorld, a_tmcm1636_left_reference_switch_shows_in_ap_212) {
  WorldRig rig("tmcm-1636");
  ASSERT_EQ(rig.ask({{"op", "set"}, {"number", 210}, {"value", 7}})["ok"], true);  // every switch high active
  ASSERT_EQ(rig.ask({{"op", "world_set"}, {"signal", "REF_L"}, {"value", 0}})["ok"], true);
  rig.run_for_ms(2);
  EXPECT_EQ(rig.gap(212), 0);
  ASSERT_EQ(rig.ask({{"op", "world_set"}, {"signal", "REF_L"}, {"value", 1}})["ok"], true);
  rig.run_for_ms(2);
  EXPECT_EQ(rig.gap(212), 1) << "AP 212: left reference switch active";
  EXPECT_EQ(rig.gap(211), 0) << "the right one is not";
}

TEST(WebWorld, supply_voltage_shows_in_the_modules_supply_parameter) {
  WorldRig rig("tmcm-1636");
  ASSERT_EQ(rig.ask({{"op", "world_set"}, {"signal", "VSUPPLY"}, {"value", 31.5}})["ok"], true);
  rig.run_for_ms(50);
  EXPECT_NEAR(rig.gap(220), 315, 2) << "AP 220: supply voltage in 0.1 V";
  EXPECT_EQ(rig.signal_value("VSUPPLY"), 31.5);
  // The TMCM-142 says only whether the supply is below 15 V (AP 26 bit 1).
  WorldRig stepper("tmcm-142");
  stepper.run_for_ms(1);
  EXPECT_EQ(stepper.gap(26) & 2, 0);
  ASSERT_EQ(stepper.ask({{"op", "world_set"}, {"signal", "VSUPPLY"}, {"value", 12}})["ok"], true);
  stepper.run_for_ms(1);
  EXPECT_EQ(stepper.gap(26) & 2, 2);
}

TEST(WebWorld, bad_requests_are_errors_and_change_nothing) {
  WorldRig rig("tmcm-1636");
  const double supply_before = rig.signal_value("VSUPPLY");
  const double left_before = rig.signal_value("REF_L");
  const auto refused = [&](Json request, const std::string& says) {
    request["op"] = "world_set";
    const Json reply = rig.ask(request);
    EXPECT_EQ(reply["ok"], false) << request.dump();
    EXPECT_NE(reply.value("error", "").find(says), std::string::npos) << reply.dump();
  };
  refused({{"signal", "WARP_DRIVE"}, {"value", 1}}, "unknown signal \"WARP_DRIVE\"");
  refused({{"signal", "VSUPPLY"}, {"value", 101}}, "VSUPPLY takes 0 to 100");
  refused({{"signal", "VSUPPLY"}, {"value", -1}}, "VSUPPLY takes 0 to 100");
  refused({{"signal", "REF_L"}, {"value", 0.5}}, "REF_L takes 0 or 1");
  refused({{"signal", "VSUPPLY"}, {"value", "30"}}, "\"value\": expected a number");
  refused({{"signal", "REF_L"}, {"value", true}}, "\"value\": expected a number");
  refused({{"signal", "VSUPPLY"}}, "\"value\": expected a number");
  refused({{"signal", 3}, {"value", 1}}, "\"signal\": expected");
  refused({{"module", 1}, {"signal", "VSUPPLY"}, {"value", 30}}, "no module 1");
  const Json bad_flag = rig.ask({{"op", "world"}, {"values_only", "yes"}});
  EXPECT_EQ(bad_flag["ok"], false);
  EXPECT_EQ(rig.signal_value("VSUPPLY"), supply_before) << "unchanged";
  EXPECT_EQ(rig.signal_value("REF_L"), left_before) << "unchanged";
  EXPECT_EQ(rig.runtime().scenario(), nullptr) << "nothing was queued";
}

// The servo's speed with a load torque set from the console at 1 s equals, bit for bit, the speed
// with the same torque from a scenario file at 1 s; and the load slows it.
TEST(WebWorld, a_load_torque_set_live_slows_a_servo_exactly_as_a_scenario_event_does) {
  auto run = [](bool live) {
    WorldRig rig("tmcm-1636", "default-24v");
    if (!live) {
      const Result<std::vector<sim::ScenarioEvent>> scenario =
          sim::parse_scenario("1.0 LOAD_TORQUE 0.025\n", "load.scn", rig.module().signals().input_signals());
      EXPECT_TRUE(scenario) << scenario.error();
      rig.runtime().set_scenario(*scenario);
    }
    EXPECT_EQ(rig.ask({{"op", "set"}, {"number", 44}, {"value", 20000}})["ok"], true);
    EXPECT_EQ(rig.ask({{"op", "tmcl"}, {"text", "ROR 0, 1500"}})["ok"], true);
    // Ticks from the present time to 1 s, then 1000 ticks (50 ms) of the speed.
    rig.runtime().advance_ticks(1'000'000 / 50 - rig.module().tick_count());
    if (live) {
      EXPECT_EQ(rig.ask({{"op", "world_set"}, {"signal", "LOAD_TORQUE"}, {"value", 0.025}})["ok"], true);
    }
    std::vector<double> speeds;
    for (int i = 0; i < 1000; ++i) {
      rig.runtime().advance_ticks(1);
      speeds.push_back(*rig.module().signals().read_signal("SPEED_RPM"));
    }
    return speeds;
  };
  const std::vector<double> from_scenario = run(false);
  const std::vector<double> from_console = run(true);
  ASSERT_EQ(from_console.size(), from_scenario.size());
  EXPECT_EQ(std::memcmp(from_console.data(), from_scenario.data(), from_scenario.size() * sizeof(double)), 0);
  EXPECT_NEAR(from_console.front(), 1500.0, 5.0);
  double slowest = 1e9;
  for (double speed : from_console) slowest = std::min(slowest, speed);
  EXPECT_LT(slowest, 1490.0) << "the load slows the servo";
}

TEST(WebWorld, the_drawn_shaft_follows_a_move) {
  WorldRig rig("tmcm-142");
  ASSERT_EQ(rig.ask({{"op", "world_set"}, {"signal", "REF_R_AT"}, {"value", 2.5}})["ok"], true);
  ASSERT_EQ(rig.ask({{"op", "tmcl"}, {"text", "MVP ABS, 0, 307200"}})["ok"], true);
  rig.run_for_ms(100);
  const double moving_rev = rig.world()["axes"][0]["position_rev"].get<double>();
  EXPECT_GT(moving_rev, 0.0);
  EXPECT_LT(moving_rev, 1.5);
  rig.run_for_ms(20000);
  const Json world = rig.world();
  // 1024 microsteps a full step (AP 27 = 1, the default) and 200 full steps a turn: 1.5 turns.
  EXPECT_NEAR(world["axes"][0]["position_rev"].get<double>(), 1.5, 1e-9) << world["axes"].dump();
  EXPECT_EQ((*signal_named(world, "REF_R_AT"))["value"], 2.5);
}

}  // namespace
}  // namespace motwin::tools::web
