// The TMCM-3216's manufacturer objects of the stepper axes (manual 4.2.1-4.2.9, 4.2.18, 4.2.21-
// 4.2.52, 4.2.54-4.2.59; axis n at index + n x 0x200) and of the general-purpose I/O (2702, 2703,
// 270E, 2711; 60FD per axis at + n x 0x800), as rows the module's table adds (tmcm3216_objects.cpp).
//
// Templates over the module profile `Owner` (Tmcm3216) and its `Table` (anything with
// add(const EntryRow<Owner>&)), so that the rows are written once and tested on their own. Owner
// provides:
//   Tmcm3216Stepper& stepper(uint8_t axis);
//   Tmcm3216GeneralIo& general_io();
#pragma once

#include <cstdint>

#include "core/canopen/object_rows.h"
#include "core/modules/tmcm3216/tmcm3216_io.h"
#include "core/modules/tmcm3216/tmcm3216_stepper.h"

namespace motwin::modules::tmcm3216 {

inline constexpr uint16_t kManufacturerAxisStride = 0x200;
inline constexpr uint16_t kProfileAxisStride = 0x800;

namespace manufacturer_rows {

using canopen::Access;
using canopen::DataType;
using canopen::EntryBinding;
using canopen::EntryRow;
using canopen::ObjectCode;
using canopen::SdoAbort;
using canopen::StorageGroup;

// A binding to the StepperObjects field `Member` of the row's axis.
template <class Owner, auto Member>
constexpr EntryBinding<Owner> object_field() {
  return canopen::field_binding<Owner, [](Owner& d, uint8_t axis) -> auto& { return d.stepper(axis).objects.*Member; }>();
}

// Manual 4.2.6, 4.2.8, 4.2.9: "only writable in SWITCHED_ON_DISABLED state".
template <class Owner>
SdoAbort only_switch_on_disabled(Owner& d, uint8_t axis, int64_t) {
  return d.stepper(axis).configurable() ? SdoAbort::kNone : SdoAbort::kDeviceState;
}

// A stored per-axis VAR bound to field `Member`.
template <class Owner, auto Member>
constexpr EntryRow<Owner> axis_var(uint16_t index, std::string_view name, DataType type, int64_t min, int64_t max,
                                   int64_t default_value, SdoAbort (*check)(Owner&, uint8_t, int64_t) = nullptr) {
  return canopen::rows::per_axis(
      canopen::rows::var<Owner>(index, name, type, Access::kRw, min, max, default_value,
                                canopen::rows::checked(object_field<Owner, Member>(), check), StorageGroup::kAxis),
      kManufacturerAxisStride);
}

// A stored per-axis array entry bound to field `Member`.
template <class Owner, auto Member>
constexpr EntryRow<Owner> axis_entry(uint16_t index, uint8_t sub, std::string_view object, std::string_view entry,
                                     DataType type, int64_t min, int64_t max, int64_t default_value,
                                     SdoAbort (*check)(Owner&, uint8_t, int64_t) = nullptr) {
  return canopen::rows::per_axis(
      canopen::rows::row<Owner>(index, sub, ObjectCode::kArray, object, entry, type, Access::kRw, min, max,
                                default_value, canopen::rows::checked(object_field<Owner, Member>(), check),
                                StorageGroup::kAxis),
      kManufacturerAxisStride);
}

// A live per-axis read-out; its default is what it reads at power-up (the EDS shows it).
template <class Owner>
constexpr EntryRow<Owner> axis_reading(uint16_t index, std::string_view name, DataType type, int64_t min, int64_t max,
                                       int64_t (*get)(Owner&, uint8_t), int64_t power_up_value = 0) {
  return canopen::rows::per_axis(canopen::rows::var<Owner>(index, name, type, Access::kRo, min, max, power_up_value,
                                                           canopen::rows::getter<Owner>(get)),
                                 kManufacturerAxisStride);
}

template <class Owner>
SdoAbort check_off_time(Owner&, uint8_t, int64_t v) {
  return valid_chopper_off_time(v) ? SdoAbort::kNone : SdoAbort::kInvalidValue;
}
template <class Owner>
SdoAbort check_global_scaler(Owner&, uint8_t, int64_t v) {
  return valid_global_current_scaler(v) ? SdoAbort::kNone : SdoAbort::kInvalidValue;
}
template <class Owner>
SdoAbort check_io_mode(Owner&, uint8_t, int64_t v) {
  return (v & ~int64_t{Tmcm3216GeneralIo::kIoModeMask}) != 0 ? SdoAbort::kInvalidValue : SdoAbort::kNone;
}

}  // namespace manufacturer_rows

// Rows of the stepper objects 2000..2122 of axis 0 (per_axis: + 0x200 for axes 1 and 2).
template <class Owner, class Table>
constexpr void add_stepper_rows(Table& t) {
  using namespace manufacturer_rows;
  using enum DataType;
  using O = StepperObjects;
  namespace r = canopen::rows;
  constexpr SdoAbort (*kSod)(Owner&, uint8_t, int64_t) = &only_switch_on_disabled<Owner>;
  constexpr int64_t kVelocityMax = 16777215;

  t.add(axis_var<Owner, &O::microstep_code>(0x2000, "Microstep resolution", kUnsigned8, 0, 8, 8));
  t.add(axis_var<Owner, &O::full_steps_per_revolution>(0x2001, "Fullstep resolution", kUnsigned16, 0, r::kU16Max, 200));
  t.add(r::per_axis(r::highest_sub<Owner>(0x2002, ObjectCode::kArray, "Brake delay times", 2), kManufacturerAxisStride));
  t.add(axis_entry<Owner, &O::brake_apply_delay_ms>(0x2002, 1, "Brake delay times",
                                                   "Time between applying brake and disabling power stage",
                                                   kUnsigned16, 0, r::kU16Max, 0));
  t.add(axis_entry<Owner, &O::brake_release_delay_ms>(0x2002, 2, "Brake delay times",
                                                     "Time between releasing brake and switching to operational",
                                                     kUnsigned16, 0, r::kU16Max, 0));
  t.add(axis_var<Owner, &O::run_current>(0x2003, "Maximum current", kUnsigned8, 0, 255, 128));
  t.add(axis_var<Owner, &O::standby_current>(0x2004, "Standby current", kUnsigned8, 0, 255, 8));
  t.add(axis_var<Owner, &O::switch_config>(0x2005, "Switch parameters", kUnsigned32, 0, 63, 0, kSod));
  t.add(axis_var<Owner, &O::enable_drive_delay_ms>(0x200A, "Enable drive delay time", kUnsigned16, 0, r::kU16Max, 0));
  t.add(r::per_axis(r::highest_sub<Owner>(0x200B, ObjectCode::kArray, "Encoder parameters", 3), kManufacturerAxisStride));
  t.add(axis_entry<Owner, &O::encoder_index_inverted>(0x200B, 1, "Encoder parameters", "Null channel polarity",
                                                     kUnsigned8, 0, 1, 0, kSod));
  t.add(axis_entry<Owner, &O::encoder_reversed>(0x200B, 2, "Encoder parameters", "Direction of rotation", kUnsigned8,
                                               0, 1, 0, kSod));
  t.add(axis_entry<Owner, &O::encoder_initialize_position>(0x200B, 3, "Encoder parameters", "Initialize position",
                                                          kUnsigned8, 0, 1, 1, kSod));
  t.add(r::per_axis(r::highest_sub<Owner>(0x200C, ObjectCode::kArray, "Brake current feed", 2), kManufacturerAxisStride));
  t.add(axis_entry<Owner, &O::brake_apply_current>(0x200C, 1, "Brake current feed", "Apply current", kUnsigned8, 0,
                                                  255, 0, kSod));
  t.add(axis_entry<Owner, &O::brake_release_current>(0x200C, 2, "Brake current feed", "Release current", kUnsigned8,
                                                    0, 255, 0, kSod));
  // Default 200 (2 s) as table 49 and 4.2.5 say; table 86 prints 0 (docs "Decisions").
  t.add(axis_var<Owner, &O::standby_delay_10ms>(0x2089, "Setting delay", kUnsigned16, 0, 400, 200));
  t.add(axis_var<Owner, &O::chopper_blank_time>(0x2092, "Chopper blank time", kUnsigned8, 0, 3, 2));
  t.add(axis_var<Owner, &O::chopper_mode>(0x2093, "Chopper mode", kUnsigned8, 0, 1, 0));
  t.add(axis_var<Owner, &O::chopper_fast_decay_comparator_off>(0x2094, "Chopper disable fast decay comparator",
                                                               kUnsigned8, 0, 1, 0));
  t.add(axis_var<Owner, &O::chopper_hysteresis_end>(0x2095, "Chopper hysteresis end", kInteger8, -3, 12, 0));
  t.add(axis_var<Owner, &O::chopper_hysteresis_start>(0x2096, "Chopper hysteresis start", kUnsigned8, 0, 8, 3));
  t.add(axis_var<Owner, &O::chopper_off_time>(0x2097, "Chopper off time", kUnsigned8, 0, 15, 5,
                                              &check_off_time<Owner>));
  t.add(axis_var<Owner, &O::coolstep_current_minimum>(0x2098, "Smart energy current minimum", kUnsigned8, 0, 1, 0));
  t.add(axis_var<Owner, &O::coolstep_down_step>(0x2099, "Smart energy current down step", kUnsigned8, 0, 3, 0));
  t.add(axis_var<Owner, &O::coolstep_hysteresis>(0x209A, "Smart energy hysteresis", kUnsigned8, 0, 15, 0));
  t.add(axis_var<Owner, &O::coolstep_up_step>(0x209B, "Smart energy current up step", kUnsigned8, 0, 3, 0));
  t.add(axis_var<Owner, &O::coolstep_hysteresis_start>(0x209C, "Smart energy hysteresis start", kUnsigned8, 0, 15, 0));
  t.add(axis_var<Owner, &O::stallguard2_filter>(0x209D, "Smart energy filter enable", kUnsigned8, 0, 1, 0));
  t.add(axis_var<Owner, &O::stallguard2_threshold>(0x209E, "StallGuard2 threshold", kInteger8, -63, 63, 0));
  t.add(axis_var<Owner, &O::short_protection_disabled>(0x20A1, "Short protection disable", kUnsigned8, 0, 1, 0));
  t.add(axis_var<Owner, &O::global_current_scaler>(0x20A2, "Global current scaler", kUnsigned8, 0, 255, 0,
                                                   &check_global_scaler<Owner>));
  t.add(axis_var<Owner, &O::current_range>(0x20A3, "Driver current range", kUnsigned8, 0, 3, 3));
  t.add(axis_var<Owner, &O::stop_on_stall_velocity>(0x20A4, "Stop on stall", kUnsigned32, 0, r::kI32Max, 0));
  t.add(axis_var<Owner, &O::coolstep_threshold_velocity>(0x20A5, "Smart energy threshold speed", kUnsigned32, 0,
                                                         r::kI32Max, 0));
  t.add(axis_var<Owner, &O::stop_on_stall_option>(0x20A7, "Stop on stall option code", kUnsigned8, 0, 1, 0));
  t.add(axis_var<Owner, &O::stallguard4_threshold>(0x20A8, "StallGuard4 threshold value", kUnsigned16, 0, 511, 0));
  t.add(axis_var<Owner, &O::stallguard4_filter>(0x20A9, "StallGuard4 filter enable", kUnsigned8, 0, 1, 0));
  t.add(axis_var<Owner, &O::stallguard4_angle_offset>(0x20AA, "StallGuard4 angle offset", kUnsigned8, 0, 1, 0));
  t.add(axis_var<Owner, &O::pwm_threshold_velocity>(0x20B0, "PWM threshold speed", kUnsigned32, 0, kVelocityMax, 0));
  t.add(axis_var<Owner, &O::pwm_gradient>(0x20B1, "PWM gradient", kUnsigned8, 0, 255, 0));
  t.add(axis_var<Owner, &O::pwm_amplitude>(0x20B2, "PWM amplitude", kUnsigned8, 0, 255, 0));
  t.add(axis_var<Owner, &O::dcstep_minimum_velocity>(0x20B3, "DcStep minimum speed", kUnsigned32, 0, kVelocityMax, 0));
  t.add(axis_var<Owner, &O::dcstep_time>(0x20B4, "DcStep time", kUnsigned16, 0, 1023, 0));
  t.add(axis_var<Owner, &O::dcstep_stallguard>(0x20B5, "DcStep StallGuard", kUnsigned8, 0, 255, 0));
  t.add(axis_var<Owner, &O::fullstep_threshold_velocity>(0x20B6, "Fullstep threshold speed", kUnsigned32, 0,
                                                         kVelocityMax, 0));
  t.add(axis_var<Owner, &O::high_speed_chopper>(0x20B7, "High-speed chopper mode", kUnsigned8, 0, 1, 0));
  t.add(axis_var<Owner, &O::high_speed_fullstep>(0x20B8, "High-speed fullstep mode", kUnsigned8, 0, 1, 0));
  t.add(axis_var<Owner, &O::power_down_ramp>(0x20B9, "Power down ramp", kUnsigned8, 0, 15, 7));
  // Read-outs (2100 home offset display is the drive's).
  t.add(axis_reading<Owner>(0x2101, "Actual load value", kUnsigned16, 0, 1023,
                            [](Owner& d, uint8_t a) -> int64_t { return d.stepper(a).load_value(); }));
  t.add(axis_reading<Owner>(0x2102, "Driver error flags", kUnsigned8, 0, 255,
                            [](Owner& d, uint8_t a) -> int64_t { return d.stepper(a).driver_error_flags(); }));
  t.add(axis_reading<Owner>(0x2107, "Microstep resolution display", kUnsigned8, 0, 8,
                            [](Owner& d, uint8_t a) -> int64_t { return d.stepper(a).active_microstep_code(); }, 8));
  t.add(axis_reading<Owner>(0x210A, "StallGuard4 result", kUnsigned16, 0, 511,
                            [](Owner& d, uint8_t a) -> int64_t { return d.stepper(a).stallguard4_result(); }));
  t.add(axis_reading<Owner>(0x2121, "PWM scale value", kUnsigned8, 0, 255,
                            [](Owner& d, uint8_t a) -> int64_t { return d.stepper(a).pwm_scale(); }));
  t.add(axis_reading<Owner>(0x2122, "Measured velocity", kInteger32, -kVelocityMax, kVelocityMax,
                            [](Owner& d, uint8_t a) -> int64_t { return d.stepper(a).measured_velocity(); }));
}

// Rows of the device's I/O objects 2702, 2703, 270E, 2711 (not stored).
template <class Owner, class Table>
constexpr void add_io_rows(Table& t) {
  using namespace manufacturer_rows;
  using enum DataType;
  namespace r = canopen::rows;
  t.add(r::mappable(r::var<Owner>(0x2702, "Device digital inputs", kUnsigned32, Access::kRo, 0, r::kU32Max, 0,
                                  r::getter<Owner>([](Owner& d, uint8_t) -> int64_t {
                                    return d.general_io().digital_inputs();
                                  }))));
  t.add(r::highest_sub<Owner>(0x2703, ObjectCode::kArray, "Device digital outputs", 2));
  {
    EntryBinding<Owner> b;
    b.get = [](Owner& d, uint8_t) -> int64_t { return d.general_io().outputs; };
    b.set = [](Owner& d, uint8_t, int64_t v) {
      d.general_io().write_outputs(static_cast<uint32_t>(v));
      return SdoAbort::kNone;
    };
    // Bits 16..19 only: the module has OUT0..OUT3 (table 173); other bits name no output.
    b.check = [](Owner&, uint8_t, int64_t v) {
      return Tmcm3216GeneralIo::valid_outputs(static_cast<uint32_t>(v)) ? SdoAbort::kNone : SdoAbort::kInvalidValue;
    };
    t.add(r::mappable(r::row<Owner>(0x2703, 1, ObjectCode::kArray, "Device digital outputs", "Physical outputs",
                                    kUnsigned32, Access::kRw, 0, r::kU32Max, 0, b)));
  }
  t.add(r::row<Owner>(0x2703, 2, ObjectCode::kArray, "Device digital outputs", "Output mask", kUnsigned32, Access::kRw,
                      0, r::kU32Max, 0,
                      canopen::field_binding<Owner, [](Owner& d, uint8_t) -> uint32_t& {
                        return d.general_io().output_mask;
                      }>()));
  t.add(r::highest_sub<Owner>(0x270E, ObjectCode::kArray, "Device analog inputs", 2));
  t.add(r::mappable(r::row<Owner>(0x270E, 1, ObjectCode::kArray, "Device analog inputs", "Analog input 0", kUnsigned32,
                                  Access::kRo, 0, 4095, 0, r::getter<Owner>([](Owner& d, uint8_t) -> int64_t {
                                    return d.general_io().analog_input(0);
                                  }))));
  t.add(r::mappable(r::row<Owner>(0x270E, 2, ObjectCode::kArray, "Device analog inputs", "Analog input 1", kUnsigned32,
                                  Access::kRo, 0, 4095, 0, r::getter<Owner>([](Owner& d, uint8_t) -> int64_t {
                                    return d.general_io().analog_input(1);
                                  }))));
  t.add(r::var<Owner>(0x2711, "I/O mode", kUnsigned16, Access::kRw, 0, 3855, 0,
                      r::checked(canopen::field_binding<Owner, [](Owner& d, uint8_t) -> uint16_t& {
                                   return d.general_io().io_mode;
                                 }>(),
                                 &check_io_mode<Owner>)));
}

// 60FD of each axis (+ 0x800): CiA-402 bits 0 negative (left) limit, 1 positive (right) limit,
// 2 home switch (as 2005 makes them), 16..19 the DIO inputs (as 2702).
template <class Owner>
int64_t digital_inputs_60fd(Owner& d, uint8_t axis) {
  const SwitchState s = d.stepper(axis).switches();
  uint32_t bits = d.general_io().digital_inputs();
  if (s.left) bits |= 1u << 0;
  if (s.right) bits |= 1u << 1;
  if (s.home) bits |= 1u << 2;
  return bits;
}

template <class Owner, class Table>
constexpr void add_digital_inputs_row(Table& t) {
  namespace r = canopen::rows;
  t.add(r::per_axis(r::mappable(r::var<Owner>(0x60FD, "Digital inputs", canopen::DataType::kUnsigned32,
                                              canopen::Access::kRo, 0, r::kU32Max, 0,
                                              r::getter<Owner>(&digital_inputs_60fd<Owner>))),
                    kProfileAxisStride));
}

}  // namespace motwin::modules::tmcm3216
