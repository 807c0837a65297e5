// Axis 0 of the TMCM-1636: its settings (the E parameters of manual table 11), its live
// state, and the motion of the *ideal* motor, which follows the ramp generator exactly. The
// BLDC physics issue adds the FOC cascade and a plant; the ideal motor stays as the fast
// option.
#pragma once

#include <cstdint>

#include "board/tmcm1636_io.h"
#include "core/motion/trapezoid_ramp.h"

namespace motwin::modules::tmcm1636 {

// Stored settings of the axis, one field per writable row of table 11. Defaults are the
// manual's, except where docs/tmcm-1636.md records a decision.
struct AxisConfig {
  int32_t adc_phase_a_offset = 32767;        // AP 5
  int32_t adc_phase_b_offset = 32767;        // AP 6
  int32_t dual_shunt_factor = 256;           // AP 7
  int32_t motor_pole_pairs = 4;              // AP 10
  int32_t max_current_ma = 2000;             // AP 11
  int32_t open_loop_current_ma = 2000;       // AP 12
  int32_t motor_type = 0;                    // AP 14: 0 none, 1 DC, 3 BLDC
  int32_t commutation_mode = 0;              // AP 15
  int32_t position_commutation_mode = 0;     // AP 25
  int32_t max_velocity_rpm = 4000;           // AP 43
  int32_t acceleration_rpm_per_s = 2000;     // AP 44
  int32_t velocity_ramp_enabled = 1;         // AP 45
  int32_t position_reached_distance = 5;     // AP 53, position counts
  int32_t position_reached_velocity_rpm = 500;  // AP 54
  int32_t torque_p = 0;                      // AP 70
  int32_t torque_i = 0;                      // AP 71
  int32_t velocity_p = 0;                    // AP 72
  int32_t velocity_i = 0;                    // AP 73
  int32_t position_p = 0;                    // AP 74
  int32_t hall_polarity = 0;                 // AP 90
  int32_t hall_direction = 0;                // AP 91
  int32_t hall_interpolation = 0;            // AP 92
  int32_t hall_phi_e_offset = 0;             // AP 93
  int32_t encoder_steps = 8192;              // AP 100, counts per revolution
  int32_t encoder_direction = 0;             // AP 101
  int32_t encoder_init_mode = 1;             // AP 102
  int32_t encoder_init_delay_ms = 1000;      // AP 104
  int32_t encoder_init_velocity_rpm = 100;   // AP 105
  int32_t encoder_offset = 0;                // AP 106
  int32_t clear_on_null = 0;                 // AP 107
  int32_t clear_once = 0;                    // AP 108
  int32_t pwm_frequency_hz = 25000;          // AP 110
  int32_t brake_release_duty_percent = 75;   // AP 121
  int32_t brake_hold_duty_percent = 11;      // AP 122
  int32_t brake_release_duration_ms = 80;    // AP 123
  int32_t brake_output_enable = 0;           // AP 124
  int32_t brake_output_invert = 0;           // AP 125
  int32_t brake_chopper_enabled = 0;         // AP 140
  int32_t brake_chopper_limit_decivolt = 260;     // AP 141
  int32_t brake_chopper_hysteresis_decivolt = 5;  // AP 142
  int32_t absolute_encoder_type = 0;         // AP 160
  int32_t absolute_encoder_init = 0;         // AP 161
  int32_t absolute_encoder_direction = 0;    // AP 162
  int32_t absolute_encoder_offset = 0;       // AP 163
  int32_t reference_switch_enable = 0;       // AP 209: bit 0 right, bit 1 left
  int32_t reference_switch_polarity = 0;     // AP 210: bit 0 right, 1 left, 2 home; 1 = high active
};

enum class MotionMode : uint8_t { kVelocity, kPosition, kTorque };

// Live values: measured, computed, or commanded without being stored.
struct AxisState {
  MotionMode mode = MotionMode::kVelocity;
  // Current measurement (AP 0..4); mid-scale raw counts mean zero current. Live once the
  // BLDC physics issue lands.
  int32_t adc_phase_a_raw = 32767;  // AP 0
  int32_t adc_phase_b_raw = 32767;  // AP 1
  int32_t adc_phase_a = 0;          // AP 2
  int32_t adc_phase_b = 0;          // AP 3
  int32_t adc_phase_c = 0;          // AP 4
  int32_t open_loop_angle = 0;      // AP 16
  int32_t encoder_angle = 0;        // AP 17
  int32_t hall_angle = 0;           // AP 18
  int32_t absolute_encoder_angle = 0;  // AP 19
  int32_t target_torque_ma = 0;     // AP 30
  int32_t actual_torque_ma = 0;     // AP 31
  int32_t target_flux_ma = 0;       // AP 32
  int32_t actual_flux_ma = 0;       // AP 33
  int32_t target_velocity_rpm = 0;  // AP 40
  int32_t ramp_velocity_rpm = 0;    // AP 41
  int32_t actual_velocity_rpm = 0;  // AP 42
  int32_t actual_position = 0;      // AP 52
  int32_t position_reached = 0;     // AP 55
  int32_t torque_error_sum = 0;     // AP 75
  int32_t flux_error_sum = 0;       // AP 76
  int32_t velocity_error_sum = 0;   // AP 77
  int32_t torque_error = 0;         // AP 78
  int32_t flux_error = 0;           // AP 79
  int32_t velocity_error = 0;       // AP 80
  int32_t position_error = 0;       // AP 81
  int32_t encoder_init_state = 0;   // AP 103
  int32_t release_brake = 0;        // AP 120
  int32_t brake_chopper_active = 0;  // AP 144 (the manual's default column says 255)
  int32_t status_flags = 0;         // AP 156, bits defined by the BLDC physics issue
  int32_t right_switch_active = 0;  // AP 211
  int32_t left_switch_active = 0;   // AP 212
  int32_t home_switch_active = 0;   // AP 213
  uint32_t main_loops_per_s = 0;    // AP 230
  uint32_t torque_loops_per_s = 0;  // AP 231
  uint32_t velocity_loops_per_s = 0;  // AP 232
  int32_t driver_enabled = 1;       // AP 255 (docs/tmcm-1636.md: enabled at power-up)
  int32_t debug_values[10] = {};    // AP 240..249
};

class Tmcm1636Axis {
 public:
  AxisConfig config;
  AxisState state;

  // Commands (ROR/ROL/MST/MVP and the writable live parameters).
  void set_target_velocity(int32_t velocity_rpm);
  void set_target_position(int32_t position);
  void set_actual_position(int32_t position);
  void set_target_torque(int32_t torque_ma);
  void set_target_flux(int32_t flux_ma);
  void set_driver_enabled(bool enabled);

  // One control tick of `dt_s` seconds with the ideal motor.
  void tick(const board::Tmcm1636Io& io, double dt_s);

  // Power-up: live state cleared, settings kept.
  void reset_state();

  int32_t target_position() const { return ramp_.target_position(); }
  int32_t ramp_position() const { return ramp_.position(); }
  bool position_reached() const { return state.position_reached != 0; }
  const motion::TrapezoidRamp& ramp() const { return ramp_; }

  // rpm <-> position counts per second, with AP 100 counts per revolution.
  double counts_per_second(double velocity_rpm) const;
  double rpm(double counts_per_second) const;

 private:
  void update_switches(const board::Tmcm1636Io& io);
  void update_position_reached();

  motion::TrapezoidRamp ramp_;
};

}  // namespace motwin::modules::tmcm1636
