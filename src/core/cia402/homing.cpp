#include "core/cia402/homing.h"

namespace motwin::cia402 {
namespace {

// Difference a - b on the wrapping 32-bit position counter.
int32_t wrapped_difference(int32_t a, int32_t b) {
  return static_cast<int32_t>(static_cast<uint32_t>(a) - static_cast<uint32_t>(b));
}

uint32_t magnitude(int32_t value) {
  return value < 0 ? 0u - static_cast<uint32_t>(value) : static_cast<uint32_t>(value);
}

}  // namespace

// Table 296. The final direction is the one in which the switch is left: a switch that is
// active on the negative side of its edge (negative limit, "negative" home switch) is left
// towards positive, and the other way round. Index methods search on in that direction.
const Homing::MethodSpec* Homing::find_method(int8_t method) {
  static constexpr MethodSpec kMethods[] = {
      {0, Signal::kNone, +1, false},
      {1, Signal::kLeftLimit, +1, true},
      {2, Signal::kRightLimit, -1, true},
      {3, Signal::kHomeSwitch, -1, true},
      {5, Signal::kHomeSwitch, +1, true},
      {17, Signal::kLeftLimit, +1, false},
      {18, Signal::kRightLimit, -1, false},
      {19, Signal::kHomeSwitch, -1, false},
      {21, Signal::kHomeSwitch, +1, false},
      {33, Signal::kNone, -1, true},
      {34, Signal::kNone, +1, true},
      {35, Signal::kNone, +1, false},
  };
  for (const MethodSpec& spec : kMethods) {
    if (spec.method == method) return &spec;
  }
  return nullptr;
}

bool Homing::is_supported(int8_t method) { return find_method(method) != nullptr; }

const char* Homing::reason_name(Reason reason) {
  switch (reason) {
    case Reason::kNone: return "none";
    case Reason::kUnsupportedMethod: return "unsupported method";
    case Reason::kZeroSpeed: return "homing speed is 0";
    case Reason::kIndexUnavailable: return "no encoder index";
    case Reason::kLimitSwitch: return "limit switch hit";
    case Reason::kSwitchNotFound: return "switch not found";
    case Reason::kIndexNotFound: return "index pulse not found";
  }
  return "?";
}

void Homing::start(int8_t method, const HomingConfig& config) {
  method_ = method;
  spec_ = find_method(method);
  config_ = config;
  state_ = State::kActive;
  reason_ = Reason::kNone;
  phase_ = Phase::kBegin;
  reversed_ = false;
  motion_direction_ = 0;
  travel_usteps_ = 0;
  elapsed_us_ = 0;
}

HomingCommand Homing::stop() {
  if (state_ == State::kActive) {
    state_ = State::kInterrupted;
    phase_ = Phase::kIdle;
  }
  HomingCommand command;
  command.acceleration_pps2 = config_.acceleration_pps2;
  return command;
}

HomingCommand Homing::velocity(int32_t direction, int32_t speed_pps) const {
  HomingCommand command;
  command.kind = HomingCommand::Kind::kVelocity;
  command.velocity_pps = direction * speed_pps;
  command.acceleration_pps2 = config_.acceleration_pps2;
  return command;
}

HomingCommand Homing::fail(Reason reason) {
  state_ = State::kError;
  reason_ = reason;
  phase_ = Phase::kIdle;
  HomingCommand command;
  command.kind = HomingCommand::Kind::kError;
  command.acceleration_pps2 = config_.acceleration_pps2;
  return command;
}

bool Homing::signal_active(const HomingInputs& in) const {
  switch (spec_->signal) {
    case Signal::kLeftLimit: return in.left_limit;
    case Signal::kRightLimit: return in.right_limit;
    case Signal::kHomeSwitch: return in.home_switch;
    case Signal::kNone: return false;
  }
  return false;
}

bool Homing::other_limit_in(int32_t direction, const HomingInputs& in) const {
  if (direction > 0) return in.right_limit && spec_->signal != Signal::kRightLimit;
  return in.left_limit && spec_->signal != Signal::kLeftLimit;
}

HomingCommand Homing::begin(const HomingInputs& in) {
  if (spec_ == nullptr) return fail(Reason::kUnsupportedMethod);
  home_point_ = in.position_usteps;
  if (method_ == 0) {  // nothing to do: attained at once, the position is left alone
    state_ = State::kAttained;
    phase_ = Phase::kIdle;
    HomingCommand command;
    command.kind = HomingCommand::Kind::kDone;
    command.acceleration_pps2 = config_.acceleration_pps2;
    return command;
  }
  if (method_ == 35) {  // the current position is home: no motion, so no ramp to wait for
    state_ = State::kAttained;
    phase_ = Phase::kIdle;
    HomingCommand command;
    command.kind = HomingCommand::Kind::kDone;
    command.acceleration_pps2 = config_.acceleration_pps2;
    command.set_position = true;
    command.new_position = config_.home_offset_usteps;
    return command;
  }

  const bool switch_method = spec_->signal != Signal::kNone;
  if (config_.slow_speed_pps <= 0 || (switch_method && config_.fast_speed_pps <= 0)) {
    return fail(Reason::kZeroSpeed);
  }
  if (spec_->index && !in.index_available) return fail(Reason::kIndexUnavailable);

  const int32_t final_direction = spec_->final_direction;
  if (!switch_method) {  // 33, 34: the start point plays the edge
    edge_position_ = in.position_usteps;
    index_events_at_edge_ = in.index_events;
    phase_ = Phase::kIndexSearch;
    return velocity(final_direction, config_.slow_speed_pps);
  }
  if (signal_active(in)) {  // on the switch already: leave it slowly
    phase_ = Phase::kLeaveSlow;
    return velocity(final_direction, config_.slow_speed_pps);
  }
  phase_ = Phase::kSeekFast;
  return velocity(-final_direction, config_.fast_speed_pps);
}

HomingCommand Homing::found_edge(const HomingInputs& in) {
  edge_position_ = in.position_usteps;
  if (!spec_->index) return found_home(in.position_usteps);
  // An index pulse seen in this very tick counts if it lies beyond the edge.
  index_events_at_edge_ = previous_index_events_;
  phase_ = Phase::kIndexSearch;
  return search_index(in);
}

HomingCommand Homing::found_home(int32_t home_point) {
  home_point_ = home_point;
  phase_ = Phase::kMoveToHome;
  HomingCommand command;
  command.kind = HomingCommand::Kind::kPosition;
  command.velocity_pps = config_.slow_speed_pps;
  command.acceleration_pps2 = config_.acceleration_pps2;
  command.target_position_usteps = home_point;
  return command;
}

HomingCommand Homing::step(const HomingInputs& in, uint32_t dt_us) {
  if (state_ != State::kActive) {
    HomingCommand hold;
    hold.acceleration_pps2 = config_.acceleration_pps2;
    return hold;
  }
  elapsed_us_ += dt_us;

  HomingCommand command;
  if (phase_ == Phase::kBegin) {
    command = begin(in);
  } else {
    const int32_t delta = wrapped_difference(in.position_usteps, previous_position_);
    if (delta != 0) motion_direction_ = delta > 0 ? 1 : -1;
    travel_usteps_ += magnitude(delta);
    command = run_phase(in);
  }

  previous_signal_ = spec_ != nullptr && signal_active(in);
  previous_left_ = in.left_limit;
  previous_right_ = in.right_limit;
  previous_position_ = in.position_usteps;
  previous_index_events_ = in.index_events;
  return command;
}

HomingCommand Homing::run_phase(const HomingInputs& in) {
  const int32_t final_direction = spec_->final_direction;
  const bool signal = signal_active(in);

  if (phase_ == Phase::kMoveToHome) {
    if (in.target_reached && in.position_usteps == home_point_) {
      state_ = State::kAttained;
      phase_ = Phase::kIdle;
      HomingCommand done;
      done.kind = HomingCommand::Kind::kDone;
      done.acceleration_pps2 = config_.acceleration_pps2;
      done.set_position = true;
      done.new_position = config_.home_offset_usteps;
      return done;
    }
    return found_home(home_point_);
  }

  if (config_.search_limit_usteps != 0 && travel_usteps_ > config_.search_limit_usteps) {
    return fail(spec_->signal == Signal::kNone ? Reason::kIndexNotFound : Reason::kSwitchNotFound);
  }

  // The direction this phase drives in; a limit switch in that direction is handled by the
  // phase itself. One that becomes active behind the axis (it ran onto it while braking, or
  // the switches are swapped) is an error.
  const int32_t commanded = phase_ == Phase::kSeekFast ? -final_direction : final_direction;
  const bool left_rose = in.left_limit && !previous_left_ && spec_->signal != Signal::kLeftLimit;
  const bool right_rose = in.right_limit && !previous_right_ && spec_->signal != Signal::kRightLimit;
  if ((left_rose && commanded > 0) || (right_rose && commanded < 0)) return fail(Reason::kLimitSwitch);

  switch (phase_) {
    case Phase::kSeekFast:
      if (signal) {
        phase_ = Phase::kLeaveSlow;
        return velocity(final_direction, config_.slow_speed_pps);
      }
      if (other_limit_in(commanded, in)) {
        // "If the initial direction of movement leads away from the home switch, the drive
        // shall reverse on encountering the relevant limit" (8.1.7); a second limit means the
        // home switch is nowhere between them.
        if (spec_->signal != Signal::kHomeSwitch) return fail(Reason::kLimitSwitch);
        if (reversed_) return fail(Reason::kSwitchNotFound);
        reversed_ = true;
        phase_ = Phase::kReverseFast;
        return velocity(final_direction, config_.fast_speed_pps);
      }
      return velocity(commanded, config_.fast_speed_pps);

    case Phase::kReverseFast:
      // Coming from the far side, the switch is entered from the wrong end: run through it
      // and look for it again from the near side, so the edge is always found the same way.
      if (signal) phase_ = Phase::kPassFast;
      if (other_limit_in(final_direction, in)) return fail(Reason::kSwitchNotFound);
      return velocity(final_direction, config_.fast_speed_pps);

    case Phase::kPassFast:
      if (!signal) {
        phase_ = Phase::kSeekFast;
        return velocity(-final_direction, config_.fast_speed_pps);
      }
      if (other_limit_in(final_direction, in)) return fail(Reason::kSwitchNotFound);
      return velocity(final_direction, config_.fast_speed_pps);

    case Phase::kLeaveSlow:
      // Released while moving in the final direction: the edge. (Released while still braking
      // the other way means the axis ran through a narrow switch; it comes back.)
      if (previous_signal_ && !signal && motion_direction_ == final_direction) return found_edge(in);
      if (other_limit_in(final_direction, in)) return fail(Reason::kLimitSwitch);
      return velocity(final_direction, config_.slow_speed_pps);

    case Phase::kIndexSearch:
      return search_index(in);

    case Phase::kIdle:
    case Phase::kBegin:
    case Phase::kMoveToHome:
      break;
  }
  HomingCommand hold;
  hold.acceleration_pps2 = config_.acceleration_pps2;
  return hold;
}

HomingCommand Homing::search_index(const HomingInputs& in) {
  const int32_t final_direction = spec_->final_direction;
  if (in.index_events != index_events_at_edge_) {
    const int32_t beyond = wrapped_difference(in.index_position_usteps, edge_position_) * final_direction;
    if (beyond >= 0) return found_home(in.index_position_usteps);
  }
  if (other_limit_in(final_direction, in)) return fail(Reason::kIndexNotFound);
  if (config_.index_search_limit_usteps != 0 &&
      magnitude(wrapped_difference(in.position_usteps, edge_position_)) > config_.index_search_limit_usteps) {
    return fail(Reason::kIndexNotFound);
  }
  return velocity(final_direction, config_.slow_speed_pps);
}

}  // namespace motwin::cia402
