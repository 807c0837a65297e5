// Simulated general I/O of the TMCM-142 (connector 3, manual table 5.2): digital inputs IN0..IN8,
// the analog inputs IN0..IN2 A/D (12 bit), the outputs OUT_0..OUT_2 and the motor supply. The
// host sets inputs by name (--set, scenario files) and logs output changes. The limit switches
// and the encoder belong to the motor side (sim/modules/tmcm142/tmcm142_sim_board.h).
#pragma once

#include <cstdint>
#include <optional>
#include <span>
#include <string_view>

#include "board/modules/tmcm142/tmcm142_io.h"
#include "sim/general_io.h"
#include "sim/signals.h"

namespace motwin::sim {

class Tmcm142SimIo final
    : public SimGeneralIo<Tmcm142SimIo, board::Tmcm142Io, board::Tmcm142Io::kAnalogInputCount> {
 public:
  // IN0..IN2 are one pin each, read both ways: the digital level is high from half scale on
  // (a Motwin decision: the pins have no Schmitt trigger documented).
  static constexpr uint16_t kDigitalThresholdRaw = 2048;

  // IN0..IN8, AIN0..AIN2, VSUPPLY.
  static std::span<const SignalInfo> signal_table();

  Tmcm142SimIo();

  // board::Tmcm142Io (the digital inputs and outputs: SimGeneralIo).
  uint16_t analog_input(uint8_t channel) const override;

  // A digital level on IN0..IN2 drives the pin to 0 or full scale; an analog count sets the
  // level too.
  void set_digital_input(uint8_t port, bool level);
  void set_analog_input_raw(uint8_t channel, uint16_t raw);

  // SignalBoard.
  std::span<const SignalInfo> input_signals() const override { return signal_table(); }
  void set_input(std::string_view name, double value) override;
  // Inputs and OUT0..OUT2.
  std::optional<double> read_signal(std::string_view name) const override;
};

}  // namespace motwin::sim
