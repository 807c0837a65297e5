// Axis 0 of the TMCM-1636: its settings (the E parameters of manual table 11), its live state,
// and its motion. Two motors:
//  - the *ideal* motor (no power stage attached): the axis follows the ramp generator exactly,
//    the fast option (docs/tmcm-1636.md);
//  - a real motor behind the power-stage seam (board/modules/tmcm1636/tmcm1636_power_stage.h): the cascaded
//    regulators of manual chapter 5 (FOC current/flux PI, velocity PI, position P), commutation
//    (open loop, digital hall, ABN encoder, absolute encoder), encoder initialisation, brake,
//    brake chopper and protections, reading only ADC counts, hall levels and encoder counts and
//    writing only PWM duties and outputs (docs/tmcm-1636-servo.md).
#pragma once

#include <cstdint>

#include "board/modules/tmcm1636/tmcm1636_io.h"
#include "board/modules/tmcm1636/tmcm1636_power_stage.h"
#include "core/motion/hall_decoder.h"
#include "core/motion/pi_regulator.h"
#include "core/motion/position_pll.h"
#include "core/motion/trapezoid_ramp.h"

namespace motwin::modules::tmcm1636 {

// The mode parameters of table 11 as named values. Each enumerator is the manual's number, so
// the wire values, ranges, defaults and EEPROM slots are those of the table; a number the range
// allows but the manual does not name (motor type 2) is kept as it is.
// AP 14.
enum class MotorType : int32_t { kNone = 0, kDc = 1, kBldc = 3 };
// AP 15: the source of the electrical angle the FOC turns the field with.
enum class CommutationMode : int32_t { kDisabled = 0, kOpenLoop = 1, kDigitalHall = 2, kAbnEncoder = 3, kAbsoluteEncoder = 4 };
// AP 25: the source of the position counter (AP 52).
enum class PositionCommutationMode : int32_t { kSameAsCommutation = 0, kAbnEncoder = 1, kAbsoluteEncoder = 2 };
// AP 102: how the ABN encoder initialisation finds the commutation offset.
enum class VelocitySensorSelection : int32_t { kSameAsCommutation = 0, kAbnEncoder = 1, kAbsoluteEncoder = 2 };
enum class EncoderInitMode : int32_t { kEstimateOffset = 0, kNChannel = 1, kUseHall = 2 };
// AP 160.
enum class AbsoluteEncoderType : int32_t { kNone = 0, kAmt20 = 1, kAmt23 = 2 };
// AP 161.
enum class AbsoluteEncoderInit : int32_t { kEstimateOffset = 0, kUseOffset = 1 };
// AP 124, named as the manual's values read: 0 enables the brake output function.
enum class BrakeOutput : int32_t { kEnabled = 0, kDisabled = 1 };
// AP 125: 0 (the manual's "inverted", its default) drives the connector as computed, 1 (its
// "normal") complements the duty (docs/tmcm-1636-servo.md).
enum class BrakeOutputPolarity : int32_t { kAsComputed = 0, kComplemented = 1 };

// Stored settings of the axis, one field per writable row of table 11. Defaults are the
// manual's, except where docs/tmcm-1636.md records a decision.
struct AxisConfig {
  int32_t adc_phase_a_offset = 32767;        // AP 5
  int32_t adc_phase_b_offset = 32767;        // AP 6
  int32_t dual_shunt_factor = 256;           // AP 7: mA = (raw - offset) * factor / 256
  int32_t motor_pole_pairs = 4;              // AP 10
  int32_t max_current_ma = 2000;             // AP 11
  int32_t open_loop_current_ma = 2000;       // AP 12
  // Firmware 1.13 only (docs/tmcm-1636.md "Firmware generations"); 1.09 has no row for them, so
  // they keep these defaults there.
  int32_t motor_direction = 0;               // AP 13: 1 = host frame is the motor's inverted
  MotorType motor_type = MotorType::kNone;   // AP 14
  CommutationMode commutation_mode = CommutationMode::kDisabled;  // AP 15
  PositionCommutationMode position_commutation_mode = PositionCommutationMode::kSameAsCommutation;  // AP 25
  VelocitySensorSelection velocity_sensor_selection = VelocitySensorSelection::kSameAsCommutation;  // AP 26 (1.13), stored only
  int32_t max_velocity_rpm = 4000;           // AP 43
  int32_t acceleration_rpm_per_s = 2000;     // AP 44
  int32_t velocity_ramp_enabled = 1;         // AP 45
  int32_t position_reached_distance = 5;     // AP 53, position counts
  int32_t position_reached_velocity_rpm = 500;  // AP 54
  int32_t position_scaler = 65536;           // AP 56 (1.13): the host's position counts per revolution
  motion::PiConfig current_pi;               // AP 70 (P), 71 (I): torque and flux regulators
  motion::PiConfig velocity_pi;              // AP 72, 73
  motion::PiConfig position_pi;              // AP 74 (P only; I stays 0)
  int32_t hall_polarity = 0;                 // AP 90
  int32_t hall_direction = 0;                // AP 91
  int32_t hall_interpolation = 0;            // AP 92
  int32_t hall_phi_e_offset = 0;             // AP 93
  int32_t encoder_steps = 8192;              // AP 100, counts per revolution
  int32_t encoder_direction = 0;             // AP 101
  EncoderInitMode encoder_init_mode = EncoderInitMode::kNChannel;  // AP 102
  int32_t encoder_init_delay_ms = 1000;      // AP 104
  int32_t encoder_init_velocity_rpm = 100;   // AP 105
  int32_t encoder_offset = 0;                // AP 106
  int32_t clear_on_null = 0;                 // AP 107
  int32_t clear_once = 0;                    // AP 108
  int32_t pwm_frequency_hz = 25000;          // AP 110
  int32_t brake_release_duty_percent = 75;   // AP 121
  int32_t brake_hold_duty_percent = 11;      // AP 122
  int32_t brake_release_duration_ms = 80;    // AP 123
  BrakeOutput brake_output = BrakeOutput::kEnabled;  // AP 124
  BrakeOutputPolarity brake_output_polarity = BrakeOutputPolarity::kAsComputed;  // AP 125
  int32_t brake_chopper_enabled = 0;         // AP 140
  int32_t brake_chopper_limit_decivolt = 260;     // AP 141
  int32_t brake_chopper_hysteresis_decivolt = 5;  // AP 142
  AbsoluteEncoderType absolute_encoder_type = AbsoluteEncoderType::kNone;  // AP 160: AMT20 12 bit, AMT23 14 bit
  AbsoluteEncoderInit absolute_encoder_init = AbsoluteEncoderInit::kEstimateOffset;  // AP 161
  int32_t absolute_encoder_direction = 0;    // AP 162
  int32_t absolute_encoder_offset = 0;       // AP 163, 65536 per mechanical revolution
  int32_t absolute_encoder_data_length = 16;     // AP 165 (1.13), bits per transfer, stored only
  int32_t absolute_encoder_position_start = 0;   // AP 166 (1.13), first position bit, stored only
  int32_t absolute_encoder_position_length = 16; // AP 167 (1.13), position bits, stored only
  int32_t reference_switch_enable = 0;       // AP 209: bit 0 right, bit 1 left
  int32_t reference_switch_polarity = 0;     // AP 210: bit 0 right, 1 left, 2 home; 1 = high active
};

enum class MotionMode : uint8_t { kVelocity, kPosition, kTorque };

// The normalisation of the gains AP 70..74 (docs/tmcm-1636-servo.md "Gains and units", with the
// evidence and the derivation in "Regulator scaling: evidence"). All loops run every 50 µs tick.
// Current (AP 70/71): mV = P * e / 256 + I * sum(e) / 65536, e in mA.
inline constexpr motion::PiScale kCurrentPiScale{1.0f / 256.0f, 1.0f / 65536.0f};
// Velocity (AP 72/73): mA = P * e / 256 + I * sum(e) / 262144, e in rpm.
inline constexpr motion::PiScale kVelocityPiScale{1.0f / 256.0f, 1.0f / 262144.0f};
// Position (AP 74): rpm = P * e / 1024, e in 1/65536 revolution whatever AP 100 (or AP 56) counts,
// so that one P means the same stiffness on a hall, ABN or absolute position.
inline constexpr motion::PiScale kPositionPiScale{1.0f / 1024.0f, motion::kPiIntegralScale};  // no I (AP 74 only)
inline constexpr double kPositionErrorUnitsPerRevolution = 65536.0;

// AP 103 (manual table 11).
enum class EncoderInitState : int32_t { kIdle = 0, kStartInit = 1, kWaitInitTime = 2, kEstimateOffset = 3 };

// AP 156 status flags (docs/tmcm-1636-servo.md, "Status flags").
namespace status_flag {
inline constexpr uint32_t kDriverEnabled = 1u << 0;        // AP 255 = 1
inline constexpr uint32_t kPowerStageOn = 1u << 1;         // the bridge switches
inline constexpr uint32_t kTorqueMode = 1u << 2;
inline constexpr uint32_t kVelocityMode = 1u << 3;
inline constexpr uint32_t kPositionMode = 1u << 4;
inline constexpr uint32_t kPositionReached = 1u << 5;      // AP 55
inline constexpr uint32_t kCurrentLimit = 1u << 6;         // torque demand clipped at AP 11
inline constexpr uint32_t kVelocityLimit = 1u << 7;        // velocity demand clipped at AP 43
inline constexpr uint32_t kVoltageLimit = 1u << 8;         // current regulator at the supply limit
inline constexpr uint32_t kEncoderInitialised = 1u << 9;   // ABN offset found since power-up
inline constexpr uint32_t kEncoderInitRunning = 1u << 10;  // AP 103 != 0
inline constexpr uint32_t kAbsoluteEncoderReady = 1u << 11;
inline constexpr uint32_t kHallError = 1u << 12;           // hall state 000 or 111
inline constexpr uint32_t kBrakeReleased = 1u << 13;
inline constexpr uint32_t kBrakeChopperActive = 1u << 14;
inline constexpr uint32_t kUndervoltage = 1u << 15;
inline constexpr uint32_t kOvervoltage = 1u << 16;
inline constexpr uint32_t kOvertemperature = 1u << 17;
inline constexpr uint32_t kRightSwitchStop = 1u << 18;
inline constexpr uint32_t kLeftSwitchStop = 1u << 19;
inline constexpr uint32_t kAll = (1u << 20) - 1;
}  // namespace status_flag

// Protection thresholds of the power stage (docs/tmcm-1636-servo.md).
inline constexpr int32_t kUndervoltageTripDecivolt = 80;
inline constexpr int32_t kUndervoltageClearDecivolt = 90;
inline constexpr int32_t kOvervoltageTripDecivolt = 600;
inline constexpr int32_t kOvervoltageClearDecivolt = 580;
inline constexpr int32_t kOvertemperatureTripCelsius = 100;
inline constexpr int32_t kOvertemperatureClearCelsius = 90;

// Live values: measured, computed, or commanded without being stored.
struct AxisState {
  MotionMode mode = MotionMode::kVelocity;
  int32_t adc_phase_a_raw = 32767;  // AP 0
  int32_t adc_phase_b_raw = 32767;  // AP 1
  int32_t adc_phase_a = 0;          // AP 2, mA
  int32_t adc_phase_b = 0;          // AP 3, mA
  int32_t adc_phase_c = 0;          // AP 4, mA
  int32_t open_loop_angle = 0;      // AP 16
  int32_t encoder_angle = 0;        // AP 17
  int32_t hall_angle = 0;           // AP 18
  int32_t absolute_encoder_angle = 0;  // AP 19
  int32_t target_torque_ma = 0;     // AP 30
  int32_t actual_torque_ma = 0;     // AP 31
  int32_t target_flux_ma = 0;       // AP 32
  int32_t actual_flux_ma = 0;       // AP 33
  int32_t target_velocity_rpm = 0;  // AP 40
  int32_t ramp_velocity_rpm = 0;    // AP 41
  int32_t actual_velocity_rpm = 0;  // AP 42
  int32_t actual_position = 0;      // AP 52
  int32_t position_reached = 0;     // AP 55
  motion::PiState torque_pi;        // AP 75 (error sum), 78 (error)
  motion::PiState flux_pi;          // AP 76, 79
  motion::PiState velocity_pi;      // AP 77, 80
  motion::PiState position_pi;      // AP 81
  EncoderInitState encoder_init_state = EncoderInitState::kIdle;  // AP 103
  int32_t release_brake = 0;        // AP 120
  int32_t brake_chopper_active = 0;  // AP 144 (the manual's default column says 255)
  uint32_t status_flags = 0;        // AP 156, status_flag bits
  int32_t right_switch_active = 0;  // AP 211
  int32_t left_switch_active = 0;   // AP 212
  int32_t home_switch_active = 0;   // AP 213
  uint32_t main_loops_per_s = 0;    // AP 230
  uint32_t torque_loops_per_s = 0;  // AP 231
  uint32_t velocity_loops_per_s = 0;  // AP 232
  int32_t driver_enabled = 1;       // AP 255 (docs/tmcm-1636.md: enabled at power-up)
  int32_t debug_values[10] = {};    // AP 240..249
};

class Tmcm1636Axis {
 public:
  AxisConfig config;
  AxisState state;

