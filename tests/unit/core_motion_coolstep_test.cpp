// CoolStep's current regulation and the stop-on-stall detector, rule by rule (TMCM-3216 manual
// 4.1, 4.2.27..4.2.40).
#include <gtest/gtest.h>

#include <cstdint>

#include "core/motion/coolstep.h"
#include "core/modules/tmcm3216/tmcm3216_stepper.h"
#include "core/motion/stall_detector.h"

namespace motwin::motion {
namespace {

constexpr int32_t kFast = 100000;  // pps, above every threshold used here

CoolStepConfig enabled_config() {
  CoolStepConfig config;
  config.run_current_scale = 31;
  config.hysteresis_start = 2;  // lower threshold 64
  config.hysteresis = 3;        // upper threshold (2 + 3 + 1) x 32 = 192
  config.up_step = 0;
  config.down_step = 3;
  config.threshold_velocity_pps = 1000;
  return config;
}

// Feeds `count` fresh measurements of `sg` at speed; returns the final scale.
uint8_t measure(CoolStep& coolstep, const CoolStepConfig& config, uint16_t sg, int count, int32_t velocity = kFast) {
  for (int i = 0; i < count; ++i) coolstep.step(config, {velocity, sg, true, false});
  return coolstep.current_scale();
}

TEST(CoolStep, thresholds_are_semin_times_32_and_semin_plus_semax_plus_one_times_32) {
  CoolStepConfig config;
  config.hysteresis_start = 2;
  config.hysteresis = 3;
  EXPECT_EQ(config.lower_threshold(), 64);
  EXPECT_EQ(config.upper_threshold(), 192);
  config.hysteresis_start = 15;
  config.hysteresis = 15;
  EXPECT_EQ(config.lower_threshold(), 480);
  EXPECT_EQ(config.upper_threshold(), 992);
}

TEST(CoolStep, current_scale_of_the_0_255_object_is_in_32_steps) {
  EXPECT_EQ(CoolStep::current_scale_of(0), 0);
  EXPECT_EQ(CoolStep::current_scale_of(7), 0);
  EXPECT_EQ(CoolStep::current_scale_of(8), 1);
  EXPECT_EQ(CoolStep::current_scale_of(128), 16);
  EXPECT_EQ(CoolStep::current_scale_of(255), 31);
}

TEST(CoolStep, minimum_is_one_half_or_one_quarter_of_the_run_current) {
  CoolStepConfig config;
  config.run_current_scale = 31;
  config.minimum_current = 0;
  EXPECT_EQ(CoolStep::minimum_scale(config), 15);  // 16 / 32
  config.minimum_current = 1;
  EXPECT_EQ(CoolStep::minimum_scale(config), 7);  // 8 / 32
  config.run_current_scale = 15;
  EXPECT_EQ(CoolStep::minimum_scale(config), 3);  // 4 / 16
  config.minimum_current = 0;
  EXPECT_EQ(CoolStep::minimum_scale(config), 7);  // 8 / 16
  config.run_current_scale = 0;
  EXPECT_EQ(CoolStep::minimum_scale(config), 0);
}

TEST(CoolStep, light_load_lowers_one_step_per_sedn_results_down_to_the_floor) {
  const uint8_t expected_per_step[4] = {32, 8, 2, 1};
  for (uint8_t sedn = 0; sedn < 4; ++sedn) {
    CoolStepConfig config = enabled_config();
    config.down_step = sedn;
    CoolStep coolstep;
    EXPECT_EQ(measure(coolstep, config, 192, expected_per_step[sedn] - 1), 31) << int{sedn};
    EXPECT_EQ(measure(coolstep, config, 192, 1), 30) << int{sedn};
    EXPECT_EQ(measure(coolstep, config, 1023, 15 * expected_per_step[sedn]), 15) << int{sedn};
    EXPECT_EQ(measure(coolstep, config, 1023, 100), 15) << int{sedn};  // the floor: 1/2
    EXPECT_EQ(coolstep.scaled_current_ma(config, 2000), 1000);
  }
}

TEST(CoolStep, results_in_the_band_hold_and_restart_the_down_count) {
  CoolStepConfig config = enabled_config();
  config.down_step = 1;  // 8 results per step
  CoolStep coolstep;
  measure(coolstep, config, 500, 7);
  measure(coolstep, config, 100, 1);  // between 64 and 192: hold, count restarts
  EXPECT_EQ(measure(coolstep, config, 500, 7), 31);
  EXPECT_EQ(measure(coolstep, config, 500, 1), 30);
  EXPECT_EQ(measure(coolstep, config, 64, 50), 30);   // 64 is not below the lower threshold
  EXPECT_EQ(measure(coolstep, config, 191, 50), 30);  // 191 is below the upper one
}

TEST(CoolStep, heavy_load_raises_by_seup_steps_per_result_up_to_the_run_current) {
  const uint8_t steps[4] = {1, 2, 4, 8};
  for (uint8_t seup = 0; seup < 4; ++seup) {
    CoolStepConfig config = enabled_config();
    config.up_step = seup;
    CoolStep coolstep;
    ASSERT_EQ(measure(coolstep, config, 1023, 16), 15);
    EXPECT_EQ(measure(coolstep, config, 63, 1), 15 + steps[seup]) << int{seup};
    EXPECT_EQ(measure(coolstep, config, 0, 20), 31) << int{seup};  // never above the run scale
    EXPECT_EQ(coolstep.scaled_current_ma(config, 2000), 2000);
  }
}

TEST(CoolStep, only_fresh_results_count) {
  CoolStepConfig config = enabled_config();
  CoolStep coolstep;
  for (int i = 0; i < 100; ++i) coolstep.step(config, {kFast, 1023, false, false});
  EXPECT_TRUE(coolstep.active());
  EXPECT_EQ(coolstep.current_scale(), 31);
  coolstep.step(config, {kFast, 1023, true, false});
  EXPECT_EQ(coolstep.current_scale(), 30);
}

TEST(CoolStep, inactive_at_or_below_the_threshold_speed_at_the_run_current) {
  CoolStepConfig config = enabled_config();
  CoolStep coolstep;
  measure(coolstep, config, 1023, 10);
  ASSERT_EQ(coolstep.current_scale(), 21);
  // At the threshold (1000 pps, either direction): off, back to the run scale.
  EXPECT_EQ(measure(coolstep, config, 1023, 5, 1000), 31);
  EXPECT_FALSE(coolstep.active());
  EXPECT_EQ(measure(coolstep, config, 1023, 5, -1000), 31);
  // Above it again the regulation starts from the run scale.
  EXPECT_EQ(measure(coolstep, config, 1023, 1, -1001), 30);
  EXPECT_TRUE(coolstep.active());
  // Threshold 0: active whenever the axis moves, not at standstill.
  config.threshold_velocity_pps = 0;
  EXPECT_EQ(measure(coolstep, config, 1023, 1, 1), 29);
  EXPECT_EQ(measure(coolstep, config, 1023, 1, 0), 31);
  EXPECT_FALSE(coolstep.active());
}

TEST(CoolStep, semin_zero_or_stealthchop_disables_it) {
  CoolStepConfig config = enabled_config();
  config.hysteresis_start = 0;
  CoolStep coolstep;
  EXPECT_EQ(measure(coolstep, config, 1023, 100), 31);
  EXPECT_FALSE(coolstep.active());
  config = enabled_config();
  measure(coolstep, config, 1023, 5);
  ASSERT_EQ(coolstep.current_scale(), 26);
  coolstep.step(config, {kFast, 1023, true, true});
  EXPECT_FALSE(coolstep.active());
  EXPECT_EQ(coolstep.current_scale(), 31);
}

TEST(CoolStep, a_lower_run_current_caps_and_scales) {
  CoolStepConfig config = enabled_config();
  CoolStep coolstep;
  measure(coolstep, config, 1023, 3);
  ASSERT_EQ(coolstep.current_scale(), 28);
  config.run_current_scale = 19;  // 2003 lowered to 159 while running
  coolstep.step(config, {kFast, 100, false, false});
  EXPECT_EQ(coolstep.current_scale(), 19);
  EXPECT_EQ(coolstep.scaled_current_ma(config, 1200), 1200);
  EXPECT_EQ(measure(coolstep, config, 1023, 100), 9);  // (19 + 1) / 2 - 1
  EXPECT_EQ(coolstep.scaled_current_ma(config, 1200), 600);
  EXPECT_EQ(coolstep.scaled_current_ma(config, 1000), 500);
  coolstep.reset();
  EXPECT_FALSE(coolstep.active());
  EXPECT_EQ(coolstep.scaled_current_ma(config, 1200), 1200);
}

// --- Stop on stall -----------------------------------------------------------------------------

StallDetectorConfig stop_above(uint32_t velocity_pps) {
  StallDetectorConfig config;
  config.stop_velocity_pps = velocity_pps;
  return config;
}

TEST(StallDetector, stallguard2_reaching_zero_above_the_velocity_is_a_stall) {
  StallDetector detector;
  const StallDetectorConfig config = stop_above(5000);
  EXPECT_FALSE(detector.step(config, {6000, 1, 0, true, false}));
  EXPECT_FALSE(detector.stalled());
  EXPECT_TRUE(detector.step(config, {6000, 0, 0, true, false}));
  EXPECT_TRUE(detector.stalled());
  EXPECT_EQ(detector.stall_velocity_pps(), 6000);
  // Latched: no new edge, stays set when the value recovers.
  EXPECT_FALSE(detector.step(config, {6000, 0, 0, true, false}));
  EXPECT_FALSE(detector.step(config, {6000, 900, 0, true, false}));
  EXPECT_TRUE(detector.stalled());
  detector.clear();
  EXPECT_FALSE(detector.stalled());
  EXPECT_TRUE(detector.step(config, {-6000, 0, 0, true, false}));  // either direction
  EXPECT_EQ(detector.stall_velocity_pps(), -6000);
}

TEST(StallDetector, not_at_or_below_the_velocity_nor_at_standstill_nor_when_off) {
  StallDetector detector;
  EXPECT_FALSE(detector.step(stop_above(5000), {5000, 0, 0, true, false}));
  EXPECT_FALSE(detector.step(stop_above(5000), {-5000, 0, 0, true, false}));
  EXPECT_FALSE(detector.step(stop_above(5000), {0, 0, 0, true, false}));
  EXPECT_FALSE(detector.step(stop_above(0), {1000000, 0, 0, true, false}));  // 20A4 = 0: off
  EXPECT_FALSE(detector.step(stop_above(1), {0, 0, 0, true, false}));
  // A stale value does not count: only a fresh measurement.
  EXPECT_FALSE(detector.step(stop_above(5000), {6000, 0, 0, false, false}));
  EXPECT_FALSE(detector.stalled());
}

TEST(StallDetector, stallguard4_below_its_threshold_in_stealthchop) {
  StallDetector detector;
  StallDetectorConfig config = stop_above(5000);
  config.stallguard4_threshold = 100;
  // In StealthChop the StallGuard2 value is not looked at.
  EXPECT_FALSE(detector.step(config, {6000, 0, 100, true, true}));
  EXPECT_TRUE(detector.step(config, {6000, 0, 99, true, true}));
  detector.clear();
  // Threshold 0: nothing falls below it.
  config.stallguard4_threshold = 0;
  EXPECT_FALSE(detector.step(config, {6000, 0, 0, true, true}));
  // In SpreadCycle the StallGuard4 value is not looked at.
  config.stallguard4_threshold = 511;
  EXPECT_FALSE(detector.step(config, {6000, 500, 0, true, false}));
}

TEST(StallDetector, option_code_20A7) {
  using modules::tmcm3216::stall_reaction_of;  // the module decodes its object
  StallReaction reaction = StallReaction::kStop;
  EXPECT_TRUE(stall_reaction_of(0, reaction));
  EXPECT_EQ(reaction, StallReaction::kFault);
  EXPECT_TRUE(stall_reaction_of(1, reaction));
  EXPECT_EQ(reaction, StallReaction::kStop);
  EXPECT_FALSE(stall_reaction_of(2, reaction));
  EXPECT_EQ(reaction, StallReaction::kStop);  // untouched
  EXPECT_EQ(StallDetectorConfig{}.reaction, StallReaction::kFault);  // default 0
}

TEST(StallDetector, stealthchop_below_the_pwm_threshold_speed_with_a_gradient) {
  EXPECT_TRUE(stealth_chop_active(10000, 1, 9999));
  EXPECT_TRUE(stealth_chop_active(10000, 1, -9999));
  EXPECT_TRUE(stealth_chop_active(10000, 1, 0));
  EXPECT_FALSE(stealth_chop_active(10000, 1, 10000));
  EXPECT_FALSE(stealth_chop_active(10000, 0, 0));  // 20B1 = 0 turns StealthChop off
  EXPECT_FALSE(stealth_chop_active(0, 1, 0));      // 20B0 = 0: off
  EXPECT_FALSE(stealth_chop_active(10000, 1, INT32_MIN));
}

}  // namespace
}  // namespace motwin::motion
