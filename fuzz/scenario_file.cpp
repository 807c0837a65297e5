// Scenario files (src/sim/scenario.*): any text against the TMCM-1636 board's signal table.
//
// Invariants: text that parses gives events sorted by time (file order among equal times), each
// naming a signal of the table in its canonical spelling, with a value the signal accepts, a time
// within kMaxScenarioTimeS and a line number inside the text; playing them on a simulated board
// applies every one. Text that does not parse names its line ("fuzz.scn:<line>: ...").
#include <cstddef>
#include <cstdint>
#include <string>
#include <string_view>

#include "fuzz_support.h"
#include "scenario_checks.h"
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
  fuzz::check_scenario_events(result, text, signals);
  const size_t count = result.events.size();
  sim::Tmcm1636SimIo io;
  sim::Tmcm1636SimBoard board(io);
  sim::ScenarioPlayer player(std::move(result.events), board);
  FUZZ_CHECK(player.apply_due(UINT64_MAX) == count && player.finished(), "not every event was applied");
  return 0;
}
