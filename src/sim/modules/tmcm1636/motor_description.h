// What the simulated TMCM-1636 board drives: a motor (BLDC/PMSM or brushed DC) with its sensors
// and an optional holding brake, on a supply with its bus capacitance and brake resistor, plus
// the settings a drive for this motor starts with. Built-in presets (documented with their
// sources in docs/tmcm-1636-servo.md) and JSON motor description files for users' motors.
//
// Units are SI and in the key names: resistance_ohm, inductance_h, flux_linkage_wb, ...
//
// The motor knows nothing of the firmware's parameters or EEPROM layout: its start-up settings
// are named values, and the host writes them into the firmware's image through the module's
// parameter table (src/host/modules/tmcm1636/tmcm1636_startup_image.*). A description file may
// also give firmware axis parameters by number ("axis_parameters"): the motor keeps them as
// given, and the caller that knows the firmware checks them (AxisParameterCheck). A file may
// start from a preset ("preset": name) and change it key by key.
#pragma once

#include <cstddef>
#include <cstdint>
#include <functional>
#include <optional>
#include <string>
#include <string_view>
#include <utility>
#include <vector>

#include "types/result.h"

namespace motwin::sim {

enum class MotorKind : uint8_t { kBldc, kDc };

// The sensor the drive commutates on.
enum class CommutationSensor : uint8_t { kOpenLoop, kHall, kAbnEncoder, kAbsoluteEncoder };
// The sensor that gives the drive position and velocity.
enum class PositionSensor : uint8_t { kAbnEncoder, kAbsoluteEncoder };
// How the drive finds the ABN encoder's offset to the rotor field before it commutates on it:
// from a short open-loop move, at the N pulse, or from the hall sensors.
enum class EncoderAlignment : uint8_t { kEstimateOffset, kIndexPulse, kHall };

// The settings a drive for this motor starts with, as a module delivered for the motor holds
// them in a fresh EEPROM image (docs/tmcm-1636-servo.md, "Presets"). Each is optional: unset, the
// drive keeps its factory default. With start-up settings the drive is also told the motor's
// type, pole pairs and ABN encoder resolution, from the description itself.
struct StartupSettings {
  std::optional<int32_t> max_current_ma;        // largest phase current the regulators may demand
  std::optional<int32_t> open_loop_current_ma;  // phase current in open-loop commutation
  std::optional<CommutationSensor> commutation;
  std::optional<PositionSensor> position_sensor;
  std::optional<bool> hall_interpolation;       // the hall angle interpolated between edges
  // Settings that undo how the sensors are wired (hall.inverted, hall.reversed, abn.reversed):
  // true sets the firmware's hall polarity, hall direction or encoder direction to 1.
  std::optional<bool> hall_polarity_inverted;
  std::optional<bool> hall_direction_reversed;
  std::optional<bool> encoder_direction_reversed;
  std::optional<EncoderAlignment> encoder_alignment;
  std::optional<double> brake_chopper_voltage_v;  // bus voltage above which the chopper dumps energy
  // Gains of the drive's regulator cascade, in the TMCM-1636's integer scaling (docs/tmcm-1636-servo.md,
  // "Gains and units"): current mV = P * e[mA] / 256 + I * sum(e)[mA tick] / 65536, velocity
  // mA = P * e[rpm] / 256 + I * sum(e)[rpm tick] / 65536, position rpm = P * e[counts] / 256.
  std::optional<int32_t> current_p;
  std::optional<int32_t> current_i;
  std::optional<int32_t> velocity_p;
  std::optional<int32_t> velocity_i;
  std::optional<int32_t> position_p;

  bool operator==(const StartupSettings&) const = default;
};

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

  // What a drive for this motor starts with (none: a fresh image keeps the factory defaults).
  std::optional<StartupSettings> startup;
  // Firmware axis parameters a description file gives by number ("axis_parameters": number,
  // value), in number order; written into a fresh image after `startup`.
  std::vector<std::pair<uint8_t, int32_t>> axis_parameters;

  // Torque per ampere of q current (BLDC: 1.5 p lambda) or of armature current (DC).
  double torque_constant() const {
    return kind == MotorKind::kDc ? torque_constant_nm_per_a : 1.5 * pole_pairs * flux_linkage_wb;
  }
};

// "default-24v", "qbl4208-61-04-013", "large-48v", "dc-24v".
std::vector<std::string_view> motor_preset_names();
std::optional<MotorDescription> motor_preset(std::string_view name);

// The motor behind the power stage as `--motor` chose it; nullopt: the ideal motor.
using MotorChoice = std::optional<MotorDescription>;

// Checks one "axis_parameters" entry for the firmware that will get it: success when it stores
// parameter `number` and takes `value`, else what is wrong. Without a check, any number 0..255
// and any 32-bit value is kept.
using AxisParameterCheck = std::function<Result<void>(int number, int64_t value)>;

// Parses a JSON motor description (docs/tmcm-1636-servo.md, "Motor description files"); an
// error reads "<file>: <what is wrong>".
Result<MotorDescription> parse_motor_description(std::string_view json_text, std::string_view source_name,
                                                 const AxisParameterCheck& check = {});
Result<MotorDescription> load_motor_description_file(const std::string& path, const AxisParameterCheck& check = {});
// A preset name or a file path; "ideal" (or empty) is not a motor: nullopt, no error.
Result<MotorChoice> resolve_motor(std::string_view name_or_path, const AxisParameterCheck& check = {});
// The description as JSON (the file format), e.g. to start a file from a preset.
std::string motor_description_json(const MotorDescription& motor);

}  // namespace motwin::sim
