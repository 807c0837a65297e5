// The TMCM-1636 CANopen firmware's object dictionary as data, after Trinamic's EDS of firmware 1.12
// (tests/data/TMCM-1636-CANopen_Hw1.1_Fw1.12.eds): names, data types, access, PDO mapping and
// defaults as the EDS gives them, except the documented decisions (docs/tmcm-1636-canopen.md
// "Differences from the published EDS"). The communication objects are the node's
// (core/canopen/communication_objects.h), the 6xxx objects the drive's (core/cia402/profile_rows.h);
// the manufacturer objects are bound to the fields of the TMCL firmware's axis that have the same
// meaning (the ranges are those of the TMCL axis parameter of the same setting).
#include <array>

#include "core/canopen/communication_objects.h"
#include "core/cia402/profile_rows.h"
#include "core/modules/tmcm1636/tmcm1636_canopen.h"

namespace motwin::modules::tmcm1636 {
namespace {

using canopen::Access;
using canopen::DataType;
using canopen::EntryBinding;
using canopen::ObjectCode;
using canopen::SdoAbort;
using canopen::StorageGroup;
using Module = Tmcm1636Canopen;
using Row = Module::Row;
using Binding = EntryBinding<Module>;
namespace r = canopen::rows;
using enum DataType;

constexpr StorageGroup kApplication = StorageGroup::kApplication;
constexpr StorageGroup kNode = StorageGroup::kNodeSettings;
constexpr int64_t kI16Min = -32768;
constexpr int64_t kI16Max = 32767;

// --- Rows ----------------------------------------------------------------------------------------

// Sub 0 of an ARRAY or RECORD, with the access the EDS gives it (const or ro).
constexpr Row count_entry(uint16_t index, ObjectCode code, std::string_view object, uint8_t highest,
                          std::string_view entry, Access access) {
  Row row = r::highest_sub<Module>(index, code, object, highest, entry);
  row.info.access = access;
  return row;
}


constexpr Row stored(Row row, StorageGroup group) {
  row.info.storage = group;
  return row;
}

// A binding to the axis setting `Member` (AxisConfig).
template <auto Member>
constexpr Binding config_field() {
  return canopen::field_binding<Module, [](Module& m, uint8_t) -> auto& { return m.axis().config.*Member; }>();
}
// A gain of a regulator: field `Field` of the motion::PiConfig `Pi`.
template <auto Pi, auto Field>
constexpr Binding gain_field() {
  return canopen::field_binding<Module, [](Module& m, uint8_t) -> auto& { return (m.axis().config.*Pi).*Field; }>();
}
// A live value of the axis (AxisState).
template <auto Member>
constexpr Binding state_value() {
  return r::getter<Module>([](Module& m, uint8_t) { return static_cast<int64_t>(m.axis().state.*Member); });
}
template <auto Pi, auto Field>
constexpr Binding regulator_value() {
  return r::getter<Module>([](Module& m, uint8_t) { return static_cast<int64_t>((m.axis().state.*Pi).*Field); });
}

// A stored rw sub-index of a manufacturer RECORD bound to an axis setting.
template <auto Member>
constexpr Row setting(uint16_t index, uint8_t sub, std::string_view object, std::string_view entry, DataType type,
                      int64_t min, int64_t max, int64_t default_value) {
  return stored(r::row<Module>(index, sub, ObjectCode::kRecord, object, entry, type, Access::kRw, min, max,
                               default_value, config_field<Member>()),
                kApplication);
}
template <auto Member>
constexpr Row setting_var(uint16_t index, std::string_view name, DataType type, int64_t min, int64_t max,
                          int64_t default_value, Binding binding = config_field<Member>()) {
  return stored(r::var<Module>(index, name, type, Access::kRw, min, max, default_value, binding), kApplication);
}
template <auto Pi, auto Field>
constexpr Row gain(uint16_t index, uint8_t sub, std::string_view object, std::string_view entry) {
  return stored(r::row<Module>(index, sub, ObjectCode::kRecord, object, entry, kUnsigned16, Access::kRw, 0, 32767, 0,
                               gain_field<Pi, Field>()),
                kApplication);
}
template <auto Pi, auto Field>
constexpr Row regulator_reading(uint16_t index, uint8_t sub, std::string_view object, std::string_view entry) {
  return r::row<Module>(index, sub, ObjectCode::kRecord, object, entry, kInteger32, Access::kRo, r::kI32Min,
                        r::kI32Max, 0, regulator_value<Pi, Field>());
}
constexpr Row reading(uint16_t index, uint8_t sub, ObjectCode code, std::string_view object, std::string_view entry,
                      DataType type, int64_t min, int64_t max, int64_t (*get)(Module&, uint8_t)) {
  return r::row<Module>(index, sub, code, object, entry, type, Access::kRo, min, max, 0, r::getter<Module>(get));
}

// 2005: only in SWITCH ON DISABLED (TMCM-3216 manual 4.2.6: the family's rule).
SdoAbort check_switch_parameters(Module& m, uint8_t, int64_t) {
  const cia402::PdsState state = m.drive().state();
  return state == cia402::PdsState::kSwitchOnDisabled || state == cia402::PdsState::kNotReadyToSwitchOn
             ? SdoAbort::kNone
             : SdoAbort::kDeviceState;
}

// 5FFF: the key 12345678h would start the bootloader (TMCM-1690 manual 17); the virtual module has
// none to start, so it refuses the key. Other values do nothing.
constexpr uint32_t kBootModeKey = 0x1234'5678;

// --- The communication objects -------------------------------------------------------------------

// RPDO COB-IDs carry bit 30 (no RTR), as the EDS gives them; TPDO 3 goes out at every SYNC,
// TPDO 4 when its values change (docs/tmcm-1636-canopen.md "Event-driven TPDOs").
constexpr canopen::PdoObjects kPdoObjects{
    .per_axis = kCanopenPdoCount,
    .axis_stride = 0,
    .mapping_axis_offset = 0,
    .mapping_entries = kCanopenMappedObjects,
    .dummies_mappable = false,  // the EDS's DummyUsage: none
    .compatibility_access = Access::kRw,
    .rpdo = {{0x4000'0200, 0xFF, 1, {0x6040'0010}},
             {0x4000'0300, 0xFF, 2, {0x6040'0010, 0x6060'0008}},
             {0x4000'0400, 0xFF, 2, {0x6040'0010, 0x607A'0020}},
             {0x4000'0500, 0xFF, 2, {0x6040'0010, 0x60FF'0020}}},
    .tpdo = {{0x180, 0xFF, 1, {0x6041'0010}},
             {0x280, 0xFF, 2, {0x6041'0010, 0x6061'0008}},
             {0x380, 0x01, 2, {0x6041'0010, 0x6064'0020}},
             {0x480, 0xFE, 2, {0x6041'0010, 0x606C'0020}}},
    .names = &canopen::kPdoNamesDesignTool,
};

// --- The CiA-402 objects -------------------------------------------------------------------------

// EDS names, defaults and PDO mapping. The EDS gives 6081, 6083, 6084, 6085 and 6067 the default 0.
constexpr cia402::ProfileRows kProfileRows{
    .axis_stride = 0,
    .controlword = cia402::named("Controlword", true),
    .statusword = cia402::named("Statusword", true),
    .quick_stop_option = cia402::with_default("Quick Stop Option Code", 2),
    .shutdown_option = cia402::with_default("Shutdown Option Code", 0),
    .disable_operation_option = cia402::with_default("Disable Operation Option Code", 1),
    .halt_option = cia402::with_default("Halt Option Code", 1),
    .fault_reaction_option = cia402::with_default("Fault Reaction Option Code", 2),
    .mode = cia402::named("Modes of Operation", true),
    .mode_display = cia402::named("Modes of Operation Display", true),
    .position_demand = cia402::named("Position Demand Value"),
    .position_actual_internal = cia402::named("Position Actual Internal Value"),
    .position_actual = cia402::named("Position Actual Value", true),
    .following_error_window = cia402::with_default("Following Error Window", 0),
    .position_window = cia402::with_default("Position Window", 0),
    .position_window_time = cia402::with_default("Position Window Time", 0),
    .sensor_selection = cia402::with_default("Sensor Selection Code", 0),
    .velocity_demand = cia402::named("Velocity Demand Value"),
    .velocity_actual = cia402::named("Velocity Actual Value", true),
    .target_torque = cia402::named("Target Torque", true),
    .max_torque = cia402::with_default("Max Torque", 0),
    .target_position = cia402::named("Target Position", true),
    .home_offset = cia402::with_default("Home Offset", 0),
    .software_limit = cia402::named("Software Position Limit"),
    .software_limit_names = {"Software Position Limit", "Highest sub-index supported", "Min Software Position Limit",
                             "Max Software Position Limit", Access::kConst},
    .max_profile_velocity = cia402::with_default("Max Profile Velocity", 0),
    .profile_velocity = cia402::with_default("Profile Velocity in pp-mode", 0, true),
    .end_velocity = cia402::kAbsent,
    .profile_acceleration = cia402::with_default("Profile Acceleration", 0),
    .profile_deceleration = cia402::with_default("Profile Deceleration", 0),
    .quick_stop_deceleration = cia402::with_default("Quick Stop Deceleration", 0),
    .homing_method = cia402::with_default("Homing Method", 0),
    .homing_speeds = cia402::named("Homing Speeds"),
    .homing_speed_names = {"Homing Speeds", "Highest sub-index supported", "Fast Homing Speed 1", "Slow Homing Speed",
                           Access::kConst},
    .homing_acceleration = cia402::with_default("Homing Acceleration", 0),
    .position_offset = cia402::named("Position Offset"),
    .velocity_offset = cia402::named("Velocity Offset"),
    .torque_offset = cia402::named("Torque Offset"),
    .interpolation_period = cia402::with_default("Interpolation Time Period", 0),
    .interpolation_names = {"Interpolation Time Period", "NumOfEntries", "timeUnits", "timeIndex", Access::kConst},
    .interpolation_index_default = 0,
    .positioning_option = cia402::with_default("Positioning Option Code", 0),
    .target_velocity = cia402::named("Target Velocity", true),
    .supported_modes = cia402::named("Supported Drive Modes"),
    .single_device_type = cia402::with_default("Single Device Type", Module::kSingleDeviceType),
};

// --- The table -----------------------------------------------------------------------------------

// No 1006 (the EDS's module is a SYNC consumer only), node guarding, 1014 read-only, 1029 sub 1 only.
constexpr canopen::CommunicationObjects kCommunication{
    .names = &canopen::kCommunicationNamesDesignTool,
    .pdos = &kPdoObjects,
    .sync_producer = false,
    .node_guarding = true,
    .emcy_cob_id_access = Access::kRo,
    .application_error_behavior = false,
};

constexpr size_t kCapacity = 260;
using Table = canopen::RowTable<Module, kCapacity>;

constexpr void add_motor_rows(Table& t) {
  using C = AxisConfig;
  using S = AxisState;
  using motion::PiConfig;
  using motion::PiState;
  // 2000: the motion controller's chip information, 0 as the EDS gives it.
  t.add(count_entry(0x2000, ObjectCode::kRecord, "Device Info", 5, "numOfEntries", Access::kConst));
  constexpr std::string_view kInfoNames[] = {"MC_Type", "MC_Version", "MC_Date", "MC_Time", "MC_Variant"};
  for (uint8_t sub = 1; sub <= 5; ++sub) {
    t.add(r::row<Module>(0x2000, sub, ObjectCode::kRecord, "Device Info", kInfoNames[sub - 1], kUnsigned32, Access::kRo,
                         0, r::kU32Max, 0));
  }
  t.add(setting_var<&C::max_current_ma>(0x2003, "Maximum Current", kUnsigned32, 0, 60000, 0));
  t.add(setting_var<&C::open_loop_current_ma>(0x2004, "Open Loop Current", kUnsigned32, 0, 60000, 0));
  t.add(stored(r::var<Module>(0x2005, "Switch Parameters", kUnsigned32, Access::kRw, 0, 63, 3,
                              r::checked(canopen::field_binding<Module, [](Module& m, uint8_t) -> uint32_t& {
                                           return m.objects().switch_parameters;
                                         }>(),
                                         &check_switch_parameters)),
               kApplication));
  // 2006: the brake chopper (AP 140..142). The EDS gives the voltage no default: the TMCL firmware's.
  t.add(count_entry(0x2006, ObjectCode::kRecord, "Brake Chopper", 3, "Highest sub-index supported", Access::kRo));
  t.add(setting<&C::brake_chopper_enabled>(0x2006, 1, "Brake Chopper", "Enable", kUnsigned8, 0, 1, 0));
  t.add(setting<&C::brake_chopper_limit_decivolt>(0x2006, 2, "Brake Chopper", "Voltage", kUnsigned16, 50, 600, 260));
  t.add(setting<&C::brake_chopper_hysteresis_decivolt>(0x2006, 3, "Brake Chopper", "Hysteresis", kUnsigned8, 0, 50, 0));
  // 2041..2043: the regulators (AP 70..81, 25, 26). The EDS's sub 0 of 2041 says rw 1 and of 2043
  // rw 3: here read-only, the highest sub-index present.
  t.add(count_entry(0x2041, ObjectCode::kRecord, "Torque Mode Settings", 6, "Highest sub-index supported", Access::kRo));
  t.add(gain<&C::current_pi, &PiConfig::p>(0x2041, 1, "Torque Mode Settings", "Torque_P"));
  t.add(gain<&C::current_pi, &PiConfig::i>(0x2041, 2, "Torque Mode Settings", "Torque_I"));
  t.add(regulator_reading<&S::torque_pi, &PiState::error>(0x2041, 3, "Torque Mode Settings", "PID_Torque_Error"));
  t.add(regulator_reading<&S::torque_pi, &PiState::error_sum>(0x2041, 4, "Torque Mode Settings", "PID_Torque_Error_Sum"));
  t.add(regulator_reading<&S::flux_pi, &PiState::error>(0x2041, 5, "Torque Mode Settings", "PID_Flux_Error"));
  t.add(regulator_reading<&S::flux_pi, &PiState::error_sum>(0x2041, 6, "Torque Mode Settings", "PID_Flux_Error_Sum"));
  t.add(count_entry(0x2042, ObjectCode::kRecord, "Velocity Mode Settings", 5, "numOfEntries", Access::kConst));
  t.add(gain<&C::velocity_pi, &PiConfig::p>(0x2042, 1, "Velocity Mode Settings", "Velocity_P"));
  t.add(gain<&C::velocity_pi, &PiConfig::i>(0x2042, 2, "Velocity Mode Settings", "Velocity_I"));
  t.add(regulator_reading<&S::velocity_pi, &PiState::error>(0x2042, 3, "Velocity Mode Settings", "PID_Velocity_Error"));
  t.add(regulator_reading<&S::velocity_pi, &PiState::error_sum>(0x2042, 4, "Velocity Mode Settings",
                                                                "PID_Velocity_Error_Sum"));
  t.add(setting<&C::velocity_sensor_selection>(0x2042, 5, "Velocity Mode Settings", "Sensor_Selection", kUnsigned8, 0, 2,
                                               0));
  t.add(count_entry(0x2043, ObjectCode::kRecord, "Position Mode Settings", 3, "Highest sub-index supported",
                    Access::kRo));
  t.add(gain<&C::position_pi, &PiConfig::p>(0x2043, 1, "Position Mode Settings", "Position_P"));
  t.add(regulator_reading<&S::position_pi, &PiState::error>(0x2043, 2, "Position Mode Settings", "PID_Position_Error"));
  t.add(setting<&C::position_commutation_mode>(0x2043, 3, "Position Mode Settings", "Sensor_Selection", kUnsigned8, 0,
                                               2, 0));
  // The motor (AP 14, 15, 10, 13, 56). Pole pairs: the EDS's 0 would leave the hall scaling without
  // a divisor; 4, the TMCL firmware's default (and the QBL4208's).
  t.add(setting_var<&C::motor_type>(0x2050, "Motor Type", kUnsigned8, 0, 3, 0));
  t.add(setting_var<&C::commutation_mode>(0x2055, "Commutation Mode", kUnsigned8, 0, 4, 0, [] {
    Binding b = config_field<&C::commutation_mode>();
    // Selecting ABN or absolute encoder commutation starts the encoder initialisation (AP 15).
    b.set = [](Module& m, uint8_t, int64_t v) {
      m.axis().set_commutation_mode(static_cast<CommutationMode>(v));
      return SdoAbort::kNone;
    };
    return b;
  }()));
  t.add(setting_var<&C::motor_pole_pairs>(0x2056, "Motor Pole Pairs", kUnsigned8, 1, 255, 4));
  t.add(setting_var<&C::motor_direction>(0x2057, "Motor Shaft Direction", kUnsigned8, 0, 1, 0));
  t.add(setting_var<&C::position_scaler>(0x2058, "Position Scaler", kInteger32, 1, 16777215, 65536, [] {
    Binding b = config_field<&C::position_scaler>();
    // The drive's velocity units follow it (rpm = 2058 units / 60 s).
    b.set = [](Module& m, uint8_t, int64_t v) {
      m.axis().config.position_scaler = static_cast<int32_t>(v);
      m.drive().manufacturer.set_position_scaler(static_cast<int32_t>(v));
      return SdoAbort::kNone;
    };
    return b;
  }()));
  // 2060: the phase current ADCs (AP 0..6). The offsets' EDS default 0 would read mid-scale as a
  // full-scale current: the TMCL firmware's mid-scale 32767 instead.
  t.add(count_entry(0x2060, ObjectCode::kRecord, "ADC Configuration", 7, "Highest sub-index supported", Access::kRo));
  t.add(reading(0x2060, 1, ObjectCode::kRecord, "ADC Configuration", "ADC_I0_Raw", kUnsigned16, 0, r::kU16Max,
                [](Module& m, uint8_t) -> int64_t { return m.axis().state.adc_phase_a_raw; }));
  t.add(reading(0x2060, 2, ObjectCode::kRecord, "ADC Configuration", "ADC_I1_Raw", kUnsigned16, 0, r::kU16Max,
                [](Module& m, uint8_t) -> int64_t { return m.axis().state.adc_phase_b_raw; }));
  t.add(setting<&C::adc_phase_a_offset>(0x2060, 3, "ADC Configuration", "ADC_I0_Offset", kUnsigned16, 0, r::kU16Max,
                                        32767));
  t.add(setting<&C::adc_phase_b_offset>(0x2060, 4, "ADC Configuration", "ADC_I1_Offset", kUnsigned16, 0, r::kU16Max,
                                        32767));
  t.add(reading(0x2060, 5, ObjectCode::kRecord, "ADC Configuration", "ADC_I0", kInteger16, kI16Min, kI16Max,
                [](Module& m, uint8_t) -> int64_t { return m.axis().state.adc_phase_a; }));
  t.add(reading(0x2060, 6, ObjectCode::kRecord, "ADC Configuration", "ADC_I1", kInteger16, kI16Min, kI16Max,
                [](Module& m, uint8_t) -> int64_t { return m.axis().state.adc_phase_b; }));
  t.add(reading(0x2060, 7, ObjectCode::kRecord, "ADC Configuration", "ADC_I2", kInteger16, kI16Min, kI16Max,
                [](Module& m, uint8_t) -> int64_t { return m.axis().state.adc_phase_c; }));
  // 2070: hall sensors (AP 90..93).
  t.add(count_entry(0x2070, ObjectCode::kRecord, "Hall Sensor Settings", 4, "Highest sub-index supported",
                    Access::kConst));
  t.add(setting<&C::hall_polarity>(0x2070, 1, "Hall Sensor Settings", "Polarity", kUnsigned8, 0, 1, 0));
  t.add(setting<&C::hall_direction>(0x2070, 2, "Hall Sensor Settings", "Direction", kUnsigned8, 0, 1, 0));
  t.add(setting<&C::hall_interpolation>(0x2070, 3, "Hall Sensor Settings", "Interpolation", kUnsigned8, 0, 1, 0));
  t.add(setting<&C::hall_phi_e_offset>(0x2070, 4, "Hall Sensor Settings", "PHI_E_Offset", kInteger16, kI16Min, kI16Max,
                                       0));
  // 2080: the ABN encoder (AP 101, 100, 102). Steps: the EDS's 0 would leave hall and open-loop
  // velocities without a unit; 8192, the TMCL firmware's default.
  t.add(count_entry(0x2080, ObjectCode::kRecord, "ABN Encoder Settings", 3, "Highest sub-index supported",
                    Access::kConst));
  t.add(setting<&C::encoder_direction>(0x2080, 1, "ABN Encoder Settings", "Direction", kUnsigned8, 0, 1, 0));
  t.add(setting<&C::encoder_steps>(0x2080, 2, "ABN Encoder Settings", "Steps", kUnsigned16, 0, r::kU16Max, 8192));
  t.add(setting<&C::encoder_init_mode>(0x2080, 3, "ABN Encoder Settings", "Init_Mode", kUnsigned8, 0, 2, 0));
  // 2085: the absolute encoder (AP 160..163, 165..167); the EDS gives subs 5..7 no default.
  t.add(count_entry(0x2085, ObjectCode::kRecord, "ABS Encoder Settings", 7, "numOfEntries", Access::kConst));
  t.add(setting<&C::absolute_encoder_type>(0x2085, 1, "ABS Encoder Settings", "Type", kUnsigned8, 0, 2, 0));
  t.add(setting<&C::absolute_encoder_direction>(0x2085, 2, "ABS Encoder Settings", "Direction", kUnsigned8, 0, 1, 0));
  t.add(setting<&C::absolute_encoder_init>(0x2085, 3, "ABS Encoder Settings", "Init_Mode", kUnsigned8, 0, 1, 0));
  t.add(setting<&C::absolute_encoder_offset>(0x2085, 4, "ABS Encoder Settings", "Offset", kUnsigned32, 0, r::kU16Max, 0));
  t.add(setting<&C::absolute_encoder_data_length>(0x2085, 5, "ABS Encoder Settings", "Data_Length", kUnsigned8, 1, 32,
                                                  16));
  t.add(setting<&C::absolute_encoder_position_start>(0x2085, 6, "ABS Encoder Settings", "Position_Start", kUnsigned8, 0,
                                                     31, 0));
  t.add(setting<&C::absolute_encoder_position_length>(0x2085, 7, "ABS Encoder Settings", "Position_Length", kUnsigned8,
                                                      1, 32, 16));
  // Live values (AP 156, 16..18; the drive's 607C).
  t.add(r::var<Module>(0x2101, "Status Flags", kUnsigned32, Access::kRo, 0, r::kU32Max, 0,
                       r::getter<Module>([](Module& m, uint8_t) -> int64_t { return m.status_flags(); })));
  t.add(r::var<Module>(0x2102, "Open Loop Commutation Angle", kInteger16, Access::kRo, kI16Min, kI16Max, 0,
                       state_value<&S::open_loop_angle>()));
  t.add(r::var<Module>(0x2103, "Encoder Commutation Angle", kInteger16, Access::kRo, kI16Min, kI16Max, 0,
                       state_value<&S::encoder_angle>()));
  t.add(r::var<Module>(0x2104, "Hall Commutation Angle", kInteger16, Access::kRo, kI16Min, kI16Max, 0,
                       state_value<&S::hall_angle>()));
  t.add(r::var<Module>(0x2140, "Home Offset Display", kInteger32, Access::kRo, r::kI32Min, r::kI32Max, 0,
                       r::getter<Module>([](Module& m, uint8_t) -> int64_t { return m.drive().objects.home_offset; })));
}

constexpr void add_device_rows(Table& t) {
  t.add(r::var<Module>(0x2702, "Device Digital Inputs", kUnsigned32, Access::kRo, 0, r::kU32Max, 0,
                       r::getter<Module>([](Module& m, uint8_t) -> int64_t { return m.device_digital_inputs(); })));
  t.add(count_entry(0x2703, ObjectCode::kArray, "Device Digital Outputs", 2, "Highest sub-index supported",
                    Access::kConst));
  {
    Binding b = canopen::field_binding<Module, [](Module& m, uint8_t) -> uint32_t& { return m.objects().outputs; }>();
    b.set = [](Module& m, uint8_t, int64_t v) {
      m.write_outputs(static_cast<uint32_t>(v));
      return SdoAbort::kNone;
    };
    // GPO0 and GPO1 only: other bits name no output (the family's 2703, docs/canopen.md).
    b.check = [](Module&, uint8_t, int64_t v) {
      return (static_cast<uint32_t>(v) & ~kCanopenOutputBits) == 0 ? SdoAbort::kNone : SdoAbort::kInvalidValue;
    };
    t.add(r::row<Module>(0x2703, 1, ObjectCode::kArray, "Device Digital Outputs", "Pysical Outputs", kUnsigned32,
                         Access::kRw, 0, r::kU32Max, 0, b));
  }
  t.add(stored(r::row<Module>(0x2703, 2, ObjectCode::kArray, "Device Digital Outputs", "Output Mask", kUnsigned32,
                              Access::kRw, 0, r::kU32Max, 0,
                              canopen::field_binding<Module, [](Module& m, uint8_t) -> uint32_t& {
                                return m.objects().output_mask;
                              }>()),
               kApplication));
  // Node ID and bit rate: what applies after the next reset (the EDS gives no defaults).
  t.add(stored(r::var<Module>(0x2704, "CAN Bit Rate", kUnsigned16, Access::kRw, 20, 1000, 1000,
                              canopen::node_bit_rate_binding<Module>()),
               kNode));
  {
    Binding b = canopen::node_id_binding<Module>();
    b.check = nullptr;  // no LSS on this firmware: 1..127 only (the range)
    t.add(stored(r::var<Module>(0x2705, "Node-ID", kUnsigned8, Access::kRw, 1, 127, 1, b), kNode));
  }
  t.add(count_entry(0x2706, ObjectCode::kArray, "Store", 1, "Highest sub-index supported", Access::kConst));
  {
    // The same as 1010 sub 1.
    Binding b;
    b.set = [](Module& m, uint8_t, int64_t v) { return m.node().store_parameters(1, static_cast<uint32_t>(v)); };
    t.add(r::row<Module>(0x2706, 1, ObjectCode::kArray, "Store", "Save all Parameters", kUnsigned32, Access::kRw, 0,
                         r::kU32Max, 1, b));
  }
  // 270E: the analog inputs' raw readings (AI0, AI1, the supply and the temperature ADC).
  t.add(count_entry(0x270E, ObjectCode::kArray, "Analog Inputs", 4, "Highest sub-index supported", Access::kConst));
  constexpr std::string_view kAnalogNames[] = {"AIN_0", "AIN_1", "ADC_VM", "ADC_TEMP"};
  t.add(reading(0x270E, 1, ObjectCode::kArray, "Analog Inputs", kAnalogNames[0], kUnsigned32, 0, r::kU32Max,
                [](Module& m, uint8_t) -> int64_t { return m.io().analog_input(0); }));
  t.add(reading(0x270E, 2, ObjectCode::kArray, "Analog Inputs", kAnalogNames[1], kUnsigned32, 0, r::kU32Max,
                [](Module& m, uint8_t) -> int64_t { return m.io().analog_input(1); }));
  t.add(reading(0x270E, 3, ObjectCode::kArray, "Analog Inputs", kAnalogNames[2], kUnsigned32, 0, r::kU32Max,
                [](Module& m, uint8_t) -> int64_t { return m.io().analog_input(2); }));
  t.add(reading(0x270E, 4, ObjectCode::kArray, "Analog Inputs", kAnalogNames[3], kUnsigned32, 0, r::kU32Max,
                [](Module& m, uint8_t) -> int64_t { return m.io().analog_input(3); }));
  {
    Binding b;
    b.check = [](Module&, uint8_t, int64_t v) {
      return v == kBootModeKey ? SdoAbort::kDataTransfer : SdoAbort::kNone;
    };
    b.set = [](Module&, uint8_t, int64_t) { return SdoAbort::kNone; };
    t.add(r::var<Module>(0x5FFF, "Enter Boot Mode", kUnsigned32, Access::kRw, 0, r::kU32Max, 0, b));
  }
}

constexpr void add_drive_rows(Table& t) {
  cia402::add_profile_rows<Module>(
      t, kProfileRows, [](Table&) {},
      [](Table& rows) {
        // 6074 / 6077: the current regulator's target and actual torque (AP 30, 31), in the host's
        // direction; 60FD.
        rows.add(r::mappable(r::var<Module>(0x6077, "Torque Actual Value", kInteger16, Access::kRo, kI16Min, kI16Max, 0,
                                            r::getter<Module>([](Module& m, uint8_t) -> int64_t {
                                              return m.directed(m.axis().state.actual_torque_ma);
                                            }))));
        rows.add(r::var<Module>(0x6074, "Torque Demand Value", kInteger16, Access::kRo, kI16Min, kI16Max, 0,
                                r::getter<Module>([](Module& m, uint8_t) -> int64_t {
                                  return m.directed(m.axis().state.target_torque_ma);
                                })));
        rows.add(r::mappable(r::var<Module>(0x60FD, "Digital Inputs", kUnsigned32, Access::kRo, 0, r::kU32Max, 0,
                                            r::getter<Module>([](Module& m, uint8_t) -> int64_t {
                                              return m.digital_inputs();
                                            }))));
      });
}

constexpr Table build_table() {
  Table t;
  canopen::add_communication_rows<Module, Table, kCommunication>(t);
  add_motor_rows(t);
  add_device_rows(t);
  add_drive_rows(t);
  return t;
}

constexpr Table kTable = build_table();

}  // namespace

std::span<const Module::Row> Tmcm1636Canopen::object_table() { return {kTable.rows.data(), kTable.count}; }

}  // namespace motwin::modules::tmcm1636
