// What a TMCL module's parameter tables are written with: the bindings of rows to the parts
// tmcl::TmclModule owns (the axis with its config and state, the bank-0 settings) and the range
// bounds of 32-bit values. TmclModule inherits it, so a module's table functions
// (Tmcm1636::axis_parameters(), ...) name these helpers without qualification and each row
// reads as the manual's line plus one binding:
//   {{43, "max velocity", 0, 200000, 4000, access("RWEX"), ...}, config_field<&AxisConfig::max_velocity_rpm>()},
// Only what the module does differently (unit conversions, I/O readings) needs a hand-written
// params::Binding.
#pragma once

#include <cstddef>
#include <cstdint>
#include <type_traits>

#include "core/params/parameter.h"
#include "core/tmcl/status.h"

namespace motwin::tmcl {

namespace detail {
// The class a pointer to member (data or function) belongs to.
template <class MemberPointer>
struct MemberOf;
template <class Member, class Class>
struct MemberOf<Member Class::*> {
  using type = Class;
};

// The value a setter `Result (Class::*)(Value)` takes, and what it returns.
template <class Setter>
struct SetterOf;
template <class Result, class Class, class Value>
struct SetterOf<Result (Class::*)(Value)> {
  using value_type = std::remove_cvref_t<Value>;
  using result_type = Result;
};
}  // namespace detail

template <class Module, class Axis, class Globals>
class ModuleRows {
 public:
  using Row = params::ParameterRow<Module>;
  using Binding = params::Binding<Module>;
  using AxisConfig = decltype(Axis::config);
  using AxisState = decltype(Axis::state);

  // Range bounds of the tables: the wire's 32 bits, signed or unsigned.
  static constexpr int64_t kMin32 = INT32_MIN;
  static constexpr int64_t kMax32 = INT32_MAX;
  static constexpr int64_t kMaxU32 = UINT32_MAX;

  // A stored setting of the axis: plain read and write.
  template <auto Field>
  static constexpr Binding config_field() {
    return params::field_binding<Module, config_of, Field>();
  }
  // A live value the firmware computes: read-only.
  template <auto Field>
  static constexpr Binding state_value() {
    return params::field_binding<Module, state_of, Field, false>();
  }
  // A live value a host may also write, without side effects (debug values, brake release).
  template <auto Field>
  static constexpr Binding state_field() {
    return params::field_binding<Module, state_of, Field>();
  }
  // A bank-0 setting.
  template <auto Field>
  static constexpr Binding global_field() {
    return params::field_binding<Module, globals_of, Field>();
  }

  // A value whose write is a command of the axis (a new target starts a move, a new position
  // re-bases the counter). `Get` reads it: a field of the axis config or state, or a member
  // function of the axis; `Set` is the axis's member function that takes it (int32_t, bool or
  // an enum) and returns nothing or a tmcl::Status.
  template <auto Get, auto Set>
  static constexpr Binding axis_command() {
    return {read_axis_value<Get>, [](Module& module, uint8_t motor, int32_t value) {
              using Setter = detail::SetterOf<decltype(Set)>;
              Axis& axis = module.axis(motor);
              if constexpr (std::is_void_v<typename Setter::result_type>) {
                (axis.*Set)(static_cast<typename Setter::value_type>(value));
                return Status::kOk;
              } else {
                return (axis.*Set)(static_cast<typename Setter::value_type>(value));
              }
            }};
  }
  // A read-only value of the axis: a member function (a computed flag, a counter, a value read
  // and cleared) or a field of its state.
  template <auto Get>
  static constexpr Binding axis_value() {
    return {read_axis_value<Get>, nullptr};
  }
  // One element of an int32_t array in the axis config or state (the bows of an S-ramp, the
  // debug values): plain read and write.
  template <auto ArrayField, size_t kIndex>
  static constexpr Binding element_field() {
    using Part = typename detail::MemberOf<decltype(ArrayField)>::type;
    return {[](Module& module, uint8_t motor) { return (part_of<Part>(module.axis(motor)).*ArrayField)[kIndex]; },
            [](Module& module, uint8_t motor, int32_t value) {
              (part_of<Part>(module.axis(motor)).*ArrayField)[kIndex] = value;
              return Status::kOk;
            }};
  }

 private:
  // The rows' `axis` argument is the motor of SAP/GAP (the bank of a global row).
  static AxisConfig& config_of(Module& module, uint8_t motor) { return module.axis(motor).config; }
  static AxisState& state_of(Module& module, uint8_t motor) { return module.axis(motor).state; }
  static Globals& globals_of(Module& module) { return module.global_config(); }

  // The axis, its config or its state: the part a member pointer of type `Part` applies to.
  template <class Part>
  static Part& part_of(Axis& axis) {
    if constexpr (std::is_same_v<Part, AxisConfig>) {
      return axis.config;
    } else if constexpr (std::is_same_v<Part, AxisState>) {
      return axis.state;
    } else {
      static_assert(std::is_same_v<Part, Axis>, "a member of the axis, its config or its state");
      return axis;
    }
  }

  template <auto Get>
  static int32_t read_axis_value(Module& module, uint8_t motor) {
    auto& part = part_of<typename detail::MemberOf<decltype(Get)>::type>(module.axis(motor));
    if constexpr (std::is_member_function_pointer_v<decltype(Get)>) {
      return static_cast<int32_t>((part.*Get)());
    } else {
      return static_cast<int32_t>(part.*Get);
    }
  }
};

}  // namespace motwin::tmcl
