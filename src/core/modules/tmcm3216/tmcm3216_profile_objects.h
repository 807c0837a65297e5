// The CiA-402 objects of the TMCM-3216's axes (manual chapters 5-10; axis n at index + n x
// 0x800) and the EightPoint ramp and unit objects of the manufacturer area (2010..2018, 208C,
// 208E, 2100; + n x 0x200), as rows the module's table adds (tmcm3216_objects.cpp).
//
// Templates over the module profile `Owner` (Tmcm3216) and its `Table`, like
// tmcm3216_manufacturer_objects.h. Owner provides:
//   Tmcm3216Drive& drive(uint8_t axis);
//   Tmcm3216Stepper& stepper(uint8_t axis);
// Configuration objects are stored with the motor's parameters (1010 sub 4 + n); the controlword,
// mode and set-points are not (they start at their defaults after a reset, as CiA-402 drives do).
#pragma once

#include <cstdint>
#include <limits>
#include <string_view>

#include "core/canopen/object_rows.h"
#include "core/cia402/homing.h"
#include "core/cia402/profile_objects.h"
#include "core/modules/tmcm3216/tmcm3216_drive.h"
#include "core/modules/tmcm3216/tmcm3216_manufacturer_objects.h"

namespace motwin::modules::tmcm3216 {

// 67FF: profile 402, stepper motor (bit 18), multi device module (bit 23), generic PDO set.
inline constexpr uint32_t kSingleDeviceType = 0x0084'0192;

namespace profile_rows {

using canopen::Access;
using canopen::DataType;
using canopen::EntryBinding;
using canopen::EntryRow;
using canopen::ObjectCode;
using canopen::SdoAbort;
using canopen::StorageGroup;

// A binding to the ProfileObjects field `Member` of the row's axis.
template <class Owner, auto Member>
constexpr EntryBinding<Owner> field() {
  return canopen::field_binding<Owner, [](Owner& d, uint8_t axis) -> auto& { return d.drive(axis).objects.*Member; }>();
}

// A binding to the Tmcm3216DriveObjects field `Member` (the drive's manufacturer part) of the row's axis.
template <class Owner, auto Member>
constexpr EntryBinding<Owner> manufacturer_field() {
  return canopen::field_binding<Owner,
                                [](Owner& d, uint8_t axis) -> auto& { return d.drive(axis).manufacturer.*Member; }>();
}

template <class Owner>
constexpr EntryRow<Owner> axis_row(EntryRow<Owner> r, uint16_t stride, bool mappable, bool stored) {
  r.info.axis_stride = stride;
  r.info.pdo_mappable = mappable;
  if (stored) r.info.storage = StorageGroup::kAxis;
  return r;
}

// A stored rw VAR of the profile area bound to a ProfileObjects field.
template <class Owner, auto Member>
constexpr EntryRow<Owner> config_var(uint16_t index, std::string_view name, DataType type, int64_t min, int64_t max,
                                     int64_t default_value, bool mappable = false,
                                     SdoAbort (*check)(Owner&, uint8_t, int64_t) = nullptr) {
  return axis_row(canopen::rows::var<Owner>(index, name, type, Access::kRw, min, max, default_value,
                                            canopen::rows::checked(field<Owner, Member>(), check)),
                  kProfileAxisStride, mappable, true);
}

// A stored rw VAR of the manufacturer area (+ n x 0x200) bound to a Tmcm3216DriveObjects field.
template <class Owner, auto Member>
constexpr EntryRow<Owner> ramp_var(uint16_t index, std::string_view name, DataType type, int64_t max) {
  return axis_row(
      canopen::rows::var<Owner>(index, name, type, Access::kRw, 0, max, 0, manufacturer_field<Owner, Member>()),
      kManufacturerAxisStride, false, true);
}

template <class Owner, auto Member>
constexpr EntryRow<Owner> config_entry(uint16_t index, uint8_t sub, ObjectCode code, std::string_view object,
                                       std::string_view entry, DataType type, int64_t min, int64_t max,
                                       int64_t default_value) {
  return axis_row(canopen::rows::row<Owner>(index, sub, code, object, entry, type, Access::kRw, min, max,
                                            default_value, field<Owner, Member>()),
                  kProfileAxisStride, false, true);
}

template <class Owner>
constexpr EntryRow<Owner> reading(uint16_t index, std::string_view name, DataType type, int64_t min, int64_t max,
                                  int64_t (*get)(Owner&, uint8_t), bool mappable = true,
                                  uint16_t stride = kProfileAxisStride, int64_t power_on_value = 0) {
  // The default is the value right after power-up (what the EDS lists).
  return axis_row(canopen::rows::var<Owner>(index, name, type, Access::kRo, min, max, power_on_value,
                                            canopen::rows::getter<Owner>(get)),
                  stride, mappable, false);
}

// A mappable set-point (607A, 60FF) the drive acts on when written: the value goes into field
// `Member`, then the drive's `Written` hook runs. Not stored: it is 0 after a reset.
template <class Owner, auto Member, auto Written>
constexpr EntryRow<Owner> set_point(uint16_t index, std::string_view name) {
  EntryBinding<Owner> b = field<Owner, Member>();
  b.set = [](Owner& d, uint8_t a, int64_t v) {
    d.drive(a).objects.*Member = static_cast<int32_t>(v);
    (d.drive(a).*Written)();
    return SdoAbort::kNone;
  };
  return axis_row(canopen::rows::var<Owner>(index, name, DataType::kInteger32, Access::kRw, canopen::rows::kI32Min,
                                            canopen::rows::kI32Max, 0, b),
                  kProfileAxisStride, true, false);
}

template <class Owner>
SdoAbort check_quick_stop_option(Owner&, uint8_t, int64_t v) {
  return cia402::valid_quick_stop_option(v) ? SdoAbort::kNone : SdoAbort::kInvalidValue;
}
template <class Owner>
SdoAbort check_mode(Owner&, uint8_t, int64_t v) {
  return cia402::supported_mode(v) ? SdoAbort::kNone : SdoAbort::kInvalidValue;
}
template <class Owner>
SdoAbort check_sensor_selection(Owner&, uint8_t, int64_t v) {
  return v == 0 || v == -1 ? SdoAbort::kNone : SdoAbort::kInvalidValue;
}
template <class Owner>
SdoAbort check_homing_method(Owner&, uint8_t, int64_t v) {
  return cia402::Homing::is_supported(static_cast<int8_t>(v)) ? SdoAbort::kNone : SdoAbort::kInvalidValue;
}
// 208C: 0 or 181, only in SWITCH ON DISABLED (manual 4.2.19).
template <class Owner>
SdoAbort check_velocity_dimension(Owner& d, uint8_t axis, int64_t v) {
  if (v != kVelocityDimensionInternal && v != kVelocityDimensionPps) return SdoAbort::kInvalidValue;
  const cia402::PdsState state = d.drive(axis).state();
  return state == cia402::PdsState::kSwitchOnDisabled || state == cia402::PdsState::kNotReadyToSwitchOn
             ? SdoAbort::kNone
             : SdoAbort::kDeviceState;
}

}  // namespace profile_rows

template <class Owner, class Table>
constexpr void add_profile_rows(Table& t) {
  using namespace profile_rows;
  using enum DataType;
  using O = cia402::ProfileObjects;
  namespace r = canopen::rows;
  constexpr uint16_t kStride = kProfileAxisStride;
  constexpr int64_t kI8Min = -128;
  constexpr int64_t kI8Max = 127;
  constexpr int64_t kI16Min = -32768;
  constexpr int64_t kI16Max = 32767;

  // 6040 / 6041: the PDS (not stored).
  {
    EntryBinding<Owner> b;
    b.get = [](Owner& d, uint8_t a) -> int64_t { return d.drive(a).pds().controlword(); };
    b.set = [](Owner& d, uint8_t a, int64_t v) {
      d.drive(a).write_controlword(static_cast<uint16_t>(v));
      return SdoAbort::kNone;
    };
    t.add(axis_row(r::var<Owner>(0x6040, "Controlword", kUnsigned16, Access::kRw, 0, r::kU16Max, 0, b), kStride,
                   true, false));
  }
  t.add(reading<Owner>(0x6041, "Statusword", kUnsigned16, 0, r::kU16Max,
                       [](Owner& d, uint8_t a) -> int64_t { return d.drive(a).statusword(); }, true, kStride,
                       cia402::kSwSwitchOnDisabled | cia402::kSwRemote));
  // Option codes 605A..605E.
  t.add(config_var<Owner, &O::quick_stop_option>(0x605A, "Quick stop option code", kInteger16, kI16Min, kI16Max, 2,
                                                 false, &check_quick_stop_option<Owner>));
  t.add(config_var<Owner, &O::shutdown_option>(0x605B, "Shutdown option code", kInteger16, 0, 0, 0));
  t.add(config_var<Owner, &O::disable_operation_option>(0x605C, "Disable operation option code", kInteger16, 1, 1, 1));
  t.add(config_var<Owner, &O::halt_option>(0x605D, "Halt option code", kInteger16, 1, 1, 1));
  t.add(config_var<Owner, &O::fault_reaction_option>(0x605E, "Fault reaction option code", kInteger16, 2, 2, 2));
  // 6060 / 6061: modes (6060 not stored: a reset starts without a mode).
  {
    EntryBinding<Owner> b = field<Owner, &O::mode>();
    b.check = &check_mode<Owner>;
    t.add(axis_row(r::var<Owner>(0x6060, "Modes of operation", kInteger8, Access::kRw, kI8Min, kI8Max, 0, b), kStride,
                   true, false));
  }
  t.add(reading<Owner>(0x6061, "Modes of operation display", kInteger8, kI8Min, kI8Max,
                       [](Owner& d, uint8_t a) -> int64_t { return d.drive(a).mode_display(); }));
  t.add(reading<Owner>(0x6062, "Position demand value", kInteger32, r::kI32Min, r::kI32Max,
                       [](Owner& d, uint8_t a) -> int64_t { return d.drive(a).position_demand(); }));
  t.add(reading<Owner>(0x6063, "Position actual internal value", kInteger32, r::kI32Min, r::kI32Max,
                       [](Owner& d, uint8_t a) -> int64_t { return d.drive(a).position_actual(); }));
  t.add(reading<Owner>(0x6064, "Position actual value", kInteger32, r::kI32Min, r::kI32Max,
                       [](Owner& d, uint8_t a) -> int64_t { return d.drive(a).position_actual(); }));
  t.add(config_var<Owner, &O::following_error_window>(0x6065, "Following error window", kUnsigned32, 0, r::kI32Max, 0));
  t.add(config_var<Owner, &O::position_window>(0x6067, "Position window", kUnsigned32, 0, r::kU32Max, r::kU32Max));
  t.add(config_var<Owner, &O::position_window_time_ms>(0x6068, "Position window time", kUnsigned16, 0, r::kU16Max, 0));
  t.add(config_var<Owner, &O::sensor_selection>(0x606A, "Sensor selection code", kInteger16, kI16Min, kI16Max, -1,
                                                false, &check_sensor_selection<Owner>));
  t.add(reading<Owner>(0x606C, "Velocity actual value", kInteger32, r::kI32Min, r::kI32Max,
                       [](Owner& d, uint8_t a) -> int64_t { return d.drive(a).velocity_actual_value(); }));
  t.add(set_point<Owner, &O::target_position, &Tmcm3216Drive::target_position_written>(0x607A, "Target position"));
  t.add(config_var<Owner, &O::home_offset>(0x607C, "Home offset", kInteger32, r::kI32Min, r::kI32Max, 0));
  t.add(r::per_axis(r::highest_sub<Owner>(0x607D, ObjectCode::kArray, "Software position limit", 2), kStride));
  t.add(config_entry<Owner, &O::software_limit_min>(0x607D, 1, ObjectCode::kArray, "Software position limit",
                                                    "Minimum position limit", kInteger32, r::kI32Min, r::kI32Max,
                                                    r::kI32Min));
  t.add(config_entry<Owner, &O::software_limit_max>(0x607D, 2, ObjectCode::kArray, "Software position limit",
                                                    "Maximum position limit", kInteger32, r::kI32Min, r::kI32Max,
                                                    r::kI32Max));
  t.add(config_var<Owner, &O::profile_velocity>(0x6081, "Profile velocity", kUnsigned32, 0, r::kU32Max, 51200, true));
  t.add(config_var<Owner, &O::end_velocity>(0x6082, "End velocity", kUnsigned32, 0, r::kU32Max, 0));
  t.add(config_var<Owner, &O::profile_acceleration>(0x6083, "Profile acceleration", kUnsigned32, 0, r::kU32Max, 51200,
                                                    true));
  t.add(config_var<Owner, &O::profile_deceleration>(0x6084, "Profile deceleration", kUnsigned32, 0, r::kU32Max, 51200,
                                                    true));
  t.add(config_var<Owner, &O::quick_stop_deceleration>(0x6085, "Quick stop deceleration", kUnsigned32, 0, r::kU32Max,
                                                       51200));
  // 608F: sub 1 is the stepper's (it scales the encoder), sub 2 is 1.
  t.add(r::per_axis(r::highest_sub<Owner>(0x608F, ObjectCode::kArray, "Position encoder resolution", 2), kStride));
  t.add(axis_row(r::row<Owner>(0x608F, 1, ObjectCode::kArray, "Position encoder resolution", "Encoder increments",
                               kUnsigned32, Access::kRw, 0, r::kI32Max, 1,
                               canopen::field_binding<Owner, [](Owner& d, uint8_t a) -> uint32_t& {
                                 return d.stepper(a).objects.encoder_increments;
                               }>()),
                 kStride, false, true));
  t.add(r::per_axis(r::row<Owner>(0x608F, 2, ObjectCode::kArray, "Position encoder resolution", "Motor revolutions",
                                  kUnsigned32, Access::kRo, 1, 1, 1),
                    kStride));
  t.add(config_var<Owner, &O::homing_method>(0x6098, "Homing method", kInteger8, kI8Min, kI8Max, 0, false,
                                             &check_homing_method<Owner>));
  t.add(r::per_axis(r::highest_sub<Owner>(0x6099, ObjectCode::kArray, "Homing speeds", 2), kStride));
  t.add(config_entry<Owner, &O::homing_speed_fast>(0x6099, 1, ObjectCode::kArray, "Homing speeds", "Fast homing speed",
                                                   kUnsigned32, 0, r::kU32Max, 0));
  t.add(config_entry<Owner, &O::homing_speed_slow>(0x6099, 2, ObjectCode::kArray, "Homing speeds", "Slow homing speed",
                                                   kUnsigned32, 0, r::kU32Max, 0));
  t.add(config_var<Owner, &O::homing_acceleration>(0x609A, "Homing acceleration", kUnsigned32, 0, r::kU32Max, 0));
  t.add(axis_row(r::var<Owner>(0x60B0, "Position offset", kInteger32, Access::kRw, r::kI32Min, r::kI32Max, 0,
                               field<Owner, &O::position_offset>()),
                 kStride, true, false));
  t.add(axis_row(r::var<Owner>(0x60B1, "Velocity offset", kInteger32, Access::kRw, r::kI32Min, r::kI32Max, 0,
                               field<Owner, &O::velocity_offset>()),
                 kStride, true, false));
  t.add(r::per_axis(r::highest_sub<Owner>(0x60C2, ObjectCode::kRecord, "Interpolation time period", 2), kStride));
  t.add(config_entry<Owner, &O::interpolation_period>(0x60C2, 1, ObjectCode::kRecord, "Interpolation time period",
                                                      "Interpolation time period value", kUnsigned8, 0, r::kU8Max, 1));
  t.add(config_entry<Owner, &O::interpolation_index>(0x60C2, 2, ObjectCode::kRecord, "Interpolation time period",
                                                     "Interpolation time index", kInteger8, -3, 3, -3));
  t.add(config_var<Owner, &O::positioning_option>(0x60F2, "Positioning option code", kUnsigned16, 0, 2, 0));
  add_digital_inputs_row<Owner>(t);  // 60FD (hstepper's rows)
  t.add(set_point<Owner, &O::target_velocity, &Tmcm3216Drive::target_velocity_written>(0x60FF, "Target velocity"));
  t.add(r::per_axis(r::var<Owner>(0x6502, "Supported drive modes", kUnsigned32, Access::kRo, 0, r::kU32Max,
                                  cia402::kSupportedDriveModes),
                    kStride));
  t.add(r::per_axis(r::var<Owner>(0x67FF, "Single device type", kUnsigned32, Access::kRo, 0, r::kU32Max,
                                  kSingleDeviceType),
                    kStride));
}

// 2010..2018 (EightPoint ramp), 208C/208E (units), 2100 (home offset display); + n x 0x200.
template <class Owner, class Table>
constexpr void add_ramp_rows(Table& t) {
  using namespace profile_rows;
  using enum DataType;
  using M = Tmcm3216DriveObjects;
  namespace r = canopen::rows;
  constexpr uint16_t kStride = kManufacturerAxisStride;
  constexpr int64_t kVelocityMax = 16777215;
  t.add(ramp_var<Owner, &M::start_velocity>(0x2010, "Profile start velocity", kUnsigned32, 268435455));
  t.add(ramp_var<Owner, &M::a1>(0x2011, "Profile A1", kUnsigned32, kVelocityMax));
  t.add(ramp_var<Owner, &M::v1>(0x2012, "Profile V1", kUnsigned32, kVelocityMax));
  t.add(ramp_var<Owner, &M::d1>(0x2013, "Profile D1", kUnsigned32, kVelocityMax));
  t.add(ramp_var<Owner, &M::ramp_wait_time>(0x2015, "Ramp wait time", kUnsigned16, r::kU16Max));
  t.add(ramp_var<Owner, &M::a2>(0x2016, "Profile A2", kUnsigned32, kVelocityMax));
  t.add(ramp_var<Owner, &M::v2>(0x2017, "Profile V2", kUnsigned32, kVelocityMax));
  t.add(ramp_var<Owner, &M::d2>(0x2018, "Profile D2", kUnsigned32, kVelocityMax));
  {
    EntryBinding<Owner> b = manufacturer_field<Owner, &M::velocity_dimension>();
    b.set = [](Owner& d, uint8_t a, int64_t v) {
      d.drive(a).manufacturer.velocity_dimension = static_cast<uint8_t>(v);
      d.stepper(a).objects.velocity_in_chip_units = v == kVelocityDimensionInternal;
      return SdoAbort::kNone;
    };
    b.check = &check_velocity_dimension<Owner>;
    t.add(axis_row(r::var<Owner>(0x208C, "Velocity dimension index", kUnsigned8, Access::kRw, 0, r::kU8Max,
                                 kVelocityDimensionPps, b),
                   kStride, false, true));
  }
  t.add(reading<Owner>(0x208E, "Acceleration dimension index", kUnsigned8, 0, r::kU8Max,
                       [](Owner& d, uint8_t a) -> int64_t {
                         return d.drive(a).manufacturer.velocity_dimension == kVelocityDimensionInternal
                                    ? kAccelerationDimensionInternal
                                    : kAccelerationDimensionPps2;
                       },
                       false, kStride, kAccelerationDimensionPps2));
  t.add(reading<Owner>(0x2100, "Home offset display", kInteger32, r::kI32Min, r::kI32Max,
                       [](Owner& d, uint8_t a) -> int64_t { return d.drive(a).objects.home_offset; }, false, kStride));
}

}  // namespace motwin::modules::tmcm3216
