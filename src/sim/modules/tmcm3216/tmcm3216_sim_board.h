// The simulated TMCM-3216 board: three steppers behind the power-stage seams of
// board::Tmcm3216Board (the ideal motor or the physical StepperPlant), their motor-side sensors
// (ABN encoder with N pulse, right/left/home switches as windows of rotor positions), what the
// driver chips measure and flag (StallGuard2/4 from sim::StallGuardModel, open load, short,
// temperature, undervoltage), an optional holding brake per axis, and the module's I/O (DIO0..3,
// AIN0/1, supply voltage, the enable signal of the shutdown switch). One signal table for `--set` and scenario files
// (docs/tmcm-3216-drive.md, "Signals"); per-axis signals are named AXIS<n>_<NAME>.
//
// Per tick: before_tick() samples sensors and inputs into board(), the firmware ticks,
// after_tick() applies the drives to the motors and updates the measurements.
#pragma once

#include <array>
#include <cstdint>
#include <memory>
#include <optional>
#include <span>
#include <string_view>
#include <vector>

#include "board/modules/tmcm3216/tmcm3216_board.h"
#include "sim/signals.h"
#include "sim/stallguard_model.h"
#include "sim/stepper_plant.h"
#include "sim/stepper_switch_sources.h"

namespace motwin::sim {

class Tmcm3216SimBoard final : public LoggingSignalBoard {
 public:
  static constexpr uint8_t kAxisCount = board::kTmcm3216AxisCount;
  static constexpr int32_t kDefaultSupplyMillivolt = 24000;
  static constexpr uint16_t kAdcMax = 4095;
  // Driver temperature flags (TMC5160 class): pre-warning and shutdown.
  static constexpr double kTemperatureWarningCelsius = 120.0;
  static constexpr double kOvertemperatureCelsius = 150.0;

  // DIO0..DIO3, AIN0, AIN1, VSUPPLY, ENABLE, then AXIS0_* .. AXIS2_* (LOAD_TORQUE ... BRAKE).
  static std::span<const SignalInfo> signal_table();

  // The ideal motors: exact positions; load, obstacle and brake signals are accepted without
  // effect. Encoders, switches and the I/O work as with physical motors.
  Tmcm3216SimBoard();
  // Three physical hybrid steppers of the same description.
  explicit Tmcm3216SimBoard(const StepperMotorDescription& motor, int sub_steps = StepperPlant::kDefaultSubSteps);
  // A motor per axis (`--motor nema17,ideal,nema23`, sim::resolve_stepper_motors): an empty entry,
  // or an axis beyond the span, has the ideal motor.
  explicit Tmcm3216SimBoard(std::span<const std::optional<StepperMotorDescription>> motors,
                            int sub_steps = StepperPlant::kDefaultSubSteps);

  board::Tmcm3216Board& board() { return board_; }
  const board::Tmcm3216Board& board() const { return board_; }
  StepperPlant* plant(uint8_t axis) { return axes_[axis].plant.get(); }
  const StallGuardModel& stallguard(uint8_t axis) const { return axes_[axis].stallguard; }
  double rotor_revolutions(uint8_t axis) const;
  // Moves a rotor (at rest) and lets the sensors see it there.
  void set_rotor_revolutions(uint8_t axis, double position);
  bool brake_engaged(uint8_t axis) const;

  // Around each control tick of the firmware.
  void before_tick();
  void after_tick(double dt_s);
  // Whether an axis with the ideal motor rests: its last two full ticks had the same drive, with
  // the bridges off or with a powered motor standing past the StallGuard pause, which leaves
  // sensing, motor and StallGuard model as they are, so the next ticks with the same drive and
  // inputs are skipped (docs/tmcm-3216-drive.md "Idle ticks").
  bool axis_resting(uint8_t axis) const { return resting_[axis]; }
  // Tests: false makes every tick a full one.
  void set_resting_axes_enabled(bool enabled) {
    resting_enabled_ = enabled;
    touched_ = true;
  }

  // SignalBoard.
  std::span<const SignalInfo> input_signals() const override { return signal_table(); }
  void set_input(std::string_view name, double value) override;
  // Inputs; DIO levels as the pins show them; BRAKE0..2 (duty 0..255); per axis POSITION_REV,
  // SPEED_RPM, ENCODER_COUNT, SG2, SG4, BRAKE_ENGAGED and, with a physical motor, COIL_A_A,
  // COIL_B_A, TORQUE_NM.
  std::optional<double> read_signal(std::string_view name) const override;

 private:
  struct Axis {
    std::unique_ptr<StepperPlant> plant;
    IdealStepper ideal;
    StepperSensors sensors{StepperSensorConfig{}};
    StallGuardModel stallguard;
    StepperSwitchSources switches;
    StepperSensorConfig::Encoder encoder{};
    bool index_active_low = false;  // the encoder's N channel polarity
    FreezableEncoder encoder_freeze;
    uint32_t sensor_index_events = 0;   // N pulses the sensor model counted at the last sample
    uint32_t reported_index_events = 0; // ... that the interface saw (matching polarity)
    int32_t reported_index_count = 0;
    double load_torque = 0.0;
    double load_inertia = 0.0;
    bool blocked = false;
    bool open_coil_a = false;
    bool open_coil_b = false;
    bool short_circuit = false;
    double driver_celsius = 25.0;
    bool brake_fitted = false;
  };

  void apply_motor_settings(uint8_t axis);
  void apply_sensor_config(uint8_t axis);
  void sense_axis(uint8_t axis);
  bool pin_level(uint8_t dio) const;
  uint8_t brake_duty_seen(uint8_t axis) const;
  std::optional<double> read_axis_signal(uint8_t axis, size_t index) const;

  board::Tmcm3216Board board_{};
  std::array<Axis, kAxisCount> axes_;
  std::array<bool, board::Tmcm3216Io::kDioCount> dio_external_{};  // what the outside drives
  std::array<uint16_t, board::Tmcm3216Io::kAnalogInputCount> analog_raw_{};
  int32_t supply_millivolt_ = kDefaultSupplyMillivolt;
  bool enable_input_ = true;  // the shutdown switch closed: the drivers may run
  // Output logging.
  std::array<int32_t, board::Tmcm3216Io::kDioCount> logged_dio_{};
  std::array<int32_t, kAxisCount> logged_brake_{};
  // Resting axes: what their last full tick started from and saw.
  bool resting_enabled_ = true;
  bool touched_ = true;  // an input was set or a rotor moved: the next tick is a full one
  std::array<bool, kAxisCount> resting_{};
  std::array<bool, kAxisCount> skipped_sensing_{};
  std::array<board::StepperDrive, kAxisCount> resting_drive_{};
  std::array<board::StepperFeedback, kAxisCount> resting_feedback_{};
  std::array<board::StepperFeedback, kAxisCount> feedback_before_{};
  std::array<board::StepperDrive, kAxisCount> drive_before_{};
};

}  // namespace motwin::sim
