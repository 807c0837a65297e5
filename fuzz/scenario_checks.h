// The invariants of parsed scenario files (src/sim/scenario.*), shared by the targets that parse
// them (scenario_file, tmcm142_board): each event names a signal of the board's table in its
// canonical spelling, with a value the signal accepts, a time within kMaxScenarioTimeS and a line
// number inside the text; events are sorted by time, file order among equal times.
#pragma once

#include <cmath>
#include <cstddef>
#include <cstdint>
#include <span>
#include <string_view>
#include <vector>

#include "fuzz_support.h"
#include "sim/scenario.h"
#include "sim/signals.h"

namespace motwin::fuzz {

inline void check_scenario_events(const std::vector<sim::ScenarioEvent>& events, std::string_view text,
                                  std::span<const sim::SignalInfo> signals) {
  size_t lines = 1;
  for (char c : text) lines += c == '\n' ? 1 : 0;
  for (size_t i = 0; i < events.size(); ++i) {
    const sim::ScenarioEvent& event = events[i];
    const sim::SignalInfo* signal = sim::find_signal(signals, event.signal);
    FUZZ_CHECK(signal != nullptr && signal->name == event.signal, "event signal '%s'", event.signal.c_str());
    FUZZ_CHECK(std::isfinite(event.value) && sim::check_signal_value(*signal, event.value).ok(), "%s = %g",
               event.signal.c_str(), event.value);
    FUZZ_CHECK(event.time_us <= static_cast<uint64_t>(sim::kMaxScenarioTimeS * 1e6), "time %llu us",
               static_cast<unsigned long long>(event.time_us));
    FUZZ_CHECK(event.line >= 1 && event.line <= lines, "line %zu of %zu", event.line, lines);
    if (i > 0) {
      const sim::ScenarioEvent& previous = events[i - 1];
      FUZZ_CHECK(previous.time_us < event.time_us || (previous.time_us == event.time_us && previous.line < event.line),
                 "events %zu and %zu out of order", i - 1, i);
    }
  }
}

}  // namespace motwin::fuzz
