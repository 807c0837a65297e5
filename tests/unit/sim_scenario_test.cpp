#include <gtest/gtest.h>

#include <cstdio>
#include <filesystem>
#include <fstream>
#include <string>

#include "sim/scenario.h"
#include "sim/modules/tmcm1636/tmcm1636_sim_io.h"
#include "support/host_test_support.h"

namespace motwin::sim {
namespace {

Result<std::vector<ScenarioEvent>> parse(std::string_view text) {
  return parse_scenario(text, "test.scn", Tmcm1636SimIo::signal_table());
}

TEST(ScenarioParser, reads_events_sorted_by_time_with_comments_and_blank_lines) {
  const Result<std::vector<ScenarioEvent>> result = parse(
      "# supply dip while the home switch closes\n"
      "\n"
      "2.0   VSUPPLY 26.5   # after the dip\n"
      "0.5\tGPI0 1\n"
      "   1e-3 ref_h 1\r\n"
      "0.5 GPI0 0\n");
  ASSERT_TRUE(result.ok()) << result.error();
  ASSERT_EQ(result->size(), 4u);
  EXPECT_EQ((*result)[0].time_us, 1000u);
  EXPECT_EQ((*result)[0].signal, "REF_H");  // canonical name
  EXPECT_EQ((*result)[0].line, 5u);
  EXPECT_EQ((*result)[1].time_us, 500'000u);
  EXPECT_EQ((*result)[1].value, 1.0);
  EXPECT_EQ((*result)[2].time_us, 500'000u);  // equal times keep file order
  EXPECT_EQ((*result)[2].value, 0.0);
  EXPECT_EQ((*result)[3].signal, "VSUPPLY");
  EXPECT_EQ((*result)[3].time_us, 2'000'000u);
  EXPECT_EQ((*result)[3].value, 26.5);
}

TEST(ScenarioParser, an_empty_file_has_no_events) {
  const Result<std::vector<ScenarioEvent>> result = parse("# nothing\n\n");
  EXPECT_TRUE(result.ok());
  EXPECT_TRUE(result->empty());
}

TEST(ScenarioParser, reports_each_kind_of_error_with_file_and_line) {
  EXPECT_EQ(parse("0.5 GPI0\n").error(), "test.scn:1: expected \"<time_s> <SIGNAL> <value>\", got 2 fields");
  EXPECT_EQ(parse("\n0.5 GPI0 1 2\n").error(), "test.scn:2: expected \"<time_s> <SIGNAL> <value>\", got 4 fields");
  EXPECT_EQ(parse("soon GPI0 1\n").error(), "test.scn:1: expected a time in seconds, got \"soon\"");
  EXPECT_EQ(parse("-1 GPI0 1\n").error(), "test.scn:1: expected a time >= 0 s, got -1");
  EXPECT_EQ(parse("1e12 GPI0 1\n").error(), "test.scn:1: time 1e12 s is too large");
  EXPECT_EQ(parse("0 GPI7 1\n").error(),
            "test.scn:1: unknown signal \"GPI7\" (expected one of GPI0, GPI1, GPI2, GPI3, AI0, AI1, VSUPPLY, TEMP, "
            "REF_R, REF_L, REF_H)");
  EXPECT_EQ(parse("0 VSUPPLY high\n").error(), "test.scn:1: expected a number as the value of VSUPPLY, got \"high\"");
  EXPECT_EQ(parse("# ok\n0 GPI0 1\n3 GPI0 5\n").error(), "test.scn:3: GPI0 takes 0 or 1 (digital input level), got 5");
  EXPECT_EQ(parse("0 AI0 5000\n").error(),
            "test.scn:1: AI0 takes a whole number from 0 to 4095 (raw 12-bit ADC count), got 5000");
  EXPECT_FALSE(parse("0 GPI0 5\n").ok());  // never half parsed: no events
}

TEST(ScenarioParser, a_missing_file_is_an_error_naming_it) {
  const Result<std::vector<ScenarioEvent>> result = load_scenario_file("/nonexistent/x.scn", Tmcm1636SimIo::signal_table());
  EXPECT_EQ(result.error(), "cannot read scenario file /nonexistent/x.scn: No such file or directory");
}

TEST(ScenarioParser, loads_a_file) {
  testing::ScratchDirectory scratch;
  const std::string path = (scratch.path() / "dip.scn").string();
  std::ofstream(path) << "0.25 TEMP 80\n0.25 GPI3 x\n";
  const Result<std::vector<ScenarioEvent>> result = load_scenario_file(path, Tmcm1636SimIo::signal_table());
  EXPECT_EQ(result.error(), path + ":2: expected a number as the value of GPI3, got \"x\"");
}

TEST(ScenarioPlayer, applies_events_when_their_time_is_reached) {
  Tmcm1636SimIo io;
  const Result<std::vector<ScenarioEvent>> parsed = parse("0.5 GPI0 1\n0.00001 AI0 100\n0.5 VSUPPLY 12\n1 GPI0 0\n");
  ASSERT_TRUE(parsed.ok());
  ScenarioPlayer player(*parsed, io);
  EXPECT_EQ(player.next_event_time_us(), 10u);
  EXPECT_EQ(player.apply_due(0), 0u);
  EXPECT_EQ(io.analog_input(0), 0);
  EXPECT_EQ(player.apply_due(50), 1u);  // 10 µs: before the tick starting at 50 µs
  EXPECT_EQ(io.analog_input(0), 100);
  EXPECT_EQ(player.apply_due(499'950), 0u);
  EXPECT_FALSE(io.digital_input(0));
  EXPECT_EQ(player.apply_due(500'000), 2u);
  EXPECT_TRUE(io.digital_input(0));
  EXPECT_EQ(io.supply_millivolt(), 12000);
  EXPECT_EQ(player.next_event_time_us(), 1'000'000u);
  EXPECT_EQ(player.apply_due(5'000'000), 1u);
  EXPECT_FALSE(io.digital_input(0));
  EXPECT_TRUE(player.finished());
  EXPECT_EQ(player.next_event_time_us(), std::nullopt);
}

// An event made now (the web console's World view) goes in before the file's later events and
// after the ones of its time; applied events are dropped, still counted.
TEST(ScenarioPlayer, an_inserted_event_applies_in_time_order_among_the_files) {
  Tmcm1636SimIo io;
  const Result<std::vector<ScenarioEvent>> parsed = parse("0.5 GPI0 1\n1 GPI0 0\n");
  ASSERT_TRUE(parsed.ok());
  ScenarioPlayer player(*parsed, io);
  EXPECT_EQ(player.apply_due(500'000), 1u);
  const Result<ScenarioEvent> live = make_scenario_event(Tmcm1636SimIo::signal_table(), "vsupply", 30, 600'000);
  ASSERT_TRUE(live.ok()) << live.error();
  EXPECT_EQ(live->signal, "VSUPPLY");
  player.insert(*live);
  EXPECT_EQ(player.next_event_time_us(), 600'000u);
  EXPECT_EQ(player.apply_due(600'000), 1u);
  EXPECT_EQ(io.supply_millivolt(), 30000);
  EXPECT_EQ(player.applied_count(), 2u);
  EXPECT_EQ(player.next_event_time_us(), 1'000'000u);
  EXPECT_FALSE(make_scenario_event(Tmcm1636SimIo::signal_table(), "VSUPPLY", 101, 0).ok());
  EXPECT_EQ(make_scenario_event(Tmcm1636SimIo::signal_table(), "NOPE", 1, 0).error().find("unknown signal \"NOPE\""),
            0u);
}

}  // namespace
}  // namespace motwin::sim
