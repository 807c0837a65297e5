// Scenario files: input values over simulated time, so that a run with switches, supply dips
// or temperature ramps is repeatable bit for bit.
//
//   # comment (also after an event)
//   <time_s> <SIGNAL> <value>
//   0.5   GPI0     1
//   2.0   VSUPPLY  26.5
//
// Times are simulated seconds from start-up (not wall time). Events are applied in time order,
// and in file order among equal times, just before the first control tick that starts at or
// after their time.
#pragma once

#include <cstddef>
#include <cstdint>
#include <optional>
#include <span>
#include <string>
#include <string_view>
#include <vector>

#include "sim/signals.h"
#include "types/result.h"

namespace motwin::sim {

// Larger times are refused: they are typing mistakes, and they keep µs arithmetic far from overflow.
inline constexpr double kMaxScenarioTimeS = 1e9;

struct ScenarioEvent {
  uint64_t time_us;
  std::string signal;  // canonical name from the board's signal table
  double value;
  size_t line;         // 1-based line in the source, for diagnostics
};

// One event of `signal` (any case) set to `value` at `time_us`: the signal's canonical name, or
// what is wrong ("unknown signal ...", "VSUPPLY takes 0 to 100 (...)"). Scenario files, and the
// web console's World view setting a signal now (HostRuntime::set_input_now), check through it.
Result<ScenarioEvent> make_scenario_event(std::span<const SignalInfo> signals, std::string_view signal, double value,
                                          uint64_t time_us, size_t line = 0);

// Parses scenario text: the events sorted by time (stable), or "<source>:<line>: <what was
// expected>"; `source_name` names the file in error messages.
Result<std::vector<ScenarioEvent>> parse_scenario(std::string_view text, std::string_view source_name,
                                                  std::span<const SignalInfo> signals);
// Reads and parses a file; an unreadable file is an error naming the file and the reason.
Result<std::vector<ScenarioEvent>> load_scenario_file(const std::string& path, std::span<const SignalInfo> signals);

// Applies due events to a board as simulated time advances.
class ScenarioPlayer {
 public:
  ScenarioPlayer(std::vector<ScenarioEvent> events, SignalBoard& board);

  // Adds an event after those already applied and those of its time or earlier: an event at the
  // present time is the next to apply.
  void insert(ScenarioEvent event);
  // Applies every not yet applied event with time_us <= sim_time_us; returns how many.
  size_t apply_due(uint64_t sim_time_us);
  // Time of the next event not yet applied.
  std::optional<uint64_t> next_event_time_us() const;
  bool finished() const { return next_ == events_.size(); }
  size_t applied_count() const { return applied_before_ + next_; }

 private:
  std::vector<ScenarioEvent> events_;
  SignalBoard& board_;
  size_t next_ = 0;            // the next event of events_ to apply
  size_t applied_before_ = 0;  // applied events insert() dropped
};

}  // namespace motwin::sim
