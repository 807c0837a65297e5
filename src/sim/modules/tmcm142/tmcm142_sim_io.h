// Simulated general I/O of the TMCM-142 (connector 3, manual table 5.2): digital inputs IN0..IN8,
// the analog inputs IN0..IN2 A/D (12 bit), the outputs OUT_0..OUT_2 and the motor supply. The
// host sets inputs by name (--set, scenario files) and logs output changes. The limit switches
// and the encoder belong to the motor side (sim/modules/tmcm142/tmcm142_sim_board.h).
#pragma once

#include <array>
#include <cstddef>
#include <cstdint>
#include <span>
#include <vector>

#include "board/modules/tmcm142/tmcm142_io.h"
#include "sim/signals.h"

namespace motwin::sim {

class Tmcm142SimIo final : public board::Tmcm142Io, public LoggingSignalBoard {
 public:
  static constexpr int32_t kDefaultSupplyMillivolt = 24000;
  static constexpr uint16_t kAdcMax = 4095;
  // IN0..IN2 are one pin each, read both ways: the digital level is high from half scale on
  // (a Motwin decision: the pins have no Schmitt trigger documented).
  static constexpr uint16_t kDigitalThresholdRaw = 2048;

  // IN0..IN8, AIN0..AIN2, VSUPPLY.
  static std::span<const SignalInfo> signal_table();

  Tmcm142SimIo() = default;

  // board::Tmcm142Io.
  bool digital_input(uint8_t port) const override;
  uint16_t analog_input(uint8_t channel) const override;
  void set_digital_output(uint8_t port, bool on) override;
  bool digital_output(uint8_t port) const override;

  // Typed setters; out-of-range ports are ignored, ADC counts clamped to 0..4095. A digital
  // level on IN0..IN2 drives the pin to 0 or full scale; an analog count sets the level too.
  void set_digital_input(uint8_t port, bool level);
  void set_analog_input_raw(uint8_t channel, uint16_t raw);
  void set_supply_millivolt(int32_t millivolt) { supply_millivolt_ = millivolt; }
  int32_t supply_millivolt() const { return supply_millivolt_; }


  // SignalBoard.
  std::span<const SignalInfo> input_signals() const override { return signal_table(); }
  void set_input(std::string_view name, double value) override;
  // Inputs and OUT0..OUT2.
  std::optional<double> read_signal(std::string_view name) const override;

 private:
  std::array<bool, kDigitalInputCount> digital_inputs_{};
  std::array<uint16_t, kAnalogInputCount> analog_inputs_raw_{};
  int32_t supply_millivolt_ = kDefaultSupplyMillivolt;
  std::array<bool, kDigitalOutputCount> digital_outputs_{};
};

}  // namespace motwin::sim
