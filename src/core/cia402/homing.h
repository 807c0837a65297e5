// CiA-402 homing of one axis, the methods this drive implements (CiA-402 part 2; the TMCM-3216
// manual lists the same ones in chapter 8.1, table 296):
//   0 no homing; 1/2 negative/positive limit switch then index; 3/5 home switch (active on its
//   positive/negative side) then index; 17/18 negative/positive limit switch; 19/21 home switch
//   edge; 33/34 next index pulse in negative/positive direction; 35 current position is home.
//
// Every switch method ends the same way: the switch is left at the slow speed (6099 sub 2) in
// the method's final direction, and the first position that reads "released" is the edge. The
// fast speed (sub 1) only finds the switch, so the edge does not depend on it. Index methods
// then go on at the slow speed to the first index pulse beyond the edge and take the position
// the encoder latched. The axis then moves back to that home point and stands on it, and the
// home point gets the value of the home offset (607C): position = home offset at home
// (docs/tmcm-3216-drive.md "Homing").
//
// A plain state machine like motion::ReferenceSearch: the drive feeds it the axis' inputs every
// tick and carries out the command it returns; it owns no ramp and no I/O.
#pragma once

#include <cstdint>

namespace motwin::cia402 {

// 6099, 609A, 607C in internal units (the drive converts with its UnitScale before start()).
struct HomingConfig {
  int32_t fast_speed_pps = 0;      // 6099 sub 1: search for the switch (> 0)
  int32_t slow_speed_pps = 0;      // 6099 sub 2: edge, index search, move to home (> 0)
  int32_t acceleration_pps2 = 0;   // 609A: passed through in every command
  int32_t home_offset_usteps = 0;  // 607C: the position value the home point gets
  // Give up (kIndexNotFound) when no index pulse comes within this travel after the edge
  // (0 = no limit; the drive passes e.g. two motor revolutions).
  uint32_t index_search_limit_usteps = 0;
  // Give up (kSwitchNotFound) after this much travel in total (0 = no limit).
  uint32_t search_limit_usteps = 0;
};

// What the axis shows this tick. Switches are the processed levels (the module applied its
// disable/invert settings):
// true = active.
struct HomingInputs {
  int32_t position_usteps = 0;        // actual (demand) position counter
  bool left_limit = false;            // negative limit switch
  bool right_limit = false;           // positive limit switch
  bool home_switch = false;
  uint32_t index_events = 0;          // counts up at every index pulse the encoder sees
  int32_t index_position_usteps = 0;  // position latched at the last index pulse
  bool index_available = false;       // an encoder with an index channel is configured
  // The ramp stands at the target of the last kPosition command (velocity 0).
  bool target_reached = false;
};

struct HomingCommand {
  enum class Kind : uint8_t {
    kVelocity,  // run at velocity_pps (signed), ramping with acceleration_pps2
    kPosition,  // go to target_position_usteps at |velocity_pps| with acceleration_pps2
    kStop,      // ramp down to standstill with acceleration_pps2 and stay (also: nothing to do)
    kDone,      // homing finished (once): if set_position, the current point becomes new_position
    kError,     // homing failed (once): stop as kStop does; see Homing::reason()
  };
  Kind kind = Kind::kStop;
  int32_t velocity_pps = 0;
  int32_t acceleration_pps2 = 0;
  int32_t target_position_usteps = 0;
  bool set_position = false;
  int32_t new_position = 0;  // the value for the CURRENT point (home offset applied)
};

class Homing {
 public:
  enum class State : uint8_t {
    kIdle,         // never started
    kActive,       // homing in progress
    kAttained,     // done: the axis stands at home, position = home offset
    kInterrupted,  // stopped by stop() (controlword bit 4 fell, halt, quick stop, disable)
    kError,        // failed: see reason()
  };
  enum class Reason : uint8_t {
    kNone,
    kUnsupportedMethod,  // not in table 296 (the OD should have refused it already)
    kZeroSpeed,          // a speed the method needs is 0
    kIndexUnavailable,   // an index method without an encoder index
    kLimitSwitch,        // a limit switch other than the searched one was hit
    kSwitchNotFound,     // both limits reached without the home switch, or search limit
    kIndexNotFound,      // limit switch or index search limit reached before an index pulse
  };

