#include "sim/modules/tmcm1636/tmcm1636_sim_io.h"

#include <cmath>
#include <string_view>

#include "core/modules/tmcm1636/tmcm1636_hardware.h"

namespace motwin::sim {
namespace {

using board::ReferenceSwitch;
namespace hw = modules::tmcm1636;

constexpr std::string_view kOutputNames[] = {"GPO0", "GPO1"};

constexpr SignalInfo kSignals[] = {
    {"GPI0", 0, 1, true, "digital input level"},
    {"GPI1", 0, 1, true, "digital input level"},
    {"GPI2", 0, 1, true, "digital input level"},
    {"GPI3", 0, 1, true, "digital input level"},
    {"AI0", 0, hw::kAdc12Max, true, "raw 12-bit ADC count"},
    {"AI1", 0, hw::kAdc12Max, true, "raw 12-bit ADC count"},
    {"VSUPPLY", 0, 100, false, "supply voltage in volts; the ADC saturates at 66 V"},
    {"TEMP", -50, 280, false, "driver temperature in degrees Celsius"},
    {"REF_R", 0, 1, true, "right reference switch input level"},
    {"REF_L", 0, 1, true, "left reference switch input level"},
    {"REF_H", 0, 1, true, "home switch input level"},
};

// Indices into kSignals, so that set_input() and read_signal() switch on one number.
enum SignalIndex : size_t { kGpi0 = 0, kAi0 = 4, kSupply = 6, kTemperature = 7, kRefRight = 8 };

size_t index_of(const SignalInfo* signal) { return static_cast<size_t>(signal - kSignals); }

}  // namespace

std::span<const SignalInfo> Tmcm1636SimIo::signal_table() { return kSignals; }

Tmcm1636SimIo::Tmcm1636SimIo() {
  set_supply_millivolt(kDefaultSupplyMillivolt);
  set_temperature_celsius(kDefaultTemperatureCelsius);
}

bool Tmcm1636SimIo::digital_input(uint8_t port) const { return port < kDigitalInputCount && digital_inputs_[port]; }

uint16_t Tmcm1636SimIo::analog_input(uint8_t channel) const {
  switch (channel) {
    case 0:
    case 1: return analog_inputs_raw_[channel];
    case kAnalogSupplyChannel: return supply_raw_;
    case kAnalogTemperatureChannel: return temperature_raw_;
    default: return 0;
  }
}

void Tmcm1636SimIo::set_digital_output(uint8_t port, bool on) {
  if (port >= kDigitalOutputCount || digital_outputs_[port] == on) return;
  digital_outputs_[port] = on;
  output_changes_.record(kOutputNames[port], on ? 1 : 0);
}

bool Tmcm1636SimIo::digital_output(uint8_t port) const { return port < kDigitalOutputCount && digital_outputs_[port]; }

bool Tmcm1636SimIo::reference_switch_level(ReferenceSwitch which) const {
  const auto index = static_cast<size_t>(which);
  return index < reference_switch_levels_.size() && reference_switch_levels_[index];
}

void Tmcm1636SimIo::set_digital_input(uint8_t port, bool level) {
  if (port < kDigitalInputCount) digital_inputs_[port] = level;
}

void Tmcm1636SimIo::set_analog_input_raw(uint8_t channel, uint16_t raw) {
  if (channel < analog_inputs_raw_.size()) {
    analog_inputs_raw_[channel] = raw > hw::kAdc12Max ? static_cast<uint16_t>(hw::kAdc12Max) : raw;
  }
}

void Tmcm1636SimIo::set_supply_millivolt(int32_t millivolt) {
  supply_millivolt_ = millivolt;
  supply_raw_ = hw::supply_adc_from_millivolt(millivolt);
}

void Tmcm1636SimIo::set_temperature_celsius(double celsius) {
  temperature_celsius_ = celsius;
  temperature_raw_ = hw::temperature_adc_from_celsius(celsius);
}

void Tmcm1636SimIo::set_measured_temperature_celsius(double celsius) {
  temperature_raw_ = hw::temperature_adc_from_celsius(celsius);
}

void Tmcm1636SimIo::set_reference_switch_level(ReferenceSwitch which, bool level) {
  const auto index = static_cast<size_t>(which);
  if (index < reference_switch_levels_.size()) reference_switch_levels_[index] = level;
}

void Tmcm1636SimIo::set_input(std::string_view name, double value) {
  const SignalInfo* signal = find_signal(kSignals, name);
  if (signal == nullptr) return;
  const size_t index = index_of(signal);
  if (index < kAi0) {
    set_digital_input(static_cast<uint8_t>(index - kGpi0), value != 0);
  } else if (index < kSupply) {
    set_analog_input_raw(static_cast<uint8_t>(index - kAi0), static_cast<uint16_t>(value));
  } else if (index == kSupply) {
    set_supply_millivolt(static_cast<int32_t>(std::lround(value * 1000.0)));
  } else if (index == kTemperature) {
    set_temperature_celsius(value);
  } else {
    set_reference_switch_level(static_cast<ReferenceSwitch>(index - kRefRight), value != 0);
  }
}

std::optional<double> Tmcm1636SimIo::read_signal(std::string_view name) const {
  for (size_t port = 0; port < kDigitalOutputCount; ++port) {
    if (same_signal_name(name, kOutputNames[port])) {
      return digital_outputs_[port] ? 1.0 : 0.0;
    }
  }
  const SignalInfo* signal = find_signal(kSignals, name);
  if (signal == nullptr) return std::nullopt;
  const size_t index = index_of(signal);
  if (index < kAi0) return digital_inputs_[index - kGpi0] ? 1.0 : 0.0;
  if (index < kSupply) return analog_inputs_raw_[index - kAi0];
  if (index == kSupply) return supply_millivolt_ / 1000.0;
  if (index == kTemperature) return temperature_celsius_;
  return reference_switch_levels_[index - kRefRight] ? 1.0 : 0.0;
}

}  // namespace motwin::sim
