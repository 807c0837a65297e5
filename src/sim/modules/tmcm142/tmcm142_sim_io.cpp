#include "sim/modules/tmcm142/tmcm142_sim_io.h"

#include <cmath>
#include <string_view>

namespace motwin::sim {
namespace {

constexpr std::string_view kOutputNames[] = {"OUT0", "OUT1", "OUT2"};

constexpr SignalInfo kSignals[] = {
    {"IN0", 0, 1, true, "digital level of IN0_A/D (sets AIN0 to 0 or 4095)"},
    {"IN1", 0, 1, true, "digital level of IN1_A/D (sets AIN1 to 0 or 4095)"},
    {"IN2", 0, 1, true, "digital level of IN2_A/D (sets AIN2 to 0 or 4095)"},
    {"IN3", 0, 1, true, "digital input level"},
    {"IN4", 0, 1, true, "digital input level"},
    {"IN5", 0, 1, true, "digital input level"},
    {"IN6", 0, 1, true, "digital input level"},
    {"IN7", 0, 1, true, "digital input level as the firmware reads it (opto-isolated)"},
    {"IN8", 0, 1, true, "digital input level as the firmware reads it (opto-isolated)"},
    {"AIN0", 0, Tmcm142SimIo::kAdcMax, true, "raw 12-bit ADC count of IN0_A/D"},
    {"AIN1", 0, Tmcm142SimIo::kAdcMax, true, "raw 12-bit ADC count of IN1_A/D"},
    {"AIN2", 0, Tmcm142SimIo::kAdcMax, true, "raw 12-bit ADC count of IN2_A/D"},
    {"VSUPPLY", 0, 80, false, "motor supply voltage in volts (the TMCM-142 takes 15..75 V)"},
};

// Indices into kSignals, so that set_input() and read_signal() switch on one number.
enum SignalIndex : size_t { kIn0 = 0, kAin0 = 9, kSupply = 12 };

size_t index_of(const SignalInfo* signal) { return static_cast<size_t>(signal - kSignals); }

}  // namespace

std::span<const SignalInfo> Tmcm142SimIo::signal_table() { return kSignals; }

bool Tmcm142SimIo::digital_input(uint8_t port) const { return port < kDigitalInputCount && digital_inputs_[port]; }

uint16_t Tmcm142SimIo::analog_input(uint8_t channel) const {
  return channel < kAnalogInputCount ? analog_inputs_raw_[channel] : 0;
}

void Tmcm142SimIo::set_digital_output(uint8_t port, bool on) {
  if (port >= kDigitalOutputCount || digital_outputs_[port] == on) return;
  digital_outputs_[port] = on;
  output_changes_.record(kOutputNames[port], on ? 1 : 0);
}

bool Tmcm142SimIo::digital_output(uint8_t port) const { return port < kDigitalOutputCount && digital_outputs_[port]; }

void Tmcm142SimIo::set_digital_input(uint8_t port, bool level) {
  if (port >= kDigitalInputCount) return;
  digital_inputs_[port] = level;
  if (port < kAnalogInputCount) analog_inputs_raw_[port] = level ? kAdcMax : 0;
}

void Tmcm142SimIo::set_analog_input_raw(uint8_t channel, uint16_t raw) {
  if (channel >= kAnalogInputCount) return;
  analog_inputs_raw_[channel] = raw > kAdcMax ? kAdcMax : raw;
  digital_inputs_[channel] = analog_inputs_raw_[channel] >= kDigitalThresholdRaw;
}

void Tmcm142SimIo::set_input(std::string_view name, double value) {
  const SignalInfo* signal = find_signal(kSignals, name);
  if (signal == nullptr) return;
  const size_t index = index_of(signal);
  if (index < kAin0) {
    set_digital_input(static_cast<uint8_t>(index - kIn0), value != 0);
  } else if (index < kSupply) {
    set_analog_input_raw(static_cast<uint8_t>(index - kAin0), static_cast<uint16_t>(value));
  } else {
    set_supply_millivolt(static_cast<int32_t>(std::lround(value * 1000.0)));
  }
}

std::optional<double> Tmcm142SimIo::read_signal(std::string_view name) const {
  for (size_t port = 0; port < kDigitalOutputCount; ++port) {
    if (same_signal_name(name, kOutputNames[port])) return digital_outputs_[port] ? 1.0 : 0.0;
  }
  const SignalInfo* signal = find_signal(kSignals, name);
  if (signal == nullptr) return std::nullopt;
  const size_t index = index_of(signal);
  if (index < kAin0) return digital_inputs_[index - kIn0] ? 1.0 : 0.0;
  if (index < kSupply) return analog_inputs_raw_[index - kAin0];
  return supply_millivolt_ / 1000.0;
}

}  // namespace motwin::sim
