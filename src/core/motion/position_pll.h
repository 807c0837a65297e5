// Velocity from a quantised position (encoder counts, hall steps) by a second-order tracking
// loop, as servo firmwares do (ODrive's encoder estimator, moteus): the estimate follows the
// measured position with bandwidth w (rad/s), kp = 2w, ki = w^2, and its velocity is smooth
// between counts instead of jumping by one count per tick.
#pragma once

#include <cstdint>

namespace motwin::motion {

class PositionPll {
 public:
  void reset(int64_t position) {
    position_ = static_cast<double>(position);
    velocity_ = 0.0;
  }
  void update(int64_t measured, double dt_s, double bandwidth) {
    position_ += velocity_ * dt_s;
    const double error = static_cast<double>(measured) - position_;
    position_ += 2.0 * bandwidth * dt_s * error;
    velocity_ += bandwidth * bandwidth * dt_s * error;
  }
  double position() const { return position_; }
  double velocity() const { return velocity_; }  // position units per second

 private:
  double position_ = 0.0;
  double velocity_ = 0.0;
};

}  // namespace motwin::motion
