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

struct StepperMotorChoices {
  std::vector<std::optional<StepperMotorDescription>> motors;  // one per axis; empty: the ideal motor
  std::string error;                                           // set when any item is unusable
};

// `--motor` of a module with `axis_count` axes: one name (or file) for every axis, or a
// comma-separated list of exactly `axis_count` of them ("nema17,ideal,nema23"; spaces around an
// item are ignored). A wrong count, an empty item or an unusable item is an error naming the axis;
// nothing is resolved further then. No file is written either way.
StepperMotorChoices resolve_stepper_motors(std::string_view list, size_t axis_count);

}  // namespace motwin::sim
