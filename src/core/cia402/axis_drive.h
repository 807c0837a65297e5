// One CiA-402 axis: the PDS state machine (power_drive_system.h), the modes of operation and
// their dispatch (pp, pv, hm, csp, csv, cst; 6060/6061), the profile generator that produces the
// position demand (6062: the EightPoint ramp, in its trapezoid form 6081/6083/6084 unless the
// module shapes it further), the monitoring functions (position window, following error,
// software limits, limit switches, stall, power-stage faults) and the statusword. It is pure
// arithmetic and does not know what executes the demand: the module hands in what the axis
// hardware saw this tick (AxisInputs) and passes the demand (AxisDemand: a position with its
// velocity, a velocity, or a torque, and the power stage's state) on to its axis, a stepper or a
// servo cascade; drive events (fault reset, following error, stall, limits) are queued as
// emergencies for the module to read.
//
// Edges of the controlword (pp new set-point, hm start, fault reset) act when the controlword
// is written, so that a statusword read right after the write already shows the
// acknowledgement (python-canopen and ros2_canopen poll at once, docs/tmcm-3216-drive.md).
//
// Internal units: increments of the axis' position counter (`usteps`: microsteps on the TMCM-3216,
// position units of 2058 on the TMCM-1636), increments/s (pps), increments/s² (pps2); velocity and
// acceleration objects are converted with the module's UnitScale, torques are in the module's own
// unit. docs/tmcm-3216-drive.md describes the behaviour in detail, docs/tmcm-1636-canopen.md the
// servo's differences.
//
// The module's part (a compile-time seam, as moteus plugs its board into the controller):
// AxisDrive<Manufacturer> keeps one `Manufacturer` per axis (`manufacturer`: the module's
// manufacturer-specific objects that shape the drive) and calls it directly, so the calls inline
// on the per-tick path. It provides (concept ManufacturerPart):
//   UnitScale units() const
//       what one unit of the velocity and acceleration objects is internally;
//   void shape_profile(motion::EightPointConfig& profile, const UnitScale& units) const
//       the module's additions to the profile of pp and pv, which the profile objects make a
//       plain trapezoid (6081 VMAX, 6083 AMAX, 6084 DMAX, 6082 VSTOP);
//   static AxisEmergency emergency(DriveEvent event)
//       the EMCY code and additional byte the module reports a drive event with;
//   static uint16_t manufacturer_status_bits(bool motor_active, bool negative_direction)
//       the manufacturer-specific statusword bits (8, 14, 15);
//   static constexpr uint32_t kSupportedModes
//       the modes 6060 accepts, as 6502 bits (drive_mode_bit());
//   static bool supports_homing_method(int8_t method)
//       the methods 6098 accepts (a subset of Homing's);
//   static constexpr bool kServo
//       false: a stepper follows the demand open loop (the ramp is the motion; 606C is the ramp's
//       velocity); true: a closed loop follows it and the actual motion is measured (606C is the
//       measured velocity, AxisInputs::actual_velocity_pps), so the profile generator restarts from
//       the measured motion whenever the motion is handed over (a mode change, the power stage off,
//       leaving cst); a position assignment (homing) is the module's to carry out on the axis'
//       counter (take_position_assignment), the drive does not re-base the reading.
// AxisDrive<Part> is a thin layer that hands the part's answers to AxisDriveCore, the drive itself,
// compiled once in axis_drive.cpp for every module.
#pragma once

#include <array>
#include <concepts>
#include <cstddef>
#include <cstdint>

#include "core/cia402/homing.h"
#include "core/cia402/power_drive_system.h"
#include "core/cia402/profile_objects.h"
#include "core/motion/eight_point_ramp.h"

