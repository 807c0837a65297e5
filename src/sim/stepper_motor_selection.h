// The stepper behind a stepper module's power stage, as `--motor` names it: "ideal" (the rotor
// follows the field exactly), a preset of sim/stepper_plant.h (nema17, nema23) or a JSON stepper
// description file (docs/tmcm-142.md, "Motor"). A multi-axis module takes one such name for all
// axes or a comma-separated list, one per axis (docs/tmcm-3216-drive.md, "Signals").
#pragma once

#include <cstddef>
#include <optional>
#include <string>
#include <string_view>
#include <vector>

#include "sim/stepper_plant.h"
#include "types/result.h"

namespace motwin::sim {

// "nema17", "nema23".
std::vector<std::string_view> stepper_motor_preset_names();
std::optional<StepperMotorDescription> stepper_motor_preset(std::string_view name);

// The motor of one axis as `--motor` chose it; nullopt: the ideal motor.
using StepperMotorChoice = std::optional<StepperMotorDescription>;

// Keys as the fields of StepperMotorDescription (resistance_ohm, inductance_h, ...), each
// optional: a missing key keeps the value of "base" (a preset name, default nema23). Unknown
// keys and values that are not positive numbers are errors naming the file and the key.
Result<StepperMotorDescription> parse_stepper_motor_description(std::string_view json_text,
                                                                std::string_view source_name);
// "" or "ideal": the ideal motor; a preset name; otherwise a file path. An unknown name or an
// unusable file is an error.
Result<StepperMotorChoice> resolve_stepper_motor(std::string_view name_or_path);

// `--motor` of a module with `axis_count` axes, one choice per axis: one name (or file) for every
// axis, or a comma-separated list of exactly `axis_count` of them ("nema17,ideal,nema23"; spaces
// around an item are ignored). A wrong count, an empty item or an unusable item is an error naming
// the axis; nothing is resolved further then. No file is written either way.
Result<std::vector<StepperMotorChoice>> resolve_stepper_motors(std::string_view list, size_t axis_count);

}  // namespace motwin::sim
