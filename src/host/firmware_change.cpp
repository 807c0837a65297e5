#include "host/firmware_change.h"

#include <cmath>
#include <limits>

namespace motwin::host {
namespace {

using params::SharedConversion;

std::optional<int64_t> rounded(double value) {
  if (!std::isfinite(value) || std::fabs(value) > static_cast<double>(std::numeric_limits<int32_t>::max())) {
    return std::nullopt;
  }
  return std::llround(value);
}

// The object's value in the TMCL parameter's units.
std::optional<int64_t> to_tmcl(const params::SharedAxisSetting& row, int64_t object_value, const cia402::UnitScale& u) {
  switch (row.conversion) {
    case SharedConversion::kSame: return object_value;
    case SharedConversion::kVelocity: return rounded(u.velocity_pps(static_cast<double>(object_value)));
    case SharedConversion::kAcceleration: return rounded(u.acceleration_pps2(static_cast<double>(object_value)));
    case SharedConversion::kBit: return (static_cast<uint64_t>(object_value) & row.bit_mask) != 0 ? 1 : 0;
  }
  return std::nullopt;
}

// The TMCL value in the object's units; `current` is the object's value now (kBit keeps its other bits).
std::optional<int64_t> to_object(const params::SharedAxisSetting& row, int64_t tmcl_value, int64_t current,
                                 const cia402::UnitScale& u) {
  switch (row.conversion) {
    case SharedConversion::kSame: return tmcl_value;
    case SharedConversion::kVelocity: return rounded(static_cast<double>(tmcl_value) / u.pps_per_velocity_unit);
    case SharedConversion::kAcceleration:
      return rounded(static_cast<double>(tmcl_value) / u.pps2_per_acceleration_unit);
    case SharedConversion::kBit:
      if (tmcl_value != 0 && tmcl_value != 1) return std::nullopt;
      return tmcl_value != 0 ? (current | row.bit_mask) : (current & ~int64_t{row.bit_mask});
  }
  return std::nullopt;
}

bool read_object(canopen::ObjectDictionary& dictionary, uint16_t index, uint8_t sub, canopen::ObjectRef& ref,
                 int64_t& value) {
  if (dictionary.find(index, sub, ref) != canopen::SdoAbort::kNone || !canopen::is_numeric(ref.info->type)) {
    return false;
  }
  uint8_t bytes[8] = {};
  size_t length = 0;
  if (dictionary.read(ref, bytes, sizeof bytes, length) != canopen::SdoAbort::kNone) return false;
  value = canopen::decode_value(ref.info->type, bytes);
  return true;
}

}  // namespace

SharedSettingValues read_tmcl_settings(tmcl::TmclDevice& device, std::span<const params::SharedAxisSetting> rows,
                                       uint8_t motor_count) {
  SharedSettingValues values(rows, motor_count);
  for (size_t r = 0; r < rows.size(); ++r) {
    for (uint8_t motor = 0; motor < motor_count; ++motor) {
      int32_t value = 0;
      if (device.get_axis_parameter(rows[r].parameter, motor, value) == tmcl::Status::kOk) values.at(r, motor) = value;
    }
  }
  return values;
}

size_t write_tmcl_settings(tmcl::TmclDevice& device, const SharedSettingValues& values) {
  size_t written = 0;
  for (size_t r = 0; r < values.rows().size(); ++r) {
    const uint8_t parameter = values.rows()[r].parameter;
    for (uint8_t motor = 0; motor < values.axis_count(); ++motor) {
      const std::optional<int64_t>& value = values.at(r, motor);
      if (!value || *value < std::numeric_limits<int32_t>::min() || *value > std::numeric_limits<int32_t>::max()) {
        continue;
      }
      if (device.set_axis_parameter(parameter, motor, static_cast<int32_t>(*value)) != tmcl::Status::kOk) continue;
      if (device.store_axis_parameter(parameter, motor) == tmcl::Status::kOk) ++written;
    }
  }
  return written;
}

SharedSettingValues read_canopen_settings(canopen::ObjectDictionary& dictionary,
                                          std::span<const params::SharedAxisSetting> rows, uint8_t axis_count,
                                          const CanopenAxisUnits& units) {
  SharedSettingValues values(rows, axis_count);
  for (uint8_t axis = 0; axis < axis_count; ++axis) {
    const cia402::UnitScale u = units ? units(axis) : cia402::UnitScale{};
    for (size_t r = 0; r < rows.size(); ++r) {
      canopen::ObjectRef ref;
      int64_t object_value = 0;
      if (read_object(dictionary, rows[r].index_of(axis), rows[r].sub, ref, object_value)) {
        values.at(r, axis) = to_tmcl(rows[r], object_value, u);
      }
    }
  }
  return values;
}

size_t write_canopen_settings(canopen::ObjectDictionary& dictionary, const SharedSettingValues& values,
                              const CanopenAxisUnits& units) {
  size_t written = 0;
  for (uint8_t axis = 0; axis < values.axis_count(); ++axis) {
    const cia402::UnitScale u = units ? units(axis) : cia402::UnitScale{};
    for (size_t r = 0; r < values.rows().size(); ++r) {
      const params::SharedAxisSetting& row = values.rows()[r];
      const std::optional<int64_t>& value = values.at(r, axis);
      canopen::ObjectRef ref;
      int64_t current = 0;
      if (!value || !read_object(dictionary, row.index_of(axis), row.sub, ref, current)) continue;
      const std::optional<int64_t> object_value = to_object(row, *value, current, u);
      if (!object_value) continue;
      uint8_t bytes[8] = {};
      canopen::encode_value(ref.info->type, *object_value, bytes);
      // Out of the object's range: refused by the write (encode_value would wrap it first).
      if (canopen::check_range(*ref.info, *object_value) != canopen::SdoAbort::kNone) continue;
      if (dictionary.write(ref, bytes, canopen::type_size(ref.info->type)) == canopen::SdoAbort::kNone) ++written;
    }
  }
  return written;
}

}  // namespace motwin::host
