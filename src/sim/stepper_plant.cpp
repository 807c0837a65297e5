#include "sim/stepper_plant.h"

#include <cmath>

namespace motwin::sim {
namespace {

constexpr double kPi = 3.14159265358979323846;
constexpr double kTwoPi = 2.0 * kPi;
constexpr double kElectricalCircle = 4294967296.0;  // 2^32 per electrical revolution
constexpr double kTwoTo32 = 4294967296.0;
constexpr double kTurnLimit = 2305843009213693952.0;  // 2^61: differences of two stay in int64

double sign(double v) { return v > 0.0 ? 1.0 : (v < 0.0 ? -1.0 : 0.0); }

// One coil over a sub-step of the exact RL solution i(h) = i_inf + (i - i_inf) d, d = exp(-hR/L),
// i_inf = (v - emf) / R. The chopper picks the bridge voltage that lands on the target current,
// limited to the supply (beyond it the coil follows the RL dynamics at full voltage).
struct CoilStep {
  double resistance;
  double inverse_resistance;
  double decay;
  double inverse_rise;  // 1 / (1 - decay)
  double supply;
  double operator()(double current, double target, double emf) const {
    const double voltage = resistance * (target - current * decay) * inverse_rise + emf;
    if (voltage <= supply && voltage >= -supply) return target;  // the chopper holds the target
    const double applied = voltage > supply ? supply : -supply;
    const double final_value = (applied - emf) * inverse_resistance;
    return final_value + (current - final_value) * decay;
  }
};

// Turns (sin, cos) on by a small angle: the series are exact to 4e-7 for |angle| < 0.25 rad
// (1e-13 at the 0.02 rad of a 12.5 µs sub-step at 5 rps); the pair is recomputed every tick.
inline void rotate(double& s, double& c, double angle) {
  const double a2 = angle * angle;
  const double sin_a = angle * (1.0 - a2 * (1.0 / 6.0) * (1.0 - a2 * (1.0 / 20.0)));
  const double cos_a = 1.0 - a2 * 0.5 * (1.0 - a2 * (1.0 / 12.0));
  const double rotated_s = s * cos_a + c * sin_a;
  c = c * cos_a - s * sin_a;
  s = rotated_s;
}

}  // namespace

StepperMotorDescription StepperMotorDescription::nema17() {
  StepperMotorDescription motor;
  motor.name = "nema17";
  motor.resistance_ohm = 1.5;
  motor.inductance_h = 2.8e-3;
  motor.torque_constant_nm_per_a = 0.27;
  motor.detent_torque_nm = 0.022;
  motor.rotor_inertia_kg_m2 = 5.4e-6;
  motor.friction_torque_nm = 0.017;
  motor.rated_current_a = 1.5;  // 0.4 N m holding torque
  motor.full_steps_per_revolution = 200;
  motor.viscous_friction_nm_s = 2e-5;
  return motor;
}

StepperMotorDescription StepperMotorDescription::nema23() {
  // A 56 mm NEMA23 of the 2.8 A, 1 N m class (datasheet-like values of such motors).
  StepperMotorDescription motor;
  motor.name = "nema23";
  motor.resistance_ohm = 0.75;
  motor.inductance_h = 2.5e-3;
  motor.torque_constant_nm_per_a = 1.0 / 2.8;
  motor.detent_torque_nm = 0.04;
  motor.rotor_inertia_kg_m2 = 2.6e-5;
  motor.friction_torque_nm = 0.03;
  motor.rated_current_a = 2.8;
  motor.full_steps_per_revolution = 200;
  motor.viscous_friction_nm_s = 1e-4;
  return motor;
}

namespace {

// Electrical stiffness and damping of the rotor as the stability check sees them.
struct RotorSpring {
  double stiffness_nm_per_rad;
  double damping_nm_s;
};

RotorSpring rotor_spring(const StepperMotorDescription& motor, double sub_step_s) {
  const double pole_pairs = motor.full_steps_per_revolution / 4.0;
  const double k = motor.torque_constant_nm_per_a;
  // Within one sub-step the back-EMF drives the current only (1 - exp(-h R / L)) of its way.
  const double emf_share = -std::expm1(-sub_step_s * motor.resistance_ohm / motor.inductance_h);
  return {(k * StepperPlant::kStabilityPeakCurrentA + 4.0 * motor.detent_torque_nm) * pole_pairs,
          motor.viscous_friction_nm_s + k * k * emf_share / motor.resistance_ohm};
}

}  // namespace

double StepperPlant::step_number(const StepperMotorDescription& motor, double sub_step_s) {
  const RotorSpring spring = rotor_spring(motor, sub_step_s);
  const double j = motor.rotor_inertia_kg_m2;
  return sub_step_s * (std::sqrt(spring.stiffness_nm_per_rad / j) + spring.damping_nm_s / j);
}

double StepperPlant::min_stable_inertia_kg_m2(const StepperMotorDescription& motor, double sub_step_s) {
  // h (sqrt(k) x + b x^2) = n with x = 1 / sqrt(J): the positive root.
  const RotorSpring spring = rotor_spring(motor, sub_step_s);
  const double h = sub_step_s;
  const double n = kStableStepNumber;
  const double root_k = std::sqrt(spring.stiffness_nm_per_rad);
  const double x = spring.damping_nm_s > 0.0
                       ? (-h * root_k + std::sqrt(h * h * spring.stiffness_nm_per_rad + 4.0 * h * spring.damping_nm_s * n)) /
                             (2.0 * h * spring.damping_nm_s)
                       : n / (h * root_k);
  return 1.0 / (x * x);
}

StepperPlant::StepperPlant(const StepperMotorDescription& motor, int sub_steps)
    : motor_(motor), sub_steps_(sub_steps < 1 ? kAdaptiveSubSteps : sub_steps) {
  pole_pairs_ = motor_.full_steps_per_revolution / 4.0;
  inverse_inertia_ = 1.0 / motor_.rotor_inertia_kg_m2;
  sync_electrical_angle();
}

void StepperPlant::update_step_constants(double dt_s) {
  step_dt_s_ = dt_s;
  active_sub_steps_ = sub_steps_;
  if (sub_steps_ == kAdaptiveSubSteps) {
    // The fewest sub-steps that integrate the rotor with its present inertia accurately.
    StepperMotorDescription loaded = motor_;
    loaded.rotor_inertia_kg_m2 = motor_.rotor_inertia_kg_m2 + load_inertia_kg_m2_;
    active_sub_steps_ = 1;
    while (active_sub_steps_ < kFinestSubSteps && step_number(loaded, dt_s / active_sub_steps_) > kAccurateStepNumber) {
      active_sub_steps_ *= 2;
    }
  }
  sub_step_s_ = dt_s / active_sub_steps_;
  rate_ = motor_.resistance_ohm / motor_.inductance_h;
  decay_ = std::exp(-sub_step_s_ * rate_);
  inverse_rise_ = 1.0 / (1.0 - decay_);
}

void StepperPlant::sync_electrical_angle() {
  ticks_since_sync_ = 0;
  const double angle = pole_pairs_ * kTwoPi * position_rev_;
  sin_e_ = std::sin(angle);
  cos_e_ = std::cos(angle);
}

double StepperPlant::velocity_rps() const { return omega_rad_s_ / kTwoPi; }

double StepperPlant::electrical_angle_rad() const { return pole_pairs_ * kTwoPi * position_rev_; }

double StepperPlant::motor_torque_nm() const {
  return motor_.torque_constant_nm_per_a * (-current_a_ * sin_e_ + current_b_ * cos_e_);
}

void StepperPlant::set_load_inertia_kg_m2(double inertia) {
  load_inertia_kg_m2_ = inertia < 0.0 ? 0.0 : inertia;
  inverse_inertia_ = 1.0 / (motor_.rotor_inertia_kg_m2 + load_inertia_kg_m2_);
  step_dt_s_ = -1.0;  // the adaptive sub-steps depend on the inertia
}

void StepperPlant::set_blocked(bool blocked) {
  blocked_ = blocked;
  if (blocked) omega_rad_s_ = 0.0;
}

void StepperPlant::set_position_revolutions(double position) {
  position_rev_ = position;
  omega_rad_s_ = 0.0;
  sync_electrical_angle();
}

// The rotor over one step h by leapfrog (half a step of turning, the torque at that midpoint
// angle, the speed, the other half): symplectic like semi-implicit Euler, with the same stability
// limit, but second order, so that the torque over a whole tick is that of the tick's mean angle
// (semi-implicit Euler over one tick would take it at the tick's start angle, a lag of a whole
// tick of turning). (s, c): sin and cos of the electrical angle, turned with the rotor.
void StepperPlant::rotor_leapfrog_step(double& s, double& c, double h) {
  const double k = motor_.torque_constant_nm_per_a;
  const double friction = motor_.friction_torque_nm;
  const auto turn = [&](double omega, double dt) {
    if (omega == 0.0) return;
    position_rev_ += omega * dt * (1.0 / kTwoPi);
    const double turned = pole_pairs_ * omega * dt;  // electrical, rad
    if (std::fabs(turned) < 0.25) {
      rotate(s, c, turned);
    } else {
      const double angle = pole_pairs_ * kTwoPi * position_rev_;
      s = std::sin(angle);
      c = std::cos(angle);
    }
  };
  turn(omega_rad_s_, 0.5 * h);
  // sin 4θ from the double-angle formulas (the detent has four periods per electrical one).
  const double detent = motor_.detent_torque_nm * 4.0 * s * c * (c * c - s * s);
  const double drive_torque =
      k * (-current_a_ * s + current_b_ * c) - detent - load_torque_nm_ - motor_.viscous_friction_nm_s * omega_rad_s_;
  if (omega_rad_s_ == 0.0 && std::fabs(drive_torque) <= friction) return;  // static friction holds
  const double moving = omega_rad_s_ != 0.0 ? sign(omega_rad_s_) : sign(drive_torque);
  const double next = omega_rad_s_ + (drive_torque - friction * moving) * inverse_inertia_ * h;
  // Friction stops the rotor rather than reversing it.
  omega_rad_s_ = (omega_rad_s_ != 0.0 && next * omega_rad_s_ < 0.0) ? 0.0 : next;
  turn(omega_rad_s_, 0.5 * h);
}

void StepperPlant::advance(const board::StepperDrive& drive, double supply_volt, double dt_s) {
  if (dt_s != step_dt_s_) update_step_constants(dt_s);
  const double h = sub_step_s_;
  const double k = motor_.torque_constant_nm_per_a;
  const CoilStep coil{motor_.resistance_ohm, 1.0 / motor_.resistance_ohm, decay_, inverse_rise_,
                      supply_volt > 0.0 ? supply_volt : 0.0};
  // Open bridges: the current can only decay through the freewheeling diodes (towards 0 at up
  // to the supply voltage), which the chopper with target 0 models.
  const double target_a = drive.enabled ? drive.coil_a_ma * 1e-3 : 0.0;
  const double target_b = drive.enabled ? drive.coil_b_ma * 1e-3 : 0.0;
  const double radians_per_revolution = pole_pairs_ * kTwoPi;
  const bool exact_emf = sub_steps_ == kAdaptiveSubSteps;
  // sin and cos of the electrical angle: exact at the tick's start (computed at the end of the
  // last one), turned with the rotor through the sub-steps.
  double s = sin_e_;
  double c = cos_e_;
  for (int i = 0; i < active_sub_steps_; ++i) {
    // Back-EMF of each coil (V): the time derivative of its flux linkage K cos / K sin.
    double emf_a = -k * omega_rad_s_ * s;
    double emf_b = k * omega_rad_s_ * c;
    if (exact_emf && omega_rad_s_ != 0.0) {
      // The rotor turns by phi over the step at its initial speed: the coils see the back-EMF
      // K w exp(j (theta + w_e t)) (B the real part, A minus the imaginary part) weighted by the
      // RL response, i.e. times W = a / (1 - d) (exp(j phi) - d) / (a + j w_e), a = R / L.
      const double omega_e = pole_pairs_ * omega_rad_s_;
      const double phi = omega_e * h;
      const double p2 = phi * phi;
      const double sin_phi = phi * (1.0 - p2 * (1.0 / 6.0) * (1.0 - p2 * (1.0 / 20.0)));
      const double cos_phi = 1.0 - p2 * 0.5 * (1.0 - p2 * (1.0 / 12.0));
      const double nr = (std::fabs(phi) < 0.25 ? cos_phi : std::cos(phi)) - decay_;
      const double ni = std::fabs(phi) < 0.25 ? sin_phi : std::sin(phi);
      const double scale = rate_ * inverse_rise_ / (rate_ * rate_ + omega_e * omega_e);
      const double wr = (nr * rate_ + ni * omega_e) * scale;
      const double wi = (ni * rate_ - nr * omega_e) * scale;
      const double kw = k * omega_rad_s_;
      emf_b = kw * (c * wr - s * wi);
      emf_a = -kw * (c * wi + s * wr);
    }
    current_a_ = coil(current_a_, target_a, emf_a);
    current_b_ = coil(current_b_, target_b, emf_b);
    if (blocked_) continue;  // (omega is 0: the angle stays)
    if (exact_emf) {
      rotor_leapfrog_step(s, c, h);
      continue;
    }
    // sin 4θ from the double-angle formulas (the detent has four periods per electrical one).
    const double detent = motor_.detent_torque_nm * 4.0 * s * c * (c * c - s * s);
    const double drive_torque = k * (-current_a_ * s + current_b_ * c) - detent - load_torque_nm_ -
                                motor_.viscous_friction_nm_s * omega_rad_s_;
    const double friction = motor_.friction_torque_nm;
    if (omega_rad_s_ == 0.0 && std::fabs(drive_torque) <= friction) continue;  // static friction holds
    const double moving = omega_rad_s_ != 0.0 ? sign(omega_rad_s_) : sign(drive_torque);
    const double next = omega_rad_s_ + (drive_torque - friction * moving) * inverse_inertia_ * h;
    // Friction stops the rotor rather than reversing it.
    omega_rad_s_ = (omega_rad_s_ != 0.0 && next * omega_rad_s_ < 0.0) ? 0.0 : next;
    position_rev_ += omega_rad_s_ * h * (1.0 / kTwoPi);
    const double turned = pole_pairs_ * omega_rad_s_ * h;  // electrical, rad
    if (std::fabs(turned) < 0.25) {
      rotate(s, c, turned);
    } else {
      s = std::sin(radians_per_revolution * position_rev_);
      c = std::cos(radians_per_revolution * position_rev_);
    }
  }
  // The tick's end (what StallGuard and the next tick read): the reference integrator computes
  // it exactly every tick, as before; the default keeps the rotated pair and computes it exactly
  // every millisecond (the rotations drift by rounding only, below 1e-11 in that time).
  if (exact_emf && ++ticks_since_sync_ < kTicksPerSync) {
    sin_e_ = s;
    cos_e_ = c;
  } else {
    sync_electrical_angle();
  }
}

// --- IdealStepper ---------------------------------------------------------------------------

void IdealStepper::advance(const board::StepperDrive& drive, double dt_s) {
  if (!drive.enabled) {
    velocity_rps_ = 0.0;
    return;
  }
  // The rotor's angle within its electrical revolution moves onto the field: the nearest way,
  // which follows a moving field and snaps to it after the driver was off.
  const auto delta = static_cast<int32_t>(drive.electrical_angle - static_cast<uint32_t>(electrical_position_));
  electrical_position_ += delta;
  velocity_rps_ = dt_s > 0.0 ? delta * (4.0 / full_steps_per_revolution) / kElectricalCircle / dt_s : 0.0;
}

double IdealStepper::position_revolutions() const {
  return static_cast<double>(electrical_position_) * (4.0 / full_steps_per_revolution) / kElectricalCircle;
}

void IdealStepper::set_position_revolutions(double position) {
  electrical_position_ = std::llround(position * (full_steps_per_revolution / 4.0) * kElectricalCircle);
  velocity_rps_ = 0.0;
}

// --- StepperSensors -------------------------------------------------------------------------

int32_t StepperSensors::encoder_count_at(double rotor_position_revolutions) const {
  const double counts = std::floor(rotor_position_revolutions * config_.encoder.counts_per_revolution);
  if (!std::isfinite(counts)) return 0;
  // The counter wraps at 32 bits: the remainder (exact for doubles) fits int64 for any position.
  auto whole = static_cast<int64_t>(std::fmod(counts, kTwoTo32));
  if (config_.encoder.reversed) whole = -whole;
  return static_cast<int32_t>(static_cast<uint32_t>(static_cast<uint64_t>(whole)));
}

void StepperSensors::sense(double rotor_position_revolutions, board::StepperFeedback& out) {
  const bool finite = std::isfinite(rotor_position_revolutions);
  auto level = [rotor_position_revolutions, finite](const StepperSensorConfig::Switch& sw) -> uint8_t {
    const bool pressed = finite && sw.present && rotor_position_revolutions >= sw.from_revolutions &&
                         rotor_position_revolutions <= sw.to_revolutions;
    return pressed == sw.active_high ? 1 : 0;
  };
  out.switches = static_cast<uint8_t>(level(config_.right) | (level(config_.left) << 1) | (level(config_.home) << 2));
  if (!finite) {
    out.encoder_count = 0;
    out.encoder_index_events = index_events_;
    out.encoder_index_count = index_count_;
    return;
  }
  const double index = config_.encoder.index_revolutions;
  // Turns beyond +-2^61 (only a runaway plant gets there) saturate instead of overflowing.
  const double turns = std::floor(rotor_position_revolutions - index);
  const int64_t turn = turns >= kTurnLimit ? static_cast<int64_t>(kTurnLimit)
                                         : (turns <= -kTurnLimit ? -static_cast<int64_t>(kTurnLimit) : static_cast<int64_t>(turns));
  if (!started_) {
    started_ = true;
    last_index_turn_ = turn;
  }
  if (config_.encoder.counts_per_revolution != 0 && turn != last_index_turn_) {
    // Each whole turn crossed is one N pulse; the last one crossed latches the count there.
    const int64_t crossed = turn > last_index_turn_ ? turn - last_index_turn_ : last_index_turn_ - turn;
    index_events_ += static_cast<uint32_t>(crossed);
    const int64_t last_crossing = turn > last_index_turn_ ? turn : turn + 1;
    index_count_ = encoder_count_at(static_cast<double>(last_crossing) + index);
  }
  last_index_turn_ = turn;
  out.encoder_count = config_.encoder.counts_per_revolution != 0 ? encoder_count_at(rotor_position_revolutions) : 0;
  out.encoder_index_events = index_events_;
  out.encoder_index_count = index_count_;
}

}  // namespace motwin::sim
