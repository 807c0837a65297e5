// Reference search (RFS) of a single stepper axis, TMCM-142 style (docs/tmcm-142.md
// "Reference search (RFS, AP 193..196)"):
//   mode 1: the left switch only;
//   mode 2: the right switch, then the left switch; the travel between them is measured;
//   mode 3: as 2, and the reference point is the centre of the left switch's two switching
//           points (a cam the axis passes through);
//   mode 4: as 3 without the right switch: the centre of the left switch, approached from both
//           sides (the TMCL mode of Trinamic's TMC5160-generation modules, the TMCM-3216's).
// Switches are approached at the fast speed and hit with a hard stop; each switching point is
// then found at the slow speed, so its position does not depend on the fast speed. The reference
// point becomes position 0. A plain state machine: the axis feeds it the switch states and the
// position every tick and carries out the command it returns.
#pragma once

#include <cstdint>

namespace motwin::motion {

class ReferenceSearch {
 public:
  enum class Action : uint8_t {
    kNone,          // keep going as commanded
    kVelocity,      // velocity mode at `velocity` (signed, µsteps/s)
    kStopAndVelocity,  // hard stop at once, then velocity mode at `velocity`
    kSetPositionAndStop,  // set the position counter to `position`, hard stop: done
    kSetPositionAndMove,  // set the counter to `position`, then move to 0 at the slow speed
    kDone,          // the final move arrived
  };
  struct Command {
    Action action = Action::kNone;
    double velocity = 0.0;
    int32_t position = 0;
  };
  struct Inputs {
    bool left_active = false;
    bool right_active = false;
    int32_t position = 0;          // actual position (position counter)
    bool position_reached = false;  // for the final move of mode 3
  };

  // Mode 1..4, speeds in µsteps/s (> 0). Returns the first command.
  Command start(int32_t mode, double fast_velocity, double slow_velocity);
  void stop() { phase_ = Phase::kIdle; }
  bool running() const { return phase_ != Phase::kIdle; }
  Command step(const Inputs& inputs);

  // Mode 2/3: right switching point - left switching point, µsteps (AP 196).
  int32_t measured_travel() const { return travel_; }

 private:
  enum class Phase : uint8_t {
    kIdle,
    kFastToRight,
    kSlowOffRight,
    kFastToLeft,
    kSlowOffLeft,
    kSlowIntoLeftCam,    // mode 3: back into the cam from its right side...
    kSlowThroughLeftCam, // ...and through it to its left switching point
    kMoveToCentre,
  };

  Command velocity(double v, bool stop_first) const {
    return Command{stop_first ? Action::kStopAndVelocity : Action::kVelocity, v, 0};
  }

  Phase phase_ = Phase::kIdle;
  int32_t mode_ = 1;
  double fast_ = 0.0;
  double slow_ = 0.0;
  int32_t right_point_ = 0;
  int32_t left_entry_point_ = 0;
  int32_t travel_ = 0;
};

}  // namespace motwin::motion
