// The general-purpose I/O of a simulated TMCL module board (TMCM-1636, TMCM-142): digital input
// levels, raw 12-bit ADC counts of the analog inputs, the digital outputs (each change logged
// under its signal name) and the supply voltage the host sets. A module's simulated I/O derives
// from it, answers the rest of its board seam and adds its own signals.
//
// The module's signal table starts with its digital inputs, then its kAnalogInputs analog
// inputs, then VSUPPLY; the module's own signals follow (set_general_input() and
// read_general_signal() take the index of a signal in that table). A CRTP base: `Derived` may
// hide set_digital_input(), set_analog_input_raw() and set_supply_millivolt() when a pin drives
// another or the supply feeds an ADC channel. SimBoardOverIo is the board around it.
#pragma once

#include <array>
#include <cmath>
#include <cstddef>
#include <cstdint>
#include <optional>
#include <span>
#include <string_view>
#include <vector>

#include "sim/signals.h"

namespace motwin::sim {

template <class Derived, class Seam, size_t kAnalogInputs>
class SimGeneralIo : public Seam, public LoggingSignalBoard {
 public:
  static constexpr int32_t kDefaultSupplyMillivolt = 24000;
  static constexpr uint16_t kAdcMax = 4095;  // 12 bits

  // Seam.
  bool digital_input(uint8_t port) const override { return port < Seam::kDigitalInputCount && digital_inputs_[port]; }
  void set_digital_output(uint8_t port, bool on) override {
    if (port >= Seam::kDigitalOutputCount || digital_outputs_[port] == on) return;
    digital_outputs_[port] = on;
    output_changes_.record(output_names_[port], on ? 1 : 0);
  }
  bool digital_output(uint8_t port) const override { return port < Seam::kDigitalOutputCount && digital_outputs_[port]; }

  // Typed setters. Out-of-range ports are ignored; ADC counts are clamped to 0..4095.
  void set_digital_input(uint8_t port, bool level) {
    if (port < Seam::kDigitalInputCount) digital_inputs_[port] = level;
  }
  void set_analog_input_raw(uint8_t channel, uint16_t raw) {
    if (channel < kAnalogInputs) analog_inputs_raw_[channel] = raw > kAdcMax ? kAdcMax : raw;
  }
  void set_supply_millivolt(int32_t millivolt) { supply_millivolt_ = millivolt; }
  int32_t supply_millivolt() const { return supply_millivolt_; }

 protected:
  using OutputNames = std::array<std::string_view, Seam::kDigitalOutputCount>;

  explicit SimGeneralIo(const OutputNames& output_names) : output_names_(output_names) {}

  // set_input() for the signals the table starts with; false for a module's own signal.
  bool set_general_input(size_t index, double value) {
    if (index < kFirstAnalogInput) {
      derived().set_digital_input(static_cast<uint8_t>(index), value != 0);
    } else if (index < kSupply) {
      derived().set_analog_input_raw(static_cast<uint8_t>(index - kFirstAnalogInput), static_cast<uint16_t>(value));
    } else if (index == kSupply) {
      derived().set_supply_millivolt(static_cast<int32_t>(std::lround(value * 1000.0)));
    } else {
      return false;
    }
    return true;
  }

  // read_signal() for the outputs (by name) and the signals the table starts with (by index);
  // nullopt for anything else.
  std::optional<double> read_output_signal(std::string_view name) const {
    for (size_t port = 0; port < Seam::kDigitalOutputCount; ++port) {
      if (same_signal_name(name, output_names_[port])) return digital_outputs_[port] ? 1.0 : 0.0;
    }
    return std::nullopt;
  }
  std::optional<double> read_general_signal(size_t index) const {
    if (index < kFirstAnalogInput) return digital_inputs_[index] ? 1.0 : 0.0;
    if (index < kSupply) return analog_inputs_raw_[index - kFirstAnalogInput];
    if (index == kSupply) return supply_millivolt_ / 1000.0;
    return std::nullopt;
  }

  std::array<bool, Seam::kDigitalInputCount> digital_inputs_{};
  std::array<uint16_t, kAnalogInputs> analog_inputs_raw_{};

 private:
  static constexpr size_t kFirstAnalogInput = Seam::kDigitalInputCount;
  static constexpr size_t kSupply = kFirstAnalogInput + kAnalogInputs;

  Derived& derived() { return static_cast<Derived&>(*this); }

  OutputNames output_names_;
  std::array<bool, Seam::kDigitalOutputCount> digital_outputs_{};
  int32_t supply_millivolt_ = kDefaultSupplyMillivolt;
};

// A module's simulated board around its I/O (a SimGeneralIo): its signal table is the I/O's
// followed by the motor side's (Derived::signal_table()); the I/O's output changes are the
// board's. The board hands the inputs that are not the motor's to io_.
template <class Derived, class SimIo>
class SimBoardOverIo : public SignalBoard {
 public:
  SimIo& io() { return io_; }

  // SignalBoard.
  std::span<const SignalInfo> input_signals() const override { return Derived::signal_table(); }
  void take_output_changes(std::vector<OutputChange>& out) override { io_.take_output_changes(out); }

 protected:
  explicit SimBoardOverIo(SimIo& io) : io_(io) {}

  SimIo& io_;
};

}  // namespace motwin::sim