  // Methods of table 296.
  static bool is_supported(int8_t method);
  // Methods 0 and 35 do not move the axis (35 works in any PDS state).
  static bool moves(int8_t method) { return method != 0 && method != 35; }

  // Arms `method`; the first step() decides the direction from the switch states. Restarting
  // while active is allowed: the search begins anew from where the axis is.
  void start(int8_t method, const HomingConfig& config);
  // Abandons the homing: the axis ramps down with the homing acceleration, not attained.
  HomingCommand stop();
  // Every tick while the axis is in homing mode and operation is enabled (or any time for 35).
  HomingCommand step(const HomingInputs& inputs, uint32_t dt_us);

  // For the statusword (docs/tmcm-3216-drive.md): bit 12 = attained(), bit 13 = error(), bit 10 (target
  // reached) = !active() once started. reason() says why an error happened.
  State state() const { return state_; }
  bool active() const { return state_ == State::kActive; }
  bool attained() const { return state_ == State::kAttained; }
  bool error() const { return state_ == State::kError; }
  bool interrupted() const { return state_ == State::kInterrupted; }
  Reason reason() const { return reason_; }
  int8_t method() const { return method_; }
  // The home point found, in the counter's values before the new position was set.
  int32_t home_point_usteps() const { return home_point_; }
  uint32_t elapsed_us() const { return elapsed_us_; }

  static const char* reason_name(Reason reason);

 private:
  enum class Phase : uint8_t {
    kIdle,
    kBegin,        // first step: pick the direction from the switch states
    kSeekFast,     // fast, towards the switch's active side, until it is active
    kReverseFast,  // home switch: a limit was hit, fast the other way until the switch...
    kPassFast,     // ...is active, then through it at fast speed; then kSeekFast again
    kLeaveSlow,    // slow, final direction, until the switch is released: the edge
    kIndexSearch,  // slow, final direction, until an index pulse beyond the edge
    kMoveToHome,   // slow, back to the home point
  };
  enum class Signal : uint8_t { kNone, kLeftLimit, kRightLimit, kHomeSwitch };

  struct MethodSpec {
    int8_t method;
    Signal signal;
    int8_t final_direction;  // +1 / -1: the direction in which the switch is left
    bool index;
  };
  static const MethodSpec* find_method(int8_t method);

  HomingCommand velocity(int32_t direction, int32_t speed_pps) const;
  HomingCommand fail(Reason reason);
  bool signal_active(const HomingInputs& in) const;
  // The limit switch in `direction` (+1 right, -1 left) other than the searched signal.
  bool other_limit_in(int32_t direction, const HomingInputs& in) const;
  HomingCommand begin(const HomingInputs& in);
  HomingCommand run_phase(const HomingInputs& in);
  HomingCommand search_index(const HomingInputs& in);
  HomingCommand found_edge(const HomingInputs& in);
  HomingCommand found_home(int32_t home_point);

  State state_ = State::kIdle;
  Reason reason_ = Reason::kNone;
  Phase phase_ = Phase::kIdle;
  int8_t method_ = 0;
  const MethodSpec* spec_ = nullptr;
  HomingConfig config_{};

  bool reversed_ = false;          // home switch search: reversed at a limit once already
  bool previous_signal_ = false;   // the signal's level in the previous step
  bool previous_left_ = false;
  bool previous_right_ = false;
  int32_t previous_position_ = 0;
  int32_t motion_direction_ = 0;   // sign of the last position change
  uint32_t previous_index_events_ = 0;
  uint32_t index_events_at_edge_ = 0;
  int32_t edge_position_ = 0;
  int32_t home_point_ = 0;
  uint64_t travel_usteps_ = 0;
  uint32_t elapsed_us_ = 0;
};

}  // namespace motwin::cia402
