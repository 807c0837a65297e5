// The axis of the TMCM-142: TMC457-style S-ramp (motion/s_ramp.h), microstep sequencer and coil
// currents into the stepper power stage (board/stepper_drive.h), limit switches, ABN encoder with
// the easyPID closed loop and the encoder deviation stop, standby current, and the reference
// search. Reads only the feedback fields of the stage and writes only its drive fields.
#pragma once

#include <cstdint>

#include "board/stepper_drive.h"
#include "core/modules/tmcm142/tmcm142_hardware.h"
#include "core/motion/easy_pid.h"
#include "core/motion/reference_search.h"
#include "core/motion/s_ramp.h"
#include "core/tmcl/status.h"

namespace motwin::modules::tmcm142 {

// Default velocities and accelerations in µsteps/s (the table's defaults are the same values in
// TMC457 units, unit mode 0).
inline constexpr int32_t kDefaultMaxVelocity = 13743895;      // AP 4: 204800 µsteps/s, 1 rev/s at 1024
inline constexpr int32_t kDefaultAcceleration = 14073;        // AP 5: 204786 µsteps/s²
inline constexpr int32_t kDefaultBow = 1000;                  // AP 18: 1.42e7 µsteps/s³
inline constexpr int32_t kDefaultReferenceSlow = kDefaultMaxVelocity / 4;  // AP 195

// The mode parameters as named values; each enumerator is the number on the wire.
// AP 40.
enum class PidMode : int32_t { kOpenLoop = 0, kEasyPid = 1 };
// AP 193: the switches a reference search uses (core/motion/reference_search.h takes the number).
enum class ReferenceSearchMode : int32_t { kLeftSwitch = 1, kRightThenLeftSwitch = 2, kCentreOfLeftSwitch = 3 };
// AP 255: the units of speeds and accelerations on the wire.
enum class UnitMode : int32_t { kTmc457 = 0, kMicrostepsPerSecond = 1 };

// Stored settings (the E parameters). Velocities and accelerations are kept in µsteps/s and
// µsteps/s² whatever the unit mode, so AP 255 changes only how they are read and written.
struct AxisConfig {
  double max_velocity_pps = kDefaultMaxVelocity * kPpsPerVelocityUnit;        // AP 4
  double acceleration_pps2 = kDefaultAcceleration * kPps2PerAccelerationUnit;  // AP 5 = AP 16
  int32_t run_current_code = 5;           // AP 6: (c + 1) * 7000 / 16 mA peak
  int32_t standby_current_code = 1;       // AP 7
  int32_t right_switch_disable = 0;       // AP 12
  int32_t left_switch_disable = 0;        // AP 13
  int32_t switch_mode = 0;                // AP 14: bit 2 left polarity, 3 right polarity, 4 swap, 5 soft stop
  double stop_deceleration_pps2 = kDefaultAcceleration * kPps2PerAccelerationUnit;  // AP 15
  double deceleration_pps2 = 0.0;         // AP 17: 0 = the acceleration of AP 5/16
  int32_t max_bow = kDefaultBow;          // AP 18: all four changes of acceleration
  int32_t shaft = 0;                      // AP 19: 1 mirrors the axis (motor and encoder)
  int32_t standby_delay_10ms = 200;       // AP 20
  int32_t mixed_decay_run = 0;            // AP 21 (stored; the simulated chopper regulates ideally)
  int32_t mixed_decay_standby = 0;        // AP 22
  int32_t chopper_clock_divider = 0;      // AP 23
  int32_t microstep_code = kFinestResolutionCode;  // AP 27
  int32_t pid_tolerance = 0;              // AP 28: |pid_e| up to it counts as 0
  int32_t sine_wave_offset = 0;           // AP 29 (stored)
  motion::EasyPidConfig pid{65536, 0, 0, 0, 0, 67108864};  // AP 30, 31, 32, 33, 35, 37
  PidMode pid_mode = PidMode::kOpenLoop;  // AP 40
  int32_t encoder_constant = 3355443;     // AP 42: µsteps per encoder count * 65536 (51.2)
  int32_t encoder_mode = 0;               // AP 43: encoder_mode bits below
  int32_t encoder_warn_distance = 0;      // AP 47, µsteps; 0 = off
  int32_t compare_position = 0;           // AP 48
  int32_t right_position_limit = 0;       // AP 50
  int32_t left_position_limit = 0;        // AP 51
  int32_t right_position_limit_enable = 0;  // AP 52
  int32_t left_position_limit_enable = 0;   // AP 53
  int32_t step_pulse_length = 0;          // AP 64 (stored; the module drives its own stage)
  ReferenceSearchMode reference_mode = ReferenceSearchMode::kLeftSwitch;  // AP 193
  double reference_fast_pps = kDefaultMaxVelocity * kPpsPerVelocityUnit;    // AP 194
  double reference_slow_pps = kDefaultReferenceSlow * kPpsPerVelocityUnit;  // AP 195
  int32_t max_encoder_deviation = 0;      // AP 212, µsteps; 0 = off
  UnitMode unit_mode = UnitMode::kTmc457;  // AP 255
};

// AP 14 bits.
namespace switch_mode {
inline constexpr int32_t kInvertLeft = 1 << 2;
inline constexpr int32_t kInvertRight = 1 << 3;
inline constexpr int32_t kSwap = 1 << 4;
inline constexpr int32_t kSoftStop = 1 << 5;
}  // namespace switch_mode

// AP 43 bits (Motwin decision, docs/tmcm-142.md "Encoder, easyPID and deviation").
namespace encoder_mode {
inline constexpr int32_t kReverse = 1 << 0;        // count the other way
inline constexpr int32_t kLatchOnNull = 1 << 1;    // latch AP 45/46 on every N pulse
inline constexpr int32_t kClearOnNull = 1 << 2;    // and set the encoder counter to 0 there
inline constexpr int32_t kAll = kReverse | kLatchOnNull | kClearOnNull;
}  // namespace encoder_mode

// AP 44 bits.
namespace encoder_status {
inline constexpr int32_t kLatched = 1 << 0;  // a latch happened since the last read (cleared by reading)
}  // namespace encoder_status

// AP 26 bits (Motwin decision).
namespace driver_status {
inline constexpr int32_t kStandby = 1 << 0;       // the standby current (AP 7) is applied
inline constexpr int32_t kUndervoltage = 1 << 1;  // motor supply below the module's 15 V
inline constexpr int32_t kCompareOutput = 1 << 2;  // the compare output (AP 48) is high
}  // namespace driver_status
inline constexpr int32_t kMinimumSupplyMillivolt = 15000;

// AP 129 bits.
namespace status_flag {
inline constexpr int32_t kPositionReached = 1 << 0;
inline constexpr int32_t kVelocityReached = 1 << 1;
inline constexpr int32_t kStandstill = 1 << 2;
inline constexpr int32_t kEncoderWarning = 1 << 3;  // beyond AP 47 (or AP 212)
}  // namespace status_flag

// AP 207 bits (cleared on read).
namespace error_flag {
inline constexpr int32_t kDeviationStop = 1 << 1;
}  // namespace error_flag

// AP 128.
enum class RampMode : int32_t { kPosition = 0, kVelocity = 2, kHold = 3 };

struct AxisState {
  double target_velocity_pps = 0.0;  // AP 2
  int32_t right_switch_active = 0;   // AP 10
  int32_t left_switch_active = 0;    // AP 11
  int32_t home_switch_active = 0;
  int32_t error_flags = 0;           // AP 207
  int32_t travel = 0;                // AP 196
  int32_t encoder_position = 0;      // AP 41
  int32_t encoder_status = 0;        // AP 44
  int32_t encoder_latch = 0;         // AP 45
  int32_t position_latch = 0;        // AP 46
  int32_t supply_millivolt = 24000;
  bool compare_output = false;       // actual position >= AP 48
  bool deviation_exceeded = false;
  bool standby = false;
};

class Tmcm142Axis {
 public:
  AxisConfig config;
  AxisState state;

