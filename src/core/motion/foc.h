// Field-oriented control arithmetic: Clarke and Park transforms, their inverses and space-vector
// modulation. Angles are electrical, 16 bits per turn (0..65535), as the TMCM-1636 reports them
// (AP 16..19). Amplitude-invariant transforms: a current vector of magnitude I is a phase current
// of amplitude I.
#pragma once

#include <cmath>
#include <cstdint>

namespace motwin::motion {

inline constexpr float kTwoPi = 6.2831853071795864769f;
inline constexpr float kSqrt3 = 1.7320508075688772935f;
inline constexpr float kOneBySqrt3 = 0.57735026918962576451f;
inline constexpr float kAngleToRadians = kTwoPi / 65536.0f;

struct AlphaBeta {
  float alpha = 0.0f;
  float beta = 0.0f;
};

struct Dq {
  float d = 0.0f;
  float q = 0.0f;
};

struct SinCos {
  float sin = 0.0f;
  float cos = 1.0f;
};

inline SinCos sin_cos(uint16_t angle) {
  const float radians = static_cast<float>(angle) * kAngleToRadians;
  return SinCos{std::sin(radians), std::cos(radians)};
}

// sin/cos of (angle + delta) for a small delta in radians (|delta| <= 0.25: Taylor terms to the
// 5th order; larger deltas take the library call).
inline SinCos rotate(SinCos angle, float delta) {
  if (delta > 0.25f || delta < -0.25f) {
    const float c = std::cos(delta);
    const float s = std::sin(delta);
    return SinCos{angle.sin * c + angle.cos * s, angle.cos * c - angle.sin * s};
  }
  const float d2 = delta * delta;
  const float c = 1.0f - d2 * (0.5f - d2 * (1.0f / 24.0f));
  const float s = delta * (1.0f - d2 * ((1.0f / 6.0f) - d2 * (1.0f / 120.0f)));
  return SinCos{angle.sin * c + angle.cos * s, angle.cos * c - angle.sin * s};
}

// Two measured phase currents (a, b) of a star-connected motor: c = -(a + b).
inline AlphaBeta clarke(float a, float b) { return AlphaBeta{a, (a + 2.0f * b) * kOneBySqrt3}; }

inline Dq park(AlphaBeta v, SinCos angle) {
  return Dq{v.alpha * angle.cos + v.beta * angle.sin, -v.alpha * angle.sin + v.beta * angle.cos};
}

inline AlphaBeta inverse_park(Dq v, SinCos angle) {
  return AlphaBeta{v.d * angle.cos - v.q * angle.sin, v.d * angle.sin + v.q * angle.cos};
}

struct Duties {
  float a = 0.5f;
  float b = 0.5f;
  float c = 0.5f;
};

// Largest voltage vector that space-vector modulation produces without distortion.
inline float svm_voltage_limit(float supply_voltage) { return supply_voltage * kOneBySqrt3; }

// Space-vector modulation by min-max zero-sequence injection: the three half-bridge duties whose
// line-to-line voltages make the vector v on a bus of supply_voltage. Duties are clipped to 0..1
// (a vector beyond svm_voltage_limit() is distorted, not wrapped).
inline Duties svm(AlphaBeta v, float supply_voltage) {
  if (supply_voltage <= 0.0f) return Duties{};
  const float va = v.alpha;
  const float vb = -0.5f * v.alpha + 0.5f * kSqrt3 * v.beta;
  const float vc = -0.5f * v.alpha - 0.5f * kSqrt3 * v.beta;
  const float max = va > vb ? (va > vc ? va : vc) : (vb > vc ? vb : vc);
  const float min = va < vb ? (va < vc ? va : vc) : (vb < vc ? vb : vc);
  const float offset = -0.5f * (max + min);
  const float scale = 1.0f / supply_voltage;
  auto duty = [&](float phase) {
    const float d = 0.5f + (phase + offset) * scale;
    return d < 0.0f ? 0.0f : (d > 1.0f ? 1.0f : d);
  };
  return Duties{duty(va), duty(vb), duty(vc)};
}

// Electrical angle of an 16-bit angle plus a signed offset, wrapping.
inline uint16_t add_angle(uint16_t angle, int32_t offset) {
  return static_cast<uint16_t>(static_cast<uint32_t>(angle) + static_cast<uint32_t>(offset));
}

}  // namespace motwin::motion
