// `--set` and `--scenario` as `motwin serve` and `motwin run` take them: the levels of a module's
// inputs before power-up, and their changes over simulated time (sim/scenario.h), checked
// against the module's signals.
#pragma once

#include <optional>
#include <span>
#include <string>
#include <vector>

#include "host/module_descriptor.h"
#include "sim/scenario.h"
#include "sim/signals.h"
#include "types/result.h"

namespace motwin::cli {

struct ModuleInputs {
  std::vector<host::InitialInput> initial_inputs;           // --set NAME=VALUE, in the order given
  std::optional<std::vector<sim::ScenarioEvent>> scenario;  // --scenario FILE; nullopt without one
};

// An error names what was given: "--set GPI0=3: GPI0 takes 0 or 1 ...", or the scenario file
// and line ("inputs.scn:2: expected a time in seconds ...").
Result<ModuleInputs> read_module_inputs(std::span<const sim::SignalInfo> signals,
                                        const std::vector<std::string>& assignments, const std::string& scenario_path);

}  // namespace motwin::cli
