// The TMC457 easyPID (docs/tmcm-142.md "Encoder, easyPID and deviation"): a position regulator on
// the encoder that corrects the microstep velocity of a stepper. pid_e = encoder - actual (ramp)
// position, clipped to +-2^23; P part pid_e * P / 256; I part from the error sum (clipped to
// +-Iclip * 2^16) * I / 256 / 256; D part D * (pid_e of the last D sample - pid_e now), that
// difference clipped to +-127; the sum, clipped to +-dv_clip, is the velocity correction. Each part
// pushes pid_e back towards 0: an encoder that lags behind the ramp speeds the microsteps up.
// Velocities are TMC457 units (µsteps/t, docs/tmcm-142.md). Integer arithmetic as on the chip.
#pragma once

#include <cstdint>

namespace motwin::motion {

struct EasyPidConfig {
  int32_t p = 0;                 // 0..16777215
  int32_t i = 0;                 // 0..16777215
  int32_t d = 0;                 // 0..16777215
  int32_t i_clip = 0;            // 0..32640: error sum within +-i_clip * 2^16
  int32_t d_clock_divider = 0;   // 0..255 (0 = 256): D sampled every divider * 128 clocks
  int32_t velocity_clip = 0;     // 0..2^31-1: |correction| limit
};

struct EasyPidState {
  int32_t error = 0;             // pid_e, µsteps (AP 38)
  int64_t error_sum = 0;         // pid_isum (AP 34)
  int32_t last_d_error = 0;      // pid_e at the last D sample
  int32_t d_part = 0;            // held between D samples
  int32_t correction = 0;        // clipped PID result, velocity units (AP 39 - v_actual)
  uint32_t ticks_since_d = 0;
};

class EasyPid {
 public:
  static constexpr int32_t kErrorClip = 1 << 23;
  static constexpr int32_t kDeltaClip = 127;

  // One control tick: `samples_per_tick` chip samples of the integrator, the D part every
  // `d_ticks` ticks. Returns the velocity correction.
  static int32_t step(const EasyPidConfig& config, EasyPidState& state, int64_t encoder_minus_actual,
                      int32_t samples_per_tick, uint32_t d_ticks);
};

}  // namespace motwin::motion