namespace motwin::cia402 {

// What the drive reports (take_emergency()), in CiA-402 terms; the module's part gives each its
// EMCY code and additional byte.
enum class DriveEvent : uint8_t {
  kFaultReset,             // transition 15 carried out
  kFollowingError,         // 6065 exceeded (606A = 0)
  kStall,                  // the stall input rose
  kSoftwareLimitPositive,  // the axis ran onto 607D sub 2 (corrected by 607C)
  kSoftwareLimitNegative,  // ... onto 607D sub 1
  kLimitSwitchPositive,    // ... onto the positive (right) limit switch
  kLimitSwitchNegative,    // ... onto the negative (left) limit switch
};

struct AxisEmergency {
  uint16_t code = 0;
  uint8_t sub = 0;  // additional byte 1
};

template <class M>
concept ManufacturerPart = requires(const M& part, motion::EightPointConfig& profile, const UnitScale& units,
                                    DriveEvent event, bool flag) {
  { part.units() } -> std::same_as<UnitScale>;
  part.shape_profile(profile, units);
  { M::emergency(event) } -> std::same_as<AxisEmergency>;
  { M::manufacturer_status_bits(flag, flag) } -> std::same_as<uint16_t>;
  { M::kSupportedModes } -> std::convertible_to<uint32_t>;
  { M::supports_homing_method(int8_t{0}) } -> std::same_as<bool>;
  { M::kServo } -> std::convertible_to<bool>;
};

// What the axis hardware shows this tick.
struct AxisInputs {
  int32_t encoder_position_usteps = 0;  // scaled to microsteps (608F); used when 606A = 0
  double actual_velocity_pps = 0.0;     // the measured velocity (a servo's; a stepper's is ignored)
  bool left_limit = false;              // processed levels (the module applied disable/invert)
  bool right_limit = false;
  bool home_switch = false;
  uint32_t index_events = 0;
  int32_t index_position_usteps = 0;
  bool index_available = false;
  bool stall = false;               // the stepper's stall detection
  bool stall_enters_fault = true;   // the module's stall reaction: FAULT, or only a stop
  // The power stage reports a fault that keeps the motor from running (the module decides which
  // of its driver's flags do): FAULT while the power stage is on.
  bool power_stage_fault = false;
  // The power stage is on and the brake open (the module's delays passed): motion may start.
  bool ready = true;
};

// What the axis follows this tick: the position (with the velocity as its feed-forward), the
// velocity, or the torque.
enum class DriveControl : uint8_t { kPosition, kVelocity, kTorque };

// What the axis asks of the stepper (or servo) this tick.
struct AxisDemand {
  DriveControl control = DriveControl::kPosition;
  int32_t position_usteps = 0;
  int32_t velocity_pps = 0;         // rounded (a stepper's; 0 for a servo)
  double velocity_exact_pps = 0.0;  // unrounded (a servo's feed-forward)
  int32_t torque = 0;               // 6074, in the module's torque unit (control kTorque)
  bool power_enabled = false;
  bool brake_released_request = false;
  bool switch_on_disabled = true;
  bool clear_stall = false;  // the stall was handled: detect the next one
};

// The drive without the module's part, compiled once (axis_drive.cpp) for every module: what the
// part decides reaches it as data its AxisDrive<Part> hands in before each entry point (the unit
// scale, the shaped profile, whether a servo follows the demand), and the events it reports are
// given their EMCY codes there.
class AxisDriveCore {
 public:
  // csp/csv/cst: a set-point written without a SYNC for this long is taken at once.
  static constexpr uint32_t kSyncAbsentUs = 100'000;

  ProfileObjects objects;

  // Power-up and NMT reset node: SWITCH ON DISABLED, standing at `position`, objects kept.
  void reset(int32_t position = 0);
  // Microsteps per motor revolution: index homing gives up after two revolutions.
  void set_usteps_per_revolution(uint32_t usteps) { usteps_per_revolution_ = usteps; }

  // 6040 written (SDO or RPDO).
  void write_controlword(uint16_t controlword);
  // 607A / 60FF written: csp/csv take the set-point at once when no SYNC drives them; in pp a
  // 607A written in the same instant as the bit 4 edge (one RPDO) is the set-point taken.
  void target_position_written();
  void target_velocity_written();
  // 6071 written: cst takes it at once when no SYNC drives it.
  void target_torque_written();
  // A SYNC (after the synchronous RPDOs were written): csp/csv take 607A + 60B0 / 60FF + 60B1.
  void on_sync();
  // A fault from outside the axis (NMT stopped while operation enabled, ...).
  void external_fault() { pds_.fault(); }
  // The position counter takes `position` without motion (homing, or the module's encoder
  // position initialisation); the encoder position is re-based to it.
  void assign_position(int32_t position);

  // One motion tick.
  void step(const AxisInputs& inputs, uint32_t dt_us);
  // What step() changes besides in an axis it otherwise leaves as it is: the time since the
  // last SYNC. A module that has seen a step change nothing else, with nothing changed since,
  // calls this instead (docs/tmcm-3216-drive.md "Idle ticks").
  void rest(uint32_t dt_us) {
    if (us_since_sync_ < kSyncAbsentUs) us_since_sync_ += dt_us;
  }

