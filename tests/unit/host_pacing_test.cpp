#include <gtest/gtest.h>

#include <string>

#include "host/pacing.h"

namespace motwin::host {
namespace {

constexpr uint32_t kTickUs = 50;
constexpr uint64_t kWall0 = 1'000'000;

TEST(Pacing, parses_modes_and_factors) {
  EXPECT_EQ(Pacing::parse("realtime")->mode, Pacing::Mode::kPaced);
  EXPECT_EQ(Pacing::parse("realtime")->speed_factor, 1.0);
  EXPECT_EQ(Pacing::parse("fast")->mode, Pacing::Mode::kFast);
  EXPECT_EQ(Pacing::parse("2")->speed_factor, 2.0);
  EXPECT_EQ(Pacing::parse("0.5")->speed_factor, 0.5);
  EXPECT_EQ(Pacing::parse("0.5")->describe(), "x0.5");
  EXPECT_EQ(Pacing::parse("1")->describe(), "realtime");
  for (const char* bad : {"0", "-1", "abc", "", "1e9", "Fast"}) {
    SCOPED_TRACE(bad);
    const Result<Pacing> parsed = Pacing::parse(bad);
    EXPECT_FALSE(parsed);
    EXPECT_EQ(parsed.error(),
              "--speed takes realtime, fast or a factor from 0.001 to 10000, got \"" + std::string(bad) + "\"");
  }
}

TEST(Pacer, realtime_runs_a_batch_per_millisecond_of_wall_time) {
  Pacer pacer(Pacing::realtime(), kTickUs);
  pacer.start(kWall0, 0);
  EXPECT_EQ(pacer.batch_ticks(), 20u);
  EXPECT_EQ(pacer.ticks_due(kWall0 + 999, 0), 0u);  // not a whole batch yet: keep sleeping
  EXPECT_EQ(pacer.wait_us(kWall0 + 999, 0), 2u);      // due at +1000 (+1 µs of rounding margin)
  EXPECT_EQ(pacer.ticks_due(kWall0 + 1000, 0), 20u);
  EXPECT_EQ(pacer.ticks_due(kWall0 + 1000, 1000), 0u);  // after running them
  EXPECT_EQ(pacer.wait_us(kWall0 + 1000, 1000), 1001u);
  EXPECT_EQ(pacer.ticks_due(kWall0 + 50'000, 1000), 980u);  // behind by 49 ms: all of it
  EXPECT_EQ(pacer.dropped_backlog_sim_us(), 0u);
}

TEST(Pacer, a_factor_scales_sim_time_against_wall_time) {
  Pacer double_speed(Pacing::factor(2), kTickUs);
  double_speed.start(kWall0, 5000);
  EXPECT_EQ(double_speed.batch_ticks(), 40u);
  EXPECT_EQ(double_speed.target_sim_us(kWall0 + 1000), 7000u);
  EXPECT_EQ(double_speed.ticks_due(kWall0 + 1000, 5000), 40u);
  EXPECT_EQ(double_speed.ticks_due(kWall0 + 10'000, 5000), 400u);

  Pacer half_speed(Pacing::factor(0.5), kTickUs);
  half_speed.start(kWall0, 0);
  EXPECT_EQ(half_speed.batch_ticks(), 10u);
  EXPECT_EQ(half_speed.target_sim_us(kWall0 + 1000), 500u);
  EXPECT_EQ(half_speed.ticks_due(kWall0 + 1000, 0), 10u);
  EXPECT_EQ(half_speed.wait_us(kWall0 + 1000, 500), 1001u);

  // Very slow: a batch is a single tick, due every 50 ms of wall time.
  Pacer crawl(Pacing::factor(0.001), kTickUs);
  crawl.start(kWall0, 0);
  EXPECT_EQ(crawl.batch_ticks(), 1u);
  EXPECT_EQ(crawl.ticks_due(kWall0 + 49'999, 0), 0u);
  EXPECT_EQ(crawl.ticks_due(kWall0 + 50'000, 0), 1u);
}

TEST(Pacer, catches_up_at_most_100_ms_and_drops_the_rest) {
  Pacer pacer(Pacing::realtime(), kTickUs);
  pacer.start(kWall0, 0);
  // A 1 s stall: only 100 ms of sim time is owed afterwards.
  EXPECT_EQ(pacer.ticks_due(kWall0 + 1'000'000, 0), 2000u);
  EXPECT_EQ(pacer.dropped_backlog_sim_us(), 900'000u);
  EXPECT_EQ(pacer.ticks_due(kWall0 + 1'000'000, 100'000), 0u);
  // From then on sim time follows the wall clock again, 900 ms behind the original anchor.
  EXPECT_EQ(pacer.ticks_due(kWall0 + 1'001'000, 100'000), 20u);
}

TEST(Pacer, fast_mode_always_has_a_chunk_due_and_never_waits) {
  Pacer pacer(Pacing::fast(), kTickUs);
  pacer.start(kWall0, 0);
  EXPECT_EQ(pacer.chunk_ticks(), 20u);  // 1 ms of sim time between looks at the sockets
  EXPECT_EQ(pacer.ticks_due(kWall0, 0), 20u);
  EXPECT_EQ(pacer.ticks_due(kWall0, 1'000'000'000), 20u);
  EXPECT_EQ(pacer.wait_us(kWall0, 1'000'000'000), 0u);
}

}  // namespace
}  // namespace motwin::host
