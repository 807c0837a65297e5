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

  // Applies every not yet applied event with time_us <= sim_time_us; returns how many.
  size_t apply_due(uint64_t sim_time_us);
  // Time of the next event not yet applied.
  std::optional<uint64_t> next_event_time_us() const;
  bool finished() const { return next_ == events_.size(); }
  size_t applied_count() const { return next_; }

 private:
  std::vector<ScenarioEvent> events_;
  SignalBoard& board_;
  size_t next_ = 0;
};

}  // namespace motwin::sim
