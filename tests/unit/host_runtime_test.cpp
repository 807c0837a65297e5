#include <gtest/gtest.h>

#include <filesystem>
#include <string>
#include <vector>

#include "core/modules/tmcm1636/tmcm1636_hardware.h"
#include "core/tmcl/serial_link.h"
#include "host/host_runtime.h"
#include "host/module_registry.h"
#include "host/modules/tmcm1636/tmcm1636_virtual_module.h"
#include "sim/scenario.h"
#include "support/host_test_support.h"

namespace motwin::host {
namespace {

constexpr uint8_t kRor = 1, kGap = 6, kGio = 15, kSap = 5, kStap = 7;

// Runs one instruction straight through the module's engine (no transport).
tmcl::CommandResult execute(VirtualModule& module, uint8_t command, uint8_t type, uint8_t motor, int32_t value) {
  return module.engine().execute(tmcl::Instruction{command, type, motor, value}, tmcl::Origin::kHost, 1);
}
int32_t read(VirtualModule& module, uint8_t command, uint8_t type, uint8_t motor) {
  const tmcl::CommandResult result = execute(module, command, type, motor, 0);
  EXPECT_EQ(result.status, tmcl::Status::kOk);
  return result.value;
}

MakeModuleResult make_quiet(ModuleOptions options = {}) {
  options.log = [](const std::string&) {};
  return make_module("tmcm-1636", options);
}

TEST(ModuleRegistry, knows_the_tmcm_1636_and_refuses_unknown_names) {
  EXPECT_EQ(module_names(), "tmcm-1636, tmcm-142, tmcm-3216");
  ASSERT_NE(find_module("tmcm-1636"), nullptr);
  // 11 I/O signals (GPI0..REF_H) and 9 of the motor (LOAD_TORQUE..HALL_FAULT, REF_AT_LEVEL among them).
  EXPECT_EQ(find_module("tmcm-1636")->input_signals().size(), 20u);
  const MakeModuleResult unknown = make_module("tmcm-9999", {});
  EXPECT_FALSE(unknown);
  EXPECT_EQ(unknown.error(), "unknown module \"tmcm-9999\" (available: tmcm-1636, tmcm-142, tmcm-3216)");
}

TEST(VirtualModule, a_tmcm_1636_in_memory_describes_itself) {
  MakeModuleResult made = make_quiet();
  ASSERT_TRUE(made) << made.error();
  VirtualModule& module = **made;
  EXPECT_EQ(module.name(), "tmcm-1636");
  EXPECT_EQ(module.firmware_version(), "1636V109");
  EXPECT_EQ(module.tick_period_us(), 50u);
  EXPECT_EQ(module.nvm_location(), "none");
  EXPECT_EQ(module.nvm().size(), Tmcm1636VirtualModule::Device::kNvmLayout.total_size);
  module.run_ticks(20);
  module.tick();
  EXPECT_EQ(module.tick_count(), 21u);
  EXPECT_EQ(module.sim_time_us(), 1050u);
}

TEST(VirtualModule, stores_go_to_the_image_file_and_survive_a_restart) {
  testing::ScratchDirectory scratch;
  ModuleOptions options;
  options.state_dir = scratch.path();
  {
    MakeModuleResult made = make_quiet(options);
    ASSERT_TRUE(made) << made.error();
    EXPECT_EQ((*made)->nvm_location(), (scratch.path() / "tmcm-1636.eeprom").string());
    EXPECT_EQ(execute(**made, kSap, 43, 0, 3210).status, tmcl::Status::kOk);
    EXPECT_EQ(execute(**made, kStap, 43, 0, 0).status, tmcl::Status::kOk);
  }
  MakeModuleResult restarted = make_quiet(options);
  ASSERT_TRUE(restarted) << restarted.error();
  EXPECT_EQ(read(**restarted, kGap, 43, 0), 3210);
}

TEST(VirtualModule, initial_inputs_are_set_before_power_up) {
  ModuleOptions options;
  options.initial_inputs = {{"VSUPPLY", 30.0}, {"GPI1", 1}};
  MakeModuleResult made = make_quiet(options);
  ASSERT_TRUE(made);
  EXPECT_EQ(read(**made, kGio, 2, 1), modules::tmcm1636::supply_adc_from_millivolt(30000));  // ADC_VM
  EXPECT_EQ(read(**made, kGio, 1, 0), 1);
}

TEST(HostRuntime, a_scenario_event_lands_on_the_first_tick_at_or_after_its_time) {
  MakeModuleResult made = make_quiet();
  ASSERT_TRUE(made);
  HostRuntime runtime(**made, Pacing::fast());
  const Result<std::vector<sim::ScenarioEvent>> scenario =
      sim::parse_scenario("0.50001 GPI0 1\n0 GPI2 1\n", "t.scn", (*made)->signals().input_signals());
  ASSERT_TRUE(scenario.ok());
  runtime.set_scenario(*scenario);
  runtime.start();
  EXPECT_EQ(read(**made, kGio, 2, 0), 1);  // time 0: applied at start
  runtime.advance_ticks(10'000);                 // up to 0.5 s: one batch, split at the event
  EXPECT_EQ(runtime.sim_time_us(), 500'000u);
  EXPECT_EQ(read(**made, kGio, 0, 0), 0);
  runtime.advance_ticks(1);  // the event (0.50001 s) applies before the tick starting at 0.50005 s
  EXPECT_EQ(read(**made, kGio, 0, 0), 1);
  EXPECT_TRUE(runtime.scenario()->finished());
}

// The same inputs at the same sim times give the same trajectory, however ticks are batched.
TEST(HostRuntime, trajectories_do_not_depend_on_batching) {
  auto run = [](uint64_t batch_ticks) {
    MakeModuleResult made = make_quiet();
    HostRuntime runtime(**made, Pacing::fast());
    runtime.set_scenario(
        *sim::parse_scenario("0.0123 VSUPPLY 12\n0.0371 VSUPPLY 48\n", "t.scn", (*made)->signals().input_signals()));
    runtime.start();
    EXPECT_EQ(execute(**made, kRor, 0, 0, 1500).status, tmcl::Status::kOk);
    std::vector<int32_t> samples;
    for (uint64_t done = 0; done < 2000;) {
      runtime.advance_ticks(batch_ticks);
      done += batch_ticks;
      if (done % 400 == 0) {
        for (uint8_t parameter : {41, 42, 51, 52}) samples.push_back(read(**made, kGap, parameter, 0));
      }
    }
    samples.push_back(read(**made, kGap, 42, 0));  // actual velocity
    samples.push_back(read(**made, kGap, 41, 0));  // ramp velocity
    return samples;
  };
  const std::vector<int32_t> one_by_one = run(1);
  EXPECT_EQ(run(8), one_by_one);
  EXPECT_EQ(run(400), one_by_one);
  EXPECT_NE(one_by_one.back(), 0);  // the ramp did run
}

TEST(HostRuntime, realtime_pacing_follows_the_wall_clock) {
  MakeModuleResult made = make_quiet();
  HostRuntime runtime(**made, Pacing::realtime());
  runtime.start();
  const uint64_t start_us = monotonic_now_us();
  while (monotonic_now_us() - start_us < 50'000) runtime.step(10'000);
  // A loaded machine may stall this process just before the loop ends: the runtime catches up
  // the backlog one chunk per step, so the steps it is owed are taken before it is judged. Beyond
  // Pacer::kMaxBacklogWallUs the backlog is dropped (sim time slips, by design) and counted.
  const Pacer& pacer = runtime.pacer();
  const auto owed_a_step = [&] {
    return pacer.target_sim_us(monotonic_now_us()) >= runtime.sim_time_us() + 2 * Pacer::kBatchWallUs;
  };
  for (int i = 0; i < 1000 && owed_a_step(); ++i) runtime.step(0);
  const uint64_t elapsed_us = monotonic_now_us() - start_us;
  // Never ahead of the wall clock, and behind by at most a batch plus scheduling slack.
  EXPECT_LE(runtime.sim_time_us(), elapsed_us);
  EXPECT_GE(runtime.sim_time_us() + pacer.dropped_backlog_sim_us(), 25'000u);
}

}  // namespace
}  // namespace motwin::host
