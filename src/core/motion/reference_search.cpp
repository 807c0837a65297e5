#include "core/motion/reference_search.h"

namespace motwin::motion {

ReferenceSearch::Command ReferenceSearch::start(int32_t mode, double fast_velocity, double slow_velocity) {
  mode_ = mode;
  fast_ = fast_velocity;
  slow_ = slow_velocity;
  travel_ = 0;
  const bool left_only = mode == 1 || mode == 4;
  phase_ = left_only ? Phase::kFastToLeft : Phase::kFastToRight;
  return velocity(left_only ? -fast_ : fast_, false);
}

ReferenceSearch::Command ReferenceSearch::step(const Inputs& in) {
  switch (phase_) {
    case Phase::kIdle:
      return Command{};
    case Phase::kFastToRight:
      if (!in.right_active) return Command{};
      phase_ = Phase::kSlowOffRight;
      return velocity(-slow_, true);
    case Phase::kSlowOffRight:
      if (in.right_active) return Command{};
      right_point_ = in.position;
      phase_ = Phase::kFastToLeft;
      return velocity(-fast_, false);
    case Phase::kFastToLeft:
      if (!in.left_active) return Command{};
      phase_ = Phase::kSlowOffLeft;
      return velocity(slow_, true);
    case Phase::kSlowOffLeft: {
      if (in.left_active) return Command{};
      // The left switching point seen from inside the travel range.
      left_entry_point_ = in.position;
      if (mode_ == 2 || mode_ == 3) {
        travel_ = static_cast<int32_t>(static_cast<uint32_t>(right_point_) - static_cast<uint32_t>(left_entry_point_));
      }
      if (mode_ == 3 || mode_ == 4) {
        phase_ = Phase::kSlowIntoLeftCam;
        return velocity(-slow_, true);
      }
      phase_ = Phase::kIdle;
      return Command{Action::kSetPositionAndStop, 0.0, 0};
    }
    case Phase::kSlowIntoLeftCam:
      if (!in.left_active) return Command{};
      phase_ = Phase::kSlowThroughLeftCam;
      return Command{};
    case Phase::kSlowThroughLeftCam: {
      if (in.left_active) return Command{};
      // Far switching point reached: the centre of the two points becomes 0.
      const int64_t far_point = in.position;
      const int64_t centre2 = far_point + left_entry_point_;  // twice the centre
      const int64_t offset = far_point - centre2 / 2;
      phase_ = Phase::kMoveToCentre;
      return Command{Action::kSetPositionAndMove, 0.0, static_cast<int32_t>(offset)};
    }
    case Phase::kMoveToCentre:
      if (!in.position_reached) return Command{};
      phase_ = Phase::kIdle;
      return Command{Action::kDone, 0.0, 0};
  }
  return Command{};
}

}  // namespace motwin::motion
