#include "sim/stepper_motor_selection.h"

#include <cmath>
#include <fstream>
#include <sstream>

#include <nlohmann/json.hpp>

namespace motwin::sim {
namespace {

using Json = nlohmann::json;

// The description's real-valued fields as a declarative table: JSON key, field and the physical
// range of a stepper motor (NEMA8 to NEMA42 with margin; docs/tmcm-142.md, Decisions). 0 is
// allowed only where the lower bound is 0 (a motor without cogging or friction).
struct NumberField {
  const char* key;
  double StepperMotorDescription::* field;
  double min;
  double max;
};

constexpr NumberField kNumberFields[] = {
    {"resistance_ohm", &StepperMotorDescription::resistance_ohm, 0.01, 1000.0},
    {"inductance_h", &StepperMotorDescription::inductance_h, 1e-6, 10.0},
    {"torque_constant_nm_per_a", &StepperMotorDescription::torque_constant_nm_per_a, 1e-3, 20.0},
    {"detent_torque_nm", &StepperMotorDescription::detent_torque_nm, 0.0, 10.0},
    {"rotor_inertia_kg_m2", &StepperMotorDescription::rotor_inertia_kg_m2, 1e-8, 1.0},
    {"friction_torque_nm", &StepperMotorDescription::friction_torque_nm, 0.0, 100.0},
    {"rated_current_a", &StepperMotorDescription::rated_current_a, 0.01, 20.0},
    {"viscous_friction_nm_s", &StepperMotorDescription::viscous_friction_nm_s, 0.0, 10.0},
};

std::string number_text(double value) {
  std::ostringstream text;
  text << value;
  return text.str();
}

// The plant integrates the rotor explicitly: a stiff, light rotor would diverge. Names the key
// that usually needs changing (the inertia) with the smallest value this motor allows.
Result<void> check_stability(const StepperMotorDescription& motor) {
  const double sub_step_s = StepperPlant::kBoardTickS / StepperPlant::kFinestSubSteps;
  if (StepperPlant::step_number(motor, sub_step_s) <= StepperPlant::kStableStepNumber) return {};
  return Error{"\"rotor_inertia_kg_m2\" must be at least " +
               number_text(StepperPlant::min_stable_inertia_kg_m2(motor, sub_step_s)) +
               " for this torque constant, detent torque, viscous friction and step count (the simulation's " +
               number_text(sub_step_s * 1e6) + " us steps would diverge; " +
               number_text(StepperPlant::kStabilityPeakCurrentA) + " A peak assumed)"};
}

std::string preset_list() {
  std::string names = "ideal";
  for (std::string_view name : stepper_motor_preset_names()) names += ", " + std::string(name);
  return names;
}

}  // namespace

std::vector<std::string_view> stepper_motor_preset_names() { return {"nema17", "nema23"}; }

std::optional<StepperMotorDescription> stepper_motor_preset(std::string_view name) {
  if (name == "nema17") return StepperMotorDescription::nema17();
  if (name == "nema23") return StepperMotorDescription::nema23();
  return std::nullopt;
}

Result<StepperMotorDescription> parse_stepper_motor_description(std::string_view json_text,
                                                                std::string_view source_name) {
  const std::string prefix = std::string(source_name) + ": ";
  const Json document = Json::parse(json_text.begin(), json_text.end(), nullptr, false, true);
  if (document.is_discarded() || !document.is_object()) return Error{prefix + "expected a JSON object"};
  std::string base = "nema23";
  if (auto it = document.find("base"); it != document.end()) {
    if (!it->is_string() || !stepper_motor_preset(it->get<std::string>())) {
      return Error{prefix + "\"base\" must be a preset name (nema17, nema23)"};
    }
    base = it->get<std::string>();
  }
  StepperMotorDescription motor = *stepper_motor_preset(base);
  motor.name = std::string(source_name);
  for (const auto& [key, value] : document.items()) {
    if (key == "base") continue;
    if (key == "name") {
      if (!value.is_string()) return Error{prefix + "\"name\" must be a string"};
      motor.name = value.get<std::string>();
      continue;
    }
    if (key == "full_steps_per_revolution") {
      // Whole electrical periods (4 full steps) per revolution.
      if (!value.is_number_integer() || value.get<int64_t>() < 4 || value.get<int64_t>() > 4000 ||
          value.get<int64_t>() % 4 != 0) {
        return Error{prefix + "\"full_steps_per_revolution\" must be a multiple of 4 from 4 to 4000"};
      }
      motor.full_steps_per_revolution = static_cast<int>(value.get<int64_t>());
      continue;
    }
    const NumberField* field = nullptr;
    for (const NumberField& candidate : kNumberFields) {
      if (key == candidate.key) field = &candidate;
    }
    if (field == nullptr) return Error{prefix + "unknown key \"" + key + "\""};
    const double number = value.is_number() ? value.get<double>() : -1.0;
    if (!std::isfinite(number) || number < field->min || number > field->max) {
      return Error{prefix + "\"" + key + "\" must be a number from " + number_text(field->min) + " to " +
                   number_text(field->max)};
    }
    motor.*(field->field) = number;
  }
  if (const Result<void> stable = check_stability(motor); !stable) return stable.error_with_context(prefix);
  return motor;
}

Result<StepperMotorChoice> resolve_stepper_motor(std::string_view name_or_path) {
  if (name_or_path.empty() || name_or_path == "ideal") return StepperMotorChoice{};
  if (std::optional<StepperMotorDescription> preset = stepper_motor_preset(name_or_path)) return preset;
  const std::string path(name_or_path);
  std::ifstream file(path);
  if (!file) {
    return Error{"unknown stepper motor \"" + path + "\" (expected " + preset_list() +
                 " or a .json stepper description)"};
  }
  std::ostringstream text;
  text << file.rdbuf();
  Result<StepperMotorDescription> described = parse_stepper_motor_description(text.str(), path);
  if (!described) return Error{described.error()};
  return StepperMotorChoice{std::move(*described)};
}

namespace {

std::string_view trimmed(std::string_view text) {
  while (!text.empty() && (text.front() == ' ' || text.front() == '\t')) text.remove_prefix(1);
  while (!text.empty() && (text.back() == ' ' || text.back() == '\t')) text.remove_suffix(1);
  return text;
}

}  // namespace

Result<std::vector<StepperMotorChoice>> resolve_stepper_motors(std::string_view list, size_t axis_count) {
  if (list.find(',') == std::string_view::npos) {
    // One motor for all axes, as before per-axis lists (also "" = ideal).
    Result<StepperMotorChoice> single = resolve_stepper_motor(trimmed(list));
    if (!single) return Error{single.error()};
    return std::vector<StepperMotorChoice>(axis_count, *single);
  }
  std::vector<std::string_view> items;
  for (size_t start = 0;;) {
    const size_t comma = list.find(',', start);
    items.push_back(trimmed(list.substr(start, comma == std::string_view::npos ? std::string_view::npos : comma - start)));
    if (comma == std::string_view::npos) break;
    start = comma + 1;
  }
  if (items.size() != axis_count) {
    return Error{"--motor \"" + std::string(list) + "\" names " + std::to_string(items.size()) + " motors for " +
                 std::to_string(axis_count) +
                 " axes (give one motor for all axes, or one per axis separated by commas)"};
  }
  std::vector<StepperMotorChoice> motors;
  for (size_t axis = 0; axis < items.size(); ++axis) {
    const std::string prefix = "motor of axis " + std::to_string(axis) + ": ";
    if (items[axis].empty()) {
      return Error{prefix + "empty name (expected " + preset_list() + " or a .json stepper description)"};
    }
    Result<StepperMotorChoice> choice = resolve_stepper_motor(items[axis]);
    if (!choice) return choice.error_with_context(prefix);
    motors.push_back(std::move(*choice));
  }
  return motors;
}

}  // namespace motwin::sim
