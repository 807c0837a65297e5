// One stepper axis of the TMCM-3216 on its power stage (board/stepper_drive.h): what the module's
// driver chip and its firmware do below the CiA-402 drive. Microstep sequencer and coil currents
// (2000/2107, 2001), run and standby current with the standby delay and power-down ramp (2003,
// 2004, 2089, 20B9, 20A2, 20A3), CoolStep and StallGuard2/4 (2098..209E, 20A4..20AA, 2101, 210A),
// StealthChop (20B0..20B2, 2121), the switches (2005), the brake timing (2002, 200A, 200C), the
// ABN encoder (200B with 608F's resolution) and the driver error flags (2102). Chopper and DcStep
// settings (2092..2097, 20A1, 20B3..20B8) are stored and reported only.
//
// The CiA-402 drive (Tmcm3216, hdrive) owns the position: each tick it hands in the demand
// (position and velocity from its ramp, what the PDS state allows) and reads back switches,
// encoder, stall and readiness. The microstep counter IS the open-loop actual position; the
// field follows the demand's changes, so assigning a position (homing) never moves the motor.
//
// Units: positions in microsteps of the active resolution, velocities in microsteps/s, currents
// in mA (peak of the sine), times in µs unless named otherwise. Object fields keep the object's
// own units and value as written (docs/tmcm-3216-drive.md lists them).
#pragma once

#include <cstdint>

#include "board/stepper_drive.h"
#include "core/cia402/trinamic_conventions.h"
#include "core/motion/coolstep.h"
#include "core/motion/stall_detector.h"