  // Commands (ROR/ROL/MST/MVP and the writable live parameters).
  void set_target_velocity(int32_t velocity_rpm);
  void set_target_position(int32_t position);
  void set_actual_position(int32_t position);
  void set_target_torque(int32_t torque_ma);
  void set_target_flux(int32_t flux_ma);
  void set_driver_enabled(bool enabled);
  // AP 15: selecting ABN or absolute encoder commutation (with AP 161 = estimate) starts the
  // encoder initialisation; restoring AP 15 at power-up does not (docs/tmcm-1636-servo.md).
  void set_commutation_mode(CommutationMode mode);
  // AP 107: writing it re-arms the clear on the next N pulse.
  void set_clear_on_null(int32_t clear);

  // A reference generated outside the axis: the CANopen firmware's CiA-402 drive profiles the
  // motion (docs/tmcm-1636-canopen.md) and hands the axis a position (axis counts) with its
  // velocity as the feed-forward of the position regulator, or a velocity for the velocity
  // regulator. Between two the reference moves on with the velocity given. The axis' own ramp
  // (AP 43..45) is then not used; AP 43 still bounds the velocity reference. Any other command
  // (set_target_*) ends it.
  void follow_position(int32_t position, double velocity_counts_per_s);
  void follow_velocity(double velocity_counts_per_s);
  bool following_reference() const { return external_reference_; }

