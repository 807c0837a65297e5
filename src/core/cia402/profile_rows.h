// The CiA-402 objects of a drive's axes (6040..67FF) as rows a module's table adds, bound to the
// cia402::AxisDrive of each axis: one builder for every CANopen drive. The module's ProfileRows
// say which objects it has, how its manual or EDS names them, their defaults (the manuals differ:
// the TMCM-3216's 6081 is 51200 µsteps/s, the TMCM-1636's 0 rpm) and which may be mapped; the
// behaviour behind them is the drive's. Objects only one module has (608F, 60FD, 6074, 6077, the
// manufacturer area) are the module's rows.
//
// Templates over the module profile `Owner` and its `Table`. Owner provides:
//   cia402::AxisDrive<Part>& drive(uint8_t axis);
// Configuration objects are stored with the axis' parameters (StorageGroup::kAxis); the
// controlword, the mode and the set-points are not (they start at their defaults after a reset,
// as CiA-402 drives do).
#pragma once

#include <cstdint>
#include <string_view>
#include <type_traits>
#include <utility>

#include "core/canopen/object_rows.h"
#include "core/cia402/axis_drive.h"
#include "core/cia402/homing.h"
#include "core/cia402/power_drive_system.h"
#include "core/cia402/profile_objects.h"

namespace motwin::cia402 {

// One object as a module has it. `present` false: the module lacks it.
struct ProfileRow {
  bool present = false;
  std::string_view name;
  int64_t default_value = 0;
  bool mappable = false;
};

// An object the module does not have.
inline constexpr ProfileRow kAbsent{};
// A row that exists in every drive (no default to choose).
constexpr ProfileRow named(std::string_view name, bool mappable = false) { return {true, name, 0, mappable}; }
constexpr ProfileRow with_default(std::string_view name, int64_t default_value, bool mappable = false) {
  return {true, name, default_value, mappable};
}

// An ARRAY or RECORD's names: the object, sub 0, subs 1 and 2; and sub 0's access (ro or const).
struct ProfileArrayNames {
  std::string_view object;
  std::string_view count;
  std::string_view first;
  std::string_view second;
  canopen::Access count_access;
};

struct ProfileRows {
  uint16_t axis_stride = 0;  // 0x800 on a multi-axis module (axis n at index + n x 0x800), else 0
  ProfileRow controlword;                 // 6040
  ProfileRow statusword;                  // 6041
  ProfileRow quick_stop_option;           // 605A
  ProfileRow shutdown_option;             // 605B
  ProfileRow disable_operation_option;    // 605C
  ProfileRow halt_option;                 // 605D
  ProfileRow fault_reaction_option;       // 605E
  ProfileRow mode;                        // 6060
  ProfileRow mode_display;                // 6061
  ProfileRow position_demand;             // 6062
  ProfileRow position_actual_internal;    // 6063
  ProfileRow position_actual;             // 6064
  ProfileRow following_error_window;      // 6065
  ProfileRow position_window;             // 6067
  ProfileRow position_window_time;        // 6068
  ProfileRow sensor_selection;            // 606A
  ProfileRow velocity_demand;             // 606B
  ProfileRow velocity_actual;             // 606C
  ProfileRow target_torque;               // 6071
  ProfileRow max_torque;                  // 6072
  ProfileRow target_position;             // 607A
  ProfileRow home_offset;                 // 607C
  ProfileRow software_limit;              // 607D (the array; defaults: the int32 range)
  ProfileArrayNames software_limit_names;
  ProfileRow max_profile_velocity;        // 607F
  ProfileRow profile_velocity;            // 6081
  ProfileRow end_velocity;                // 6082
  ProfileRow profile_acceleration;        // 6083
  ProfileRow profile_deceleration;        // 6084
  ProfileRow quick_stop_deceleration;     // 6085
  ProfileRow homing_method;               // 6098
  ProfileRow homing_speeds;               // 6099 (the array; defaults 0)
  ProfileArrayNames homing_speed_names;
  ProfileRow homing_acceleration;         // 609A
  ProfileRow position_offset;             // 60B0
  ProfileRow velocity_offset;             // 60B1
  ProfileRow torque_offset;               // 60B2
  ProfileRow interpolation_period;        // 60C2 (the record; sub 1 default here, sub 2 below)
  ProfileArrayNames interpolation_names;
  int64_t interpolation_index_default = 0;
  ProfileRow positioning_option;          // 60F2
  ProfileRow target_velocity;             // 60FF
  ProfileRow supported_modes;             // 6502 (its value: the drive's Part::kSupportedModes)
  ProfileRow single_device_type;          // 67FF
};

namespace profile_rows {

using canopen::Access;
using canopen::DataType;
using canopen::EntryBinding;
using canopen::EntryRow;
using canopen::ObjectCode;
using canopen::SdoAbort;
using canopen::StorageGroup;

// The drive type of an Owner and its module part.
template <class Owner>
using DriveOf = std::remove_reference_t<decltype(std::declval<Owner&>().drive(uint8_t{0}))>;
template <class Owner>
using PartOf = typename DriveOf<Owner>::Part;

// A binding to the ProfileObjects field `Member` of the row's axis.
template <class Owner, auto Member>
constexpr EntryBinding<Owner> field() {
  return canopen::field_binding<Owner, [](Owner& d, uint8_t axis) -> auto& { return d.drive(axis).objects.*Member; }>();
}

template <class Owner>
constexpr EntryRow<Owner> axis_row(EntryRow<Owner> r, uint16_t stride, bool mappable, bool stored) {
  r.info.axis_stride = stride;
  r.info.pdo_mappable = mappable;
  if (stored) r.info.storage = StorageGroup::kAxis;
  return r;
}

// A stored rw VAR bound to a ProfileObjects field.
template <class Owner, auto Member>
constexpr EntryRow<Owner> config_var(uint16_t index, const ProfileRow& p, uint16_t stride, DataType type, int64_t min,
                                     int64_t max, SdoAbort (*check)(Owner&, uint8_t, int64_t) = nullptr) {
  return axis_row(canopen::rows::var<Owner>(index, p.name, type, Access::kRw, min, max, p.default_value,
                                            canopen::rows::checked(field<Owner, Member>(), check)),
                  stride, p.mappable, true);
}

template <class Owner, auto Member>
constexpr EntryRow<Owner> config_entry(uint16_t index, uint8_t sub, ObjectCode code, std::string_view object,
                                       std::string_view entry, uint16_t stride, DataType type, int64_t min,
                                       int64_t max, int64_t default_value) {
  return axis_row(canopen::rows::row<Owner>(index, sub, code, object, entry, type, Access::kRw, min, max,
                                            default_value, field<Owner, Member>()),
                  stride, false, true);
}

// A read-only live value. The default is the value right after power-up (what an EDS lists).
template <class Owner>
constexpr EntryRow<Owner> reading(uint16_t index, std::string_view name, uint16_t stride, DataType type, int64_t min,
                                  int64_t max, int64_t (*get)(Owner&, uint8_t), bool mappable,
                                  int64_t power_on_value = 0) {
  return axis_row(canopen::rows::var<Owner>(index, name, type, Access::kRo, min, max, power_on_value,
                                            canopen::rows::getter<Owner>(get)),
                  stride, mappable, false);
}

// A set-point the drive acts on when written (607A, 60FF, 6071): the value goes into field
// `Member`, then the drive's `Written` hook runs. Not stored: it is 0 after a reset.
template <class Owner, auto Member, auto Written>
constexpr EntryRow<Owner> set_point(uint16_t index, const ProfileRow& p, uint16_t stride, DataType type, int64_t min,
                                    int64_t max) {
  EntryBinding<Owner> b = field<Owner, Member>();
  b.set = [](Owner& d, uint8_t a, int64_t v) {
    auto& value = d.drive(a).objects.*Member;
    value = static_cast<std::remove_reference_t<decltype(value)>>(v);
    (d.drive(a).*Written)();
    return SdoAbort::kNone;
  };
  return axis_row(canopen::rows::var<Owner>(index, p.name, type, Access::kRw, min, max, 0, b), stride, p.mappable,
                  false);
}

// A live rw VAR that is not stored (60B0..60B2).
template <class Owner, auto Member>
constexpr EntryRow<Owner> offset_var(uint16_t index, const ProfileRow& p, uint16_t stride, DataType type, int64_t min,
                                     int64_t max) {
  return axis_row(canopen::rows::var<Owner>(index, p.name, type, Access::kRw, min, max, 0, field<Owner, Member>()),
                  stride, p.mappable, false);
}

// Sub 0 of 607D, 6099, 60C2: 2.
template <class Owner>
constexpr EntryRow<Owner> array_head(uint16_t index, ObjectCode code, const ProfileArrayNames& names, uint16_t stride) {
  EntryRow<Owner> head = canopen::rows::per_axis(canopen::rows::highest_sub<Owner>(index, code, names.object, 2, names.count), stride);
  head.info.access = names.count_access;
  return head;
}

template <class Owner>
SdoAbort check_quick_stop_option(Owner&, uint8_t, int64_t v) {
  return valid_quick_stop_option(v) ? SdoAbort::kNone : SdoAbort::kInvalidValue;
}
template <class Owner>
SdoAbort check_mode(Owner&, uint8_t, int64_t v) {
  return supported_mode(PartOf<Owner>::kSupportedModes, v) ? SdoAbort::kNone : SdoAbort::kInvalidValue;
}
template <class Owner>
SdoAbort check_sensor_selection(Owner&, uint8_t, int64_t v) {
  return v == 0 || v == -1 ? SdoAbort::kNone : SdoAbort::kInvalidValue;
}
template <class Owner>
SdoAbort check_homing_method(Owner&, uint8_t, int64_t v) {
  const auto method = static_cast<int8_t>(v);
  return Homing::is_supported(method) && PartOf<Owner>::supports_homing_method(method) ? SdoAbort::kNone
                                                                                       : SdoAbort::kInvalidValue;
}

}  // namespace profile_rows

// The profile area in index order. A module adds its own objects where they belong:
// `after_quick_stop` after 6085 (the TMCM-3216's 608F), `before_target_velocity` after 60F2 (60FD).
template <class Owner, class Table, class AfterQuickStop, class BeforeTargetVelocity>
constexpr void add_profile_rows(Table& t, const ProfileRows& p, const AfterQuickStop& after_quick_stop,
                                const BeforeTargetVelocity& before_target_velocity) {
  using namespace profile_rows;
  using enum DataType;
  using O = ProfileObjects;
  using Drive = DriveOf<Owner>;
  namespace r = canopen::rows;
  const uint16_t s = p.axis_stride;
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
    t.add(axis_row(r::var<Owner>(0x6040, p.controlword.name, kUnsigned16, Access::kRw, 0, r::kU16Max, 0, b), s,
                   p.controlword.mappable, false));
  }
  t.add(reading<Owner>(0x6041, p.statusword.name, s, kUnsigned16, 0, r::kU16Max,
                       [](Owner& d, uint8_t a) -> int64_t { return d.drive(a).statusword(); }, p.statusword.mappable,
                       kSwSwitchOnDisabled | kSwRemote));
  // Option codes 605A..605E: the values the PDS implements.
  t.add(config_var<Owner, &O::quick_stop_option>(0x605A, p.quick_stop_option, s, kInteger16, kI16Min, kI16Max,
                                                 &check_quick_stop_option<Owner>));
  t.add(config_var<Owner, &O::shutdown_option>(0x605B, p.shutdown_option, s, kInteger16, 0, 0));
  t.add(config_var<Owner, &O::disable_operation_option>(0x605C, p.disable_operation_option, s, kInteger16, 1, 1));
  t.add(config_var<Owner, &O::halt_option>(0x605D, p.halt_option, s, kInteger16, 1, 1));
  t.add(config_var<Owner, &O::fault_reaction_option>(0x605E, p.fault_reaction_option, s, kInteger16, 2, 2));
  // 6060 / 6061: modes (6060 not stored: a reset starts without a mode).
  {
    EntryBinding<Owner> b = field<Owner, &O::mode>();
    b.check = &check_mode<Owner>;
    t.add(axis_row(r::var<Owner>(0x6060, p.mode.name, kInteger8, Access::kRw, kI8Min, kI8Max, 0, b), s,
                   p.mode.mappable, false));
  }
  t.add(reading<Owner>(0x6061, p.mode_display.name, s, kInteger8, kI8Min, kI8Max,
                       [](Owner& d, uint8_t a) -> int64_t { return d.drive(a).mode_display(); },
                       p.mode_display.mappable));
  t.add(reading<Owner>(0x6062, p.position_demand.name, s, kInteger32, r::kI32Min, r::kI32Max,
                       [](Owner& d, uint8_t a) -> int64_t { return d.drive(a).position_demand(); },
                       p.position_demand.mappable));
  t.add(reading<Owner>(0x6063, p.position_actual_internal.name, s, kInteger32, r::kI32Min, r::kI32Max,
                       [](Owner& d, uint8_t a) -> int64_t { return d.drive(a).position_actual(); },
                       p.position_actual_internal.mappable));
  t.add(reading<Owner>(0x6064, p.position_actual.name, s, kInteger32, r::kI32Min, r::kI32Max,
                       [](Owner& d, uint8_t a) -> int64_t { return d.drive(a).position_actual(); },
                       p.position_actual.mappable));
  t.add(config_var<Owner, &O::following_error_window>(0x6065, p.following_error_window, s, kUnsigned32, 0, r::kI32Max));
  t.add(config_var<Owner, &O::position_window>(0x6067, p.position_window, s, kUnsigned32, 0, r::kU32Max));
  t.add(config_var<Owner, &O::position_window_time_ms>(0x6068, p.position_window_time, s, kUnsigned16, 0, r::kU16Max));
  t.add(config_var<Owner, &O::sensor_selection>(0x606A, p.sensor_selection, s, kInteger16, kI16Min, kI16Max,
                                                &check_sensor_selection<Owner>));
  if (p.velocity_demand.present) {
    t.add(reading<Owner>(0x606B, p.velocity_demand.name, s, kInteger32, r::kI32Min, r::kI32Max,
                         [](Owner& d, uint8_t a) -> int64_t { return d.drive(a).velocity_demand_value(); },
                         p.velocity_demand.mappable));
  }
  t.add(reading<Owner>(0x606C, p.velocity_actual.name, s, kInteger32, r::kI32Min, r::kI32Max,
                       [](Owner& d, uint8_t a) -> int64_t { return d.drive(a).velocity_actual_value(); },
                       p.velocity_actual.mappable));
  if (p.target_torque.present) {
    t.add(set_point<Owner, &O::target_torque, &Drive::target_torque_written>(0x6071, p.target_torque, s, kInteger16,
                                                                            kI16Min, kI16Max));
  }
  if (p.max_torque.present) {
    t.add(config_var<Owner, &O::max_torque>(0x6072, p.max_torque, s, kUnsigned16, 0, r::kU16Max));
  }
  t.add(set_point<Owner, &O::target_position, &Drive::target_position_written>(0x607A, p.target_position, s, kInteger32,
                                                                              r::kI32Min, r::kI32Max));
  t.add(config_var<Owner, &O::home_offset>(0x607C, p.home_offset, s, kInteger32, r::kI32Min, r::kI32Max));
  t.add(array_head<Owner>(0x607D, ObjectCode::kArray, p.software_limit_names, s));
  t.add(config_entry<Owner, &O::software_limit_min>(0x607D, 1, ObjectCode::kArray, p.software_limit_names.object,
                                                    p.software_limit_names.first, s, kInteger32, r::kI32Min,
                                                    r::kI32Max, r::kI32Min));
  t.add(config_entry<Owner, &O::software_limit_max>(0x607D, 2, ObjectCode::kArray, p.software_limit_names.object,
                                                    p.software_limit_names.second, s, kInteger32, r::kI32Min,
                                                    r::kI32Max, r::kI32Max));
  if (p.max_profile_velocity.present) {
    t.add(config_var<Owner, &O::max_profile_velocity>(0x607F, p.max_profile_velocity, s, kUnsigned32, 0, r::kU32Max));
  }
  t.add(config_var<Owner, &O::profile_velocity>(0x6081, p.profile_velocity, s, kUnsigned32, 0, r::kU32Max));
  if (p.end_velocity.present) {
    t.add(config_var<Owner, &O::end_velocity>(0x6082, p.end_velocity, s, kUnsigned32, 0, r::kU32Max));
  }
  t.add(config_var<Owner, &O::profile_acceleration>(0x6083, p.profile_acceleration, s, kUnsigned32, 0, r::kU32Max));
  t.add(config_var<Owner, &O::profile_deceleration>(0x6084, p.profile_deceleration, s, kUnsigned32, 0, r::kU32Max));
  t.add(config_var<Owner, &O::quick_stop_deceleration>(0x6085, p.quick_stop_deceleration, s, kUnsigned32, 0,
                                                       r::kU32Max));
  after_quick_stop(t);
  t.add(config_var<Owner, &O::homing_method>(0x6098, p.homing_method, s, kInteger8, kI8Min, kI8Max,
                                             &check_homing_method<Owner>));
  t.add(array_head<Owner>(0x6099, ObjectCode::kArray, p.homing_speed_names, s));
  t.add(config_entry<Owner, &O::homing_speed_fast>(0x6099, 1, ObjectCode::kArray, p.homing_speed_names.object,
                                                   p.homing_speed_names.first, s, kUnsigned32, 0, r::kU32Max, 0));
  t.add(config_entry<Owner, &O::homing_speed_slow>(0x6099, 2, ObjectCode::kArray, p.homing_speed_names.object,
                                                   p.homing_speed_names.second, s, kUnsigned32, 0, r::kU32Max, 0));
  t.add(config_var<Owner, &O::homing_acceleration>(0x609A, p.homing_acceleration, s, kUnsigned32, 0, r::kU32Max));
  t.add(offset_var<Owner, &O::position_offset>(0x60B0, p.position_offset, s, kInteger32, r::kI32Min, r::kI32Max));
  t.add(offset_var<Owner, &O::velocity_offset>(0x60B1, p.velocity_offset, s, kInteger32, r::kI32Min, r::kI32Max));
  if (p.torque_offset.present) {
    t.add(offset_var<Owner, &O::torque_offset>(0x60B2, p.torque_offset, s, kInteger16, kI16Min, kI16Max));
  }
  t.add(array_head<Owner>(0x60C2, ObjectCode::kRecord, p.interpolation_names, s));
  t.add(config_entry<Owner, &O::interpolation_period>(0x60C2, 1, ObjectCode::kRecord, p.interpolation_names.object,
                                                      p.interpolation_names.first, s, kUnsigned8, 0, r::kU8Max,
                                                      p.interpolation_period.default_value));
  t.add(config_entry<Owner, &O::interpolation_index>(0x60C2, 2, ObjectCode::kRecord, p.interpolation_names.object,
                                                     p.interpolation_names.second, s, kInteger8, -3, 3,
                                                     p.interpolation_index_default));
  t.add(config_var<Owner, &O::positioning_option>(0x60F2, p.positioning_option, s, kUnsigned16, 0, 2));
  before_target_velocity(t);
  t.add(set_point<Owner, &O::target_velocity, &Drive::target_velocity_written>(0x60FF, p.target_velocity, s,
                                                                              kInteger32, r::kI32Min, r::kI32Max));
  t.add(r::per_axis(r::var<Owner>(0x6502, p.supported_modes.name, kUnsigned32, Access::kRo, 0, r::kU32Max,
                                  PartOf<Owner>::kSupportedModes),
                    s));
  t.add(r::per_axis(r::var<Owner>(0x67FF, p.single_device_type.name, kUnsigned32, Access::kRo, 0, r::kU32Max,
                                  p.single_device_type.default_value),
                    s));
}

}  // namespace motwin::cia402
