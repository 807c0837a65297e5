// The simulated TMCM-1636 board as a whole: its general I/O (Tmcm1636SimIo) and, unless the
// motor is ideal, the motor plant behind the power-stage seam. One signal table for `--set` and
// scenario files covers both: the I/O signals plus load torque, load inertia, an obstacle,
// reference switches at rotor positions and sensor faults (docs/tmcm-1636-servo.md, "Scenarios").
#pragma once

#include <array>
#include <cstdint>
#include <memory>
#include <optional>
#include <span>
#include <string_view>
#include <vector>

#include "board/modules/tmcm1636/tmcm1636_power_stage.h"
#include "sim/general_io.h"
#include "sim/modules/tmcm1636/motor_description.h"
#include "sim/signals.h"
#include "sim/modules/tmcm1636/tmcm1636_plant.h"
#include "sim/modules/tmcm1636/tmcm1636_sim_io.h"

namespace motwin::sim {

class Tmcm1636SimBoard final : public SimBoardOverIo<Tmcm1636SimBoard, Tmcm1636SimIo> {
 public:
  static constexpr uint64_t kDefaultNoiseSeed = 0x1636;

  // Tmcm1636SimIo's signals followed by the motor's (LOAD_TORQUE, ..., HALL_FAULT).
  static std::span<const SignalInfo> signal_table();

  // The ideal motor: no plant, the signals of the motor are accepted and have no effect.
  explicit Tmcm1636SimBoard(Tmcm1636SimIo& io);
  // A physical motor; the source voltage starts at the motor description's supply voltage.
  Tmcm1636SimBoard(Tmcm1636SimIo& io, const MotorDescription& motor, uint64_t noise_seed = kDefaultNoiseSeed,
                   int sub_steps = Tmcm1636Plant::kDefaultSubSteps);

  Tmcm1636Plant* plant() { return plant_.get(); }
  const Tmcm1636Plant* plant() const { return plant_.get(); }
  // What the firmware's axis is attached to; nullptr for the ideal motor.
  board::Tmcm1636PowerStage* power_stage() { return plant_ ? &stage_ : nullptr; }

  // Around each control tick of the firmware; nothing to do for the ideal motor.
  void before_tick() {
    if (plant_) sense();
  }
  void after_tick(double dt_s) {
    if (plant_) plant_->advance(stage_.drive, dt_s);
  }

  // SignalBoard (signals and output changes: SimBoardOverIo).
  void set_input(std::string_view name, double value) override;
  // Inputs, outputs and, with a physical motor, what the plant does: SPEED_RPM, POSITION_REV,
  // VBUS, TORQUE_NM, IQ_A, ID_A, CHOPPER, BRAKE_ENGAGED, DRIVER_TEMP.
  std::optional<double> read_signal(std::string_view name) const override;

 private:
  void sense();

  std::unique_ptr<Tmcm1636Plant> plant_;
  board::Tmcm1636PowerStage stage_{};
  // Reference switches driven by the rotor position (REF_R_AT ...): right, left, home.
  std::array<std::optional<double>, 3> switch_at_revolutions_{};
  // The level those switches give while the rotor is past them (REF_AT_LEVEL); the other level
  // elsewhere. 0 is a switch that pulls its input low when pressed, as AP 210 = 0 expects.
  bool switch_at_pressed_level_ = true;
  double load_torque_ = 0.0;
  double load_inertia_ = 0.0;
  bool blocked_ = false;
  bool encoder_fault_ = false;
  bool hall_fault_ = false;
};

}  // namespace motwin::sim
