#include "host/modules/tmcm1636/tmcm1636_startup_image.h"

#include <cmath>
#include <optional>

#include "core/canopen/storage.h"
#include "core/modules/tmcm1636/tmcm1636.h"
#include "core/modules/tmcm1636/tmcm1636_canopen.h"
#include "core/tmcl/nvm_layout.h"

namespace motwin::host {
namespace {

using modules::tmcm1636::Tmcm1636;
using sim::MotorDescription;
using sim::StartupSettings;

constexpr uint8_t kMotorTypeParameter = 14;

// Table 11's codes for the named values.
int32_t motor_type_of(sim::MotorKind kind) { return kind == sim::MotorKind::kDc ? 1 : 3; }  // AP 14
int32_t commutation_mode_of(sim::CommutationSensor sensor) {                                // AP 15
  switch (sensor) {
    case sim::CommutationSensor::kOpenLoop: return 1;
    case sim::CommutationSensor::kHall: return 2;
    case sim::CommutationSensor::kAbnEncoder: return 3;
    case sim::CommutationSensor::kAbsoluteEncoder: return 4;
  }
  return 0;
}
int32_t position_source_of(sim::PositionSensor sensor) {  // AP 25 (0 = the commutation sensor)
  return sensor == sim::PositionSensor::kAbsoluteEncoder ? 2 : 1;
}
int32_t encoder_init_mode_of(sim::EncoderAlignment alignment) {  // AP 102
  switch (alignment) {
    case sim::EncoderAlignment::kEstimateOffset: return 0;
    case sim::EncoderAlignment::kIndexPulse: return 1;
    case sim::EncoderAlignment::kHall: return 2;
  }
  return 1;
}

template <class T, class Code>
std::optional<int32_t> coded(const std::optional<T>& setting, Code code) {
  if (!setting) return std::nullopt;
  return code(*setting);
}

// A flag setting as the firmware's 0/1 parameter.
std::optional<int32_t> flag_value(const std::optional<bool>& setting) {
  return coded(setting, [](bool on) -> int32_t { return on ? 1 : 0; });
}

// One named start-up value: its key in the description, the axis parameter of table 11 it goes
// to, and its value there (none: not set, the factory default stays).
struct NamedValue {
  std::string_view key;
  uint8_t number;
  std::optional<int32_t> (*value)(const MotorDescription& motor, const StartupSettings& settings);
};

// In parameter-number order.
const NamedValue kNamedValues[] = {
    {"pole_pairs", 10,
     [](const MotorDescription& m, const StartupSettings&) -> std::optional<int32_t> { return m.pole_pairs; }},
    {"max_current_ma", 11, [](const MotorDescription&, const StartupSettings& s) { return s.max_current_ma; }},
    {"open_loop_current_ma", 12, [](const MotorDescription&, const StartupSettings& s) { return s.open_loop_current_ma; }},
    {"type", kMotorTypeParameter,
     [](const MotorDescription& m, const StartupSettings&) -> std::optional<int32_t> { return motor_type_of(m.kind); }},
    {"commutation", 15,
     [](const MotorDescription&, const StartupSettings& s) { return coded(s.commutation, commutation_mode_of); }},
    {"position_sensor", 25,
     [](const MotorDescription&, const StartupSettings& s) { return coded(s.position_sensor, position_source_of); }},
    {"current_p", 70, [](const MotorDescription&, const StartupSettings& s) { return s.current_p; }},
    {"current_i", 71, [](const MotorDescription&, const StartupSettings& s) { return s.current_i; }},
    {"velocity_p", 72, [](const MotorDescription&, const StartupSettings& s) { return s.velocity_p; }},
    {"velocity_i", 73, [](const MotorDescription&, const StartupSettings& s) { return s.velocity_i; }},
    {"position_p", 74, [](const MotorDescription&, const StartupSettings& s) { return s.position_p; }},
    {"hall_polarity_inverted", 90,
     [](const MotorDescription&, const StartupSettings& s) { return flag_value(s.hall_polarity_inverted); }},
    {"hall_direction_reversed", 91,
     [](const MotorDescription&, const StartupSettings& s) { return flag_value(s.hall_direction_reversed); }},
    {"hall_interpolation", 92,
     [](const MotorDescription&, const StartupSettings& s) { return flag_value(s.hall_interpolation); }},
    {"abn_encoder.counts_per_rev", 100,
     [](const MotorDescription& m, const StartupSettings&) -> std::optional<int32_t> {
       if (!m.abn.present) return std::nullopt;
       return m.abn.counts_per_rev;  // AP 100 counts per revolution: the encoder's resolution
     }},
    {"encoder_direction_reversed", 101,
     [](const MotorDescription&, const StartupSettings& s) { return flag_value(s.encoder_direction_reversed); }},
    {"encoder_alignment", 102,
     [](const MotorDescription&, const StartupSettings& s) { return coded(s.encoder_alignment, encoder_init_mode_of); }},
    {"brake_chopper_voltage_v", 141,
     [](const MotorDescription&, const StartupSettings& s) {
       // AP 141 is in 0.1 V.
       return coded(s.brake_chopper_voltage_v, [](double volt) { return static_cast<int32_t>(std::lround(volt * 10.0)); });
     }},
};

// The named start-up values that are set, in parameter-number order.
std::vector<Tmcm1636StartupParameter> named_parameters(const MotorDescription& motor) {
  std::vector<Tmcm1636StartupParameter> parameters;
  if (!motor.startup) return parameters;
  for (const NamedValue& named : kNamedValues) {
    if (const std::optional<int32_t> value = named.value(motor, *motor.startup)) {
      parameters.push_back({named.number, *value, named.key});
    }
  }
  return parameters;
}

}  // namespace

std::vector<Tmcm1636StartupParameter> tmcm1636_startup_parameters(const MotorDescription& motor) {
  std::vector<Tmcm1636StartupParameter> parameters = named_parameters(motor);
  for (const auto& [number, value] : motor.axis_parameters) parameters.push_back({number, value, "axis_parameters"});
  return parameters;
}

Result<void> check_tmcm1636_axis_parameter(int number, int64_t value) {
  const auto* row = number >= 0 && number <= 255 ? Tmcm1636::axis_parameters().find(static_cast<uint16_t>(number)) : nullptr;
  if (row == nullptr) return Error{"axis parameter " + std::to_string(number) + " does not exist"};
  if (!params::has(row->info.access, params::Access::kEeprom)) {
    return Error{"axis parameter " + std::to_string(number) + " is not stored in the EEPROM"};
  }
  if (value < row->info.min || value > row->info.max) {
    return Error{"axis parameter " + std::to_string(number) + " takes " + std::to_string(row->info.min) + " to " +
                 std::to_string(row->info.max) + ", got " + std::to_string(value)};
  }
  return {};
}

Result<sim::MotorChoice> resolve_tmcm1636_motor(std::string_view name_or_path) {
  Result<sim::MotorChoice> motor = sim::resolve_motor(name_or_path, check_tmcm1636_axis_parameter);
  if (!motor || !*motor) return motor;
  // The numbered ones were checked while parsing; the named ones are checked here.
  for (const Tmcm1636StartupParameter& parameter : named_parameters(**motor)) {
    if (const Result<void> usable = check_tmcm1636_axis_parameter(parameter.number, parameter.value); !usable) {
      return usable.error_with_context(std::string(name_or_path) + ": startup: " + std::string(parameter.source) +
                                       ": ");
    }
  }
  return motor;
}

void write_tmcm1636_startup_image(const MotorDescription& motor, uint8_t* image, size_t size) {
  if (size < Tmcm1636::kNvmLayout.total_size) return;
  for (const Tmcm1636StartupParameter& parameter : tmcm1636_startup_parameters(motor)) {
    if (!check_tmcm1636_axis_parameter(parameter.number, parameter.value)) continue;
    tmcl::put_le32(image + Tmcm1636::kNvmLayout.axis_parameter(0, parameter.number), parameter.value);
  }
}

void write_tmcm1636_canopen_startup_image(const MotorDescription& motor, uint8_t* image, size_t size) {
  using modules::tmcm1636::Tmcm1636Canopen;
  if (!canopen::StorageImage::valid(image, size)) return;
  size_t count = canopen::StorageImage::count(image);
  for (const Tmcm1636StartupParameter& parameter : tmcm1636_startup_parameters(motor)) {
    for (const modules::tmcm1636::AxisParameterObject& object : modules::tmcm1636::kAxisParameterObjects) {
      if (object.axis_parameter != parameter.number) continue;
      for (const auto& row : Tmcm1636Canopen::object_table()) {
        const canopen::EntryInfo& info = row.info;
        if (info.index != object.index || info.sub != object.sub) continue;
        if (parameter.value < info.min || parameter.value > info.max) break;
        if (canopen::StorageImage::size_for(count + 1) > size) return;
        // A later value of the same object (a numbered one over a named one) replaces the record.
        size_t slot = count;
        for (size_t i = 0; i < count; ++i) {
          const canopen::StorageRecord record = canopen::StorageImage::record(image, i);
          if (record.index == object.index && record.sub == object.sub) slot = i;
        }
        canopen::StorageImage::put_record(image, slot, {object.index, object.sub, static_cast<uint32_t>(parameter.value)});
        if (slot == count) canopen::StorageImage::set_count(image, ++count);
        break;
      }
    }
  }
}

bool tmcm1636_image_configures_motor(const uint8_t* image, size_t size) {
  if (size < Tmcm1636::kNvmLayout.total_size) return false;
  return tmcl::get_le32(image + Tmcm1636::kNvmLayout.axis_parameter(0, kMotorTypeParameter)) != 0;
}

}  // namespace motwin::host
