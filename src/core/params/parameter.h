// The declarative description of one exposed parameter (axis or global), as the manuals'
// tables give it: number, name, range, default, access letters, unit. Module tables are
// arrays of ParameterRow; the dispatcher, range checks, EEPROM layout and the CLI listing
// all walk those arrays (docs/architecture.md "Principles").
#pragma once

#include <cstdint>
#include <string_view>
#include <type_traits>
#include <utility>

#include "core/tmcl/status.h"

namespace motwin::params {

// Access letters of the manuals' access columns (TMCM-1636 table 12).
enum class Access : uint8_t {
  kNone = 0,
  kRead = 1 << 0,       // R: GAP/GGP
  kWrite = 1 << 1,      // W: SAP/SGP/AAP/AGP
  kEeprom = 1 << 2,     // E: STAP/RSAP/STGP/RSGP; restored at power-up
  kAutoStore = 1 << 3,  // A: every write is also stored in the EEPROM
  kExpert = 1 << 4,     // X: listed by the manual as a configuration parameter; informational
};

constexpr Access operator|(Access a, Access b) {
  return static_cast<Access>(static_cast<uint8_t>(a) | static_cast<uint8_t>(b));
}
constexpr bool has(Access set, Access flag) {
  return (static_cast<uint8_t>(set) & static_cast<uint8_t>(flag)) != 0;
}

// Deliberately not constexpr: reaching it during constant evaluation is a compile error.
void invalid_access_letter();

// "RWEX" -> flags. consteval so that a typo in a table fails to compile.
consteval Access access(std::string_view letters) {
  Access result = Access::kNone;
  for (char c : letters) {
    switch (c) {
      case 'R': result = result | Access::kRead; break;
      case 'W': result = result | Access::kWrite; break;
      case 'E': result = result | Access::kEeprom; break;
      case 'A': result = result | Access::kAutoStore; break;
      case 'X': result = result | Access::kExpert; break;
      default: invalid_access_letter(); break;
    }
  }
  return result;
}

// Writes the access letters (at most 5 characters plus NUL) into out.
inline void access_letters(Access set, char (&out)[6]) {
  int n = 0;
  if (has(set, Access::kRead)) out[n++] = 'R';
  if (has(set, Access::kWrite)) out[n++] = 'W';
  if (has(set, Access::kEeprom)) out[n++] = 'E';
  if (has(set, Access::kAutoStore)) out[n++] = 'A';
  if (has(set, Access::kExpert)) out[n++] = 'X';
  out[n] = '\0';
}

enum class Unit : uint8_t {
  kNone,
  kMilliampere,
  kRpm,
  kRpmPerSecond,
  kMillisecond,
  kHertz,
  kPercent,
  kDecivolt,         // 0.1 V
  kDegreeCelsius,
  kPerSecond,
  kPositionCount,    // position counter units (see docs/tmcm-1636.md)
  kAdcCount,
  kEncoderSteps,
  kBaudRateCode,
  kBitRateCode,
  kAddress,
  kMicrosteps,        // stepper position (TMCM-142)
  kSpeed,             // stepper velocity: TMC457 units or µsteps/s, per AP 255 (TMCM-142)
  kAcceleration,      // stepper acceleration: TMC457 units or µsteps/s² (TMCM-142)
  kTmc457Velocity,    // TMC457 velocity units whatever AP 255 says (TMCM-142)
  kTenMilliseconds,
  kMicrostepsPerSecond,         // stepper velocity in µsteps/s (TMCM-3216 TMCL)
  kMicrostepsPerSecondSquared,  // stepper acceleration in µsteps/s² (TMCM-3216 TMCL)
  kMicrosecond,
  kThirtyTwoMicroseconds,       // the EightPoint ramp's wait time (TMCM-3216)
};

constexpr std::string_view unit_symbol(Unit unit) {
  switch (unit) {
    case Unit::kNone: return "";
    case Unit::kMilliampere: return "mA";
    case Unit::kRpm: return "rpm";
    case Unit::kRpmPerSecond: return "rpm/s";
    case Unit::kMillisecond: return "ms";
    case Unit::kHertz: return "Hz";
    case Unit::kPercent: return "%";
    case Unit::kDecivolt: return "0.1V";
    case Unit::kDegreeCelsius: return "degC";
    case Unit::kPerSecond: return "1/s";
    case Unit::kPositionCount: return "counts";
    case Unit::kAdcCount: return "adc";
    case Unit::kEncoderSteps: return "steps";
    case Unit::kBaudRateCode: return "code";
    case Unit::kBitRateCode: return "code";
    case Unit::kAddress: return "address";
    case Unit::kMicrosteps: return "usteps";
    case Unit::kSpeed: return "v (AP 255)";
    case Unit::kAcceleration: return "a (AP 255)";
    case Unit::kTmc457Velocity: return "v457";
    case Unit::kTenMilliseconds: return "10ms";
    case Unit::kMicrostepsPerSecond: return "pps";
    case Unit::kMicrostepsPerSecondSquared: return "pps/s";
    case Unit::kMicrosecond: return "us";
    case Unit::kThirtyTwoMicroseconds: return "32us";
  }
  return "";
}

// Descriptions of parameters whose number or meaning no public source gives start with this tag
// (`motwin params` and the module docs show it; TMCM-142: docs/tmcm-142.md "Sources").
inline constexpr std::string_view kMotwinDecisionTag = "[Motwin decision] ";
constexpr bool is_motwin_decision(std::string_view description) { return description.starts_with(kMotwinDecisionTag); }

// What the manual says about one parameter. Pure data.
struct ParameterInfo {
  uint16_t number;
  std::string_view name;
  int64_t min;            // int64 so that unsigned 32-bit ranges (0..4294967295) fit
  int64_t max;
  int64_t default_value;
  Access access;
  Unit unit;
  std::string_view description;
};

// A wire value (always 32 bits) seen through the parameter's range: parameters whose range
// goes beyond INT32_MAX are unsigned 32-bit values.
constexpr int64_t widen(const ParameterInfo& info, int32_t wire_value) {
  if (info.min >= 0 && info.max > INT32_MAX) return static_cast<int64_t>(static_cast<uint32_t>(wire_value));
  return wire_value;
}

constexpr bool in_range(const ParameterInfo& info, int32_t wire_value) {
  const int64_t v = widen(info, wire_value);
  return v >= info.min && v <= info.max;
}

// How a row reaches the module's data. Owner is the module class (or a part of it); axis is
// the motor number for axis parameters and the bank for global parameters.
template <class Owner>
struct Binding {
  int32_t (*get)(Owner& owner, uint8_t axis) = nullptr;
  // Called only with values already checked against the row's range. nullptr = read-only.
  tmcl::Status (*set)(Owner& owner, uint8_t axis, int32_t value) = nullptr;
};

// The types a plain field behind a row may have: the wire's 32 bits, signed or unsigned, or an
// enum over int32_t whose named values are the manual's numbers (a mode: `CommutationMode`).
// The row's range decides which numbers reach the field, so an enum also keeps numbers it does
// not name (the manual allows them) and reads them back unchanged.
template <class Value>
concept WireField = std::is_same_v<Value, int32_t> || std::is_same_v<Value, uint32_t> ||
                    (std::is_enum_v<Value> && std::is_same_v<std::underlying_type_t<Value>, int32_t>);

// A binding to one plain field of a part of the owner: `Part` is a function returning that part
// (for example the axis config struct), given the owner alone or the owner and the row's axis
// (a module with several motors: the config of motor `axis`), `Field` a pointer to the member.
// Writable fields store the value as it comes; read-only ones (Writable = false) reject writes.
template <class Owner, auto Part>
constexpr auto& part_at(Owner& owner, uint8_t axis) {
  if constexpr (std::is_invocable_v<decltype(Part), Owner&, uint8_t>) {
    return Part(owner, axis);
  } else {
    return Part(owner);
  }
}

template <class Owner, auto Part, auto Field, bool Writable = true>
constexpr Binding<Owner> field_binding() {
  using Value = std::remove_cvref_t<decltype(part_at<Owner, Part>(std::declval<Owner&>(), 0).*Field)>;
  static_assert(WireField<Value>, "a parameter field is int32_t, uint32_t or an enum over int32_t");
  Binding<Owner> binding;
  binding.get = [](Owner& owner, uint8_t axis) { return static_cast<int32_t>(part_at<Owner, Part>(owner, axis).*Field); };
  if constexpr (Writable) {
    binding.set = [](Owner& owner, uint8_t axis, int32_t value) {
      part_at<Owner, Part>(owner, axis).*Field = static_cast<Value>(value);
      return tmcl::Status::kOk;
    };
  }
  return binding;
}

template <class Owner>
struct ParameterRow {
  ParameterInfo info;
  Binding<Owner> binding;
};

}  // namespace motwin::params
