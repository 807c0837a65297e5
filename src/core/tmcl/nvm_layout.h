// Layout of a TMCL module's EEPROM image: one 32-bit little-endian slot per parameter
// number, so STAP n writes slot n and the layout never shifts when a parameter is added.
#pragma once

#include <cstddef>
#include <cstdint>

namespace motwin::tmcl {

struct NvmLayout {
  uint32_t motors;                   // motors with axis parameters (and coordinates)
  uint32_t axis_parameters_offset;   // motor m, parameter n: + (m * 256 + n) * 4
  uint32_t global_parameters_offset; // bank 0 parameter n: + n * 4
  uint32_t user_variables_offset;    // bank 2 variable n: + n * 4 (n < storable count)
  uint32_t storable_user_variables;
  uint32_t coordinates_offset;       // motor m, coordinate n: + (m * count + n) * 4 (TMCM-142)
  uint32_t coordinates_per_motor;    // 0: the module has no stored coordinates
  uint32_t program_offset;           // 8 bytes per instruction (standalone-mode issue)
  uint32_t program_capacity;
  uint32_t total_size;

  constexpr uint32_t axis_parameter(uint8_t motor, uint8_t number) const {
    return axis_parameters_offset + (static_cast<uint32_t>(motor) * 256u + number) * 4u;
  }
  constexpr uint32_t global_parameter(uint8_t number) const { return global_parameters_offset + number * 4u; }
  constexpr uint32_t user_variable(uint8_t number) const { return user_variables_offset + number * 4u; }
  constexpr uint32_t coordinate(uint8_t motor, uint8_t number) const {
    return coordinates_offset + (static_cast<uint32_t>(motor) * coordinates_per_motor + number) * 4u;
  }
};

// Coordinates sit between the user variables and the program, so a module without them keeps
// the layout it always had, and command 137 (which rewrites everything before the program)
// clears them with the parameters.
constexpr NvmLayout make_nvm_layout(uint8_t motors, size_t storable_user_variables, size_t program_capacity,
                                    size_t coordinates_per_motor = 0) {
  NvmLayout layout{};
  layout.motors = motors;
  layout.axis_parameters_offset = 0;
  layout.global_parameters_offset = static_cast<uint32_t>(motors) * 256u * 4u;
  layout.user_variables_offset = layout.global_parameters_offset + 256u * 4u;
  layout.storable_user_variables = static_cast<uint32_t>(storable_user_variables);
  layout.coordinates_offset = layout.user_variables_offset + static_cast<uint32_t>(storable_user_variables) * 4u;
  layout.coordinates_per_motor = static_cast<uint32_t>(coordinates_per_motor);
  layout.program_offset =
      layout.coordinates_offset + static_cast<uint32_t>(motors) * static_cast<uint32_t>(coordinates_per_motor) * 4u;
  layout.program_capacity = static_cast<uint32_t>(program_capacity);
  layout.total_size = layout.program_offset + static_cast<uint32_t>(program_capacity) * 8u;
  return layout;
}

inline void put_le32(uint8_t* out, int32_t value) {
  const auto v = static_cast<uint32_t>(value);
  out[0] = static_cast<uint8_t>(v);
  out[1] = static_cast<uint8_t>(v >> 8);
  out[2] = static_cast<uint8_t>(v >> 16);
  out[3] = static_cast<uint8_t>(v >> 24);
}
inline int32_t get_le32(const uint8_t* in) {
  return static_cast<int32_t>(static_cast<uint32_t>(in[0]) | (static_cast<uint32_t>(in[1]) << 8) |
                              (static_cast<uint32_t>(in[2]) << 16) | (static_cast<uint32_t>(in[3]) << 24));
}

}  // namespace motwin::tmcl
