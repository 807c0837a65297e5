// The web console's World ops (docs/web-console.md, "Protocol" and "World view"): the signals of a
// module's simulated world, those a scenario file sets (switch levels and positions, load torque,
// supply voltage, an obstacle ...), read with "world" and set with "world_set", and each axis's
// shaft as the simulation has it. A signal is set the way a scenario event is applied
// (HostRuntime::set_input_now), so that the page does nothing a scenario file could not.
#pragma once

#include <functional>
#include <string_view>

#include <nlohmann/json.hpp>

#include "sim/signals.h"
#include "types/result.h"

namespace motwin::tools::web {

// The simulated world of one console target.
struct ConsoleWorld {
  const sim::SignalBoard* board = nullptr;  // nullptr: the target has no world to show
  // Sets an input now; empty where no scenario reaches the board (a node of a --node bus).
  std::function<Result<void>(std::string_view signal, double value)> set_input;
};

bool is_world_op(std::string_view op);

// Answers {"op":"world"} or {"op":"world_set"} for `world`, the world of module `module`: the
// reply without its id, or what is wrong with the request (then nothing changed).
Result<nlohmann::json> world_op(std::string_view op, const nlohmann::json& request, size_t module,
                                const ConsoleWorld& world, uint64_t sim_time_us);

}  // namespace motwin::tools::web