  // Commands.
  void set_target_position(int32_t position);
  void set_actual_position(int32_t position);
  void set_target_velocity(double velocity_pps);
  int32_t set_ramp_mode(int32_t mode);  // 0 ok, else the TMCL status 4
  void stop();                          // MST: velocity 0 with the ramp
  void set_encoder_position(int32_t position);
  // RFS START; status 4 for a search at speed 0 (it would never end).
  tmcl::Status start_reference_search();
  void stop_reference_search();

  // One control tick on the power stage: feedback in, drive out.
  void tick(board::StepperPowerStage& stage);

  // Power-up: live state cleared, settings kept; the rotor stays where it is.
  void reset_state();

  RampMode ramp_mode() const;
  int32_t actual_position() const { return ramp_.position(); }
  int32_t target_position() const { return ramp_.target_position(); }
  double actual_velocity_pps() const { return ramp_.velocity(); }
  bool position_reached() const { return ramp_.mode() == motion::SRamp::Mode::kPosition && ramp_.position_reached(); }
  bool velocity_reached() const { return ramp_.velocity_reached(); }
  bool reference_search_running() const { return search_.running(); }
  int32_t status_flags() const;
  // AP 207: read and clear.
  int32_t take_error_flags();
  // AP 44: read and clear the latch bit.
  int32_t take_encoder_status();
  int32_t switch_status() const;          // AP 9
  int32_t driver_status() const;          // AP 26
  int32_t microstep_table_position() const;  // AP 63
  // True once per deviation stop (the module raises the TMCL EDV flag).
  bool take_deviation_event();
  uint32_t microsteps_per_full_step() const { return microsteps_of_code(config.microstep_code); }
  int32_t coil_current_ma() const { return current_of(state.standby ? config.standby_current_code : config.run_current_code); }
  const motion::EasyPidState& pid_state() const { return pid_; }
  void clear_pid_sum() { pid_.error_sum = 0; }
  // pid_v_actual (AP 39): ramp velocity plus correction, TMC457 units.
  int64_t pid_velocity_internal() const;
  const motion::SRamp& ramp() const { return ramp_; }

