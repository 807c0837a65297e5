// The CiA-402 power drive system (PDS) state machine of one axis (TMCM-3216 manual figure 9, table
// 228 command coding, table 234 state coding; CiA-402 part 2, 6.2). It decodes the controlword,
// runs the transitions, and says what the motion part must do: keep the power stage on or off,
// run the mode, or stop on the slow-down or quick-stop ramp. It knows nothing about motion itself:
// the axis tells it when a requested stop has come to standstill (motion_stopped()) and when a
// fault is detected (fault()).
//
// Transitions (numbers of figure 9):
//   0, 1  power-on: NOT READY TO SWITCH ON -> SWITCH ON DISABLED (at once)
//   2     SWITCH ON DISABLED -> READY TO SWITCH ON       shutdown (0xxx x110)
//   3     READY TO SWITCH ON -> SWITCHED ON               switch on (0xxx 0111)
//   3+4   READY TO SWITCH ON -> OPERATION ENABLED         switch on + enable operation (0xxx 1111)
//   4     SWITCHED ON -> OPERATION ENABLED                enable operation (0xxx 1111)
//   5     OPERATION ENABLED -> SWITCHED ON                disable operation (0xxx 0111): 605C = 1,
//                                                         slow-down ramp, then the state changes
//   6     SWITCHED ON -> READY TO SWITCH ON               shutdown
//   7     READY TO SWITCH ON -> SWITCH ON DISABLED        disable voltage (0xxx xx0x) / quick stop (0xxx x01x)
//   8     OPERATION ENABLED -> READY TO SWITCH ON         shutdown: 605B = 0, power stage off at once
//   9     OPERATION ENABLED -> SWITCH ON DISABLED         disable voltage: power stage off at once
//   10    SWITCHED ON -> SWITCH ON DISABLED               disable voltage / quick stop
//   11    OPERATION ENABLED -> QUICK STOP ACTIVE          quick stop (0xxx x01x): 605A ramp
//   12    QUICK STOP ACTIVE -> SWITCH ON DISABLED         605A = 1, 2 at standstill; disable voltage
//   13    any -> FAULT REACTION ACTIVE                    fault: 605E = 2, quick-stop ramp
//   14    FAULT REACTION ACTIVE -> FAULT                  at standstill
//   15    FAULT -> SWITCH ON DISABLED                     fault reset (bit 7 rising edge)
//   16    QUICK STOP ACTIVE -> OPERATION ENABLED          enable operation, 605A = 5, 6, at standstill
#pragma once

#include <cstdint>

