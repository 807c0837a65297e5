// Motor-side inputs common to the simulated stepper boards (TMCM-142, TMCM-3216): where the
// right/left/home switch levels come from, and an encoder that stops counting when faulty.
//
// A switch follows either a level set by name (REF_R, REF_L, REF_H) or a window of rotor
// positions in which it is active (REF_R_AT, ..., REF_H_TO). Both boards list these twelve
// signals in the order of SwitchSignal inside their motor signal tables, so that a board passes
// the index relative to REF_R.
#pragma once

#include <array>
#include <cstddef>
#include <cstdint>
#include <optional>

#include "board/stepper_drive.h"
#include "sim/stepper_plant.h"

namespace motwin::sim {

class StepperSwitchSources {
 public:
  enum SwitchSignal : size_t {
    kRefRight,                        // REF_R, REF_L, REF_H in switch order
    kRefRightAt = kRefRight + 3,      // REF_R_AT, REF_L_AT, REF_H_AT
    kRefRightFrom = kRefRightAt + 3,  // REF_R_FROM, REF_R_TO, then L and H pairs
    kSignalCount = kRefRightFrom + 6,
  };

  // `signal` < kSignalCount. A level takes the switch back from the rotor position; an AT bound
  // makes it a limit switch (right and home active beyond it, left below it); FROM/TO set one
  // end of a window (a cam).
  void set(size_t signal, double value);
  // REF_R/L/H: the level in `sensed_switches` (feedback.switches as last sampled). The position
  // signals: the bound, nullopt when the switch follows a level or the bound is open.
  std::optional<double> read(size_t signal, uint8_t sensed_switches) const;

  // The windows into the sensor model's configuration (right, left, home).
  void configure(StepperSensorConfig& config) const;
  // Adds the levels set by name to `switches` (bits 0..2), after the sensor model sampled it.
  void add_levels(uint8_t& switches) const;

 private:
  struct Source {
    bool by_position = false;
    double from_revolutions = 0.0;
    double to_revolutions = 0.0;
    bool level = false;  // when not by position
  };

  std::array<Source, 3> sources_{};  // right, left, home (feedback.switches bits 0..2)
};

// A faulty encoder (lost A/B/N signals) keeps reporting what it counted when the fault began.
class FreezableEncoder {
 public:
  void set_fault(bool fault) { fault_ = fault; }
  bool fault() const { return fault_; }
  // Overwrites the encoder fields of freshly sensed `feedback` while faulty, remembers them otherwise.
  void apply(board::StepperFeedback& feedback);

 private:
  bool fault_ = false;
  board::StepperFeedback frozen_{};
};

}  // namespace motwin::sim