 private:
  static int32_t current_of(int32_t code) { return current_ma_of_code(code); }
  void read_feedback(const board::StepperFeedback& feedback);
  void run_reference_search();
  void apply_switch_stops();
  void check_deviation();
  void latch_on_null_channel(const board::StepperFeedback& feedback);
  bool counts_reversed() const;
  int32_t encoder_deviation() const;  // AP 41 - AP 1, the shorter way round the 32-bit counters
  bool encoder_warning() const;
  int32_t clipped_to_position_limits(int32_t target) const;
  motion::SRampConfig ramp_config() const;
  void write_drive(board::StepperDrive& drive, int64_t ramp_delta_q32);

  motion::SRamp ramp_;
  motion::ReferenceSearch search_;
  motion::EasyPidState pid_;
  bool search_final_move_ = false;
  bool switch_stopping_ = false;   // soft stop at a switch: AP 15 deceleration until at rest
  bool deviation_event_ = false;
  // The ABN encoder counter: the last raw count (read first at power-up) and the position in
  // 1/65536 µsteps (AP 42 scales each count).
  struct EncoderCounter {
    bool started = false;
    int32_t last_count = 0;
    int64_t position_q16 = 0;
    uint32_t index_events = 0;
  };
  EncoderCounter encoder_;
  // The microstep sequencer: electrical angle x 2^16 (only the low 48 bits matter). It follows
  // the ramp's motion (not its counter, so setting AP 1 never moves the field) plus the easyPID
  // correction.
  uint64_t angle_q16_ = 0;
  uint64_t last_ramp_q32_ = 0;
  uint32_t standstill_ticks_ = 0;
  uint32_t last_drive_angle_ = 0;
};

}  // namespace motwin::modules::tmcm142
