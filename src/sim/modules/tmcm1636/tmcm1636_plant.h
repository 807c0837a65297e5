// The physics behind the TMCM-1636 power-stage seam: a BLDC/PMSM in the dq frame or a brushed
// DC motor, the mechanical load (inertia, viscous and Coulomb friction, load torque, an optional
// holding brake, a blocking obstacle), the supply bus (source resistance behind a diode, bus
// capacitance, brake-chopper resistor), current sensing through the ADC with seeded noise, hall
// sensors, an ABN encoder with index, an absolute encoder and the driver's thermal model.
//
// Integrated in double precision. The currents take one exact step per control tick: with the
// bridge voltage held over the tick (zero-order hold of the latched duties in the stationary frame)
// and the rotor turning at the tick's initial speed, the RL circuits with back-EMF and
// cross-coupling are linear with constant coefficients, and their solution at the tick's end and
// its mean over the tick are closed forms (exponential decay and a rotation, constants computed
// when the tick length is first seen). A salient motor (Ld != Lq) and the reference stepping
// (sub_steps >= 1) take sub-steps of the exact exponential update with the back-EMF and
// cross-coupling held per sub-step, as before. The mechanics and the supply bus (whose time
// constants are far longer than a tick, or solved exactly) advance once per tick with the
// tick's mean torque and bus current. The PWM computed in a tick is applied from the next tick on
// (one-tick delay). Equations, defaults and the error against sub-stepping:
// docs/tmcm-1636-servo.md.
#pragma once

#include <cstdint>

#include "board/modules/tmcm1636/tmcm1636_power_stage.h"
#include "sim/modules/tmcm1636/motor_description.h"

namespace motwin::sim {

// A small deterministic generator (splitmix64): the same seed gives the same noise, bit for bit.
class NoiseSource {
 public:
  explicit NoiseSource(uint64_t seed) : state_(seed) {}
  uint64_t next() {
    uint64_t z = (state_ += 0x9E3779B97F4A7C15ull);
    z = (z ^ (z >> 30)) * 0xBF58476D1CE4E5B9ull;
    z = (z ^ (z >> 27)) * 0x94D049BB133111EBull;
    return z ^ (z >> 31);
  }
  double uniform() { return static_cast<double>(next() >> 11) * 0x1.0p-53; }
  // Approximately normal, mean 0 and standard deviation 1: the sum of four 16-bit uniforms
  // taken from one draw (Irwin-Hall), cheap enough for every ADC sample.
  double normal() {
    const uint64_t bits = next();
    const uint64_t sum = (bits & 0xFFFF) + ((bits >> 16) & 0xFFFF) + ((bits >> 32) & 0xFFFF) + (bits >> 48);
    return (static_cast<double>(sum) * (1.0 / 65536.0) - 2.0) * 1.7320508075688772;
  }

 private:
  uint64_t state_;
};

// Fixed properties of the TMCM-1636 board as simulated (docs/tmcm-1636-servo.md).
struct Tmcm1636BoardModel {
  double adc_counts_per_ma = 1.0;         // current amplifier gain (AP 7 = 256 reads mA)
  double adc_offset_a = 32768.0;          // true zero-current reading (firmware default AP 5 = 32767)
  double adc_offset_b = 32768.0;
  int adc_lsb_counts = 16;                // a 12-bit ADC left-aligned to 16 bits
  double current_noise_ma = 8.0;          // standard deviation of the current reading
  double switch_on_resistance_ohm = 0.01; // each MOSFET
  double switching_energy_per_volt_amp = 40e-9;  // J per (V x A) per PWM period
  double quiescent_power_w = 0.6;
  double thermal_resistance_k_per_w = 6.0;  // driver to ambient
  double thermal_capacitance_j_per_k = 20.0;
};

class Tmcm1636Plant {
 public:
  // sub_steps: kExactStep (0) steps the currents exactly once per tick (the default; a salient
  // motor takes kReferenceSubSteps); n >= 1 takes n sub-steps of the earlier integrator, kept as
  // the reference the exact step is tested against.
  static constexpr int kExactStep = 0;
  static constexpr int kReferenceSubSteps = 3;
  static constexpr int kDefaultSubSteps = kExactStep;

  explicit Tmcm1636Plant(const MotorDescription& motor, uint64_t noise_seed = 0x1636,
                         const Tmcm1636BoardModel& board = Tmcm1636BoardModel{}, int sub_steps = kDefaultSubSteps);

  // What the firmware reads at the start of a tick (everything but the reference switches,
  // which the board's inputs give).
  void sense(board::Tmcm1636Feedback& feedback);
  // One control tick: integrates with the drive latched at the end of the previous tick, then
  // latches `drive` for the next one.
  void advance(const board::Tmcm1636Drive& drive, double dt_s);

  // Environment.
  void set_source_voltage(double volts) { source_voltage_ = volts; }
  void set_ambient_celsius(double celsius) { ambient_celsius_ = celsius; }
  void set_load_torque(double newton_metre) { load_torque_ = newton_metre; }
  void set_load_inertia(double kgm2) {
    load_inertia_ = kgm2 < 0.0 ? 0.0 : kgm2;
    inverse_inertia_ = 1.0 / total_inertia_kgm2();
  }
  void set_blocked(bool blocked) {
    blocked_ = blocked;
    if (blocked) omega_ = 0.0;
  }
  void set_encoder_fault(bool fault) { encoder_fault_ = fault; }
  void set_hall_fault(bool fault) { hall_fault_ = fault; }

