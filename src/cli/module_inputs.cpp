#include "cli/module_inputs.h"

namespace motwin::cli {

Result<ModuleInputs> read_module_inputs(std::span<const sim::SignalInfo> signals,
                                        const std::vector<std::string>& assignments, const std::string& scenario_path) {
  ModuleInputs inputs;
  for (const std::string& text : assignments) {
    const Result<sim::SignalAssignment> assignment = sim::parse_signal_assignment(signals, text);
    if (!assignment) return assignment.error_with_context("--set " + text + ": ");
    inputs.initial_inputs.push_back(host::InitialInput{std::string(assignment->signal->name), assignment->value});
  }
  if (!scenario_path.empty()) {
    Result<std::vector<sim::ScenarioEvent>> events = sim::load_scenario_file(scenario_path, signals);
    if (!events) return Error{events.error()};
    inputs.scenario = std::move(*events);
  }
  return inputs;
}

}  // namespace motwin::cli
