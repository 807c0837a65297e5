// Scenario files (src/sim/scenario.*): any text against a board's signal table, the table picked
// by byte 0 (mod 3: TMCM-1636; TMCM-142; TMCM-3216 with ENABLE and the AXIS<n>_ signals).
//
// Invariants: text that parses gives events sorted by time (file order among equal times), each
// naming a signal of the table in its canonical spelling, with a value the signal accepts, a time
// within kMaxScenarioTimeS and a line number inside the text; playing them on that module's
// simulated board applies every one. Text that does not parse names its line ("fuzz.scn:<line>:
// ...").
#include <cstddef>
#include <cstdint>
#include <span>
#include <string>
#include <string_view>

#include "fuzz_support.h"
#include "scenario_checks.h"
#include "sim/scenario.h"
#include "sim/signals.h"
#include "sim/modules/tmcm142/tmcm142_sim_board.h"
#include "sim/modules/tmcm142/tmcm142_sim_io.h"
#include "sim/modules/tmcm1636/tmcm1636_sim_board.h"
#include "sim/modules/tmcm1636/tmcm1636_sim_io.h"
#include "sim/modules/tmcm3216/tmcm3216_sim_board.h"

namespace {

using namespace motwin;

// Parses `text` against `signals`; the events that parse are played on the board `make_board` gives.
template <typename MakeBoard>
void parse_and_play(std::string_view text, std::span<const sim::SignalInfo> signals, MakeBoard make_board) {
  Result<std::vector<sim::ScenarioEvent>> result = sim::parse_scenario(text, "fuzz.scn", signals);
  if (!result.ok()) {
    FUZZ_CHECK(result.error().rfind("fuzz.scn:", 0) == 0, "error without its source: %s", result.error().c_str());
    return;
  }
  fuzz::check_scenario_events(*result, text, signals);
  const size_t count = result->size();
  make_board([&](sim::SignalBoard& board) {
    sim::ScenarioPlayer player(std::move(*result), board);
    FUZZ_CHECK(player.apply_due(UINT64_MAX) == count && player.finished(), "not every event was applied");
  });
}

}  // namespace

extern "C" int LLVMFuzzerTestOneInput(const uint8_t* data, size_t size) {
  if (size < 1 || size > 64 * 1024) return 0;
  const std::string_view text(reinterpret_cast<const char*>(data + 1), size - 1);
  switch (data[0] % 3) {
    case 0:
      parse_and_play(text, sim::Tmcm1636SimBoard::signal_table(), [](auto play) {
        sim::Tmcm1636SimIo io;
        sim::Tmcm1636SimBoard board(io);
        play(board);
      });
      break;
    case 1:
      parse_and_play(text, sim::Tmcm142SimBoard::signal_table(), [](auto play) {
        sim::Tmcm142SimIo io;
        sim::Tmcm142SimBoard board(io);
        play(board);
      });
      break;
    default:
      parse_and_play(text, sim::Tmcm3216SimBoard::signal_table(), [](auto play) {
        sim::Tmcm3216SimBoard board;
        play(board);
      });
      break;
  }
  return 0;
}