  // The motor behind the power stage. nullptr (the default) is the ideal motor. The stage is
  // board wiring: it survives reset_state().
  void attach_power_stage(board::Tmcm1636PowerStage* stage) { power_stage_ = stage; }
  bool has_power_stage() const { return power_stage_ != nullptr; }

  // Firmware 1.13: the host counts positions (AP 50..53, MVP) AP 56 per revolution; the axis
  // keeps counting AP 100 per revolution (docs/tmcm-1636.md "Firmware generations"). Firmware,
  // not a setting: it survives reset_state().
  void set_position_scaler_applies(bool applies) { position_scaler_applies_ = applies; }
  // A position in the host's counts from the axis' counts and back, rounded to the nearest count;
  // the identity without the scaler or while AP 56 equals AP 100 (or AP 100 is 0).
  int32_t host_position(int32_t axis_counts) const;
  int32_t axis_position(int32_t host_counts) const;

  // One control tick of `dt_s` seconds: the ideal motor, or the regulators on the power stage.
  void tick(const board::Tmcm1636Io& io, double dt_s);

  // Power-up: live state cleared, settings kept. Parameter writes until finish_restore() (or
  // the first tick) are the restore from the EEPROM image, not host commands.
  void reset_state();
  void finish_restore() { restoring_ = false; }

