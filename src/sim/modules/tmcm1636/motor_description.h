// What the simulated TMCM-1636 board drives: a motor (BLDC/PMSM or brushed DC) with its sensors
// and an optional holding brake, on a supply with its bus capacitance and brake resistor, plus
// the axis parameters the motor wants at first power-up. Built-in presets (documented with
// their sources in docs/tmcm-1636-servo.md) and JSON motor description files for users' motors.
//
// Units are SI and in the key names: resistance_ohm, inductance_h, flux_linkage_wb, ...
#pragma once

#include <cstddef>
#include <cstdint>
#include <optional>
#include <string>
#include <string_view>
#include <utility>
#include <vector>

namespace motwin::sim {

enum class MotorKind : uint8_t { kBldc, kDc };

struct MotorDescription {
  std::string name;
  std::string source;  // where the numbers come from
  MotorKind kind = MotorKind::kBldc;

  int pole_pairs = 4;                     // BLDC only
  double resistance_ohm = 0.4;            // per phase (star equivalent); DC: terminal resistance
  double inductance_d_h = 0.6e-3;         // per phase; DC: terminal inductance
  double inductance_q_h = 0.6e-3;
  double flux_linkage_wb = 0.035 / 6.0;   // BLDC: permanent-magnet flux linkage (amplitude)
  double torque_constant_nm_per_a = 0.0;  // DC motor (also its back-EMF constant in V s/rad)
  double rotor_inertia_kgm2 = 4.8e-6;
  double viscous_friction_nm_s = 1.5e-5;  // N m per rad/s
  double coulomb_friction_nm = 0.004;
  double initial_angle_deg = 40.0;        // mechanical rotor angle at power-up

  struct Hall {
    bool present = true;
    double offset_deg = 0.0;  // electrical angle of the first sector edge (firmware AP 93 equivalent)
    bool inverted = false;    // levels inverted (firmware AP 90 = 1 undoes it)
    bool reversed = false;    // sequence reversed (firmware AP 91 = 1 undoes it)
  } hall;
  struct Abn {
    bool present = true;
    int32_t counts_per_rev = 4096;  // quadrature counts (4 x lines)
    double index_deg = 200.0;       // mechanical angle of the N pulse
    bool reversed = false;
  } abn;
  struct Absolute {
    bool present = false;
    int bits = 12;
    double offset_deg = 0.0;  // reading at rotor angle 0, mechanical degrees
    bool reversed = false;
  } absolute;
  struct Brake {
    bool present = false;
    double holding_torque_nm = 0.0;
    double pull_in_duty_percent = 50.0;  // coil drive needed to release
    double drop_out_duty_percent = 8.0;  // below this a released brake closes again
    double time_constant_s = 0.015;      // coil current time constant
  } brake;
  struct Supply {
    double voltage_v = 24.0;
    double source_resistance_ohm = 0.1;
    double capacitance_f = 470e-6;     // bus capacitance (module plus wiring)
    double brake_resistor_ohm = 10.0;  // on the brake chopper output
    bool regenerative = false;         // a lab supply cannot sink current: regeneration charges the bus
  } supply;

  // Axis parameters written into a fresh EEPROM image (number, value), in parameter-number order.
  std::vector<std::pair<uint8_t, int32_t>> startup_parameters;

  // Torque per ampere of q current (BLDC: 1.5 p lambda) or of armature current (DC).
  double torque_constant() const {
    return kind == MotorKind::kDc ? torque_constant_nm_per_a : 1.5 * pole_pairs * flux_linkage_wb;
  }
};

// "default-24v", "large-48v", "dc-24v".
std::vector<std::string_view> motor_preset_names();
std::optional<MotorDescription> motor_preset(std::string_view name);

struct MotorLoadResult {
  std::optional<MotorDescription> motor;
  std::string error;  // "<file>: <what is wrong>" when motor is empty
};

// Parses a JSON motor description (docs/tmcm-1636-servo.md, "Motor description files").
MotorLoadResult parse_motor_description(std::string_view json_text, std::string_view source_name);
MotorLoadResult load_motor_description_file(const std::string& path);
// A preset name or a file path; "ideal" (or empty) is not a motor and gives an empty result
// without error.
MotorLoadResult resolve_motor(std::string_view name_or_path);
// The description as JSON (the file format), e.g. to start a file from a preset.
std::string motor_description_json(const MotorDescription& motor);

// Writes the motor's start-up axis parameters into a TMCM-1636 EEPROM image (after the factory
// defaults): what a fresh image of a module delivered for this motor holds.
void write_startup_parameters(const MotorDescription& motor, uint8_t* image, size_t size);
// Whether a TMCM-1636 image selects a motor (AP 14 != 0).
bool image_configures_motor(const uint8_t* image, size_t size);

}  // namespace motwin::sim
