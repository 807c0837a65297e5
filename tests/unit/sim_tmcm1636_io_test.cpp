#include <gtest/gtest.h>

#include <string>
#include <vector>

#include "core/modules/tmcm1636/tmcm1636_hardware.h"
#include "sim/signals.h"
#include "sim/modules/tmcm1636/tmcm1636_sim_io.h"

namespace motwin::sim {
namespace {

namespace hw = modules::tmcm1636;
using board::ReferenceSwitch;
using board::Tmcm1636Io;

TEST(Tmcm1636SimIo, defaults_read_back_as_24_volts_and_25_degrees_through_the_firmware_formulas) {
  Tmcm1636SimIo io;
  EXPECT_EQ(io.analog_input(Tmcm1636Io::kAnalogSupplyChannel), hw::supply_adc_from_millivolt(24000));
  EXPECT_EQ(hw::supply_decivolt_from_adc(io.analog_input(Tmcm1636Io::kAnalogSupplyChannel)), 240);
  EXPECT_EQ(hw::temperature_celsius_from_adc(io.analog_input(Tmcm1636Io::kAnalogTemperatureChannel)), 25);
  EXPECT_EQ(io.analog_input(0), 0);
  EXPECT_FALSE(io.digital_input(0));
  EXPECT_FALSE(io.reference_switch_level(ReferenceSwitch::kHome));
}

TEST(Tmcm1636SimIo, named_inputs_reach_the_board_interface) {
  Tmcm1636SimIo io;
  io.set_input("VSUPPLY", 26.5);
  io.set_input("TEMP", 60.0);
  io.set_input("AI1", 4095);
  io.set_input("gpi2", 1);  // names are case-insensitive
  io.set_input("REF_H", 1);
  EXPECT_EQ(hw::supply_decivolt_from_adc(io.analog_input(Tmcm1636Io::kAnalogSupplyChannel)), 265);
  EXPECT_EQ(hw::temperature_celsius_from_adc(io.analog_input(Tmcm1636Io::kAnalogTemperatureChannel)), 60);
  EXPECT_EQ(io.analog_input(1), 4095);
  EXPECT_TRUE(io.digital_input(2));
  EXPECT_FALSE(io.digital_input(1));
  EXPECT_TRUE(io.reference_switch_level(ReferenceSwitch::kHome));
  EXPECT_FALSE(io.reference_switch_level(ReferenceSwitch::kLeft));
  EXPECT_EQ(io.supply_millivolt(), 26500);
  EXPECT_EQ(io.read_signal("VSUPPLY"), 26.5);
  EXPECT_EQ(io.read_signal("GPI2"), 1.0);
  EXPECT_EQ(io.read_signal("NOPE"), std::nullopt);
}

TEST(Tmcm1636SimIo, supply_above_the_adc_range_saturates_at_full_scale) {
  Tmcm1636SimIo io;
  io.set_input("VSUPPLY", 80);
  EXPECT_EQ(io.analog_input(Tmcm1636Io::kAnalogSupplyChannel), hw::kAdc12Max);
}

TEST(Tmcm1636SimIo, output_changes_are_recorded_once_with_their_sim_time) {
  Tmcm1636SimIo io;
  io.set_sim_time_us(500'000);
  io.set_digital_output(0, true);
  io.set_digital_output(0, true);  // no change: not recorded
  io.set_sim_time_us(750'050);
  io.set_digital_output(1, true);
  io.set_digital_output(0, false);
  std::vector<OutputChange> changes;
  io.take_output_changes(changes);
  ASSERT_EQ(changes.size(), 3u);
  EXPECT_EQ(changes[0].signal, "GPO0");
  EXPECT_EQ(changes[0].level, 1);
  EXPECT_EQ(changes[0].sim_time_us, 500'000u);
  EXPECT_EQ(changes[1].signal, "GPO1");
  EXPECT_EQ(changes[1].sim_time_us, 750'050u);
  EXPECT_EQ(changes[2].signal, "GPO0");
  EXPECT_EQ(changes[2].level, 0);
  EXPECT_TRUE(io.digital_output(1));
  EXPECT_EQ(io.read_signal("GPO1"), 1.0);
  changes.clear();
  io.take_output_changes(changes);
  EXPECT_TRUE(changes.empty());
}

TEST(Tmcm1636SimIo, a_flood_of_output_changes_keeps_only_the_newest) {
  Tmcm1636SimIo io;
  for (size_t i = 0; i < Tmcm1636SimIo::kMaxPendingOutputChanges + 10; ++i) io.set_digital_output(0, i % 2 == 0);
  std::vector<OutputChange> changes;
  io.take_output_changes(changes);
  EXPECT_EQ(changes.size(), Tmcm1636SimIo::kMaxPendingOutputChanges);
  EXPECT_EQ(io.dropped_output_changes(), 10u);
}

TEST(SignalAssignment, parses_and_checks_name_and_value) {
  const auto signals = Tmcm1636SimIo::signal_table();
  const Result<SignalAssignment> supply = parse_signal_assignment(signals, "VSUPPLY=26.5");
  ASSERT_TRUE(supply) << supply.error();
  EXPECT_EQ(supply->signal->name, "VSUPPLY");
  EXPECT_EQ(supply->value, 26.5);

  Result<SignalAssignment> refused = parse_signal_assignment(signals, "GPI0");
  EXPECT_FALSE(refused);
  EXPECT_EQ(refused.error(), "expected SIGNAL=VALUE, got \"GPI0\"");
  refused = parse_signal_assignment(signals, "GPI9=1");
  EXPECT_FALSE(refused);
  EXPECT_NE(refused.error().find("unknown signal \"GPI9\""), std::string::npos) << refused.error();
  refused = parse_signal_assignment(signals, "GPI0=2");
  EXPECT_FALSE(refused);
  EXPECT_EQ(refused.error(), "GPI0 takes 0 or 1 (digital input level), got 2");
  refused = parse_signal_assignment(signals, "AI0=1.5");
  EXPECT_FALSE(refused);
  EXPECT_EQ(refused.error(), "AI0 takes a whole number from 0 to 4095 (raw 12-bit ADC count), got 1.5");
  refused = parse_signal_assignment(signals, "TEMP=hot");
  EXPECT_FALSE(refused);
  EXPECT_EQ(refused.error(), "value of TEMP is not a number: \"hot\"");
  EXPECT_FALSE(parse_signal_assignment(signals, "TEMP=nan"));
}

}  // namespace
}  // namespace motwin::sim
