// Fault monitor of the TMCM-3216's axes: the emergencies of manual table 365 (chapter 11) that an
// axis can produce. Each tick the module hands in what the axis shows (AxisConditions: driver
// flags of 2102, the stall flag, following error, software limits, limit switches); a condition
// that rises sends its EMCY once (code, 1001, additional byte 1 = the table's sub-code, byte 2 =
// the motor), sets its 1001 bits and tells the PDS what to do (EmergencyResult). Faults stay
// latched until a fault reset (controlword bit 7) finds them gone; warnings clear with their
// condition. The module-wide shutdown switch (5441) is one EMCY with byte 2 = 255.
//
// Pure arithmetic in the shape of CANopenNode's CO_errorReport/CO_errorReset: no heap, no OS;
// the EMCY producer (emergency.h) queues and applies the 1015 inhibit time.
// docs/tmcm-3216-drive.md, "Monitoring and emergencies", has the table and the decisions.
#pragma once

#include <array>
#include <cstdint>
#include <span>

#include "core/canopen/emergency.h"

namespace motwin::cia402 {
template <class Manufacturer>
class AxisDrive;
}

namespace motwin::modules::tmcm3216 {

class Tmcm3216Stepper;
struct Tmcm3216DriveObjects;
using Tmcm3216Drive = cia402::AxisDrive<Tmcm3216DriveObjects>;  // tmcm3216_drive.h

inline constexpr uint8_t kEmergencyAxisCount = 3;
inline constexpr uint8_t kEmergencyNoMotor = 255;  // additional byte 2 of module-wide messages

// Error codes of table 365 raised by the axes.
inline constexpr uint16_t kEmcyFaultReset = 0x0000;
inline constexpr uint16_t kEmcyOpenLoad = 0x1000;
inline constexpr uint16_t kEmcyOvercurrentHighSide = 0x2310;
inline constexpr uint16_t kEmcyOvercurrentBridgeB = 0x2311;
inline constexpr uint16_t kEmcyOvercurrentBridgeA = 0x2312;
inline constexpr uint16_t kEmcyStallGuard = 0x3230;
inline constexpr uint16_t kEmcyOvertemperature = 0x4310;
inline constexpr uint16_t kEmcyShutdownSwitch = 0x5441;
inline constexpr uint16_t kEmcyFollowingError = 0x8611;
inline constexpr uint16_t kEmcyUndervoltage = 0xFF00;
inline constexpr uint16_t kEmcyLimit = 0xFF01;
// Table 365's code for an RPDO whose data the drive refused ("parameter error").
inline constexpr uint16_t kEmcyPdoParameter = 0x6320;

// 1001 bits (CiA-301 table 47; manual table 11).
using canopen::kErrorRegisterCurrent;
using canopen::kErrorRegisterDeviceProfile;
using canopen::kErrorRegisterGeneric;
using canopen::kErrorRegisterManufacturer;
using canopen::kErrorRegisterTemperature;
using canopen::kErrorRegisterVoltage;
// 1001 bits of an axis in FAULT (or its fault reaction), whatever the cause: the module sets
// them from the PDS state; a fault's EMCY carries them already (it is what the report sets).
inline constexpr uint8_t kErrorRegisterAxisFault = kErrorRegisterGeneric | kErrorRegisterDeviceProfile;

// One bit per row of table 365 that concerns an axis (active_conditions()).
enum class AxisCondition : uint8_t {
  kOpenLoadA,
  kOpenLoadB,
  kOvercurrentHighSide,
  kOvercurrentBridgeB,
  kOvercurrentBridgeA,
  kStall,
  kOvertemperatureWarning,
  kOvertemperature,
  kShutdownSwitch,
  kFollowingError,
  kUndervoltage,
  kSoftwareLimitPositive,
  kSoftwareLimitNegative,
  kLimitSwitchPositive,
  kLimitSwitchNegative,
  kCount,
};
using ConditionMask = uint16_t;
constexpr ConditionMask condition_bit(AxisCondition c) {
  return static_cast<ConditionMask>(1u << static_cast<unsigned>(c));
}

// What the PDS must do when the condition rises (table 365's descriptions, CiA-402 fault reaction).
enum class EmergencyReaction : uint8_t {
  kWarning,  // information only; the drive goes on (limits: the drive blocks that direction itself)
  kFault,    // FAULT REACTION ACTIVE -> FAULT (605E), until a fault reset finds it gone
};

// A row of table 365.
struct EmergencyDefinition {
  AxisCondition condition;
  uint16_t code;
  uint8_t sub;             // additional byte 1
  uint8_t error_register;  // 1001 bits while active
  EmergencyReaction reaction;
  // An event rather than a level (stall, following error): the drive latches it and a fault
  // reset clears it whatever the present level (the drive re-arms the detection).
  bool cleared_by_reset;
  // A driver flag that only stops a running motor: with the power stage off it is a warning,
  // and it becomes the fault when the power stage is switched on while it is present.
  bool fault_needs_power;
};
std::span<const EmergencyDefinition> emergency_table();
const EmergencyDefinition& emergency_definition(AxisCondition condition);

// What one axis shows this tick: levels, not events (the monitor finds the edges).
struct AxisConditions {
  uint8_t driver_errors = 0;             // 2102 bits (board::kDriver*)
  bool stall = false;                    // the stepper's stop-on-stall flag (20A4 / 20A8)
  bool stall_enters_fault = true;        // 20A7 = 0: FAULT; 1: stop only
  bool following_error = false;          // 6065 exceeded (latched by the drive until fault reset)
  bool software_limit_positive = false;  // actual position on or beyond 607D max (corrected by 607C)
  bool software_limit_negative = false;  // ... on or below 607D min
  bool limit_switch_positive = false;    // right switch, processed level (2005 applied)
  bool limit_switch_negative = false;    // left switch
  bool homing = false;  // the homing procedure runs: touching a switch or a limit is no error
  bool power_enabled = true;  // the PDS drives the motor (operation enabled, quick stop, reaction)
};

// The conditions of an axis from its stepper and drive (the module's wiring in one call).
AxisConditions conditions_of(const Tmcm3216Stepper& stepper, const Tmcm3216Drive& drive);

struct EmergencyResult {
  ConditionMask raised = 0;  // conditions that rose now (an EMCY each)
  bool fault = false;        // a fault rose: the PDS goes to FAULT (CiA-402 transition 13)
  bool stop = false;         // a stall with 20A7 = 1: stop on the quick-stop ramp, stay enabled
};

class Tmcm3216Emergencies {
 public:
  // Power-up, NMT reset node: nothing active, no edges remembered.
  void reset();

