// The simulated TMCM-142 board as a whole: its general I/O (Tmcm142SimIo), the stepper behind the
// power-stage seam (the ideal motor or the physical StepperPlant) and the motor-side sensors
// (ABN encoder, right/left/home switches placed at rotor positions). One signal table for `--set`
// and scenario files covers all of it (docs/tmcm-142.md, "Signals and scenarios").
//
// Per control tick: before_tick() samples the sensors into stage().feedback, the firmware ticks,
// after_tick() applies stage().drive to the motor (the wiring of tests/unit/support/tmcm142_rig.h).
#pragma once

#include <array>
#include <cstdint>
#include <memory>
#include <optional>
#include <span>
#include <string_view>
#include <vector>

#include "board/stepper_drive.h"
#include "sim/general_io.h"
#include "sim/signals.h"
#include "sim/stepper_plant.h"
#include "sim/stepper_switch_sources.h"
#include "sim/modules/tmcm142/tmcm142_sim_io.h"

namespace motwin::sim {

class Tmcm142SimBoard final : public SimBoardOverIo<Tmcm142SimBoard, Tmcm142SimIo> {
 public:
  // Tmcm142SimIo's signals followed by the motor side's (LOAD_TORQUE, ..., ENCODER_FAULT).
  static std::span<const SignalInfo> signal_table();

  // The ideal motor: exact positions; LOAD_TORQUE, LOAD_INERTIA and BLOCKED are accepted and
  // have no effect. Switches and encoder work as with a physical motor.
  explicit Tmcm142SimBoard(Tmcm142SimIo& io);
  // A physical hybrid stepper.
  Tmcm142SimBoard(Tmcm142SimIo& io, const StepperMotorDescription& motor,
                  int sub_steps = StepperPlant::kDefaultSubSteps);

  board::StepperPowerStage& power_stage() { return stage_; }
  StepperPlant* plant() { return plant_.get(); }
  const StepperPlant* plant() const { return plant_.get(); }
  const StepperSensors& sensors() const { return sensors_; }
  double rotor_revolutions() const;
  // Moves the rotor (at rest) and lets the sensors see it there.
  void set_rotor_revolutions(double position);

  // Around each control tick of the firmware.
  void before_tick();
  void after_tick(double dt_s) {
    if (plant_) {
      plant_->advance(stage_.drive, io_.supply_millivolt() * 1e-3, dt_s);
    } else {
      ideal_.advance(stage_.drive, dt_s);
    }
  }

  // SignalBoard (signals and output changes: SimBoardOverIo).
  void set_input(std::string_view name, double value) override;
  // Inputs, outputs and what the motor does: POSITION_REV, SPEED_RPM, ENCODER_COUNT and, with a
  // physical motor, COIL_A_A, COIL_B_A, TORQUE_NM.
  std::optional<double> read_signal(std::string_view name) const override;

 private:
  void apply_motor_settings();
  void apply_sensor_config();

  std::unique_ptr<StepperPlant> plant_;
  IdealStepper ideal_;
  StepperSensors sensors_;
  board::StepperPowerStage stage_{};
  StepperSwitchSources switches_;
  StepperSensorConfig::Encoder encoder_{};
  FreezableEncoder encoder_freeze_;
  uint32_t index_events_carry_ = 0;
  int32_t index_count_carry_ = 0;
  double load_torque_ = 0.0;
  double load_inertia_ = 0.0;
  bool blocked_ = false;
};

}  // namespace motwin::sim
