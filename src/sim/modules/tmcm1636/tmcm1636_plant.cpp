#include "sim/modules/tmcm1636/tmcm1636_plant.h"

#include <cmath>

#include "core/modules/tmcm1636/tmcm1636_hardware.h"

namespace motwin::sim {
namespace {

namespace hw = modules::tmcm1636;

constexpr double kPi = 3.14159265358979323846;
constexpr double kTwoPi = 2.0 * kPi;
constexpr double kSqrt3 = 1.7320508075688772;
constexpr double kInverseSqrt3 = 0.57735026918962576;
constexpr double kOneThird = 1.0 / 3.0;
// Hall state of sector 0..5 of the hall angle (firmware table core/motion/hall_decoder.h).
constexpr uint8_t kSectorState[6] = {5, 1, 3, 2, 6, 4};

double radians(double degrees) { return degrees * kPi / 180.0; }
double sign(double v) { return v > 0.0 ? 1.0 : (v < 0.0 ? -1.0 : 0.0); }
// Rounds half away from zero, as lround does, without the library call.
int32_t round_to_int(double v) { return static_cast<int32_t>(v >= 0.0 ? v + 0.5 : v - 0.5); }

// cos and sin of a small angle: Taylor terms to the 7th order are exact to 3e-13 below 0.1 rad
// (to the 5th order, as before, they were off by up to 1.4e-9); larger angles take the library.
inline void rotation(double delta, double& c, double& s) {
  if (std::fabs(delta) < 0.1) {
    const double d2 = delta * delta;
    c = 1.0 - d2 * (0.5 - d2 * ((1.0 / 24.0) - d2 * (1.0 / 720.0)));
    s = delta * (1.0 - d2 * ((1.0 / 6.0) - d2 * ((1.0 / 120.0) - d2 * (1.0 / 5040.0))));
  } else {
    c = std::cos(delta);
    s = std::sin(delta);
  }
}

// g(phi) = (exp(j phi) - 1) / (j phi): the mean of exp(j phi t / dt) over the tick, given cos and
// sin of phi; the series below 0.1 rad (the quotients lose digits there) is exact to 3e-14.
void rotation_mean(double phi, double cos_phi, double sin_phi, double& real, double& imaginary) {
  if (std::fabs(phi) < 0.1) {
    const double p2 = phi * phi;
    real = 1.0 - p2 * ((1.0 / 6.0) - p2 * ((1.0 / 120.0) - p2 * (1.0 / 5040.0)));
    imaginary = phi * (0.5 - p2 * ((1.0 / 24.0) - p2 * ((1.0 / 720.0) - p2 * (1.0 / 40320.0))));
  } else {
    real = sin_phi / phi;
    imaginary = (1.0 - cos_phi) / phi;
  }
}

}  // namespace

Tmcm1636Plant::Tmcm1636Plant(const MotorDescription& motor, uint64_t noise_seed, const Tmcm1636BoardModel& board,
                             int sub_steps)
    : motor_(motor),
      board_(board),
      noise_(noise_seed),
      sub_steps_(sub_steps < 1 ? kReferenceSubSteps : sub_steps),
      exact_step_(sub_steps < 1 && (motor.kind == MotorKind::kDc || motor.inductance_d_h == motor.inductance_q_h)) {
  theta_ = radians(motor_.initial_angle_deg);
  theta_start_ = theta_;
  source_voltage_ = motor_.supply.voltage_v;
  bus_voltage_ = source_voltage_;
  index_turn_ = static_cast<int64_t>(std::floor((theta_ - radians(motor_.abn.index_deg)) / kTwoPi));
  latched_.bridge_enabled = false;
  inverse_resistance_ = 1.0 / motor_.resistance_ohm;
  inverse_inertia_ = 1.0 / total_inertia_kgm2();
  inverse_capacitance_ = 1.0 / motor_.supply.capacitance_f;
  source_conductance_ = 1.0 / motor_.supply.source_resistance_ohm;
  chopper_conductance_ = 1.0 / motor_.supply.brake_resistor_ohm;
  for (int source = 0; source < 2; ++source) {
    for (int chopper = 0; chopper < 2; ++chopper) {
      const double total = source * source_conductance_ + chopper * chopper_conductance_;
      inverse_conductance_[source * 2 + chopper] = total > 0.0 ? 1.0 / total : 0.0;
    }
  }
  torque_per_iq_ = motor_.torque_constant();
  counts_per_radian_ = motor_.abn.counts_per_rev / kTwoPi;
  inverse_lsb_ = 1.0 / board_.adc_lsb_counts;
  reluctance_torque_ =
      motor_.kind == MotorKind::kDc ? 0.0 : 1.5 * motor_.pole_pairs * (motor_.inductance_d_h - motor_.inductance_q_h);
  sync_electrical_angle();
  update_index_window();
}

void Tmcm1636Plant::sync_electrical_angle() {
  const double electrical = motor_.kind == MotorKind::kDc ? 0.0 : motor_.pole_pairs * theta_;
  sin_e_ = std::sin(electrical);
  cos_e_ = std::cos(electrical);
}

void Tmcm1636Plant::update_index_window() {
  const double index_angle = radians(motor_.abn.index_deg);
  index_backward_ = index_angle + kTwoPi * static_cast<double>(index_turn_);
  index_forward_ = index_backward_ + kTwoPi;
}

double Tmcm1636Plant::position_revolutions() const { return theta_ / kTwoPi; }
double Tmcm1636Plant::speed_rpm() const { return omega_ * 60.0 / kTwoPi; }

double Tmcm1636Plant::electromagnetic_torque_nm() const { return (torque_per_iq_ + reluctance_torque_ * id_) * iq_; }

int32_t Tmcm1636Plant::abn_count_at(double theta) const {
  const double counts = (theta - theta_start_) * counts_per_radian_;
  auto whole = static_cast<int64_t>(std::floor(counts));
  if (motor_.abn.reversed) whole = -whole;
  return static_cast<int32_t>(static_cast<uint32_t>(static_cast<uint64_t>(whole)));
}

double Tmcm1636Plant::abn_count_at_electrical_zero() const {
  const double counts = (0.0 - theta_start_) * motor_.abn.counts_per_rev / kTwoPi;
  return motor_.abn.reversed ? -counts : counts;
}

double Tmcm1636Plant::abn_count_at_index() const {
  const double counts = (radians(motor_.abn.index_deg) - theta_start_) * motor_.abn.counts_per_rev / kTwoPi;
  return motor_.abn.reversed ? -counts : counts;
}

double Tmcm1636Plant::absolute_reading_at_electrical_zero() const {
  const double turns = radians(motor_.absolute.offset_deg) / kTwoPi;
  return (turns - std::floor(turns)) * 65536.0;
}

void Tmcm1636Plant::sense(board::Tmcm1636Feedback& feedback) {
  double phase_a = 0.0;
  double phase_b = 0.0;
  const double electrical = motor_.pole_pairs * theta_;
  if (motor_.kind == MotorKind::kDc) {
    phase_a = iq_;
    phase_b = -iq_;
  } else {
    const double alpha = id_ * cos_e_ - iq_ * sin_e_;
    const double beta = id_ * sin_e_ + iq_ * cos_e_;
    phase_a = alpha;
    phase_b = -0.5 * alpha + 0.5 * kSqrt3 * beta;
  }
  const auto adc = [&](double amps, double offset) {
    const double counts = offset + (amps * 1000.0 + noise_.normal() * board_.current_noise_ma) * board_.adc_counts_per_ma;
    const double lsb = board_.adc_lsb_counts;
    double quantised = static_cast<double>(round_to_int(counts * inverse_lsb_)) * lsb;
    if (quantised < 0.0) quantised = 0.0;
    if (quantised > 65535.0) quantised = 65536.0 - lsb;
    return static_cast<uint16_t>(quantised);
  };
  feedback.adc_phase_a = adc(phase_a, board_.adc_offset_a);
  feedback.adc_phase_b = adc(phase_b, board_.adc_offset_b);
  // ADC_VM: 12 bits over 0..66 V (core/modules/tmcm1636/tmcm1636_hardware.h).
  constexpr double kSupplyCountsPerVolt = hw::kAdc12Max / (hw::kSupplyFullScaleDecivolt * 0.1);
  const int32_t supply = round_to_int(bus_voltage_ * kSupplyCountsPerVolt);
  feedback.adc_supply = static_cast<uint16_t>(supply > hw::kAdc12Max ? hw::kAdc12Max : supply);
  // The temperature moves in seconds: its ADC reading is refreshed every millisecond.
  if (ticks_ % 20 == 0) feedback.adc_temperature = hw::temperature_adc_from_celsius(driver_celsius());

  if (!motor_.hall.present || hall_fault_) {
    feedback.hall = 0;
  } else {
    const double hall_angle = (motor_.hall.reversed ? -1.0 : 1.0) * (electrical - radians(motor_.hall.offset_deg));
    const double turns = hall_angle * (1.0 / kTwoPi);
    int sector = static_cast<int>((turns - std::floor(turns)) * 6.0);
    if (sector > 5) sector = 5;
    uint8_t state = kSectorState[sector];
    if (motor_.hall.inverted) state = static_cast<uint8_t>(~state & 7);
    feedback.hall = state;
  }

  if (motor_.abn.present) {
    if (!encoder_fault_) frozen_abn_count_ = abn_count_at(theta_);
    feedback.abn_count = frozen_abn_count_;
    feedback.abn_index_events = index_events_;
    feedback.abn_index_count = index_count_;
  }

  if (motor_.absolute.present) {
    const double turns =
        ((motor_.absolute.reversed ? -theta_ : theta_) + radians(motor_.absolute.offset_deg)) / kTwoPi;
    const double fraction = turns - std::floor(turns);
    const int bits = motor_.absolute.bits;
    auto reading = static_cast<uint32_t>(fraction * static_cast<double>(1u << bits));
    if (reading >= (1u << bits)) reading = (1u << bits) - 1;
    feedback.absolute_angle = static_cast<uint16_t>(reading << (16 - bits));
    feedback.absolute_valid = true;
  } else {
    feedback.absolute_valid = false;
  }
}

void Tmcm1636Plant::advance(const board::Tmcm1636Drive& drive, double dt_s) {
  const double h = dt_s / sub_steps_;
  if (h != step_h_) {
    step_h_ = h;
    decay_d_ = std::exp(-motor_.resistance_ohm * h / motor_.inductance_d_h);
    decay_q_ = std::exp(-motor_.resistance_ohm * h / motor_.inductance_q_h);
    rate_ = motor_.resistance_ohm / motor_.inductance_q_h;
    tick_decay_ = std::exp(-rate_ * dt_s);
    tick_rate_dt_ = rate_ * dt_s;
    tick_mean_decay_ = -std::expm1(-tick_rate_dt_) / tick_rate_dt_;
    for (int source = 0; source < 2; ++source) {
      for (int chopper = 0; chopper < 2; ++chopper) {
        const double conductance =
            source / motor_.supply.source_resistance_ohm + chopper / motor_.supply.brake_resistor_ohm;
        bus_decay_[source * 2 + chopper] = std::exp(-conductance / motor_.supply.capacitance_f * dt_s);
      }
    }
    thermal_decay_ = std::exp(-dt_s / (board_.thermal_resistance_k_per_w * board_.thermal_capacitance_j_per_k));
    brake_decay_ = std::exp(-dt_s / motor_.brake.time_constant_s);
  }
  const double da = latched_.duty[0];
  const double db = latched_.duty[1];
  const double dc = latched_.duty[2];
  duty_alpha_ = (2.0 * da - db - dc) * kOneThird;
  duty_beta_ = (db - dc) * kInverseSqrt3;
  duty_dc_ = da - db;
  // The currents with the rotor turning at the tick's initial speed (the mechanics move far slower
  // than the currents), one exact step or sub-steps, then the mechanics over the whole tick with
  // the mean torque.
  const double sin_start = sin_e_;
  const double cos_start = cos_e_;
  const double theta_start = theta_;
  double rotate_cos = 1.0;
  double rotate_sin = 0.0;
  if (exact_step_) {
    const double turned = motor_.kind == MotorKind::kDc ? 0.0 : motor_.pole_pairs * omega_ * dt_s;
    if (motor_.kind != MotorKind::kDc) rotation(turned, rotate_cos, rotate_sin);
    mechanics(dt_s, electrical_exact_step(rotate_cos, rotate_sin, turned));
  } else {
    if (motor_.kind != MotorKind::kDc) rotation(motor_.pole_pairs * omega_ * h, rotate_cos, rotate_sin);
    double torque_sum = 0.0;
    for (int i = 0; i < sub_steps_; ++i) torque_sum += electrical_substep(rotate_cos, rotate_sin);
    bus_current_sum_ /= sub_steps_;
    mechanics(dt_s, torque_sum / sub_steps_);
  }
  if (motor_.kind != MotorKind::kDc) {
    // The angle the rotor really turned, from the exact start of the tick.
    double c = 1.0;
    double sn = 0.0;
    rotation(motor_.pole_pairs * (theta_ - theta_start), c, sn);
    sin_e_ = sin_start * c + cos_start * sn;
    cos_e_ = cos_start * c - sin_start * sn;
  }
  update_bus(dt_s);

  // Driver losses -> temperature above ambient (first order).
  double losses = board_.quiescent_power_w;
  if (latched_.bridge_enabled) {
    double abs_sum = 0.0;
    double square_sum = 0.0;
    if (motor_.kind == MotorKind::kDc) {
      abs_sum = 2.0 * std::fabs(iq_);
      square_sum = 2.0 * iq_ * iq_;
    } else {
      square_sum = 1.5 * (id_ * id_ + iq_ * iq_);
      abs_sum = 2.0 * std::sqrt(id_ * id_ + iq_ * iq_);  // about the sum of |phase currents|
    }
    losses += square_sum * board_.switch_on_resistance_ohm +
              board_.switching_energy_per_volt_amp * bus_voltage_ * abs_sum * latched_.pwm_frequency_hz;
  }
  const double steady = losses * board_.thermal_resistance_k_per_w;
  temperature_rise_ = steady + (temperature_rise_ - steady) * thermal_decay_;

  // Holding brake: the coil current follows the connector duty; the brake opens above the
  // pull-in level and closes again below the drop-out level.
  if (motor_.brake.present) {
    const double duty = latched_.brake_duty_percent;
    brake_coil_ += (duty - brake_coil_) * (1.0 - brake_decay_);
    if (brake_coil_ >= motor_.brake.pull_in_duty_percent) brake_released_ = true;
    if (brake_coil_ < motor_.brake.drop_out_duty_percent) brake_released_ = false;
  }

  latched_ = drive;
  ++ticks_;
  // The rotated sin/cos drift by rounding only: an exact one every millisecond is plenty.
  if (ticks_ % 20 == 0) sync_electrical_angle();
}



// The currents over one whole tick, exactly, for the voltage held in the stationary frame and the
// rotor turning at the tick's initial speed by phi (cos, sin: rotate_cos, rotate_sin). With
// i = id + j iq, v0 the dq voltage at the tick's start, a = R / L, w = p omega:
//   L di/dt = v0 exp(-j w t) - (R + j w L) i - j w lambda,
// whose solution, with u = v0 / R, ic = -j w lambda / (L (a + j w)) and A = i(0) - u - ic, is
//   i(t) = A exp(-(a + j w) t) + u exp(-j w t) + ic.
// Sets the currents at the tick's end, adds the tick's mean inverter current to the bus sum and
// returns the mean torque (Ld = Lq: torque per amp of iq times the mean iq).
double Tmcm1636Plant::electrical_exact_step(double rotate_cos, double rotate_sin, double turned_rad) {
  const double volts = bus_voltage_;  // held over the tick (update_bus)
  const double decay = tick_decay_;
  const double mean_decay = tick_mean_decay_;
  if (!latched_.bridge_enabled) {
    id_ = 0.0;
    iq_ = 0.0;
    return 0.0;
  }
  if (motor_.kind == MotorKind::kDc) {
    const double final_amps = (duty_dc_ * volts - motor_.torque_constant_nm_per_a * omega_) * inverse_resistance_;
    const double mean_amps = final_amps + (iq_ - final_amps) * mean_decay;
    bus_current_sum_ += duty_dc_ * mean_amps;
    iq_ = final_amps + (iq_ - final_amps) * decay;
    id_ = 0.0;
    return motor_.torque_constant_nm_per_a * mean_amps;
  }
  const double c = cos_e_;
  const double s = sin_e_;
  const double v_alpha = duty_alpha_ * volts;
  const double v_beta = duty_beta_ * volts;
  const double ud = (v_alpha * c + v_beta * s) * inverse_resistance_;
  const double uq = (-v_alpha * s + v_beta * c) * inverse_resistance_;
  const double omega_e = motor_.pole_pairs * omega_;
  const double k = omega_e * motor_.flux_linkage_wb / (motor_.inductance_q_h * (rate_ * rate_ + omega_e * omega_e));
  const double icd = -omega_e * k;
  const double icq = -rate_ * k;
  const double ad = id_ - ud - icd;
  const double aq = iq_ - uq - icq;
  // End of the tick: (decay A + u) exp(-j phi) + ic.
  const double wd = decay * ad + ud;
  const double wq = decay * aq + uq;
  // Mean over the tick in the stationary frame, exp(j theta0) (A mean_decay + u + ic g(phi)),
  // for the inverter current 1.5 (duty_alpha i_alpha + duty_beta i_beta).
  double gr = 1.0;
  double gi = 0.0;
  rotation_mean(turned_rad, rotate_cos, rotate_sin, gr, gi);
  const double md = ad * mean_decay + ud + icd * gr - icq * gi;
  const double mq = aq * mean_decay + uq + icd * gi + icq * gr;
  bus_current_sum_ += 1.5 * (duty_alpha_ * (md * c - mq * s) + duty_beta_ * (md * s + mq * c));
  // Mean iq in the dq frame: Im[A (1 - decay exp(-j phi)) / ((a + j w) dt) + u conj(g(phi)) + ic].
  const double sigma = tick_rate_dt_;
  const double nr = 1.0 - decay * rotate_cos;
  const double ni = decay * rotate_sin;
  const double inverse_norm = 1.0 / (sigma * sigma + turned_rad * turned_rad);
  const double qr = (nr * sigma + ni * turned_rad) * inverse_norm;
  const double qi = (ni * sigma - nr * turned_rad) * inverse_norm;
  const double mean_iq = ad * qi + aq * qr + uq * gr - ud * gi + icq;
  id_ = wd * rotate_cos + wq * rotate_sin + icd;
  iq_ = -wd * rotate_sin + wq * rotate_cos + icq;
  return torque_per_iq_ * mean_iq;
}

// One electrical sub-step: the exact exponential update of the RL circuits with the back-EMF and
// the cross-coupling held, the electrical angle rotated by (rotate_cos, rotate_sin) after it.
// Returns the torque at its end and adds the inverter's bus current to the tick's sum.
double Tmcm1636Plant::electrical_substep(double rotate_cos, double rotate_sin) {
  const double volts = bus_voltage_;  // held over the tick (update_bus)
  const bool on = latched_.bridge_enabled;
  if (motor_.kind == MotorKind::kDc) {
    if (on) {
      bus_current_sum_ += duty_dc_ * iq_;
      iq_ = decay_q_ * iq_ + (1.0 - decay_q_) * (duty_dc_ * volts - motor_.torque_constant_nm_per_a * omega_) *
                                 inverse_resistance_;
    } else {
      iq_ = 0.0;
    }
    id_ = 0.0;
    return motor_.torque_constant_nm_per_a * iq_;
  }
  const double s = sin_e_;
  const double c = cos_e_;
  if (on) {
    // Star point voltages from the duties (the common mode drops out), and the bus current
    // sum(duty_k * i_k) written in alpha/beta: 1.5 (duty_alpha i_alpha + duty_beta i_beta).
    const double v_alpha = duty_alpha_ * volts;
    const double v_beta = duty_beta_ * volts;
    const double vd = v_alpha * c + v_beta * s;
    const double vq = -v_alpha * s + v_beta * c;
    const double omega_e = motor_.pole_pairs * omega_;
    const double i_alpha = id_ * c - iq_ * s;
    const double i_beta = id_ * s + iq_ * c;
    bus_current_sum_ += 1.5 * (duty_alpha_ * i_alpha + duty_beta_ * i_beta);
    const double new_id =
        decay_d_ * id_ + (1.0 - decay_d_) * (vd + omega_e * motor_.inductance_q_h * iq_) * inverse_resistance_;
    const double new_iq =
        decay_q_ * iq_ + (1.0 - decay_q_) *
                             (vq - omega_e * motor_.inductance_d_h * id_ - omega_e * motor_.flux_linkage_wb) *
                             inverse_resistance_;
    id_ = new_id;
    iq_ = new_iq;
  } else {
    // Open bridge: no current path (the freewheeling diodes conduct only when the back-EMF
    // exceeds the bus, which this model leaves out; docs/tmcm-1636-servo.md).
    id_ = 0.0;
    iq_ = 0.0;
  }
  sin_e_ = s * rotate_cos + c * rotate_sin;
  cos_e_ = c * rotate_cos - s * rotate_sin;
  return electromagnetic_torque_nm();
}

// Mechanics over one tick: J dw/dt = T - B w - (Coulomb friction + engaged brake) sign(w) - T_load,
// with the tick's mean electromagnetic torque.
void Tmcm1636Plant::mechanics(double dt_s, double torque) {
  const double driving = torque - load_torque_;
  const double static_friction =
      brake_released_ || !motor_.brake.present ? motor_.coulomb_friction_nm
                                               : motor_.coulomb_friction_nm + motor_.brake.holding_torque_nm;
  const double omega_before = omega_;
  if (blocked_) {
    omega_ = 0.0;
  } else if (omega_ == 0.0) {
    if (std::fabs(driving) > static_friction) {
      omega_ = dt_s * (driving - sign(driving) * static_friction) * inverse_inertia_;
    }
  } else {
    const double net = driving - motor_.viscous_friction_nm_s * omega_ - sign(omega_) * static_friction;
    const double next = omega_ + dt_s * net * inverse_inertia_;
    // Friction stops the rotor; whether it starts again is decided from standstill.
    omega_ = next * omega_ < 0.0 ? 0.0 : next;
  }
  theta_ += 0.5 * (omega_before + omega_) * dt_s;

  // N pulse: the counter latches its value at the index angle.
  if (motor_.abn.present && !encoder_fault_ && (theta_ >= index_forward_ || theta_ < index_backward_)) {
    const double crossing = theta_ >= index_forward_ ? index_forward_ : index_backward_;
    index_turn_ += theta_ >= index_forward_ ? 1 : -1;
    index_count_ = abn_count_at(crossing + 1e-12);
    ++index_events_;
    update_index_window();
  }
}

// The supply bus over one tick (its R C of tens of microseconds is solved exactly for the tick's
// mean inverter current): the source feeds through a diode (it cannot absorb regenerated energy
// unless regenerative), the inverter draws the mean of sum(duty_k i_k), the board its quiescent
// power, the chopper connects the brake resistor.
void Tmcm1636Plant::update_bus(double dt_s) {
  const double volts = bus_voltage_;
  double bus_current = bus_current_sum_;  // the tick's mean
  bus_current_sum_ = 0.0;
  if (volts > 5.0) bus_current += board_.quiescent_power_w / volts;
  const bool source_conducts = motor_.supply.regenerative || volts < source_voltage_;
  const bool chopper = latched_.brake_chopper_on;
  const double source_g = source_conducts ? source_conductance_ : 0.0;
  const double chopper_g = chopper ? chopper_conductance_ : 0.0;
  const int combination = (source_conducts ? 2 : 0) + (chopper ? 1 : 0);
  double next_volts = volts - bus_current * inverse_capacitance_ * dt_s;
  if (combination != 0) {
    const double settle = (source_g * source_voltage_ - bus_current) * inverse_conductance_[combination];
    next_volts = settle + (volts - settle) * bus_decay_[combination];
  }
  if (next_volts < 0.0) next_volts = 0.0;
  const double mean_volts = 0.5 * (volts + next_volts);
  supply_energy_j_ += source_g * (source_voltage_ - mean_volts) * source_voltage_ * dt_s;
  chopper_energy_j_ += chopper_g * mean_volts * mean_volts * dt_s;
  bus_voltage_ = next_volts;
}

}  // namespace motwin::sim
