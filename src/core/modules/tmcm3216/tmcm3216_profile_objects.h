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
#include "core/cia402/profile_rows.h"
#include "core/modules/tmcm3216/tmcm3216_drive.h"
#include "core/modules/tmcm3216/tmcm3216_manufacturer_objects.h"

namespace motwin::modules::tmcm3216 {

// 67FF: profile 402, stepper motor (bit 18), multi device module (bit 23), generic PDO set.
inline constexpr uint32_t kSingleDeviceType = 0x0084'0192;

// The TMCM-3216's CiA-402 objects (manual chapters 5-10, tables 272-338), for the generic rows.
// 6081, 6083 and 6084 may be mapped; the manual's defaults of 6081, 6083, 6084 and 6085 are 0,
// which would make its own examples (6.2, 7.2) stand still: see docs/tmcm-3216-drive.md
// "Decisions".
inline constexpr cia402::ProfileRows kProfileRows{
    .axis_stride = kProfileAxisStride,
    .controlword = cia402::named("Controlword", true),
    .statusword = cia402::named("Statusword", true),
    .quick_stop_option = cia402::with_default("Quick stop option code", 2),
    .shutdown_option = cia402::with_default("Shutdown option code", 0),
    .disable_operation_option = cia402::with_default("Disable operation option code", 1),
    .halt_option = cia402::with_default("Halt option code", 1),
    .fault_reaction_option = cia402::with_default("Fault reaction option code", 2),
    .mode = cia402::named("Modes of operation", true),
    .mode_display = cia402::named("Modes of operation display", true),
    .position_demand = cia402::named("Position demand value", true),
    .position_actual_internal = cia402::named("Position actual internal value", true),
    .position_actual = cia402::named("Position actual value", true),
    .following_error_window = cia402::with_default("Following error window", 0),
    .position_window = cia402::with_default("Position window", 0xFFFF'FFFF),
    .position_window_time = cia402::with_default("Position window time", 0),
    .sensor_selection = cia402::with_default("Sensor selection code", -1),
    .velocity_demand = cia402::kAbsent,
    .velocity_actual = cia402::named("Velocity actual value", true),
    .target_torque = cia402::kAbsent,
    .max_torque = cia402::kAbsent,
    .target_position = cia402::named("Target position", true),
    .home_offset = cia402::with_default("Home offset", 0),
    .software_limit = cia402::named("Software position limit"),
    .software_limit_names = {"Software position limit", "Highest sub-index supported", "Minimum position limit",
                             "Maximum position limit", canopen::Access::kRo},
    .max_profile_velocity = cia402::kAbsent,
    .profile_velocity = cia402::with_default("Profile velocity", 51200, true),
    .end_velocity = cia402::with_default("End velocity", 0),
    .profile_acceleration = cia402::with_default("Profile acceleration", 51200, true),
    .profile_deceleration = cia402::with_default("Profile deceleration", 51200, true),
    .quick_stop_deceleration = cia402::with_default("Quick stop deceleration", 51200),
    .homing_method = cia402::with_default("Homing method", 0),
    .homing_speeds = cia402::named("Homing speeds"),
    .homing_speed_names = {"Homing speeds", "Highest sub-index supported", "Fast homing speed", "Slow homing speed",
                           canopen::Access::kRo},
    .homing_acceleration = cia402::with_default("Homing acceleration", 0),
    .position_offset = cia402::named("Position offset", true),
    .velocity_offset = cia402::named("Velocity offset", true),
    .torque_offset = cia402::kAbsent,
    .interpolation_period = cia402::with_default("Interpolation time period", 1),
    .interpolation_names = {"Interpolation time period", "Highest sub-index supported",
                            "Interpolation time period value", "Interpolation time index", canopen::Access::kRo},
    .interpolation_index_default = -3,
    .positioning_option = cia402::with_default("Positioning option code", 0),
    .target_velocity = cia402::named("Target velocity", true),
    .supported_modes = cia402::named("Supported drive modes"),
    .single_device_type = cia402::with_default("Single device type", kSingleDeviceType),
};

namespace profile_rows {

using canopen::Access;
using canopen::DataType;
using canopen::EntryBinding;
using canopen::EntryRow;
using canopen::SdoAbort;
using cia402::profile_rows::axis_row;
using cia402::profile_rows::reading;

// A binding to the Tmcm3216DriveObjects field `Member` (the drive's manufacturer part) of the row's axis.
template <class Owner, auto Member>
constexpr EntryBinding<Owner> manufacturer_field() {
  return canopen::field_binding<Owner,
                                [](Owner& d, uint8_t axis) -> auto& { return d.drive(axis).manufacturer.*Member; }>();
}

// A stored rw VAR of the manufacturer area (+ n x 0x200) bound to a Tmcm3216DriveObjects field.
template <class Owner, auto Member>
constexpr EntryRow<Owner> ramp_var(uint16_t index, std::string_view name, DataType type, int64_t max) {
  return axis_row(
      canopen::rows::var<Owner>(index, name, type, Access::kRw, 0, max, 0, manufacturer_field<Owner, Member>()),
      kManufacturerAxisStride, false, true);
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

// The profile area: the generic rows of cia402/profile_rows.h, with the stepper's 608F and the
// I/O's 60FD in between.
template <class Owner, class Table>
constexpr void add_profile_rows(Table& t) {
  using canopen::Access;
  using canopen::DataType;
  using canopen::ObjectCode;
  namespace r = canopen::rows;
  constexpr uint16_t kStride = kProfileAxisStride;
  cia402::add_profile_rows<Owner>(
      t, kProfileRows,
      [](Table& rows) {
        // 608F: sub 1 is the stepper's (it scales the encoder), sub 2 is 1.
        rows.add(r::per_axis(r::highest_sub<Owner>(0x608F, ObjectCode::kArray, "Position encoder resolution", 2),
                             kStride));
        rows.add(cia402::profile_rows::axis_row(
            r::row<Owner>(0x608F, 1, ObjectCode::kArray, "Position encoder resolution", "Encoder increments",
                          DataType::kUnsigned32, Access::kRw, 0, r::kI32Max, 1,
                          canopen::field_binding<Owner, [](Owner& d, uint8_t a) -> uint32_t& {
                            return d.stepper(a).objects.encoder_increments;
                          }>()),
            kStride, false, true));
        rows.add(r::per_axis(r::row<Owner>(0x608F, 2, ObjectCode::kArray, "Position encoder resolution",
                                           "Motor revolutions", DataType::kUnsigned32, Access::kRo, 1, 1, 1),
                             kStride));
      },
      [](Table& rows) { add_digital_inputs_row<Owner>(rows); });  // 60FD (the stepper's rows)
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
  t.add(reading<Owner>(0x208E, "Acceleration dimension index", kStride, kUnsigned8, 0, r::kU8Max,
                       [](Owner& d, uint8_t a) -> int64_t {
                         return d.drive(a).manufacturer.velocity_dimension == kVelocityDimensionInternal
                                    ? kAccelerationDimensionInternal
                                    : kAccelerationDimensionPps2;
                       },
                       false, kAccelerationDimensionPps2));
  t.add(reading<Owner>(0x2100, "Home offset display", kStride, kInteger32, r::kI32Min, r::kI32Max,
                       [](Owner& d, uint8_t a) -> int64_t { return d.drive(a).objects.home_offset; }, false));
}

}  // namespace motwin::modules::tmcm3216
