// What a TMC5160-class driver's StallGuard2 / StallGuard4 measurement shows for the simulated motor
// (TMCM-3216 manual 1.4.1, 1.4.3; docs/tmcm-3216-drive.md "StallGuard2, StallGuard4 and CoolStep").
// The sim board calls update() once per tick after the plant advanced and hands the results to the
// firmware through board::StepperFeedback (stallguard2_result, stallguard4_result, a measurement
// counter).
//
// The driver measures once per full step of its microstep sequencer (drive.electrical_angle),
// so the model integrates over each full step of the field:
//   load angle δ = angle of the actual coil-current vector - rotor electrical angle (wrapped),
//   load fraction f = mean over the step of sin δ (signed with the direction of the field): the
//     torque the motor delivers against the torque K |I| available at the present current, which
//     already includes the current the supply can still drive at this speed;
//     (beyond |δ| = 90° the motor is past its torque limit: counts as ±1);
//   f = 1 if over the last four full steps (in one direction) the rotor turned less than half or
//     more than 1.5 times as far as the field (pull-out, a blocked rotor: no back-EMF in step
//     with the field to measure; four steps so that a rotor swinging at its resonance is not
//     taken for a stall), or the coils carry no current;
//   reserve r = 1 - clamp(f, 0, 1); fade s = min(1, full steps per second / kFadeFullStepsPerS)
//     (too little back-EMF at low speed: the value sinks towards 0, as a real chip's does);
//   SG2 = clamp(round(1023 r s) + 16 SGT, 0, 1023)  (SGT = object 209E, -64..63: higher reads
//     higher, needs more load to reach 0; filter 209D: the mean of four full steps, updated every
//     fourth full step);
//   SG4 = clamp(round(510 r s), 0, 510)  (filter 20A9: the mean of the last four measurements,
//     updated every full step).
// In SpreadCycle the SG2 value is measured and SG4 holds; in StealthChop the other way round.
// Driver disabled: both read 0 and the filters restart. At standstill (no full step) the values
// hold, as the chip's register does; of a pause within a full step only the first 20 ms count
// towards its duration, so the first result after a standstill is not faded by the pause.
#pragma once

#include <array>
#include <cstdint>

#include "board/stepper_drive.h"

namespace motwin::sim {

class StepperPlant;

// The driver's register settings the measurement depends on (written by the firmware through
// the board seam).
struct StallGuardSettings {
  bool stealth_chop = false;        // StealthChop chopper (StallGuard4) instead of SpreadCycle (StallGuard2)
  int8_t stallguard2_threshold = 0;   // SGT, 209E, -64..63
  bool stallguard2_filter = false;    // 209D: one result per four full steps
  bool stallguard4_filter = false;    // 20A9: mean of the last four results
  bool stallguard4_angle_offset = false;  // 20AA: stored; no visible effect in the model
};

class StallGuardModel {
 public:
  static constexpr uint16_t kStallGuard2Max = 1023;
  static constexpr uint16_t kStallGuard4Max = 510;
  static constexpr int kThresholdStep = 16;               // SG2 counts per SGT step
  static constexpr double kFadeFullStepsPerS = 50.0;      // below this the reading fades to 0

  // One tick, after the plant advanced by dt_s under `drive`.
  void update(const StepperPlant& plant, const board::StepperDrive& drive, const StallGuardSettings& settings,
              double dt_s);
  // The same for a motor without a physical load angle (sim::IdealStepper): load angle 0 while
  // the rotor follows the field.
  void update_ideal(const board::StepperDrive& drive, const StallGuardSettings& settings, double dt_s);
  // The same from the load angle (rad, current vector minus rotor, any value) and the rotor's
  // continuous electrical angle (rad) seen this tick.
  void update_with_angles(const board::StepperDrive& drive, double load_angle_rad, double rotor_electrical_rad,
                          bool current_present, const StallGuardSettings& settings, double dt_s);

  uint16_t stallguard2_result() const { return sg2_result_; }
  uint16_t stallguard4_result() const { return sg4_result_; }
  // Counts every new result (SG2 or SG4), wrapping: the firmware's "new measurement" edge.
  uint32_t measurements() const { return measurements_; }
  // Diagnostics of the last completed full step: load fraction f (0..1) and field speed.
  double last_load_fraction() const { return last_load_fraction_; }
  double last_full_steps_per_s() const { return last_full_steps_per_s_; }

  // Back to the power-on state: results 0, filters empty, the sequencer tracking restarts.
  void reset();

  // A powered motor's standstill has lasted the whole pause that counts (20 ms): further ticks of
  // the same standstill (the field not moving, any tick length) change nothing that is ever read
  // again. They only lengthen the pause, which is only compared with that limit, which it has
  // passed, and which restarts from 0 when the field moves. The sim board rests such a motor
  // (docs/tmcm-3216-drive.md "Idle ticks").
  bool standstill_settled() const;

 private:
  // The core of all three: the load's share of the available torque this tick (sin of the load angle
  // δ within ±90°, else ±1: load_term()) and the rotor's continuous electrical angle (rad).
  void update_with_load(const board::StepperDrive& drive, double load_term, double rotor_electrical_rad,
                        bool current_present, const StallGuardSettings& settings, double dt_s);
  static double load_term(double sin_delta, double cos_delta);
  void complete_full_step(const StallGuardSettings& settings, int direction);
  void start_window();

  // Sequencer tracking: measurements happen where the field passes a full-step position a full
  // step away from the last one (2^30 of electrical angle, board/stepper_drive.h), so a reversal
  // on a full step does not give a short window.
  bool started_ = false;
  uint32_t last_angle_ = 0;
  int64_t field_position_ = 0;  // unwrapped electrical angle
  int64_t last_boundary_ = 0;   // full-step index of the last measurement point
  // The running full step.
  double window_s_ = 0.0;
  double still_s_ = 0.0;  // how long the sequencer has not moved
  double sum_sin_dt_ = 0.0;
  bool no_current_ = false;
  double window_rotor_start_rad_ = 0.0;  // the rotor's electrical angle where the window began
  double rotor_rad_ = 0.0;               // and at the latest tick
  // The rotor's and the field's turn over the last four full steps in the same direction.
  std::array<double, 4> recent_rotor_rad_{};
  std::array<double, 4> recent_field_rad_{};
  int recent_filled_ = 0;
  int recent_next_ = 0;
  int recent_direction_ = 0;
  int64_t window_field_ = 0;  // field advance over the window, electrical angle units
  // Filters.
  std::array<uint16_t, 4> sg2_history_{};
  int sg2_count_ = 0;  // full steps in the present group of four (209D)
  std::array<uint16_t, 4> sg4_history_{};
  int sg4_filled_ = 0;
  int sg4_next_ = 0;
  // Outputs.
  uint16_t sg2_result_ = 0;
  uint16_t sg4_result_ = 0;
  uint32_t measurements_ = 0;
  double last_load_fraction_ = 0.0;
  double last_full_steps_per_s_ = 0.0;
};

}  // namespace motwin::sim
