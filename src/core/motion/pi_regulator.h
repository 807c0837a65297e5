// PI regulators of the TMCM-1636 cascade (manual chapter 5): a Config (the gains a host sets and
// the EEPROM stores: AP 70..74) and a State (what the regulator computes and a host may read:
// AP 75..81), kept apart so that the parameter table binds rows to their fields. Pure arithmetic,
// no knowledge of what is regulated.
//
// Integer gains as in the manual's tables (0..32767), applied with a PiScale of the loop:
//   output = P * error * scale.proportional + I * error_sum * scale.integral
// (by default P / 256 and I / 65536) where error_sum is the sum of the errors of all ticks so far
// (in the error's unit times ticks).
// Anti-windup by conditional integration: while the output is limited, a tick's error is not
// added if it would push the output further into the limit, and the integral term alone never
// exceeds the limit. I = 0 holds the sum at 0.
#pragma once

#include <cstdint>

namespace motwin::motion {

inline constexpr float kPiProportionalScale = 1.0f / 256.0f;
inline constexpr float kPiIntegralScale = 1.0f / 65536.0f;

// The normalisation of one loop's gains: what one unit of P and of I is worth.
struct PiScale {
  float proportional = kPiProportionalScale;  // output per (P * error)
  float integral = kPiIntegralScale;          // output per (I * error sum)
};
inline constexpr PiScale kDefaultPiScale{};

struct PiConfig {
  int32_t p = 0;
  int32_t i = 0;
};

struct PiState {
  int32_t error = 0;      // last error, in the input unit (mA, rpm, position counts)
  int32_t error_sum = 0;  // integral: sum of the errors of past ticks
  float output = 0.0f;    // last output after the limit
  bool limited = false;   // last output was clipped
};

// Output before any limit for a given error sum.
inline float pi_output(const PiConfig& config, const PiScale& scale, int64_t error_sum, int32_t error) {
  return static_cast<float>(config.p) * scale.proportional * static_cast<float>(error) +
         static_cast<float>(config.i) * scale.integral * static_cast<float>(error_sum);
}

// One step with a symmetric limit |output| <= limit (limit >= 0).
float pi_apply(const PiConfig& config, const PiScale& scale, PiState& state, int32_t error, float limit);
inline float pi_apply(const PiConfig& config, PiState& state, int32_t error, float limit) {
  return pi_apply(config, kDefaultPiScale, state, error, limit);
}

// The flux (d) and torque (q) regulators of FOC share their gains (AP 70, 71) and one vector
// limit: the output voltage vector |(d, q)| <= limit is scaled down as a whole, keeping its
// direction, and neither integrator winds up while it is.
void pi_apply_vector(const PiConfig& config, const PiScale& scale, PiState& d, PiState& q, int32_t error_d,
                     int32_t error_q, float limit);
inline void pi_apply_vector(const PiConfig& config, PiState& d, PiState& q, int32_t error_d, int32_t error_q,
                            float limit) {
  pi_apply_vector(config, kDefaultPiScale, d, q, error_d, error_q, limit);
}

inline void pi_reset(PiState& state) { state = PiState{}; }

// The moteus-style handle: a regulator that refers to its config and its state.
class PiRegulator {
 public:
  PiRegulator(const PiConfig* config, PiState* state, PiScale scale = kDefaultPiScale)
      : config_(config), state_(state), scale_(scale) {}
  float apply(int32_t error, float limit) { return pi_apply(*config_, scale_, *state_, error, limit); }

 private:
  const PiConfig* config_;
  PiState* state_;
  PiScale scale_;
};

}  // namespace motwin::motion