  const AxisDemand& demand() const { return demand_; }
  // A position assignment (homing) for the stepper since the last call.
  bool take_position_assignment(int32_t& position);
  // A drive event since the last call (AxisDrive gives it its EMCY code).
  bool take_event(DriveEvent& out);

  // 6041 without the module's bits (AxisDrive adds them).
  uint16_t statusword() const;
  // Whether the motor moves, and the direction of its last motion (statusword bits 14/15 of the
  // Trinamic drives).
  bool motor_active() const { return !ramp_.standstill(); }
  bool negative_direction() const { return negative_direction_; }
  int8_t mode_display() const { return objects.mode; }  // 6061 follows 6060 at once
  int32_t position_demand() const { return ramp_.position(); }  // 6062
  int32_t position_actual() const;                               // 6063 / 6064
  // 606C in internal units: the measured velocity of a servo, the ramp's of a stepper.
  double velocity_actual_pps() const { return servo_ ? actual_velocity_pps_ : ramp_.velocity(); }
  double velocity_pps() const { return ramp_.velocity(); }
  PdsState state() const { return pds_.state(); }
  const PowerDriveSystem& pds() const { return pds_; }
  const Homing& homing() const { return homing_; }
  const motion::EightPointRamp& ramp() const { return ramp_; }
  bool target_reached() const { return target_reached_; }
  bool following_error() const { return following_error_; }
  bool limit_active() const { return limit_active_; }
  // The profile objects' trapezoid in internal units (6081..6085 and 607F, with `units`).
  motion::EightPointConfig trapezoid_config(const UnitScale& units) const;
  // Software limits corrected by the home offset (607D, manual 6.1.11); false when unlimited.
  bool min_limit(int64_t& limit) const;
  bool max_limit(int64_t& limit) const;

 protected:
  // Out of line: the members' initial values are a good deal of code, written once for all parts.
  explicit AxisDriveCore(bool servo);
  // What the module's part says, as AxisDrive<Part>::prepare() hands it in.
  bool servo_;
  UnitScale units_{};
  motion::EightPointConfig profile_{};  // the trapezoid shaped by the module

 private:
  PdsOptions options() const;
  void emergency(DriveEvent event);
  // A new 6060 takes effect: at the next step, or at once where a set-point or SYNC must see it.
  void take_mode_change();
  void on_mode_change(int8_t from, int8_t to);
  void accept_set_point(uint16_t controlword);
  // 607A + the set-point's base, clamped to the software limits.
  int32_t set_point_target();
  void start_homing();
  double slow_down_pps2() const;
  void check_faults(const AxisInputs& inputs);
  void run_pds_motion(const AxisInputs& inputs, double dt_s);
  void run_mode(const AxisInputs& inputs, double dt_s);
  void run_profile_position(const AxisInputs& inputs, double dt_s);
  void run_profile_velocity(const AxisInputs& inputs, double dt_s);
  void run_homing(const AxisInputs& inputs, uint32_t dt_us, double dt_s);
  void run_cyclic_position(double dt_s);
  void run_cyclic_velocity(const AxisInputs& inputs, double dt_s);
  void run_cyclic_torque();
  // A servo's profile generator takes the measured motion (the part's kServo).
  void follow_actual_motion();
  int32_t limited_torque(int32_t torque) const;
  void latch_cyclic_set_point();
  // Limit switches and software limits: which directions are blocked now (EMCY FF01 on entry).
  void update_limits(const AxisInputs& inputs);
  // pv / csv: brakes on 6085 so that the axis stops exactly on a software limit it runs towards;
  // true when it drove the ramp this tick.
  bool brake_onto_software_limit(double target_pps, double velocity_ramp_pps2, double dt_s);
  void stop_ramp(double deceleration_pps2);
  void update_target_reached(const AxisInputs& inputs, uint32_t dt_us);
  double interpolation_period_s() const;

  uint32_t usteps_per_revolution_ = 51200;
  PowerDriveSystem pds_;
  motion::EightPointRamp ramp_;
  Homing homing_;
  AxisDemand demand_{};
  int8_t active_mode_ = 0;
  uint16_t controlword_ = 0;
  // The config of the last ramp step (stops keep the profile's VSTOP).
  motion::EightPointConfig ramp_config_{};