  int32_t target_position() const { return ramp_.target_position(); }
  int32_t actual_position() const { return state.actual_position; }
  int32_t ramp_position() const { return ramp_.position(); }
  bool position_reached() const { return state.position_reached != 0; }
  const motion::TrapezoidRamp& ramp() const { return ramp_; }
  bool encoder_initialised() const { return servo_.abn_initialised; }
  // AP 94 (1.13): the hall inputs' electrical levels, bit 0 H1, bit 1 H2, bit 2 H3 (0 without a
  // power stage: the ideal motor has no sensors).
  int32_t hall_inputs() const { return power_stage_ != nullptr ? power_stage_->feedback.hall & 7 : 0; }
  // AP 109 (1.13): bit 0 A, bit 1 B from the quadrature counter's phase (the board gives the
  // counter, not the levels); bit 2 N is 0 (the board latches N pulses, it gives no level).
  int32_t encoder_inputs() const {
    if (power_stage_ == nullptr) return 0;
    static constexpr int32_t kQuadrature[4] = {0b00, 0b01, 0b11, 0b10};
    return kQuadrature[static_cast<uint32_t>(power_stage_->feedback.abn_count) & 3u];
  }

  // rpm <-> position counts per second, with AP 100 counts per revolution.
  double counts_per_second(double velocity_rpm) const;
  double rpm(double counts_per_second) const;

