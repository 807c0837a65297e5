#include "sim/modules/tmcm1636/motor_description.h"

#include <algorithm>
#include <cctype>
#include <charconv>
#include <cmath>
#include <fstream>
#include <limits>
#include <set>
#include <span>
#include <sstream>
#include <variant>

#include <nlohmann/json.hpp>

namespace motwin::sim {
namespace {

using Json = nlohmann::json;
using OrderedJson = nlohmann::ordered_json;

// Start-up settings shared by the BLDC presets: hall commutation (works at once, no
// initialisation), position and velocity from the ABN encoder, hall interpolation on, the hall
// sensors as the encoder alignment when a host selects ABN commutation (SAP 15, 0, 3).
StartupSettings bldc_startup() {
  StartupSettings s;
  s.commutation = CommutationSensor::kHall;
  s.position_sensor = PositionSensor::kAbnEncoder;
  s.hall_interpolation = true;
  s.encoder_alignment = EncoderAlignment::kHall;
  return s;
}

MotorDescription default_24v() {
  MotorDescription m;
  m.name = "default-24v";
  m.source =
      "42 mm 24 V BLDC motor with 4 pole pairs, hall sensors and a 1024-line (4096-count) ABN "
      "encoder, modelled on the datasheet of the Trinamic QBL4208-61-04-013 (line-to-line 0.8 ohm "
      "and 1.2 mH, torque constant 0.035 N m/A, rotor inertia 48 g cm^2) with plainly wired "
      "sensors (no polarity or direction setting needed; for Trinamic's wiring see "
      "qbl4208-61-04-013); friction chosen for a no-load current of about 0.3 A at 4000 rpm";
  m.kind = MotorKind::kBldc;
  m.pole_pairs = 4;
  m.resistance_ohm = 0.4;
  m.inductance_d_h = 0.6e-3;
  m.inductance_q_h = 0.6e-3;
  m.flux_linkage_wb = 0.035 / (1.5 * 4);
  m.rotor_inertia_kgm2 = 4.8e-6;
  m.viscous_friction_nm_s = 1.5e-5;
  m.coulomb_friction_nm = 0.004;
  m.initial_angle_deg = 40.0;
  m.abn = {true, 4096, 200.0, false};
  m.supply = {24.0, 0.1, 470e-6, 10.0, false};
  StartupSettings s = bldc_startup();
  s.max_current_ma = 2000;
  s.open_loop_current_ma = 1000;
  s.current_p = 461;  // current loop at 3000 rad/s: P = L w, I = R w (docs/tmcm-1636-servo.md)
  s.current_i = 3932;
  s.velocity_p = 1200;  // velocity loop at about 340 rad/s, integral zero at 78 rad/s
  s.velocity_i = 4800;
  s.position_p = 75;  // position loop at 80 rad/s (1.07 rad/s per unit of P)
  m.startup = s;
  return m;
}

// Trinamic's reference motor, the one the TMCM-1636 examples of PyTrinamic name, with its sensors
// wired as on Trinamic's setup: the examples set hall polarity AP 90 = 1 and encoder direction
// AP 101 = 1, so here the hall levels are inverted and the encoder counts down for forward
// rotation (docs/tmcm-1636-servo.md "Presets").
MotorDescription qbl4208_61_04_013() {
  MotorDescription m = default_24v();  // the same 42 mm motor; what its datasheet and wiring change
  m.name = "qbl4208-61-04-013";
  m.source =
      "Trinamic QBL4208-61-04-013 (-1024-AT in the older order code), datasheet QBL4208-x-1k "
      "Rev 1.40: 4 pole pairs, 24 V, 4000 rpm rated, 3.47 A rated, line-to-line 0.72 ohm and "
      "1.2 mH, torque constant 0.036 N m/A, rotor inertia 48 g cm^2; hall sensors and a 4096-count "
      "ABN encoder wired as on Trinamic's setup (hall polarity and encoder direction 1); friction "
      "chosen for a no-load current of about 0.3 A at 4000 rpm";
  m.resistance_ohm = 0.36;  // star equivalent of the delta winding: half the line-to-line value
  m.flux_linkage_wb = 0.036 / (1.5 * 4);
  m.hall.inverted = true;
  m.abn.reversed = true;
  m.startup->hall_polarity_inverted = true;  // AP 90 = 1, as the examples set it
  m.startup->encoder_direction_reversed = true;  // AP 101 = 1
  m.startup->current_i = 3539;  // I = R w with the datasheet's resistance
  return m;
}

MotorDescription large_48v() {
  MotorDescription m;
  m.name = "large-48v";
  m.source =
      "63 mm outrunner class (ODrive's D5065-270KV): 7 pole pairs, 0.039 ohm and 15.7 uH per "
      "phase, KV 270 rpm/V (torque constant 8.27/KV = 0.0306 N m/A), inertia 1e-4 kg m^2 "
      "(docs/tmcm-1636-servo.md \"Presets\"); hall sensors and an 8192-count ABN encoder "
      "(AMT102 at 2048 lines); friction chosen";
  m.kind = MotorKind::kBldc;
  m.pole_pairs = 7;
  m.resistance_ohm = 0.039;
  m.inductance_d_h = 15.7e-6;
  m.inductance_q_h = 15.7e-6;
  m.flux_linkage_wb = (8.27 / 270.0) / (1.5 * 7);
  m.rotor_inertia_kgm2 = 1e-4;
  m.viscous_friction_nm_s = 5e-5;
  m.coulomb_friction_nm = 0.01;
  m.initial_angle_deg = 17.0;
  m.abn = {true, 8192, 0.0, false};
  m.supply = {48.0, 0.05, 1000e-6, 5.0, false};
  StartupSettings s = bldc_startup();
  s.max_current_ma = 10000;
  s.open_loop_current_ma = 3000;
  s.brake_chopper_voltage_v = 52.0;  // the chopper's factory limit (26 V) is below this bus
  s.current_p = 20;  // current loop at 5000 rad/s
  s.current_i = 639;
  s.velocity_p = 13100;
  s.velocity_i = 25200;
  s.position_p = 28;  // position loop at 30 rad/s
  m.startup = s;
  return m;
}

MotorDescription dc_24v() {
  MotorDescription m;
  m.name = "dc-24v";
  m.source =
      "generic 24 V brushed DC motor of about 60 W with a 512-line (2048-count) ABN encoder; "
      "values chosen to be typical (terminal resistance 2 ohm, 1 mH, 0.05 N m/A), not taken from "
      "one datasheet";
  m.kind = MotorKind::kDc;
  m.pole_pairs = 1;
  m.resistance_ohm = 2.0;
  m.inductance_d_h = 1e-3;
  m.inductance_q_h = 1e-3;
  m.flux_linkage_wb = 0.0;
  m.torque_constant_nm_per_a = 0.05;
  m.rotor_inertia_kgm2 = 1.5e-5;
  m.viscous_friction_nm_s = 2e-6;
  m.coulomb_friction_nm = 0.005;
  m.initial_angle_deg = 0.0;
  m.hall.present = false;
  m.abn = {true, 2048, 90.0, false};
  m.supply = {24.0, 0.1, 470e-6, 10.0, false};
  // A DC motor needs no commutation angle; any sensor but "none" switches the bridge on.
  StartupSettings s;
  s.max_current_ma = 2000;
  s.commutation = CommutationSensor::kAbnEncoder;
  s.position_sensor = PositionSensor::kAbnEncoder;
  s.current_p = 768;  // current loop at 3000 rad/s
  s.current_i = 19660;
  s.velocity_p = 1200;
  s.velocity_i = 2320;
  s.position_p = 28;  // position loop at 30 rad/s
  m.startup = s;
  return m;
}

struct Reader {
  const Json& object;
  std::string path;
  std::string& error;
  std::set<std::string> seen{};

