#include "sim/stepper_switch_sources.h"

#include <limits>

namespace motwin::sim {
namespace {

constexpr double kInfinity = std::numeric_limits<double>::infinity();

// Which bound REF_x_AT sets: right and home switches are active beyond it, the left one below it.
constexpr bool kAtIsLowerBound[3] = {true, false, true};

}  // namespace

void StepperSwitchSources::set(size_t signal, double value) {
  if (signal < kRefRightAt) {
    Source& sw = sources_[signal - kRefRight];
    sw.by_position = false;  // a level set by name takes the switch back from the rotor position
    sw.level = value != 0;
  } else if (signal < kRefRightFrom) {
    const size_t which = signal - kRefRightAt;
    sources_[which] = kAtIsLowerBound[which] ? Source{true, value, kInfinity, false}
                                             : Source{true, -kInfinity, value, false};
  } else if (signal < kSignalCount) {
    Source& sw = sources_[(signal - kRefRightFrom) / 2];
    if (!sw.by_position) sw = Source{true, -kInfinity, kInfinity, false};
    if ((signal - kRefRightFrom) % 2 == 0) {
      sw.from_revolutions = value;
    } else {
      sw.to_revolutions = value;
    }
  }
}

std::optional<double> StepperSwitchSources::read(size_t signal, uint8_t sensed_switches) const {
  if (signal < kRefRightAt) return (sensed_switches >> (signal - kRefRight)) & 1u ? 1.0 : 0.0;
  if (signal >= kSignalCount) return std::nullopt;
  const bool at = signal < kRefRightFrom;
  const size_t which = at ? signal - kRefRightAt : (signal - kRefRightFrom) / 2;
  const Source& sw = sources_[which];
  const bool lower = at ? kAtIsLowerBound[which] : (signal - kRefRightFrom) % 2 == 0;
  const double bound = lower ? sw.from_revolutions : sw.to_revolutions;
  if (!sw.by_position || bound == kInfinity || bound == -kInfinity) return std::nullopt;
  return bound;
}

void StepperSwitchSources::configure(StepperSensorConfig& config) const {
  StepperSensorConfig::Switch* targets[3] = {&config.right, &config.left, &config.home};
  for (size_t i = 0; i < sources_.size(); ++i) {
    const Source& sw = sources_[i];
    // The sensors model takes +-1e300 as "no bound".
    const double from = sw.from_revolutions == -kInfinity ? -1e300 : sw.from_revolutions;
    const double to = sw.to_revolutions == kInfinity ? 1e300 : sw.to_revolutions;
    *targets[i] = StepperSensorConfig::Switch{sw.by_position, from, to, true};
  }
}

void StepperSwitchSources::add_levels(uint8_t& switches) const {
  for (size_t i = 0; i < sources_.size(); ++i) {
    if (!sources_[i].by_position && sources_[i].level) switches |= static_cast<uint8_t>(1u << i);
  }
}

void FreezableEncoder::apply(board::StepperFeedback& feedback) {
  if (fault_) {
    feedback.encoder_count = frozen_.encoder_count;
    feedback.encoder_index_events = frozen_.encoder_index_events;
    feedback.encoder_index_count = frozen_.encoder_index_count;
  } else {
    frozen_ = feedback;
  }
}

}  // namespace motwin::sim
