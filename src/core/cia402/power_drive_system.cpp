#include "core/cia402/power_drive_system.h"

namespace motwin::cia402 {

uint16_t state_bits(PdsState state) {
  switch (state) {
    case PdsState::kNotReadyToSwitchOn: return 0x0000;
    case PdsState::kSwitchOnDisabled: return kSwSwitchOnDisabled;
    case PdsState::kReadyToSwitchOn: return kSwQuickStop | kSwVoltageEnabled | kSwReadyToSwitchOn;
    case PdsState::kSwitchedOn: return kSwQuickStop | kSwVoltageEnabled | kSwSwitchedOn | kSwReadyToSwitchOn;
    case PdsState::kOperationEnabled:
      return kSwQuickStop | kSwVoltageEnabled | kSwOperationEnabled | kSwSwitchedOn | kSwReadyToSwitchOn;
    case PdsState::kQuickStopActive:
      return kSwVoltageEnabled | kSwOperationEnabled | kSwSwitchedOn | kSwReadyToSwitchOn;
    case PdsState::kFaultReactionActive:
      return kSwVoltageEnabled | kSwFault | kSwOperationEnabled | kSwSwitchedOn | kSwReadyToSwitchOn;
    case PdsState::kFault: return kSwFault;
  }
  return 0;
}

void PowerDriveSystem::reset() {
  controlword_ = 0;
  fault_reset_event_ = false;
  disabling_operation_ = false;
  // Transition 0 (self-test done) and 1 (automatic) happen in the same instant.
  enter(PdsState::kSwitchOnDisabled, PdsMotion::kOff);
}

void PowerDriveSystem::enter(PdsState state, PdsMotion motion) {
  state_ = state;
  motion_ = motion;
  if (state != PdsState::kOperationEnabled) disabling_operation_ = false;
}

bool PowerDriveSystem::on_controlword(uint16_t controlword, const PdsOptions& options) {
  const uint16_t previous = controlword_;
  controlword_ = controlword;
  const PdsState before = state_;
  const bool fault_reset_edge = (controlword & kCwFaultReset) != 0 && (previous & kCwFaultReset) == 0;
  const bool disable_voltage = (controlword & kCwEnableVoltage) == 0;
  const bool quick_stop = !disable_voltage && (controlword & kCwQuickStop) == 0;
  const bool shutdown = (controlword & 0x7) == 0x6;
  const bool switch_on = (controlword & 0xF) == 0x7;
  const bool enable_operation = (controlword & 0xF) == 0xF;

  switch (state_) {
    case PdsState::kNotReadyToSwitchOn: break;  // left automatically
    case PdsState::kSwitchOnDisabled:
      if (shutdown) enter(PdsState::kReadyToSwitchOn, PdsMotion::kOff);  // 2
      break;
    case PdsState::kReadyToSwitchOn:
      if (disable_voltage || quick_stop) {
        enter(PdsState::kSwitchOnDisabled, PdsMotion::kOff);  // 7
      } else if (switch_on) {
        enter(PdsState::kSwitchedOn, PdsMotion::kOff);  // 3
      } else if (enable_operation) {
        enter(PdsState::kOperationEnabled, PdsMotion::kRun);  // 3 + 4
      }
      break;
    case PdsState::kSwitchedOn:
      if (disable_voltage || quick_stop) {
        enter(PdsState::kSwitchOnDisabled, PdsMotion::kOff);  // 10
      } else if (shutdown) {
        enter(PdsState::kReadyToSwitchOn, PdsMotion::kOff);  // 6
      } else if (enable_operation) {
        enter(PdsState::kOperationEnabled, PdsMotion::kRun);  // 4
      }
      break;
    case PdsState::kOperationEnabled:
      if (disable_voltage) {
        enter(PdsState::kSwitchOnDisabled, PdsMotion::kOff);  // 9
      } else if (quick_stop) {
        // 11: option codes 1 and 5 use the mode's slow-down ramp, 2 and 6 the quick-stop ramp.
        const bool slow_down = options.quick_stop == kQuickStopSlowDownThenDisable ||
                               options.quick_stop == kQuickStopSlowDownStay;
        enter(PdsState::kQuickStopActive, slow_down ? PdsMotion::kSlowDownStop : PdsMotion::kQuickStop);
      } else if (shutdown) {
        enter(PdsState::kReadyToSwitchOn, PdsMotion::kOff);  // 8, 605B = 0: power stage off at once
      } else if (switch_on) {
        // 5, 605C = 1: the state changes once the slow-down ramp has stopped the motor.
        if (!disabling_operation_) {
          disabling_operation_ = true;
          motion_ = PdsMotion::kSlowDownStop;
        }
      } else if (enable_operation && disabling_operation_) {
        disabling_operation_ = false;  // enabled again before the ramp ended: carry on
        motion_ = PdsMotion::kRun;
      }
      break;
    case PdsState::kQuickStopActive:
      if (disable_voltage) {
        enter(PdsState::kSwitchOnDisabled, PdsMotion::kOff);  // 12
      } else if (enable_operation && motion_ == PdsMotion::kHold) {
        enter(PdsState::kOperationEnabled, PdsMotion::kRun);  // 16 (only 605A = 5, 6 stay here)
      }
      break;
    case PdsState::kFaultReactionActive: break;  // nothing until the reaction ends
    case PdsState::kFault:
      if (fault_reset_edge) {
        enter(PdsState::kSwitchOnDisabled, PdsMotion::kOff);  // 15
        fault_reset_event_ = true;
      }
      break;
  }
  return state_ != before;
}

void PowerDriveSystem::fault() {
  switch (state_) {
    case PdsState::kFault:
    case PdsState::kFaultReactionActive: return;
    case PdsState::kOperationEnabled:
    case PdsState::kQuickStopActive:
      // 13, 605E = 2: the motor is brought to standstill on the quick-stop ramp first.
      enter(PdsState::kFaultReactionActive, PdsMotion::kQuickStop);
      return;
    default:
      // No drive function running: the reaction has nothing to do (13 then 14 at once).
      enter(PdsState::kFault, PdsMotion::kOff);
      return;
  }
}

void PowerDriveSystem::motion_stopped(const PdsOptions& options) {
  switch (state_) {
    case PdsState::kQuickStopActive:
      if (motion_ != PdsMotion::kSlowDownStop && motion_ != PdsMotion::kQuickStop) return;
      if (options.quick_stop == kQuickStopSlowDownThenDisable || options.quick_stop == kQuickStopQuickRampThenDisable) {
        enter(PdsState::kSwitchOnDisabled, PdsMotion::kOff);  // 12
      } else {
        motion_ = PdsMotion::kHold;  // 5, 6: stay in quick stop active, holding
      }
      return;
    case PdsState::kFaultReactionActive: enter(PdsState::kFault, PdsMotion::kOff); return;  // 14
    case PdsState::kOperationEnabled:
      if (disabling_operation_) enter(PdsState::kSwitchedOn, PdsMotion::kOff);  // end of 5
      return;
    default: return;
  }
}

}  // namespace motwin::cia402
