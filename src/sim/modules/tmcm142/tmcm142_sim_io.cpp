#include "sim/modules/tmcm142/tmcm142_sim_io.h"

#include <string_view>

namespace motwin::sim {
namespace {

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
    {"AIN0", 0, Tmcm142SimIo::kAdcMax, true, "raw 12-bit ADC count of IN0_A/D", "counts"},
    {"AIN1", 0, Tmcm142SimIo::kAdcMax, true, "raw 12-bit ADC count of IN1_A/D", "counts"},
    {"AIN2", 0, Tmcm142SimIo::kAdcMax, true, "raw 12-bit ADC count of IN2_A/D", "counts"},
    {"VSUPPLY", 0, 80, false, "motor supply voltage in volts (the TMCM-142 takes 15..75 V)", "V"},
};

size_t index_of(const SignalInfo* signal) { return static_cast<size_t>(signal - kSignals); }

}  // namespace

std::span<const SignalInfo> Tmcm142SimIo::signal_table() { return kSignals; }

Tmcm142SimIo::Tmcm142SimIo() : SimGeneralIo({"OUT0", "OUT1", "OUT2"}) {}

uint16_t Tmcm142SimIo::analog_input(uint8_t channel) const {
  return channel < kAnalogInputCount ? analog_inputs_raw_[channel] : 0;
}

void Tmcm142SimIo::set_digital_input(uint8_t port, bool level) {
  if (port >= kDigitalInputCount) return;
  digital_inputs_[port] = level;
  if (port < kAnalogInputCount) analog_inputs_raw_[port] = level ? kAdcMax : 0;
}

void Tmcm142SimIo::set_analog_input_raw(uint8_t channel, uint16_t raw) {
  if (channel >= kAnalogInputCount) return;
  SimGeneralIo::set_analog_input_raw(channel, raw);
  digital_inputs_[channel] = analog_inputs_raw_[channel] >= kDigitalThresholdRaw;
}

// Every signal of the table is one SimGeneralIo knows.
void Tmcm142SimIo::set_input(std::string_view name, double value) {
  const SignalInfo* signal = find_signal(kSignals, name);
  if (signal != nullptr) set_general_input(index_of(signal), value);
}

std::optional<double> Tmcm142SimIo::read_signal(std::string_view name) const {
  if (const auto output = read_output_signal(name)) return output;
  const SignalInfo* signal = find_signal(kSignals, name);
  if (signal == nullptr) return std::nullopt;
  return read_general_signal(index_of(signal));
}

}  // namespace motwin::sim
