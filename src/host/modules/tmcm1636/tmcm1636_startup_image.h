// The start-up image of a TMCM-1636 for a physical motor (docs/tmcm-1636-servo.md, "Which motor
// by default"): the host, which knows both sides, turns the motor description's start-up settings
// (named, in the motor's units: sim::StartupSettings) into the firmware's axis parameters and
// writes them into a fresh EEPROM image through the module's parameter table, after the factory
// defaults. The simulated motor knows neither the parameter numbers nor the image layout.
#pragma once

#include <cstddef>
#include <cstdint>
#include <string>
#include <string_view>
#include <utility>
#include <vector>

#include "sim/modules/tmcm1636/motor_description.h"
#include "types/result.h"

namespace motwin::host {

// One start-up value as an axis parameter of table 11, with what it came from (a key of the
// description: "max_current_ma", "pole_pairs", or "axis_parameters" for a numbered one).
struct Tmcm1636StartupParameter {
  uint8_t number = 0;
  int32_t value = 0;
  std::string_view source;
};

// The description's start-up values in the order they are written: the named settings with the
// motor's type, pole pairs and ABN resolution (in parameter-number order), then the parameters
// the file gives by number (which win where both name one).
std::vector<Tmcm1636StartupParameter> tmcm1636_startup_parameters(const sim::MotorDescription& motor);

// Success when the TMCM-1636 stores axis parameter `number` in its EEPROM (E) and takes `value`;
// else what is wrong ("axis parameter 42 is not stored in the EEPROM"). The
// sim::AxisParameterCheck of the module's description files.
Result<void> check_tmcm1636_axis_parameter(int number, int64_t value);

// sim::resolve_motor with every start-up value checked against the table: a description the
// module cannot start with is an error naming the file (`<file>: startup: <key>: <problem>`).
Result<sim::MotorChoice> resolve_tmcm1636_motor(std::string_view name_or_path);

// Writes the motor's start-up values into a TMCM-1636 EEPROM image that holds the factory
// defaults; a value the table refuses is skipped (resolve_tmcm1636_motor refuses such files).
void write_tmcm1636_startup_image(const sim::MotorDescription& motor, uint8_t* image, size_t size);

// The same for the CANopen firmware's image (an empty storage image): each value goes in as a stored
// record of the object bound to the same setting (modules::tmcm1636::kAxisParameterObjects); an
// axis parameter with no object, or a value the object refuses, is skipped.
void write_tmcm1636_canopen_startup_image(const sim::MotorDescription& motor, uint8_t* image, size_t size);

// Whether a TMCM-1636 image selects a motor (AP 14, motor type, is not 0).
bool tmcm1636_image_configures_motor(const uint8_t* image, size_t size);

}  // namespace motwin::host
