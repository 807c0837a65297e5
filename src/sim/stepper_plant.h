// The physics behind the stepper seam (board/stepper_drive.h): a two-phase hybrid stepper motor
// with its load, the ideal motor that follows the field exactly, and the motor-side sensors (ABN
// encoder with index, limit and home switches). Shared by the TMCM-142 and TMCM-3216 simulations.
//
// StepperPlant integrates in double precision: the coil currents by the exact exponential update
// of the RL circuits under a chopper that forces them to their targets while the supply voltage
// suffices (with the back-EMF of the rotor turning at the step's initial speed integrated
// exactly over the step), the rotor by leapfrog (the torque at the step's midpoint angle). By
// default a tick takes 1, 2 or 4 steps, the fewest its rotor step number allows accurately
// (kAccurateStepNumber: NEMA17 2, NEMA23 1); a fixed sub-step count (>= 1) takes the earlier
// integrator (back-EMF held over each sub-step, the rotor by semi-implicit Euler), kept as the
// reference the default is tested against. Torque
// K (-ia sin θe + ib cos θe) - detent sin 4θe - friction - load; θe = (full steps per rev / 4) x
// the mechanical angle. Step loss is not programmed: it happens when the load angle passes 90°
// electrical. Equations and defaults: docs/stepper-motion.md.
#pragma once

#include <cstdint>
#include <string>

#include "board/stepper_drive.h"

namespace motwin::sim {

struct StepperMotorDescription {
  std::string name;
  double resistance_ohm = 1.5;             // per coil
  double inductance_h = 2.8e-3;            // per coil
  double torque_constant_nm_per_a = 0.27;  // also the back-EMF constant, V s/rad
  double detent_torque_nm = 0.022;         // amplitude of the unpowered cogging (4 per electrical period)
  double rotor_inertia_kg_m2 = 5.4e-6;
  double friction_torque_nm = 0.017;       // Coulomb (bearing) friction
  double rated_current_a = 1.5;            // peak coil current for the holding torque
  int full_steps_per_revolution = 200;
  double viscous_friction_nm_s = 2e-5;     // N m per rad/s: bearing and iron-loss damping

  double holding_torque_nm() const { return torque_constant_nm_per_a * rated_current_a; }

  static StepperMotorDescription nema17();  // docs/stepper-motion.md "Hybrid stepper model (`sim::StepperPlant`)"
  static StepperMotorDescription nema23();  // 2.8 A, about 1 N m holding torque (TMCM-142 default)
};

class StepperPlant {
 public:
  // Sub-step choice: kAdaptiveSubSteps (the default) takes 1, 2 or 4 sub-steps per tick, the
  // fewest with step_number() <= kAccurateStepNumber (at most kFinestSubSteps, whose stability
  // the motor check guarantees); n >= 1 is the reference integrator with n sub-steps.
  static constexpr int kAdaptiveSubSteps = 0;
  static constexpr int kFinestSubSteps = 4;
  static constexpr int kReferenceSubSteps = 4;  // what every tick took before
  static constexpr int kDefaultSubSteps = kAdaptiveSubSteps;
  // The integrators' frequency error is about step number^2 / 24 (0.07 % at 0.125); 0.125 rather
  // than 0.25 because a marginal load step (docs/stepper-motion.md) pulls out at one NEMA17 step
  // per tick and holds at two.
  static constexpr double kAccurateStepNumber = 0.125;
  // The control tick of the boards that use the plant (TMCM-142 and TMCM-3216: 50 µs).
  static constexpr double kBoardTickS = 50e-6;
  // The largest peak coil current a module drives (TMCM-142: 7 A); the stability check assumes it.
  static constexpr double kStabilityPeakCurrentA = 7.0;
  // The rotor integration is explicit (semi-implicit Euler, stable below 2): a motor is accepted
  // while h (sqrt(k / J) + b / J) stays below this per sub-step h, with k the stiffest electrical
  // spring (Kt x kStabilityPeakCurrentA + 4 x detent, per mechanical rad) and b the damping
  // (viscous friction and the back-EMF current one sub-step builds up).
  static constexpr double kStableStepNumber = 0.5;
  static double step_number(const StepperMotorDescription& motor, double sub_step_s);
  // The smallest rotor inertia for which `motor` has step_number() <= kStableStepNumber.
  static double min_stable_inertia_kg_m2(const StepperMotorDescription& motor, double sub_step_s);

  explicit StepperPlant(const StepperMotorDescription& motor, int sub_steps = kDefaultSubSteps);

  // One control tick: the coil currents follow drive.coil_*_ma (the chopper) while the voltage
  // needed is within supply_volt, else RL dynamics with back-EMF at the full supply voltage;
  // drive.enabled == false: the bridges are open, the currents decay through the freewheeling
  // diodes into the supply and the rotor coasts (detent and friction only).
  void advance(const board::StepperDrive& drive, double supply_volt, double dt_s);