namespace motwin::modules::tmcm3216 {

// The driver chip's clock: TMC velocity registers are v x fCLK / 2^24 µsteps/s, the power-down ramp
// steps 2^18 clocks (docs/tmcm-3216-drive.md "How it is put together", "The axis below the drive").
inline constexpr double kDriverClockHz = 12e6;
// 20A3 driver current ranges, mA peak (manual 4.2.36).
inline constexpr int32_t kCurrentRangePeakMa[4] = {1000, 2000, 3000, 3000};
// Below this supply the driver flags undervoltage (2102 bit 5) and cannot drive the motor.
inline constexpr int32_t kUndervoltageMillivolt = 8000;

// 20A7 (stop on stall option code, manual 4.2.39): 0 FAULT, 1 stop only. false for a value out
// of range (`out` untouched).
constexpr bool stall_reaction_of(uint8_t option_code, motion::StallReaction& out) {
  if (option_code > 1) return false;
  out = option_code == 0 ? motion::StallReaction::kFault : motion::StallReaction::kStop;
  return true;
}

// Values the driver refuses within an object's range, for both firmwares' checks: 2097 = 1
// (table 102: 0 or 2..15) and 20A2 = 1..31 ("do not use").
constexpr bool valid_chopper_off_time(int64_t value) { return value != 1; }
constexpr bool valid_global_current_scaler(int64_t value) { return value == 0 || value >= 32; }

// 2005 bits (manual table 62).
namespace switch_bits = cia402::switch_parameter;

// The per-axis objects (axis n at index + n x 0x200), with the manual's defaults. Stored with
// 1010 sub 4 + n. Velocity objects hold the written value: pps, or chip units while 208C = 0
// (velocity_in_chip_units).
struct StepperObjects {
  uint8_t microstep_code = 8;               // 2000: 2^code microsteps per full step (0..8)
  uint16_t full_steps_per_revolution = 200; // 2001
  uint16_t brake_apply_delay_ms = 0;        // 2002 sub 1: brake applied -> power stage off
  uint16_t brake_release_delay_ms = 0;      // 2002 sub 2: brake released -> ready (operation enabled)
  uint8_t run_current = 128;                // 2003: 0..255 = 0..100 % of the current range
  uint8_t standby_current = 8;              // 2004
  uint32_t switch_config = 0;               // 2005: switch_bits
  uint16_t enable_drive_delay_ms = 0;       // 200A: power stage on -> brake released
  uint8_t encoder_index_inverted = 0;       // 200B sub 1: null channel polarity (1: active low)
  uint8_t encoder_reversed = 0;             // 200B sub 2: direction of rotation
  uint8_t encoder_initialize_position = 1;  // 200B sub 3: actual position := encoder at switch-on
  uint8_t brake_apply_current = 0;          // 200C sub 1: brake PWM duty while applied, 0..255
  uint8_t brake_release_current = 0;        // 200C sub 2: ... while released; both 0: no brake control
  uint16_t standby_delay_10ms = 200;        // 2089: standstill time before standby current
  uint8_t chopper_blank_time = 2;           // 2092 (stored)
  uint8_t chopper_mode = 0;                 // 2093 (stored)
  uint8_t chopper_fast_decay_comparator_off = 0;  // 2094 (stored)
  int8_t chopper_hysteresis_end = 0;        // 2095 (stored)
  uint8_t chopper_hysteresis_start = 3;     // 2096 (stored)
  uint8_t chopper_off_time = 5;             // 2097: 0 = bridges off (modelled: motor freewheels)
  uint8_t coolstep_current_minimum = 0;     // 2098: SEIMIN, 0: 1/2, 1: 1/4 of the run current
  uint8_t coolstep_down_step = 0;           // 2099: SEDN
  uint8_t coolstep_hysteresis = 0;          // 209A: SEMAX
  uint8_t coolstep_up_step = 0;             // 209B: SEUP
  uint8_t coolstep_hysteresis_start = 0;    // 209C: SEMIN, 0 = CoolStep off
  uint8_t stallguard2_filter = 0;           // 209D: SFILT
  int8_t stallguard2_threshold = 0;         // 209E: SGT -63..63
  uint8_t short_protection_disabled = 0;    // 20A1
  uint8_t global_current_scaler = 0;        // 20A2: 0 = 256/256, 32..255 = x/256
  uint8_t current_range = 3;                // 20A3
  uint32_t stop_on_stall_velocity = 0;      // 20A4: stall stops only above this (0: off)
  uint32_t coolstep_threshold_velocity = 0; // 20A5: CoolStep above this
  uint8_t stop_on_stall_option = 0;         // 20A7: 0 FAULT, 1 just stop (hdrive acts)
  uint16_t stallguard4_threshold = 0;       // 20A8: stall when the SG4 result falls below it
  uint8_t stallguard4_filter = 0;           // 20A9: the driver averages four results
  uint8_t stallguard4_angle_offset = 0;     // 20AA (stored)
  uint32_t pwm_threshold_velocity = 0;      // 20B0: StealthChop below this (0: off)
  uint8_t pwm_gradient = 0;                 // 20B1: 0 = StealthChop off
  uint8_t pwm_amplitude = 0;                // 20B2
  uint32_t dcstep_minimum_velocity = 0;     // 20B3 (stored)
  uint16_t dcstep_time = 0;                 // 20B4 (stored)
  uint8_t dcstep_stallguard = 0;            // 20B5 (stored)
  uint32_t fullstep_threshold_velocity = 0; // 20B6 (stored)
  uint8_t high_speed_chopper = 0;           // 20B7 (stored)
  uint8_t high_speed_fullstep = 0;          // 20B8 (stored)
  uint8_t power_down_ramp = 7;              // 20B9: IHOLDDELAY, 2^18 clocks per current step
  // Not manufacturer objects: the drive copies them from its profile objects each tick. 608F
  // sub 1 (encoder increments per motor revolution), 606A = 0 (the encoder is used: only then
  // does 200B sub 3 assign the position) and 208C = 0 (velocity objects in chip units).
  uint32_t encoder_increments = 1;
  bool encoder_used = false;
  bool velocity_in_chip_units = false;
};

// What the drive asks of the axis in one tick.
struct StepperDemand {
  int32_t position_usteps = 0;  // the ramp's position (wraps); its change moves the field
  int32_t velocity_pps = 0;     // the ramp's velocity (standstill, CoolStep, stall thresholds)
  bool power_enabled = false;   // PDS: power stage on (switched on, operation enabled, stopping)
  bool brake_released_request = false;  // PDS: operation enabled, the brake may open
  bool switch_on_disabled = true;       // PDS in SWITCH ON DISABLED: 2005/200B/200C writable
  // A new resolution (2000) may take effect now although the power stage is on: the TMCL
  // firmware, which has no power-off state, applies AP 140 at standstill.
  bool resolution_change_allowed = false;
};

// Switch inputs after 2005: `left/right/home` are the active levels (inversion applied) of the
// enabled switches (a disabled switch reads inactive); `raw` are the electrical levels (bit 0
// right, 1 left, 2 home as in StepperFeedback).
struct SwitchState {
  bool left = false;
  bool right = false;
  bool home = false;
  uint8_t raw = 0;
};

class Tmcm3216Stepper {
 public:
  StepperObjects objects;

