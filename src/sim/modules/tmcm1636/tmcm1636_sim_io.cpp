#include "sim/modules/tmcm1636/tmcm1636_sim_io.h"

#include <string_view>

#include "core/modules/tmcm1636/tmcm1636_hardware.h"

namespace motwin::sim {
namespace {

using board::ReferenceSwitch;
namespace hw = modules::tmcm1636;
using hw::kAdc12Max;

constexpr SignalInfo kSignals[] = {
    {"GPI0", 0, 1, true, "digital input level"},
    {"GPI1", 0, 1, true, "digital input level"},
    {"GPI2", 0, 1, true, "digital input level"},
    {"GPI3", 0, 1, true, "digital input level"},
    {"AI0", 0, kAdc12Max, true, "raw 12-bit ADC count", "counts"},
    {"AI1", 0, kAdc12Max, true, "raw 12-bit ADC count", "counts"},
    {"VSUPPLY", 0, 100, false, "supply voltage in volts; the ADC saturates at 66 V", "V"},
    {"TEMP", -50, 280, false, "driver temperature in degrees Celsius", "°C"},
    {"REF_R", 0, 1, true, "right reference switch input level"},
    {"REF_L", 0, 1, true, "left reference switch input level"},
    {"REF_H", 0, 1, true, "home switch input level"},
};

// Indices into kSignals of the TMCM-1636's own signals (SimGeneralIo knows those before them).
enum SignalIndex : size_t { kTemperature = 7, kRefRight = 8 };

size_t index_of(const SignalInfo* signal) { return static_cast<size_t>(signal - kSignals); }

}  // namespace

std::span<const SignalInfo> Tmcm1636SimIo::signal_table() { return kSignals; }

Tmcm1636SimIo::Tmcm1636SimIo() : SimGeneralIo({"GPO0", "GPO1"}) {
  set_supply_millivolt(kDefaultSupplyMillivolt);
  set_temperature_celsius(kDefaultTemperatureCelsius);
}

uint16_t Tmcm1636SimIo::analog_input(uint8_t channel) const {
  switch (channel) {
    case 0:
    case 1: return analog_inputs_raw_[channel];
    case kAnalogSupplyChannel: return supply_raw_;
    case kAnalogTemperatureChannel: return temperature_raw_;
    default: return 0;
  }
}

bool Tmcm1636SimIo::reference_switch_level(ReferenceSwitch which) const {
  const auto index = static_cast<size_t>(which);
  return index < reference_switch_levels_.size() && reference_switch_levels_[index];
}

void Tmcm1636SimIo::set_supply_millivolt(int32_t millivolt) {
  SimGeneralIo::set_supply_millivolt(millivolt);
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
  if (set_general_input(index, value)) return;
  if (index == kTemperature) {
    set_temperature_celsius(value);
  } else {
    set_reference_switch_level(static_cast<ReferenceSwitch>(index - kRefRight), value != 0);
  }
}

std::optional<double> Tmcm1636SimIo::read_signal(std::string_view name) const {
  if (const auto output = read_output_signal(name)) return output;
  const SignalInfo* signal = find_signal(kSignals, name);
  if (signal == nullptr) return std::nullopt;
  const size_t index = index_of(signal);
  if (const auto general = read_general_signal(index)) return general;
  if (index == kTemperature) return temperature_celsius_;
  return reference_switch_levels_[index - kRefRight] ? 1.0 : 0.0;
}

}  // namespace motwin::sim