  // Profile position.
  int32_t target_ = 0;            // internal absolute target
  bool moving_to_target_ = false; // a set-point is being executed
  bool set_point_ack_ = false;    // statusword bit 12
  bool pending_ = false;          // a buffered set-point (bit 5 = 0 while moving)
  int32_t pending_target_ = 0;
  bool set_point_refused_ = false;  // the last set-point was refused (warning bit 7)
  // The last accepted set-point: taken in this tick (an RPDO's 607A after its 6040 replaces it),
  // buffered or started, and what a relative 607A was added to.
  bool set_point_taken_in_tick_ = false;
  bool set_point_buffered_ = false;
  int64_t set_point_base_ = 0;
  uint32_t in_window_us_ = 0;
  bool target_reached_ = true;
  bool halted_ = false;
  bool stopping_on_limit_ = false;

  // csp / csv.
  uint32_t us_since_sync_ = kSyncAbsentUs;
  bool cyclic_latched_ = false;
  int32_t cyclic_from_ = 0;
  int32_t cyclic_to_ = 0;
  double cyclic_velocity_from_ = 0;
  double cyclic_velocity_to_ = 0;
  double cyclic_elapsed_s_ = 0;
  int32_t cyclic_torque_ = 0;
  DriveControl control_ = DriveControl::kPosition;
  double actual_velocity_pps_ = 0.0;  // the servo's measured velocity of this tick

  // Monitoring.
  bool following_error_ = false;
  bool limit_active_ = false;
  bool limit_positive_ = false;
  bool limit_negative_ = false;
  bool limit_reported_[4] = {};  // software +/-, switch +/-: EMCY once per excursion
  bool stall_latched_ = false;
  bool stall_stop_ = false;  // stopped by a stall that does not fault, until a new command
  bool clear_stall_request_ = false;  // demand.clear_stall in the next tick
  int32_t actual_position_ = 0;
  // The encoder keeps counting from its own zero: an assigned position (homing, initialisation)
  // re-bases it with this offset, so that 6064 and the following error stay in the demand's frame.
  int32_t last_encoder_usteps_ = 0;
  int32_t encoder_offset_ = 0;
  bool negative_direction_ = false;

  bool position_assigned_ = false;
  int32_t assigned_position_ = 0;

  std::array<DriveEvent, 8> emcy_{};
  size_t emcy_head_ = 0;
  size_t emcy_count_ = 0;
};

// One CiA-402 axis of a module: the drive with the module's part (see "The module's part" above).
// The part's calls inline here; the rest is AxisDriveCore's, compiled once.
template <class Manufacturer>
class AxisDrive : public AxisDriveCore {
  static_assert(ManufacturerPart<Manufacturer>, "see \"The module's part\" above");

 public:
  using Part = Manufacturer;
  Manufacturer manufacturer{};

  AxisDrive() : AxisDriveCore(Manufacturer::kServo) {}

  void reset(int32_t position = 0) {
    prepare();
    AxisDriveCore::reset(position);
  }
  void write_controlword(uint16_t controlword) {
    prepare();
    AxisDriveCore::write_controlword(controlword);
  }
  void target_position_written() {
    prepare();
    AxisDriveCore::target_position_written();
  }
  void target_velocity_written() {
    prepare();
    AxisDriveCore::target_velocity_written();
  }
  void target_torque_written() {
    prepare();
    AxisDriveCore::target_torque_written();
  }
  void on_sync() {
    prepare();
    AxisDriveCore::on_sync();
  }
  void step(const AxisInputs& inputs, uint32_t dt_us) {
    prepare();
    AxisDriveCore::step(inputs, dt_us);
  }

  bool take_emergency(AxisEmergency& out) {
    DriveEvent event{};
    if (!take_event(event)) return false;
    out = Manufacturer::emergency(event);
    return true;
  }
  uint16_t statusword() const {
    return static_cast<uint16_t>(AxisDriveCore::statusword() |
                                 Manufacturer::manufacturer_status_bits(motor_active(), negative_direction()));
  }
  int32_t velocity_actual_value() const { return units().velocity_value(velocity_actual_pps()); }  // 606C
  int32_t velocity_demand_value() const { return units().velocity_value(ramp().velocity()); }       // 606B
  UnitScale units() const { return manufacturer.units(); }
  // The profile of the present mode in internal units: 6081..6085, shaped by the module.
  motion::EightPointConfig profile_config() const {
    const UnitScale u = units();
    motion::EightPointConfig c = trapezoid_config(u);
    manufacturer.shape_profile(c, u);
    return c;
  }

 private:
  // The part's view as it is now, for the core's entry point that follows (its objects may have
  // changed by SDO since the last one).
  void prepare() {
    units_ = units();
    profile_ = profile_config();
  }
};

}  // namespace motwin::cia402