  // One tick: reads stage.feedback, writes stage.drive.
  void tick(board::StepperPowerStage& stage, const StepperDemand& demand, uint32_t dt_us);
  // What tick() changes besides in a stepper it otherwise leaves as it is: the standstill time
  // (Tmcm3216's resting axes, docs/tmcm-3216-drive.md "Idle ticks").
  void rest(uint32_t dt_us) {
    if (!moving_ && standstill_us_ < UINT64_MAX - dt_us) standstill_us_ += dt_us;
  }
  // Whether the next tick reads the standstill time as the last one did, so that rest() may stand
  // for it: the power stage is off (only the standby current of a powered motor reads it), or the
  // motor stands still and the next tick's standstill time lies before 2089 as the last one did, or
  // the last one's had already taken the power-down ramp (20B9) to the standby current, where
  // every longer standstill stays (docs/tmcm-3216-drive.md "Idle ticks").
  bool standstill_time_read_alike(uint32_t dt_us) const;
  // Power-up / NMT reset node: live state cleared, objects kept (loaded by the dictionary).
  void reset();
  // The drive assigns its position counter (homing, 200B sub 3): the next demand at `position`
  // is no motion.
  void set_actual_position(int32_t position_usteps);
  // 200B sub 3: when the power stage was switched on this tick with position initialisation
  // set and the encoder in use (606A = 0), the position to assign (the encoder position); false
  // otherwise. Read once.
  bool take_position_initialization(int32_t& position_usteps);

  // Objects' write checks: 2005, 200B and 200C only in SWITCH ON DISABLED (manual 4.2.6-4.2.9).
  bool configurable() const { return switch_on_disabled_; }

  // Readings.
  SwitchState switches() const { return switches_; }
  int32_t encoder_position() const { return encoder_position_usteps_; }  // µsteps (608F scale)
  int32_t encoder_count() const { return encoder_count_; }               // counts, 200B direction
  uint32_t index_events() const { return index_events_; }                // N pulses seen (200B polarity)
  int32_t index_position() const { return index_position_usteps_; }      // motor position at the last N
  bool index_available() const { return index_events_ != 0; }
  bool stall_detected() const { return stall_; }
  // The stall reaction 20A7 asks for (the drive acts on it: FAULT or stop).
  bool stall_enters_fault() const { return objects.stop_on_stall_option == 0; }
  void clear_stall() {
    stall_ = false;
    stall_detector_.clear();
  }
  bool power_stage_on() const { return power_on_; }
  bool brake_released() const { return brake_released_; }
  bool ready() const { return ready_; }  // brake released and 2002 sub 2 passed (200A before)
  bool standby() const { return standby_current_reached_; }
  bool stealthchop_active() const { return stealthchop_; }
  bool coolstep_active() const { return coolstep_active_; }
  int32_t current_ma() const { return current_ma_; }        // amplitude driven now
  uint8_t current_scale() const { return current_scale_; }  // CS 0..31 driven now
  uint8_t active_microstep_code() const { return active_microstep_code_; }  // 2107
  uint32_t microsteps_per_full_step() const { return 1u << active_microstep_code_; }
  uint16_t load_value() const { return load_value_; }                  // 2101
  uint16_t stallguard4_result() const { return stallguard4_result_; }  // 210A
  uint8_t pwm_scale() const { return pwm_scale_; }                     // 2121
  int32_t measured_velocity() const { return measured_velocity_; }     // 2122, object units
  uint8_t driver_error_flags() const { return driver_error_flags_; }    // 2102
  // The brake output: whether the automatic brake control drives it and its duty.
  bool brake_control() const { return objects.brake_apply_current != 0 || objects.brake_release_current != 0; }
  uint8_t brake_duty() const { return brake_duty_; }
  // A velocity object's value in µsteps/s (208C).
  double velocity_object_pps(uint32_t value) const;