  const StepperMotorDescription& motor() const { return motor_; }
  double position_revolutions() const { return position_rev_; }  // rotor, continuous
  double velocity_rps() const;
  double coil_a_current_a() const { return current_a_; }
  double coil_b_current_a() const { return current_b_; }
  double motor_torque_nm() const;  // electromagnetic torque of the coils (without detent)
  // The rotor's electrical angle, rad, continuous: 0 when the rotor sits where the field of
  // electrical angle 0 (coil A only, positive) holds it.
  double electrical_angle_rad() const;
  // sin and cos of electrical_angle_rad() (exact every millisecond, rotated with the rotor between).
  double electrical_sin() const { return sin_e_; }
  double electrical_cos() const { return cos_e_; }
  // The sub-steps a tick takes now (adaptive: 1, 2 or 4).
  int sub_steps() const { return active_sub_steps_; }

  // A constant torque pulling towards negative positions (a weight that positive moves lift);
  // negative values pull towards positive positions.
  void set_load_torque_nm(double torque) { load_torque_nm_ = torque; }
  double load_torque_nm() const { return load_torque_nm_; }
  void set_load_inertia_kg_m2(double inertia);
  // An obstacle: the rotor is held at its present position (velocity 0) while set.
  void set_blocked(bool blocked);
  bool blocked() const { return blocked_; }
  // Moves the rotor (tests and scenarios), at rest.
  void set_position_revolutions(double position);

 private:
  void update_step_constants(double dt_s);
  void sync_electrical_angle();
  void rotor_leapfrog_step(double& s, double& c, double h);

  StepperMotorDescription motor_;
  int sub_steps_;          // as asked: kAdaptiveSubSteps or a fixed count
  int active_sub_steps_ = kFinestSubSteps;
  // State.
  double position_rev_ = 0.0;
  double omega_rad_s_ = 0.0;
  double current_a_ = 0.0;
  double current_b_ = 0.0;
  // Environment.
  double load_torque_nm_ = 0.0;
  double load_inertia_kg_m2_ = 0.0;
  bool blocked_ = false;
  // Constants.
  double pole_pairs_ = 50.0;  // electrical periods per revolution
  double inverse_inertia_ = 0.0;
  double step_dt_s_ = -1.0;   // tick length the step constants were computed for
  double sub_step_s_ = 0.0;
  double decay_ = 0.0;        // exp(-h R / L)
  double inverse_rise_ = 0.0; // 1 / (1 - decay_)
  double rate_ = 0.0;         // R / L
  double sin_e_ = 0.0;        // of the electrical angle at position_rev_
  double cos_e_ = 1.0;
  static constexpr int kTicksPerSync = 20;
  int ticks_since_sync_ = 0;
};

// The ideal motor: the rotor follows the commanded electrical angle exactly, unwrapped (at most
// half an electrical revolution per tick either way), for the fastest simulation and exact
// positions. Disabled, it stays put; enabled again, it snaps to the field's nearest equilibrium
// (within two full steps), as a real rotor does.
class IdealStepper {
 public:
  void advance(const board::StepperDrive& drive, double dt_s);
  double position_revolutions() const;
  double velocity_rps() const { return velocity_rps_; }
  void set_position_revolutions(double position);
  // Rotor position as an unwrapped electrical angle, 2^32 per electrical revolution.
  int64_t electrical_position() const { return electrical_position_; }

  int full_steps_per_revolution = 200;

 private:
  int64_t electrical_position_ = 0;
  double velocity_rps_ = 0.0;
};

// Motor-side sensors from the rotor position: an ABN encoder and three switches.
struct StepperSensorConfig {
  struct Encoder {
    int32_t counts_per_revolution = 4000;  // quadrature counts (4 x lines); 0: no encoder (count stays 0)
    bool reversed = false;                 // counts down for positive rotation
    double index_revolutions = 0.0;        // rotor angle of the N pulse within a revolution, 0..1
  } encoder;
  // A switch is pressed while the rotor is within [from, to] (revolutions; use +-1e300 for a
  // limit switch pressed beyond a point) and then reads `active_high` as its level; released, the
  // opposite. An absent switch reads as released.
  struct Switch {
    bool present = false;
    double from_revolutions = 0.0;
    double to_revolutions = 0.0;
    bool active_high = true;
  };
  Switch right;  // feedback.switches bit 0
  Switch left;   // bit 1
  Switch home;   // bit 2
};

class StepperSensors {
 public:
  explicit StepperSensors(const StepperSensorConfig& config = StepperSensorConfig{}) : config_(config) {}

  // Reads the sensors at the rotor position: encoder count (floor of position x counts per
  // revolution, signed by the direction, wrapping at 32 bits), N pulses crossed since the last
  // call (each latches the count at the exact index angle) and the switch levels. The first call
  // only establishes where the rotor is (no index crossing is counted from position 0). A
  // position that is not finite (a diverged plant) counts 0, crosses no index and presses no
  // switch.
  void sense(double rotor_position_revolutions, board::StepperFeedback& out);

  const StepperSensorConfig& config() const { return config_; }
  void set_config(const StepperSensorConfig& config) { config_ = config; }
  // The encoder count at a rotor position (what sense() reports there).
  int32_t encoder_count_at(double rotor_position_revolutions) const;

 private:
  StepperSensorConfig config_;
  bool started_ = false;
  int64_t last_index_turn_ = 0;  // floor(position - index angle) at the last call
  uint32_t index_events_ = 0;
  int32_t index_count_ = 0;
};

}  // namespace motwin::sim
