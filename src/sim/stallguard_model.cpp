#include "sim/stallguard_model.h"

#include <cmath>

#include "sim/stepper_plant.h"

namespace motwin::sim {
namespace {

constexpr double kPi = 3.14159265358979323846;
constexpr double kTwoPi = 2.0 * kPi;
constexpr int kFullStepShift = 30;  // 2^30 of electrical angle per full step (board/stepper_drive.h)
constexpr double kCurrentPresentA = 1e-3;
constexpr double kPauseS = 0.02;
constexpr double kElectricalCircle = 4294967296.0;  // 2^32 per electrical revolution

uint16_t mean_of(const std::array<uint16_t, 4>& values, int count) {
  uint32_t sum = 0;
  for (int i = 0; i < count; ++i) sum += values[static_cast<size_t>(i)];
  return static_cast<uint16_t>((sum + static_cast<uint32_t>(count) / 2) / static_cast<uint32_t>(count));
}

}  // namespace

void StallGuardModel::reset() {
  started_ = false;
  recent_filled_ = 0;
  recent_next_ = 0;
  recent_direction_ = 0;
  start_window();
  sg2_count_ = 0;
  sg4_filled_ = 0;
  sg4_next_ = 0;
  sg2_result_ = 0;
  sg4_result_ = 0;
  last_load_fraction_ = 0.0;
  last_full_steps_per_s_ = 0.0;
}

void StallGuardModel::update(const StepperPlant& plant, const board::StepperDrive& drive,
                             const StallGuardSettings& settings, double dt_s) {
  double ia = plant.coil_a_current_a();
  double ib = plant.coil_b_current_a();
  const double magnitude_squared = ia * ia + ib * ib;
  const bool present = magnitude_squared > kCurrentPresentA * kCurrentPresentA;
  // The load angle δ = (the coil-current vector's angle, A the cosine, B the sine) - rotor, as
  // sin δ and cos δ from the plant's sin and cos of the rotor angle (no atan2 and sin per tick);
  // without current the vector's angle counts as 0.
  if (present) {
    const double inverse_magnitude = 1.0 / std::sqrt(magnitude_squared);
    ia *= inverse_magnitude;
    ib *= inverse_magnitude;
  } else {
    ia = 1.0;
    ib = 0.0;
  }
  const double s = plant.electrical_sin();
  const double c = plant.electrical_cos();
  const double sin_delta = ib * c - ia * s;
  const double cos_delta = ia * c + ib * s;
  update_with_load(drive, load_term(sin_delta, cos_delta), plant.electrical_angle_rad(), present, settings, dt_s);
}

bool StallGuardModel::standstill_settled() const {
  // A skipped tick of length dt would have lengthened still_s_ and compared still_s_ + dt with
  // kPauseS + dt / 2, false for any dt once still_s_ >= kPauseS; window_s_ stays as it is.
  return started_ && still_s_ >= kPauseS;
}

void StallGuardModel::update_ideal(const board::StepperDrive& drive, const StallGuardSettings& settings,
                                   double dt_s) {
  // The rotor is where the field is: its angle is the sequencer's (continuous once started).
  const double rotor = started_ ? static_cast<double>(field_position_ + static_cast<int32_t>(drive.electrical_angle - last_angle_)) *
                                      (kTwoPi / kElectricalCircle)
                                : static_cast<double>(drive.electrical_angle) * (kTwoPi / kElectricalCircle);
  update_with_load(drive, 0.0, rotor, drive.coil_a_ma != 0 || drive.coil_b_ma != 0, settings, dt_s);
}

void StallGuardModel::update_with_angles(const board::StepperDrive& drive, double load_angle_rad,
                                        double rotor_electrical_rad, bool current_present,
                                        const StallGuardSettings& settings, double dt_s) {
  const double delta = load_angle_rad - kTwoPi * std::nearbyint(load_angle_rad / kTwoPi);  // wrapped
  update_with_load(drive, load_term(std::sin(delta), std::cos(delta)), rotor_electrical_rad, current_present, settings,
                   dt_s);
}

// Past 90° the motor is beyond its torque limit (the torque falls again as the rotor slips back):
// the full available torque is used.
double StallGuardModel::load_term(double sin_delta, double cos_delta) {
  return cos_delta > 0.0 ? sin_delta : (sin_delta > 0.0 ? 1.0 : -1.0);
}

void StallGuardModel::update_with_load(const board::StepperDrive& drive, double load_term,
                                       double rotor_electrical_rad, bool current_present,
                                       const StallGuardSettings& settings, double dt_s) {
  if (!drive.enabled) {
    // Bridges off: nothing is measured; the driver's results read 0.
    const uint32_t count = measurements_;
    reset();
    measurements_ = count;
    return;
  }
  if (!started_) {
    started_ = true;
    last_angle_ = drive.electrical_angle;
    field_position_ = static_cast<int64_t>(drive.electrical_angle);
    last_boundary_ = field_position_ >> kFullStepShift;
    rotor_rad_ = rotor_electrical_rad;
    start_window();
    return;
  }
  const int32_t field_change = static_cast<int32_t>(drive.electrical_angle - last_angle_);
  field_position_ += field_change;
  last_angle_ = drive.electrical_angle;

  rotor_rad_ = rotor_electrical_rad;
  // A pause of the sequencer (standstill) counts only up to kPauseS: the first full step after
  // a standstill measures the motion, not the pause.
  still_s_ = field_change == 0 ? still_s_ + dt_s : 0.0;
  if (still_s_ < kPauseS + 0.5 * dt_s) window_s_ += dt_s;
  window_field_ += field_change;
  sum_sin_dt_ += load_term * dt_s;
  if (!current_present) no_current_ = true;

  constexpr int64_t kFullStep = int64_t{1} << kFullStepShift;
  if (field_position_ >= (last_boundary_ + 1) * kFullStep) {
    last_boundary_ = field_position_ >> kFullStepShift;  // floor
    complete_full_step(settings, 1);
    start_window();
  } else if (field_position_ <= (last_boundary_ - 1) * kFullStep) {
    last_boundary_ = -((-field_position_) >> kFullStepShift);  // ceil
    complete_full_step(settings, -1);
    start_window();
  }
}

void StallGuardModel::start_window() {
  window_s_ = 0.0;
  still_s_ = 0.0;
  sum_sin_dt_ = 0.0;
  no_current_ = false;
  window_field_ = 0;
  window_rotor_start_rad_ = rotor_rad_;  // where the last window ended
}

void StallGuardModel::complete_full_step(const StallGuardSettings& settings, int direction) {
  double load = window_s_ > 0.0 ? direction * sum_sin_dt_ / window_s_ : 0.0;
  // The rotor's turn against the field's over the window.
  if (direction != recent_direction_) {
    recent_direction_ = direction;
    recent_filled_ = 0;
    recent_next_ = 0;
  }
  recent_field_rad_[static_cast<size_t>(recent_next_)] = static_cast<double>(window_field_) * (kTwoPi / kElectricalCircle);
  recent_rotor_rad_[static_cast<size_t>(recent_next_)] = rotor_rad_ - window_rotor_start_rad_;
  recent_next_ = (recent_next_ + 1) & 3;
  if (recent_filled_ < 4) ++recent_filled_;
  double field_rad = 0.0;
  double rotor_rad = 0.0;
  for (int i = 0; i < recent_filled_; ++i) {
    field_rad += recent_field_rad_[static_cast<size_t>(i)];
    rotor_rad += recent_rotor_rad_[static_cast<size_t>(i)];
  }
  const double ratio = field_rad != 0.0 ? rotor_rad / field_rad : 0.0;
  const bool following = ratio >= 0.5 && ratio <= 1.5;
  if (no_current_ || !following) load = 1.0;
  load = load < 0.0 ? 0.0 : (load > 1.0 ? 1.0 : load);
  const double full_steps_per_s = window_s_ > 0.0 ? 1.0 / window_s_ : 0.0;
  const double fade = full_steps_per_s >= kFadeFullStepsPerS ? 1.0 : full_steps_per_s / kFadeFullStepsPerS;
  const double reserve = (1.0 - load) * fade;
  last_load_fraction_ = load;
  last_full_steps_per_s_ = full_steps_per_s;

  if (settings.stealth_chop) {
    // StallGuard4: every full step, optionally the mean of the last four.
    sg2_count_ = 0;  // a SpreadCycle filter group starts afresh after StealthChop
    const auto raw = static_cast<uint16_t>(std::lround(kStallGuard4Max * reserve));
    sg4_history_[static_cast<size_t>(sg4_next_)] = raw;
    sg4_next_ = (sg4_next_ + 1) & 3;
    if (sg4_filled_ < 4) ++sg4_filled_;
    sg4_result_ = settings.stallguard4_filter ? mean_of(sg4_history_, sg4_filled_) : raw;
    ++measurements_;
    return;
  }
  // StallGuard2: the SGT offset shifts the reading; 209D: one result per four full steps.
  sg4_filled_ = 0;
  sg4_next_ = 0;
  long value = std::lround(kStallGuard2Max * reserve) + long{kThresholdStep} * settings.stallguard2_threshold;
  value = value < 0 ? 0 : (value > kStallGuard2Max ? kStallGuard2Max : value);
  const auto raw = static_cast<uint16_t>(value);
  if (!settings.stallguard2_filter) {
    sg2_count_ = 0;
    sg2_result_ = raw;
    ++measurements_;
    return;
  }
  sg2_history_[static_cast<size_t>(sg2_count_)] = raw;
  if (++sg2_count_ == 4) {
    sg2_count_ = 0;
    sg2_result_ = mean_of(sg2_history_, 4);
    ++measurements_;
  }
}

}  // namespace motwin::sim
