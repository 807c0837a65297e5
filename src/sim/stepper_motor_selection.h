// The stepper behind a stepper module's power stage, as `--motor` names it: "ideal" (the rotor
// follows the field exactly), a preset of sim/stepper_plant.h (nema17, nema23) or a JSON stepper
// description file (docs/tmcm-142.md, "Motor").
#pragma once

#include <optional>
#include <string>
#include <string_view>
#include <vector>

#include "sim/stepper_plant.h"

namespace motwin::sim {

// "nema17", "nema23".
std::vector<std::string_view> stepper_motor_preset_names();
std::optional<StepperMotorDescription> stepper_motor_preset(std::string_view name);

struct StepperMotorChoice {
  std::optional<StepperMotorDescription> motor;  // empty: the ideal motor (or an error)
  std::string error;                             // set when the name or file is unusable
};

// Keys as the fields of StepperMotorDescription (resistance_ohm, inductance_h, ...), each
// optional: a missing key keeps the value of "base" (a preset name, default nema23). Unknown
// keys and values that are not positive numbers are errors naming the file and the key.
StepperMotorChoice parse_stepper_motor_description(std::string_view json_text, std::string_view source_name);
// "" or "ideal": the ideal motor; a preset name; otherwise a file path.
StepperMotorChoice resolve_stepper_motor(std::string_view name_or_path);

}  // namespace motwin::sim
