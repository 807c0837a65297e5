// Scenario files (src/sim/scenario.*): any text against the TMCM-1636 board's signal table.
//
// Invariants: text that parses gives events sorted by time (file order among equal times), each
// naming a signal of the table in its canonical spelling, with a value the signal accepts, a time
// within kMaxScenarioTimeS and a line number inside the text; playing them on a simulated board
// applies every one. Text that does not parse names its line ("fuzz.scn:<line>: ...").
#include <cmath>
#include <cstddef>
#include <cstdint>
#include <string>
#include <string_view>

#include "fuzz_support.h"
#include "sim/scenario.h"
#include "sim/tmcm1636_sim_board.h"
#include "sim/tmcm1636_sim_io.h"

extern "C" int LLVMFuzzerTestOneInput(const uint8_t* data, size_t size) {
  using namespace motwin;
  if (size > 64 * 1024) return 0;
  const std::string_view text(reinterpret_cast<const char*>(data), size);
  const auto signals = sim::Tmcm1636SimBoard::signal_table();
  sim::ScenarioParseResult result = sim::parse_scenario(text, "fuzz.scn", signals);
  if (!result.ok()) {
    FUZZ_CHECK(result.error.rfind("fuzz.scn:", 0) == 0, "error without its source: %s", result.error.c_str());
    return 0;
  }
  size_t lines = 1;
  for (char c : text) lines += c == '\n' ? 1 : 0;
  for (size_t i = 0; i < result.events.size(); ++i) {
    const sim::ScenarioEvent& event = result.events[i];
    const sim::SignalInfo* signal = sim::find_signal(signals, event.signal);
    FUZZ_CHECK(signal != nullptr && signal->name == event.signal, "event signal '%s'", event.signal.c_str());
    FUZZ_CHECK(std::isfinite(event.value) && sim::check_signal_value(*signal, event.value).empty(), "%s = %g",
               event.signal.c_str(), event.value);
    FUZZ_CHECK(event.time_us <= static_cast<uint64_t>(sim::kMaxScenarioTimeS * 1e6), "time %llu us",
               static_cast<unsigned long long>(event.time_us));
    FUZZ_CHECK(event.line >= 1 && event.line <= lines, "line %zu of %zu", event.line, lines);
    if (i > 0) {
      const sim::ScenarioEvent& previous = result.events[i - 1];
      FUZZ_CHECK(previous.time_us < event.time_us || (previous.time_us == event.time_us && previous.line < event.line),
                 "events %zu and %zu out of order", i - 1, i);
    }
  }
  const size_t count = result.events.size();
  sim::Tmcm1636SimIo io;
  sim::Tmcm1636SimBoard board(io);
  sim::ScenarioPlayer player(std::move(result.events), board);
  FUZZ_CHECK(player.apply_due(UINT64_MAX) == count && player.finished(), "not every event was applied");
  return 0;
}