  bool ok() const { return error.empty(); }
  void fail(const std::string& what) {
    if (error.empty()) error = what;
  }
  const Json* find(const char* key) {
    seen.insert(key);
    const auto it = object.find(key);
    return it == object.end() ? nullptr : &*it;
  }
  std::string where(const char* key) const { return path.empty() ? key : path + "." + key; }
  void number(const char* key, double& out, double min, double max) {
    const Json* value = find(key);
    if (value == nullptr) return;
    if (!value->is_number()) return fail(where(key) + " must be a number");
    const double v = value->get<double>();
    if (!std::isfinite(v) || v < min || v > max) {
      std::ostringstream text;
      text << where(key) << " must be from " << min << " to " << max << ", got " << v;
      return fail(text.str());
    }
    out = v;
  }
  void integer(const char* key, int& out, int min, int max) {
    double v = out;
    number(key, v, min, max);
    if (std::floor(v) != v) return fail(where(key) + " must be a whole number");
    out = static_cast<int>(v);
  }
  void flag(const char* key, bool& out) {
    const Json* value = find(key);
    if (value == nullptr) return;
    if (!value->is_boolean()) return fail(where(key) + " must be true or false");
    out = value->get<bool>();
  }
  void text(const char* key, std::string& out) {
    const Json* value = find(key);
    if (value == nullptr) return;
    if (!value->is_string()) return fail(where(key) + " must be a string");
    out = value->get<std::string>();
  }
  // Every key must be known: a misspelt key would otherwise be silently ignored.
  void finish() {
    for (const auto& [key, value] : object.items()) {
      if (seen.count(key) == 0) return fail("unknown key " + (path.empty() ? key : path + "." + key));
    }
  }
};

// One plain key of the file format: a member of MotorDescription or of one of its sections, with
// the range a number must be in. The tables below are what the parser reads and what
// motor_description_json() writes, in this order, so the two cannot drift apart.
template <typename Section>
struct Field {
  const char* key;
  std::variant<double Section::*, int Section::*, bool Section::*> member;
  double min = 0.0;
  double max = 0.0;
};

using Hall = MotorDescription::Hall;
using Abn = MotorDescription::Abn;
using Absolute = MotorDescription::Absolute;
using Brake = MotorDescription::Brake;
using Supply = MotorDescription::Supply;

// Top-level numbers without special rules (type, pole pairs, inductance_h and the magnet
// strength are read by hand: they depend on each other).
const Field<MotorDescription> kMotorFields[] = {
    {"resistance_ohm", &MotorDescription::resistance_ohm, 1e-4, 1000.0},
    {"inductance_d_h", &MotorDescription::inductance_d_h, 1e-7, 1.0},
    {"inductance_q_h", &MotorDescription::inductance_q_h, 1e-7, 1.0},
    {"rotor_inertia_kgm2", &MotorDescription::rotor_inertia_kgm2, 1e-9, 100.0},
    {"viscous_friction_nm_s", &MotorDescription::viscous_friction_nm_s, 0.0, 100.0},
    {"coulomb_friction_nm", &MotorDescription::coulomb_friction_nm, 0.0, 1000.0},
    {"initial_angle_deg", &MotorDescription::initial_angle_deg, -360.0, 360.0},
};
const Field<Hall> kHallFields[] = {
    {"present", &Hall::present},
    {"offset_deg", &Hall::offset_deg, -360.0, 360.0},
    {"inverted", &Hall::inverted},
    {"reversed", &Hall::reversed},
};
const Field<Abn> kAbnFields[] = {
    {"present", &Abn::present},
    {"counts_per_rev", &Abn::counts_per_rev, 4, 16777215},
    {"index_deg", &Abn::index_deg, -360.0, 360.0},
    {"reversed", &Abn::reversed},
};
const Field<Absolute> kAbsoluteFields[] = {
    {"present", &Absolute::present},
    {"bits", &Absolute::bits, 8, 16},
    {"offset_deg", &Absolute::offset_deg, -360.0, 360.0},
    {"reversed", &Absolute::reversed},
};
const Field<Brake> kBrakeFields[] = {
    {"present", &Brake::present},
    {"holding_torque_nm", &Brake::holding_torque_nm, 0.0, 1000.0},
    {"pull_in_duty_percent", &Brake::pull_in_duty_percent, 0.0, 100.0},
    {"drop_out_duty_percent", &Brake::drop_out_duty_percent, 0.0, 100.0},
    {"time_constant_s", &Brake::time_constant_s, 1e-4, 10.0},
};
const Field<Supply> kSupplyFields[] = {
    {"voltage_v", &Supply::voltage_v, 0.0, 100.0},
    {"source_resistance_ohm", &Supply::source_resistance_ohm, 1e-3, 100.0},
    {"capacitance_f", &Supply::capacitance_f, 1e-6, 10.0},
    {"brake_resistor_ohm", &Supply::brake_resistor_ohm, 0.1, 1e4},
    {"regenerative", &Supply::regenerative},
};

template <typename... Ts>
struct Overloaded : Ts... {
  using Ts::operator()...;
};
template <typename... Ts>
Overloaded(Ts...) -> Overloaded<Ts...>;  // clang 14 has no aggregate deduction yet

template <typename Section>
void read_fields(Reader& reader, Section& out, std::span<const Field<Section>> fields) {
  for (const Field<Section>& field : fields) {
    std::visit(Overloaded{
                   [&](double Section::*member) { reader.number(field.key, out.*member, field.min, field.max); },
                   [&](int Section::*member) {
                     reader.integer(field.key, out.*member, static_cast<int>(field.min), static_cast<int>(field.max));
                   },
                   [&](bool Section::*member) { reader.flag(field.key, out.*member); },
               },
               field.member);
  }
}

template <typename Section>
void write_fields(OrderedJson& j, const Section& section, std::span<const Field<Section>> fields) {
  for (const Field<Section>& field : fields) {
    std::visit([&](auto member) { j[field.key] = section.*member; }, field.member);
  }
}

// A sub-object ("hall", "brake", ...). A section that has a "present" key counts as present when
// the file gives it, unless it says "present": false.
template <typename Section>
void read_section(Reader& parent, const char* key, Section& out, std::span<const Field<Section>> fields) {
  const Json* section = parent.find(key);
  if (section == nullptr || !parent.ok()) return;
  if (!section->is_object()) return parent.fail(parent.where(key) + " must be an object");
  if constexpr (requires { out.present; }) out.present = true;
  Reader reader{*section, parent.where(key), parent.error};
  read_fields(reader, out, fields);
  if (reader.ok()) reader.finish();
}

template <typename Section>
OrderedJson section_json(const Section& section, std::span<const Field<Section>> fields) {
  OrderedJson j = OrderedJson::object();
  write_fields(j, section, fields);
  return j;
}

// The "startup" section (StartupSettings), key by key in this order; enumerations by name.
template <typename E>
struct EnumName {
  E value;
  const char* name;
};
constexpr EnumName<CommutationSensor> kCommutationNames[] = {
    {CommutationSensor::kOpenLoop, "open_loop"},
    {CommutationSensor::kHall, "hall"},
    {CommutationSensor::kAbnEncoder, "abn_encoder"},
    {CommutationSensor::kAbsoluteEncoder, "absolute_encoder"},
};
constexpr EnumName<PositionSensor> kPositionSensorNames[] = {
    {PositionSensor::kAbnEncoder, "abn_encoder"},
    {PositionSensor::kAbsoluteEncoder, "absolute_encoder"},
};
constexpr EnumName<EncoderAlignment> kEncoderAlignmentNames[] = {
    {EncoderAlignment::kEstimateOffset, "estimate_offset"},
    {EncoderAlignment::kIndexPulse, "index_pulse"},
    {EncoderAlignment::kHall, "hall"},
};
std::span<const EnumName<CommutationSensor>> names_of(CommutationSensor) { return kCommutationNames; }
std::span<const EnumName<PositionSensor>> names_of(PositionSensor) { return kPositionSensorNames; }
std::span<const EnumName<EncoderAlignment>> names_of(EncoderAlignment) { return kEncoderAlignmentNames; }

template <typename T>
using Setting = std::optional<T> StartupSettings::*;

struct StartupField {
  const char* key;
  std::variant<Setting<int32_t>, Setting<double>, Setting<bool>, Setting<CommutationSensor>, Setting<PositionSensor>,
               Setting<EncoderAlignment>>
      member;
  double min = 0.0;
  double max = 0.0;
};

// Plausible for any motor; the drive's own ranges are checked where the settings are written.
const StartupField kStartupFields[] = {
    {"max_current_ma", &StartupSettings::max_current_ma, 0, 1e6},
    {"open_loop_current_ma", &StartupSettings::open_loop_current_ma, 0, 1e6},
    {"commutation", &StartupSettings::commutation},
    {"position_sensor", &StartupSettings::position_sensor},
    {"hall_polarity_inverted", &StartupSettings::hall_polarity_inverted},
    {"hall_direction_reversed", &StartupSettings::hall_direction_reversed},
    {"hall_interpolation", &StartupSettings::hall_interpolation},
    {"encoder_direction_reversed", &StartupSettings::encoder_direction_reversed},
    {"encoder_alignment", &StartupSettings::encoder_alignment},
    {"brake_chopper_voltage_v", &StartupSettings::brake_chopper_voltage_v, 0.0, 1000.0},
    {"current_p", &StartupSettings::current_p, 0, 2147483647.0},
    {"current_i", &StartupSettings::current_i, 0, 2147483647.0},
    {"velocity_p", &StartupSettings::velocity_p, 0, 2147483647.0},
    {"velocity_i", &StartupSettings::velocity_i, 0, 2147483647.0},
    {"position_p", &StartupSettings::position_p, 0, 2147483647.0},
};

template <typename E>
void read_enum(Reader& reader, const char* key, std::optional<E>& out) {
  std::string name;
  reader.text(key, name);
  if (!reader.ok()) return;
  std::string expected;
  for (const EnumName<E>& entry : names_of(E{})) {
    if (name == entry.name) {
      out = entry.value;
      return;
    }
    expected += std::string(expected.empty() ? "" : ", ") + "\"" + entry.name + "\"";
  }
  reader.fail(reader.where(key) + " must be one of " + expected + ", got \"" + name + "\"");
}

template <typename E>
const char* enum_name(E value) {
  for (const EnumName<E>& entry : names_of(E{})) {
    if (entry.value == value) return entry.name;
  }
  return "";
}

// The "startup" object: present (even empty) means the description has start-up settings.
void read_startup(Reader& parent, std::optional<StartupSettings>& out) {
  const Json* section = parent.find("startup");
  if (section == nullptr || !parent.ok()) return;
  if (!section->is_object()) return parent.fail("startup must be an object");
  StartupSettings settings = out.value_or(StartupSettings{});  // a preset's, changed key by key
  Reader reader{*section, "startup", parent.error};
  for (const StartupField& field : kStartupFields) {
    if (!reader.ok()) return;
    if (!section->contains(field.key)) continue;
    std::visit(Overloaded{
                   [&](Setting<int32_t> member) {
                     int value = 0;
                     reader.integer(field.key, value, static_cast<int>(field.min), static_cast<int>(field.max));
                     settings.*member = value;
                   },
                   [&](Setting<double> member) {
                     double value = 0.0;
                     reader.number(field.key, value, field.min, field.max);
                     settings.*member = value;
                   },
                   [&](Setting<bool> member) {
                     bool value = false;
                     reader.flag(field.key, value);
                     settings.*member = value;
                   },
                   [&](auto member) { read_enum(reader, field.key, settings.*member); },
               },
               field.member);
  }
  if (!reader.ok()) return;
  reader.finish();
  out = settings;
}

OrderedJson startup_json(const StartupSettings& settings) {
  OrderedJson j = OrderedJson::object();
  for (const StartupField& field : kStartupFields) {
    std::visit(Overloaded{
                   [&](Setting<int32_t> member) {
                     if (settings.*member) j[field.key] = *(settings.*member);
                   },
                   [&](Setting<double> member) {
                     if (settings.*member) j[field.key] = *(settings.*member);
                   },
                   [&](Setting<bool> member) {
                     if (settings.*member) j[field.key] = *(settings.*member);
                   },
                   [&](auto member) {
                     if (settings.*member) j[field.key] = enum_name(*(settings.*member));
                   },
               },
               field.member);
  }
  return j;
}

// "type": "bldc" (the default) or "dc"; a DC motor has no hall sensors.
void read_kind(Reader& top, MotorDescription& m) {
  std::string kind = "bldc";
  top.text("type", kind);
  if (top.find("type") == nullptr) return;  // a preset's kind stays (a new description is BLDC)
  if (kind == "dc") {
    m.kind = MotorKind::kDc;
    m.hall.present = false;
  } else if (kind == "bldc") {
    m.kind = MotorKind::kBldc;
  } else {
    top.fail("type must be \"bldc\" or \"dc\", got \"" + kind + "\"");
  }
}

// The magnet strength, in whichever form the datasheet gives it: a DC motor's torque constant,
// or a BLDC motor's flux linkage, torque constant or KV. After "type" and "pole_pairs". A preset's
// stays when the file gives none.
void read_magnet_strength(Reader& top, MotorDescription& m, bool from_preset) {
  constexpr double kMinFluxLinkageWb = 1e-6;
  constexpr double kMaxFluxLinkageWb = 10.0;
  double flux = -1.0;
  double kt = -1.0;
  double kv = -1.0;
  top.number("flux_linkage_wb", flux, kMinFluxLinkageWb, kMaxFluxLinkageWb);
  top.number("torque_constant_nm_per_a", kt, 1e-5, 100.0);
  top.number("kv_rpm_per_v", kv, 0.1, 1e5);
  if (from_preset && flux <= 0.0 && kt <= 0.0 && kv <= 0.0) return;
  if (m.kind == MotorKind::kDc) {
    if (kt <= 0.0) top.fail("a DC motor needs torque_constant_nm_per_a");
    m.torque_constant_nm_per_a = kt;
    m.pole_pairs = 1;
  } else if (flux > 0.0) {
    m.flux_linkage_wb = flux;
  } else if (kt > 0.0 || kv > 0.0) {
    const char* given = kt > 0.0 ? "torque_constant_nm_per_a" : "kv_rpm_per_v";
    const double kt_nm_per_a = kt > 0.0 ? kt : 8.27 / kv;  // Kt = 8.27 / KV (ODrive, moteus)
    const double derived = kt_nm_per_a / (1.5 * m.pole_pairs);
    // The derived flux linkage is what the file is written back with: it must load again
    // (found by fuzz/motor_description.cpp: Kt 50 N·m/A on 2 pole pairs is 16.8 Wb).
    if (derived < kMinFluxLinkageWb || derived > kMaxFluxLinkageWb) {
      std::ostringstream text;
      text << given << " with " << m.pole_pairs << " pole pairs gives a flux linkage of " << derived
           << " Wb; it must be from " << kMinFluxLinkageWb << " to " << kMaxFluxLinkageWb;
      return top.fail(text.str());
    }
    m.flux_linkage_wb = derived;
  } else {
    top.fail("give one of flux_linkage_wb, torque_constant_nm_per_a or kv_rpm_per_v");
  }
}

// An "axis_parameters" key: a decimal parameter number as strtol reads it (leading blanks and
// a sign allowed, nothing after the digits); nullopt for anything else or a negative number.
std::optional<int> parameter_number(std::string_view key) {
  while (!key.empty() && std::isspace(static_cast<unsigned char>(key.front()))) key.remove_prefix(1);
  if (key.starts_with('+')) key.remove_prefix(1);
  int number = -1;
  const auto [end, problem] = std::from_chars(key.data(), key.data() + key.size(), number);
  if (key.empty() || problem != std::errc{} || end != key.data() + key.size() || number < 0) return std::nullopt;
  return number;
}

// One "axis_parameters" entry: success when it can go into the image; `check` knows the firmware.
Result<void> check_axis_parameter(int number, int64_t value, const AxisParameterCheck& check) {
  if (check) {
    if (Result<void> checked = check(number, value); !checked) return checked;
  }
  // TMCL parameter numbers are one byte and values 32 bits, whatever the firmware.
  if (number > 255) return Error{"axis parameter " + std::to_string(number) + " does not exist"};
  if (value < std::numeric_limits<int32_t>::min() || value > std::numeric_limits<int32_t>::max()) {
    return Error{"axis parameter " + std::to_string(number) + " takes 32-bit values, got " + std::to_string(value)};
  }
  return {};
}

// "axis_parameters": {"number": value, ...}, kept in parameter-number order.
void read_axis_parameters(Reader& top, const AxisParameterCheck& check, std::vector<std::pair<uint8_t, int32_t>>& out) {
  const Json* parameters = top.find("axis_parameters");
  if (parameters == nullptr || !top.ok()) return;
  if (!parameters->is_object()) return top.fail("axis_parameters must be an object of \"number\": value");
  for (const auto& [key, value] : parameters->items()) {
    const std::optional<int> number = parameter_number(key);
    if (!number) return top.fail("axis_parameters: \"" + key + "\" is not a parameter number");
    if (!value.is_number_integer()) return top.fail("axis_parameters." + key + " must be a whole number");
    const int64_t v = value.get<int64_t>();
    if (const Result<void> usable = check_axis_parameter(*number, v, check); !usable) {
      return top.fail("axis_parameters: " + usable.error());
    }
    const bool repeated =
        std::any_of(out.begin(), out.end(), [&number](const auto& entry) { return entry.first == *number; });
    if (repeated) {  // "5" and "05": which one wins would depend on the spelling
      return top.fail("axis_parameters: parameter " + std::to_string(*number) + " is given twice");
    }
    out.emplace_back(static_cast<uint8_t>(*number), static_cast<int32_t>(v));
  }
  // JSON objects have no order (the parser hands keys over sorted as text: "100" before "14"):
  // apply in parameter-number order, so that writing and reading a file keeps it.
  std::stable_sort(out.begin(), out.end(), [](const auto& a, const auto& b) { return a.first < b.first; });
}

}  // namespace

std::vector<std::string_view> motor_preset_names() {
  return {"default-24v", "qbl4208-61-04-013", "large-48v", "dc-24v"};
}

std::optional<MotorDescription> motor_preset(std::string_view name) {
  if (name == "default-24v") return default_24v();
  if (name == "qbl4208-61-04-013") return qbl4208_61_04_013();
  if (name == "large-48v") return large_48v();
  if (name == "dc-24v") return dc_24v();
  return std::nullopt;
}

Result<MotorDescription> parse_motor_description(std::string_view json_text, std::string_view source_name,
                                                 const AxisParameterCheck& check) {
  const std::string prefix = std::string(source_name) + ": ";
  const Json document = Json::parse(json_text.begin(), json_text.end(), nullptr, false, true);
  if (document.is_discarded()) return Error{prefix + "not valid JSON"};
  if (!document.is_object()) return Error{prefix + "expected a JSON object"};
  MotorDescription m;
  std::string error;
  Reader top{document, "", error};
  // "preset": the description starts from that preset and the other keys change it (a motor of
  // the bench with one sensor more, another supply), so the preset's figures are not copied.
  std::string preset_name;
  top.text("preset", preset_name);
  if (!preset_name.empty()) {
    std::optional<MotorDescription> preset = motor_preset(preset_name);
    if (!preset) return Error{prefix + "unknown preset \"" + preset_name + "\""};
    m = std::move(*preset);
    m.name.clear();
  }
  top.text("name", m.name);
  top.text("source", m.source);
  read_kind(top, m);
  top.integer("pole_pairs", m.pole_pairs, 1, 255);
  // Both inductances at once; inductance_d_h / inductance_q_h (kMotorFields) override it.
  double inductance = -1.0;
  top.number("inductance_h", inductance, 1e-7, 1.0);
  if (inductance > 0.0) m.inductance_d_h = m.inductance_q_h = inductance;
  read_magnet_strength(top, m, !preset_name.empty());
  read_fields<MotorDescription>(top, m, kMotorFields);
  read_section<Hall>(top, "hall", m.hall, kHallFields);
  read_section<Abn>(top, "abn_encoder", m.abn, kAbnFields);
  read_section<Absolute>(top, "absolute_encoder", m.absolute, kAbsoluteFields);
  read_section<Brake>(top, "brake", m.brake, kBrakeFields);
  read_section<Supply>(top, "supply", m.supply, kSupplyFields);
  read_startup(top, m.startup);
  std::vector<std::pair<uint8_t, int32_t>> listed;
  read_axis_parameters(top, check, listed);
  // A preset's own entries stay unless the file gives the same number.
  std::erase_if(m.axis_parameters, [&listed](const auto& kept) {
    return std::any_of(listed.begin(), listed.end(), [&kept](const auto& entry) { return entry.first == kept.first; });
  });
  m.axis_parameters.insert(m.axis_parameters.end(), listed.begin(), listed.end());
  std::stable_sort(m.axis_parameters.begin(), m.axis_parameters.end(),
                   [](const auto& a, const auto& b) { return a.first < b.first; });
  if (top.ok()) top.finish();
  if (!error.empty()) return Error{prefix + error};
  if (m.name.empty()) m.name = std::string(source_name);
  return m;
}

Result<MotorDescription> load_motor_description_file(const std::string& path, const AxisParameterCheck& check) {
  std::ifstream file(path);
  if (!file) return Error{"cannot read motor description " + path};
  std::stringstream contents;
  contents << file.rdbuf();
  return parse_motor_description(contents.str(), path, check);
}

Result<MotorChoice> resolve_motor(std::string_view name_or_path, const AxisParameterCheck& check) {
  if (name_or_path.empty() || name_or_path == "ideal") return MotorChoice{};
  if (std::optional<MotorDescription> preset = motor_preset(name_or_path)) return preset;
  if (name_or_path.find('/') == std::string_view::npos && name_or_path.find('.') == std::string_view::npos) {
    std::string names = "ideal";
    for (std::string_view preset_name : motor_preset_names()) names += ", " + std::string(preset_name);
    return Error{"unknown motor \"" + std::string(name_or_path) + "\" (expected " + names + " or a .json file)"};
  }
  Result<MotorDescription> described = load_motor_description_file(std::string(name_or_path), check);
  if (!described) return Error{described.error()};
  return MotorChoice{std::move(*described)};
}

std::string motor_description_json(const MotorDescription& m) {
  OrderedJson j;
  j["name"] = m.name;
  j["source"] = m.source;
  j["type"] = m.kind == MotorKind::kDc ? "dc" : "bldc";
  if (m.kind == MotorKind::kBldc) {
    j["pole_pairs"] = m.pole_pairs;
    j["flux_linkage_wb"] = m.flux_linkage_wb;
  } else {
    j["torque_constant_nm_per_a"] = m.torque_constant_nm_per_a;
  }
  write_fields<MotorDescription>(j, m, kMotorFields);
  j["hall"] = section_json<Hall>(m.hall, kHallFields);
  j["abn_encoder"] = section_json<Abn>(m.abn, kAbnFields);
  j["absolute_encoder"] = section_json<Absolute>(m.absolute, kAbsoluteFields);
  j["brake"] = section_json<Brake>(m.brake, kBrakeFields);
  j["supply"] = section_json<Supply>(m.supply, kSupplyFields);
  if (m.startup) j["startup"] = startup_json(*m.startup);
  OrderedJson parameters = OrderedJson::object();
  for (const auto& [number, value] : m.axis_parameters) parameters[std::to_string(number)] = value;
  j["axis_parameters"] = parameters;
  return j.dump(2) + "\n";
}

}  // namespace motwin::sim