  // One tick of `axis`: an EMCY for each condition that rose and is not active yet, and for a
  // driver fault present when the power stage comes on. The EMCY's 1001 byte is 1001 as the
  // report leaves it: error_register() with the condition's bits | `other_error_register` (the
  // communication bits, the FAULT bits of the axes) | kErrorRegisterAxisFault for a fault.
  // Overtemperature escalates: one EMCY per transition (the pre-warning, then the error; the
  // error alone when both flags rise together; the pre-warning after the error has gone).
  EmergencyResult update(uint8_t axis, const AxisConditions& conditions, canopen::EmergencyProducer& emcy,
                         uint8_t other_error_register = 0);
  // The shutdown switch (enable input, module-wide): EMCY 5441 with byte 2 = 255 once when it
  // opens; a fault of every axis (result.fault applies to all three).
  EmergencyResult update_shutdown(bool active, canopen::EmergencyProducer& emcy, uint8_t other_error_register = 0);

  // Controlword bit 7 rising edge in FAULT (transition 15). Conditions that are gone (and the
  // events stall and following error) are cleared. true: no fault remains, EMCY 0000 with the
  // axis in byte 2 went out, the axis may leave FAULT. false: a fault is still present: its
  // EMCY is sent again (once per reset command) and the axis stays in FAULT.
  bool fault_reset(uint8_t axis, canopen::EmergencyProducer& emcy, uint8_t other_error_register = 0);

  ConditionMask active_conditions(uint8_t axis) const { return axes_[axis].active; }
  ConditionMask active_faults(uint8_t axis) const { return axes_[axis].faults; }
  bool fault_present(uint8_t axis) const { return axes_[axis].faults != 0; }
  // 1001 bits of the active conditions: of one axis, of all (the module's part of 1001).
  uint8_t error_register(uint8_t axis) const;
  uint8_t error_register() const;

 private:
  struct AxisState {
    ConditionMask levels = 0;  // the raw levels of the last update (edge detection)
    ConditionMask active = 0;  // reported and not cleared yet
    ConditionMask faults = 0;  // the active ones that hold the axis in FAULT
  };

  // Reports `condition` (of `axis`, or kEmergencyNoMotor) and marks it active.
  void raise(uint8_t axis, AxisCondition condition, EmergencyReaction reaction, canopen::EmergencyProducer& emcy,
             uint8_t other_error_register, uint8_t motor);
  static void send(canopen::EmergencyProducer& emcy, uint16_t code, uint8_t sub, uint8_t error_register, uint8_t motor);

  std::array<AxisState, kEmergencyAxisCount> axes_{};
  bool shutdown_level_ = false;
};

}  // namespace motwin::modules::tmcm3216