 private:
  void read_switches(uint8_t levels);
  void read_encoder(const board::StepperFeedback& feedback, int32_t demand_position);
  void run_power_sequence(const StepperDemand& demand, uint32_t dt_us);
  void run_current_control(const StepperDemand& demand);
  // At standstill from `standstill_us` on: false before 2089; past it true, and `scale` the
  // power-down ramp's scale (non-increasing with the time, down to the standby scale `hold_scale`).
  bool standby_scale(uint64_t standstill_us, uint8_t run_scale, uint8_t hold_scale, uint8_t& scale) const;
  void run_stallguard(const board::StepperFeedback& feedback, const StepperDemand& demand);
  void write_drive(board::StepperDrive& drive);
  int32_t current_of_scale(uint8_t scale) const;
  int32_t velocity_object_value(int32_t velocity_pps) const;

  // Switches and encoder.
  SwitchState switches_{};
  bool encoder_started_ = false;
  int32_t encoder_last_raw_ = 0;
  int32_t encoder_count_ = 0;
  uint32_t raw_index_events_ = 0;
  uint32_t index_events_ = 0;
  int32_t encoder_position_usteps_ = 0;
  int32_t index_position_usteps_ = 0;
  uint8_t brake_duty_ = 0;
  // Power sequence (2002, 200A).
  bool switch_on_disabled_ = true;
  bool power_on_ = false;
  bool brake_released_ = false;
  bool ready_ = false;
  uint64_t phase_us_ = 0;   // time in the present phase of switching on
  uint64_t apply_us_ = 0;   // time since the brake was applied while switching off
  bool position_init_pending_ = false;
  int32_t position_init_value_ = 0;
  // Sequencer: the field's electrical angle follows the demand's changes.
  bool demand_started_ = false;
  int32_t last_demand_position_ = 0;
  uint32_t electrical_angle_ = 0;
  uint8_t active_microstep_code_ = 8;
  // Current control.
  bool moving_ = false;         // the demand moved or asked for a velocity this tick
  uint64_t standstill_us_ = 0;  // time without motion, this tick included
  bool standby_current_reached_ = false;
  uint8_t current_scale_ = 0;   // CS driven now
  int32_t current_ma_ = 0;
  bool coolstep_active_ = false;
  bool stealthchop_ = false;
  motion::CoolStep coolstep_;
  // StallGuard.
  motion::StallDetector stall_detector_;
  bool stall_ = false;
  bool measurements_started_ = false;
  bool new_measurement_ = false;  // a new StallGuard result this tick
  uint32_t last_measurements_ = 0;
  uint16_t load_value_ = 0;
  uint16_t stallguard4_result_ = 0;
  uint8_t pwm_scale_ = 0;
  int32_t measured_velocity_ = 0;
  uint8_t driver_error_flags_ = 0;
};

}  // namespace motwin::modules::tmcm3216
