// Simulated general I/O of the TMCM-1636: digital inputs GPI0..3, analog inputs AI0/AI1,
// supply voltage and driver temperature (as the raw ADC_VM / ADC_TEMP counts the firmware
// converts back, manual 2.6.13/2.6.14), outputs GPO0/1 and the reference switch inputs.
// The host sets inputs by name (--set, scenario files) and logs output changes.
#pragma once

#include <array>
#include <cstdint>
#include <optional>
#include <span>
#include <string_view>

#include "board/modules/tmcm1636/tmcm1636_io.h"
#include "sim/general_io.h"
#include "sim/signals.h"

namespace motwin::sim {

// AI0 and AI1 are the analog inputs of the signal table; ADC_VM and ADC_TEMP follow VSUPPLY and TEMP.
class Tmcm1636SimIo final : public SimGeneralIo<Tmcm1636SimIo, board::Tmcm1636Io, 2> {
 public:
  static constexpr double kDefaultTemperatureCelsius = 25.0;

  // GPI0..3, AI0, AI1, VSUPPLY, TEMP, REF_R, REF_L, REF_H.
  static std::span<const SignalInfo> signal_table();

  Tmcm1636SimIo();

  // board::Tmcm1636Io (the digital inputs and outputs: SimGeneralIo).
  uint16_t analog_input(uint8_t channel) const override;
  bool reference_switch_level(board::ReferenceSwitch which) const override;

  // Typed setters beyond SimGeneralIo's. Values are clamped to what the ADC reads.
  void set_supply_millivolt(int32_t millivolt);
  void set_temperature_celsius(double celsius);
  double temperature_celsius() const { return temperature_celsius_; }
  void set_reference_switch_level(board::ReferenceSwitch which, bool level);
  // With a physical motor the board measures its own bus and heat sink: ADC_VM and ADC_TEMP
  // then read these, while VSUPPLY and TEMP stay the source voltage and the ambient
  // temperature that the signals set (sim/modules/tmcm1636/tmcm1636_sim_board.h).
  void set_measured_supply_raw(uint16_t raw) { supply_raw_ = raw; }
  void set_measured_temperature_celsius(double celsius);

  // SignalBoard.
  std::span<const SignalInfo> input_signals() const override { return signal_table(); }
  void set_input(std::string_view name, double value) override;
  std::optional<double> read_signal(std::string_view name) const override;

 private:
  uint16_t supply_raw_ = 0;
  double temperature_celsius_ = kDefaultTemperatureCelsius;
  uint16_t temperature_raw_ = 0;
  std::array<bool, 3> reference_switch_levels_{};
};

}  // namespace motwin::sim