  // True physical values.
  const MotorDescription& motor() const { return motor_; }
  double mechanical_angle_rad() const { return theta_; }
  double position_revolutions() const;
  double speed_rad_s() const { return omega_; }
  double speed_rpm() const;
  double id_amps() const { return id_; }
  double iq_amps() const { return iq_; }  // DC motor: armature current
  double electromagnetic_torque_nm() const;
  double total_inertia_kgm2() const { return motor_.rotor_inertia_kgm2 + load_inertia_; }
  double load_torque_nm() const { return load_torque_; }
  double bus_voltage() const { return bus_voltage_; }
  bool chopper_on() const { return latched_.brake_chopper_on; }
  bool brake_engaged() const { return motor_.brake.present && !brake_released_; }
  double driver_celsius() const { return ambient_celsius_ + temperature_rise_; }
  double supply_energy_j() const { return supply_energy_j_; }
  double chopper_energy_j() const { return chopper_energy_j_; }
  uint64_t ticks() const { return ticks_; }

  // Where the sensors' zeros are, for tests comparing a found commutation offset with the model:
  // the raw ABN count at which the electrical angle is 0 (one of pole_pairs such counts), and the
  // raw count the N pulse latches (the first one forward of the start position).
  double abn_count_at_electrical_zero() const;
  double abn_count_at_index() const;
  // The absolute encoder reading (16-bit) at electrical angle 0.
  double absolute_reading_at_electrical_zero() const;

 private:
  double electrical_substep(double rotate_cos, double rotate_sin);
  double electrical_exact_step(double rotate_cos, double rotate_sin, double turned_rad);
  void mechanics(double dt_s, double torque);
  void update_bus(double dt_s);
  int32_t abn_count_at(double theta) const;
  void sync_electrical_angle();
  void update_index_window();

  MotorDescription motor_;
  Tmcm1636BoardModel board_;
  NoiseSource noise_;
  int sub_steps_;      // of the reference integrator
  bool exact_step_;    // one exact step per tick (non-salient BLDC, DC)
  board::Tmcm1636Drive latched_{};
  // State.
  double theta_ = 0.0;  // mechanical angle, rad, continuous
  double omega_ = 0.0;  // rad/s
  double id_ = 0.0;     // A (DC motor: armature current in iq_)
  double iq_ = 0.0;
  double bus_voltage_ = 24.0;
  double temperature_rise_ = 0.0;
  double brake_coil_ = 0.0;  // filtered coil duty, 0..1
  bool brake_released_ = false;
  uint64_t ticks_ = 0;
  double supply_energy_j_ = 0.0;
  double chopper_energy_j_ = 0.0;
  // Sensors.
  double theta_start_ = 0.0;
  int32_t frozen_abn_count_ = 0;
  int64_t index_turn_ = 0;
  uint32_t index_events_ = 0;
  int32_t index_count_ = 0;
  // Environment.
  double source_voltage_ = 24.0;
  double ambient_celsius_ = 25.0;
  double load_torque_ = 0.0;
  double load_inertia_ = 0.0;
  bool blocked_ = false;
  bool encoder_fault_ = false;
  bool hall_fault_ = false;
  // Step constants, recomputed when the tick length changes.
  double step_h_ = 0.0;
  double decay_d_ = 0.0;
  double decay_q_ = 0.0;
  double bus_decay_[4] = {};  // per tick, [source conducting][chopper on]
  double bus_current_sum_ = 0.0;
  // The exact step: decay over the tick exp(-R dt / L), its mean over the tick (1 - decay) L /
  // (R dt), and R / L.
  double tick_decay_ = 0.0;
  double tick_mean_decay_ = 0.0;
  double rate_ = 0.0;
  double tick_rate_dt_ = 0.0;  // R dt / L
  // The latched duties as the stationary voltage vector per volt of bus (alpha, beta), and the
  // DC motor's U-V duty difference: set once per tick.
  double duty_alpha_ = 0.0;
  double duty_beta_ = 0.0;
  double duty_dc_ = 0.0;
  double inverse_resistance_ = 0.0;
  double counts_per_radian_ = 0.0;
  double inverse_lsb_ = 1.0;
  double torque_per_iq_ = 0.0;          // 1.5 p lambda (DC: Kt)
  double reluctance_torque_ = 0.0;      // 1.5 p (Ld - Lq)
  double inverse_conductance_[4] = {};  // 1 / (source + chopper conductance), 0 when none
  double inverse_inertia_ = 0.0;
  double inverse_capacitance_ = 0.0;
  double source_conductance_ = 0.0;
  double chopper_conductance_ = 0.0;
  double thermal_decay_ = 0.0;
  double brake_decay_ = 0.0;
  // sin and cos of the electrical angle, exact at each tick start and rotated through the
  // sub-steps by the small angle they advance (saves a sincos per sub-step).
  double sin_e_ = 0.0;
  double cos_e_ = 1.0;
  // The N pulse: the rotor angles of the next index crossing forward and backward.
  double index_forward_ = 0.0;
  double index_backward_ = 0.0;
};

}  // namespace motwin::sim