 private:
  // Everything the regulators keep between ticks that is not a parameter.
  struct Servo {
    bool started = false;           // first tick since power-up done
    // ABN encoder: the commutation counter (direction applied, since power-up or the N pulse of
    // an N-channel initialisation) and the last raw reading.
    int32_t abn_last_raw = 0;
    int64_t abn_count = 0;
    int64_t abn_reference = 0;      // commutation counter value that counts as 0
    uint32_t abn_index_events = 0;
    bool abn_initialised = false;
    bool clear_armed = false;       // AP 107 clear pending
    motion::HallDecoder hall;
    int32_t hall_last_steps = 0;
    uint16_t absolute_last = 0;
    uint32_t open_loop_phase = 0;   // electrical angle, 2^32 per turn (wraps)
    uint32_t open_loop_last = 0;
    bool absolute_estimated = false;
    // Position source in AP 100 counts, continuous, and the fractions left over by scaling.
    int64_t sensor_position = 0;
    int64_t hall_remainder = 0;
    int64_t absolute_remainder = 0;
    int64_t open_loop_remainder = 0;
    motion::PositionPll pll;
    double velocity_counts_per_s = 0.0;
    // Encoder initialisation.
    bool init_for_absolute = false;
    uint32_t init_ticks = 0;
    // Power stage.
    bool undervoltage = false;
    bool overvoltage = false;
    bool overtemperature = false;
    bool chopper_on = false;
    int32_t brake_previous_release = 0;
    uint32_t brake_release_ticks = 0;
    // Loop counters for AP 230..232.
    uint32_t window_ticks = 0;
    uint32_t torque_loops = 0;
    uint32_t velocity_loops = 0;
    uint32_t flags = 0;             // limit flags collected during a tick
    double inverse_encoder_steps = 1.0 / 8192.0;  // 1 / AP 100, refreshed every tick
  };

  // Phase currents A and B of this tick, mA.
  struct PhaseCurrents {
    float a;
    float b;
  };
  // The sensor movements of one tick, in their native units.
  struct SensorDeltas {
    int64_t abn = 0;                 // commutation counter counts (AP 101 applied)
    int64_t hall = 0;                // hall steps, 6 per electrical turn
    int64_t absolute = 0;            // 65536 per mechanical turn
    int32_t open_loop = 0;           // open-loop field, 2^32 per electrical turn
    bool index = false;              // an N pulse came
    int64_t counts_since_index = 0;  // commutation counts since that pulse
  };
  // What the current regulators of one tick aim at.
  struct CurrentDemand {
    uint16_t angle = 0;                   // electrical angle of the field, 65536 per turn
    float id_ref = 0.0f;                  // flux current, mA
    float iq_ref = 0.0f;                  // torque current, mA
    double electrical_turns_per_s = 0.0;  // for the PWM delay advance
  };