namespace motwin::cia402 {

enum class PdsState : uint8_t {
  kNotReadyToSwitchOn,
  kSwitchOnDisabled,
  kReadyToSwitchOn,
  kSwitchedOn,
  kOperationEnabled,
  kQuickStopActive,
  kFaultReactionActive,
  kFault,
};

// Controlword bits (6040).
inline constexpr uint16_t kCwSwitchOn = 1u << 0;
inline constexpr uint16_t kCwEnableVoltage = 1u << 1;
inline constexpr uint16_t kCwQuickStop = 1u << 2;  // 0 = quick stop requested
inline constexpr uint16_t kCwEnableOperation = 1u << 3;
inline constexpr uint16_t kCwNewSetPoint = 1u << 4;  // pp; homing operation start in hm
inline constexpr uint16_t kCwChangeImmediately = 1u << 5;
inline constexpr uint16_t kCwRelative = 1u << 6;
inline constexpr uint16_t kCwFaultReset = 1u << 7;
inline constexpr uint16_t kCwHalt = 1u << 8;

// Statusword bits (6041).
inline constexpr uint16_t kSwReadyToSwitchOn = 1u << 0;
inline constexpr uint16_t kSwSwitchedOn = 1u << 1;
inline constexpr uint16_t kSwOperationEnabled = 1u << 2;
inline constexpr uint16_t kSwFault = 1u << 3;
inline constexpr uint16_t kSwVoltageEnabled = 1u << 4;
inline constexpr uint16_t kSwQuickStop = 1u << 5;  // 0 = quick stop active
inline constexpr uint16_t kSwSwitchOnDisabled = 1u << 6;
inline constexpr uint16_t kSwWarning = 1u << 7;
inline constexpr uint16_t kSwRemote = 1u << 9;
inline constexpr uint16_t kSwTargetReached = 1u << 10;
inline constexpr uint16_t kSwInternalLimit = 1u << 11;
inline constexpr uint16_t kSwOms12 = 1u << 12;  // set-point acknowledge / homing attained / target used
inline constexpr uint16_t kSwOms13 = 1u << 13;  // following error / homing error
// Bits 8, 14 and 15 are manufacturer-specific: the module's part of the drive sets them
// (axis_drive.h, manufacturer_status_bits()).

// The state bits of the statusword (bits 0..3, 5, 6) per table 234; bit 4 (voltage enabled) is
// set in the states where the controlword enabled the voltage.
uint16_t state_bits(PdsState state);

// 605A quick stop option codes the manual supports.
inline constexpr int16_t kQuickStopSlowDownThenDisable = 1;
inline constexpr int16_t kQuickStopQuickRampThenDisable = 2;
inline constexpr int16_t kQuickStopSlowDownStay = 5;
inline constexpr int16_t kQuickStopQuickRampStay = 6;
constexpr bool valid_quick_stop_option(int64_t code) { return code == 1 || code == 2 || code == 5 || code == 6; }

// What the motion part must do now.
enum class PdsMotion : uint8_t {
  kOff,             // power stage off (no current), nothing runs
  kHold,            // power stage on, standing still (switched on; quick stop active at standstill)
  kRun,             // operation enabled: the mode runs
  kSlowDownStop,    // decelerate on the mode's slow-down ramp to standstill
  kQuickStop,       // decelerate on the quick-stop ramp (6085) to standstill
};

struct PdsOptions {
  int16_t quick_stop = kQuickStopQuickRampThenDisable;  // 605A
  int16_t shutdown = 0;                                  // 605B (0 only)
  int16_t disable_operation = 1;                         // 605C (1 only)
  int16_t halt = 1;                                      // 605D (1 only)
  int16_t fault_reaction = 2;                            // 605E (2 only)
};

class PowerDriveSystem {
 public:
  // Power-on / NMT reset node: transitions 0 and 1.
  void reset();

  // A controlword written (SDO or RPDO). Returns true when it changed the state.
  bool on_controlword(uint16_t controlword, const PdsOptions& options);
  // A fault detected by the axis (following error, a stall that faults, NMT stopped, ...):
  // transition 13 from any state but FAULT. From states without power the drive goes straight
  // to FAULT (there is nothing to stop).
  void fault();
  // The stop the PDS asked for (kSlowDownStop / kQuickStop) has reached standstill.
  void motion_stopped(const PdsOptions& options);

  PdsState state() const { return state_; }
  PdsMotion motion() const { return motion_; }
  uint16_t controlword() const { return controlword_; }
  uint16_t statusword_state_bits() const { return state_bits(state_); }
  bool power_enabled() const { return motion_ != PdsMotion::kOff; }
  bool operation_enabled() const { return state_ == PdsState::kOperationEnabled; }
  // True once after a fault reset (15) was carried out: the axis sends EMCY 0000.
  bool take_fault_reset_event() {
    const bool event = fault_reset_event_;
    fault_reset_event_ = false;
    return event;
  }

 private:
  void enter(PdsState state, PdsMotion motion);

  PdsState state_ = PdsState::kNotReadyToSwitchOn;
  PdsMotion motion_ = PdsMotion::kOff;
  uint16_t controlword_ = 0;
  bool fault_reset_event_ = false;
  // Transition 5 is under way: operation enabled until the slow-down ramp ends.
  bool disabling_operation_ = false;
};

}  // namespace motwin::cia402