  void ideal_tick(const board::Tmcm1636Io& io, double dt_s);
  // follow_position / follow_velocity's reference one tick on, at its velocity.
  void advance_reference(double dt_s);
  // The steps of servo_tick() and read_sensors(), in their order. Declared inline: each is
  // defined and called only in tmcm1636_axis_servo.cpp, once per tick, and inline lets the
  // compiler fold them back into the tick (out of line, bench_tmcm1636_servo ran 4-7 % slower).
  void servo_tick(board::Tmcm1636PowerStage& stage, double dt_s);
  inline void refresh_velocity_scales();
  inline PhaseCurrents measure_phase_currents(const board::Tmcm1636Feedback& feedback);
  inline bool bridge_switches() const;
  inline void coast(const PhaseCurrents& currents, board::Tmcm1636Drive& drive);
  inline void regulate_currents(const board::Tmcm1636Feedback& feedback, const PhaseCurrents& currents,
                                float supply_volts, board::Tmcm1636Drive& drive, double dt_s);
  inline CurrentDemand current_demand(const board::Tmcm1636Feedback& feedback, double dt_s);
  inline void torque_mode_demand(bool open_loop, CurrentDemand& demand);
  inline void velocity_mode_demand(bool open_loop, CurrentDemand& demand, double dt_s);
  inline uint16_t commutation_angle(uint16_t otherwise) const;
  inline void regulate_dc_current(const CurrentDemand& demand, const PhaseCurrents& currents, float supply_volts,
                                  board::Tmcm1636Drive& drive);
  inline void regulate_foc_currents(const CurrentDemand& demand, const PhaseCurrents& currents, float supply_volts,
                                    board::Tmcm1636Drive& drive, double dt_s);
  inline void count_loops();
  inline uint32_t servo_status_flags(bool bridge) const;
  void update_switches(uint8_t levels);
  double position_reached_distance_counts() const;
  void update_position_reached();
  void update_position_reached_servo();
  void read_sensors(const board::Tmcm1636Feedback& feedback, double dt_s);
  inline motion::HallConfig hall_config() const;
  inline uint16_t absolute_reading(uint16_t raw) const;
  inline void start_sensors(const board::Tmcm1636Feedback& feedback, uint16_t absolute);
  inline SensorDeltas sensor_deltas(const board::Tmcm1636Feedback& feedback, uint16_t absolute);
  inline void update_position(const SensorDeltas& deltas, double dt_s);
  inline void find_encoder_offset(const SensorDeltas& deltas);
  void start_encoder_init(bool absolute);
  bool run_encoder_init(const board::Tmcm1636Feedback& feedback, uint16_t& angle, float& id_ref, double dt_s);
  void update_brake(board::Tmcm1636Drive& drive, double dt_s);
  void update_protection(const board::Tmcm1636Feedback& feedback, int32_t supply_decivolt);
  float velocity_reference_rpm(double dt_s);
  bool switch_blocks(double direction) const;
  void stop_at_switch();
  void seed_ramp();
  void reset_regulators();
  uint16_t abn_angle() const;
  uint16_t absolute_angle(uint16_t mechanical) const;
  int64_t position_source_count() const;

  // rpm <-> counts/s factors of the servo path, refreshed once per tick from AP 100 (saves the
  // divisions of rpm() and counts_per_second() in the hot path).
  double to_rpm(double counts_per_s) const { return counts_per_s * rpm_per_count_per_s_; }
  double to_counts_per_s(double velocity_rpm) const { return velocity_rpm * counts_per_s_per_rpm_; }

  // The ideal motor's ramp limits in counts/s, derived again only when AP 43, 44 or 100 changed
  // (two divisions less in every tick; docs/firmware.md, "Where a tick's instructions go").
  struct IdealRampLimits {
    int32_t max_velocity_rpm = 0;
    int32_t acceleration_rpm_per_s = 0;
    int32_t encoder_steps = -1;  // never a value of AP 100: the first tick derives the limits
    motion::TrapezoidRampConfig ramp;
  };
  const motion::TrapezoidRampConfig& ideal_ramp_config();

  motion::TrapezoidRamp ramp_;
  IdealRampLimits ideal_ramp_limits_;
  Servo servo_;
  double rpm_per_count_per_s_ = 60.0 / 8192.0;
  double counts_per_s_per_rpm_ = 8192.0 / 60.0;
  board::Tmcm1636PowerStage* power_stage_ = nullptr;
  bool position_scaler_applies_ = false;
  bool external_reference_ = false;  // follow_position / follow_velocity
  // Set by reset_state(), cleared by the first tick: parameter writes in between are the
  // power-up restore, not host commands.
  bool restoring_ = false;
};

}  // namespace motwin::modules::tmcm1636
