#include "core/modules/tmcm3216/tmcm3216_emergencies.h"

#include <array>
#include <cstddef>
#include <cstdint>

#include "board/stepper_drive.h"
#include "core/modules/tmcm3216/tmcm3216_drive.h"
#include "core/modules/tmcm3216/tmcm3216_stepper.h"

namespace motwin::modules::tmcm3216 {

namespace {

using enum AxisCondition;
constexpr EmergencyReaction kWarning = EmergencyReaction::kWarning;
constexpr EmergencyReaction kFault = EmergencyReaction::kFault;
constexpr uint8_t kGeneric = kErrorRegisterGeneric;

// Table 365 in the order of AxisCondition. 1001 bits follow the CiA-301 class of the code
// (2xxx current, 4xxx temperature) or, where the class says nothing about the cause, its meaning:
// FF00 undervoltage is a voltage error; 3230 (CiA-402 "load error"), 5441 and 8611 are codes of
// the drive profile; FF01 is manufacturer specific. Reactions: what the table says the driver
// does (switched off: fault) and CiA-402 (following error: fault). The driver's faults stop a
// running motor only: with the power stage off they are reported and the axis stays where it is
// until it is switched on.
constexpr std::array<EmergencyDefinition, static_cast<size_t>(AxisCondition::kCount)> kTable{{
    {kOpenLoadA, kEmcyOpenLoad, 1, kGeneric, kWarning, false, false},
    {kOpenLoadB, kEmcyOpenLoad, 2, kGeneric, kWarning, false, false},
    {kOvercurrentHighSide, kEmcyOvercurrentHighSide, 0, kGeneric | kErrorRegisterCurrent, kFault, false, true},
    {kOvercurrentBridgeB, kEmcyOvercurrentBridgeB, 0, kGeneric | kErrorRegisterCurrent, kFault, false, true},
    {kOvercurrentBridgeA, kEmcyOvercurrentBridgeA, 0, kGeneric | kErrorRegisterCurrent, kFault, false, true},
    // 20A7 decides per stall whether it is a fault (update()).
    {kStall, kEmcyStallGuard, 0, kGeneric | kErrorRegisterDeviceProfile, kFault, true, false},
    {kOvertemperatureWarning, kEmcyOvertemperature, 1, kGeneric | kErrorRegisterTemperature, kWarning, false, false},
    {kOvertemperature, kEmcyOvertemperature, 0, kGeneric | kErrorRegisterTemperature, kFault, false, true},
    {kShutdownSwitch, kEmcyShutdownSwitch, 0, kGeneric | kErrorRegisterDeviceProfile, kFault, false, false},
    {kFollowingError, kEmcyFollowingError, 0, kGeneric | kErrorRegisterDeviceProfile, kFault, true, false},
    {kUndervoltage, kEmcyUndervoltage, 0, kGeneric | kErrorRegisterVoltage, kFault, false, true},
    {kSoftwareLimitPositive, kEmcyLimit, 1, kGeneric | kErrorRegisterManufacturer, kWarning, false, false},
    {kSoftwareLimitNegative, kEmcyLimit, 2, kGeneric | kErrorRegisterManufacturer, kWarning, false, false},
    {kLimitSwitchPositive, kEmcyLimit, 3, kGeneric | kErrorRegisterManufacturer, kWarning, false, false},
    {kLimitSwitchNegative, kEmcyLimit, 4, kGeneric | kErrorRegisterManufacturer, kWarning, false, false},
}};

constexpr bool table_in_order() {
  for (size_t i = 0; i < kTable.size(); ++i) {
    if (static_cast<size_t>(kTable[i].condition) != i) return false;
  }
  return true;
}
static_assert(table_in_order(), "kTable rows follow AxisCondition");

// The conditions an axis reports itself (the shutdown switch comes from update_shutdown()).
constexpr ConditionMask kAxisLevels = static_cast<ConditionMask>(~condition_bit(kShutdownSwitch));
// Not errors while the homing procedure runs: it looks for the switches, and the coordinate
// system (hence 607D) is not established yet.
constexpr ConditionMask kNotDuringHoming = condition_bit(kSoftwareLimitPositive) |
                                           condition_bit(kSoftwareLimitNegative) |
                                           condition_bit(kLimitSwitchPositive) | condition_bit(kLimitSwitchNegative);

ConditionMask levels_of(const AxisConditions& c) {
  const uint8_t d = c.driver_errors;
  ConditionMask m = 0;
  auto set = [&m](bool level, AxisCondition condition) {
    if (level) m = static_cast<ConditionMask>(m | condition_bit(condition));
  };
  set((d & board::kDriverOpenLoadA) != 0, kOpenLoadA);
  set((d & board::kDriverOpenLoadB) != 0, kOpenLoadB);
  set((d & board::kDriverOvercurrentHighSide) != 0, kOvercurrentHighSide);
  set((d & board::kDriverOvercurrentB) != 0, kOvercurrentBridgeB);
  set((d & board::kDriverOvercurrentA) != 0, kOvercurrentBridgeA);
  set(c.stall, kStall);
  set((d & board::kDriverTemperatureWarning) != 0, kOvertemperatureWarning);
  set((d & board::kDriverOvertemperature) != 0, kOvertemperature);
  set(c.following_error, kFollowingError);
  set((d & board::kDriverUndervoltage) != 0, kUndervoltage);
  set(c.software_limit_positive, kSoftwareLimitPositive);
  set(c.software_limit_negative, kSoftwareLimitNegative);
  set(c.limit_switch_positive, kLimitSwitchPositive);
  set(c.limit_switch_negative, kLimitSwitchNegative);
  return m;
}

}  // namespace

std::span<const EmergencyDefinition> emergency_table() { return kTable; }

const EmergencyDefinition& emergency_definition(AxisCondition condition) {
  return kTable[static_cast<size_t>(condition)];
}

AxisConditions conditions_of(const Tmcm3216Stepper& stepper, const Tmcm3216Drive& drive) {
  AxisConditions c;
  c.driver_errors = stepper.driver_error_flags();
  c.stall = stepper.stall_detected();
  c.stall_enters_fault = stepper.stall_enters_fault();
  c.following_error = drive.following_error();
  // "The actual position is outside the range defined by 607D": on or beyond the corrected
  // limit, where the drive stops the motion and shows statusword bit 11 (a move ended by the
  // limit stands on it).
  int64_t limit = 0;
  const int64_t actual = drive.position_actual();
  c.software_limit_positive = drive.max_limit(limit) && actual >= limit;
  c.software_limit_negative = drive.min_limit(limit) && actual <= limit;
  const SwitchState switches = stepper.switches();
  c.limit_switch_positive = switches.right;
  c.limit_switch_negative = switches.left;
  c.homing = drive.homing().active();
  c.power_enabled = drive.pds().power_enabled();
  return c;
}

void Tmcm3216Emergencies::reset() {
  axes_ = {};
  shutdown_level_ = false;
}

uint8_t Tmcm3216Emergencies::error_register(uint8_t axis) const {
  uint8_t bits = 0;
  const ConditionMask active = axes_[axis].active;
  for (const EmergencyDefinition& row : kTable) {
    if ((active & condition_bit(row.condition)) != 0) bits = static_cast<uint8_t>(bits | row.error_register);
  }
  return bits;
}

uint8_t Tmcm3216Emergencies::error_register() const {
  uint8_t bits = 0;
  for (uint8_t axis = 0; axis < kEmergencyAxisCount; ++axis) bits = static_cast<uint8_t>(bits | error_register(axis));
  return bits;
}

void Tmcm3216Emergencies::send(canopen::EmergencyProducer& emcy, uint16_t code, uint8_t sub, uint8_t error_register,
                               uint8_t motor) {
  const uint8_t manufacturer[5] = {sub, motor, 0, 0, 0};
  emcy.report(code, error_register, manufacturer);
}

void Tmcm3216Emergencies::raise(uint8_t axis, AxisCondition condition, EmergencyReaction reaction,
                                canopen::EmergencyProducer& emcy, uint8_t other_error_register, uint8_t motor) {
  AxisState& s = axes_[axis];
  const ConditionMask bit = condition_bit(condition);
  s.active = static_cast<ConditionMask>(s.active | bit);
  if (reaction == EmergencyReaction::kFault) s.faults = static_cast<ConditionMask>(s.faults | bit);
  if (motor == kEmergencyNoMotor) return;  // update_shutdown() sends one message for all axes
  const EmergencyDefinition& row = emergency_definition(condition);
  // A fault puts the axis into FAULT at once: its message carries the bits that state sets.
  const uint8_t fault_bits = reaction == EmergencyReaction::kFault ? kErrorRegisterAxisFault : 0;
  send(emcy, row.code, row.sub, static_cast<uint8_t>(error_register() | other_error_register | fault_bits), motor);
}

EmergencyResult Tmcm3216Emergencies::update(uint8_t axis, const AxisConditions& conditions,
                                            canopen::EmergencyProducer& emcy, uint8_t other_error_register) {
  EmergencyResult result;
  if (axis >= kEmergencyAxisCount) return result;
  AxisState& s = axes_[axis];
  const ConditionMask levels = levels_of(conditions);
  // An EMCY on the rising edge of the level only: a condition that stays (or is still active,
  // awaiting a fault reset) sends nothing more, so nothing floods the bus.
  ConditionMask rising = static_cast<ConditionMask>(levels & ~s.levels & ~s.active & kAxisLevels);
  if (conditions.homing) rising = static_cast<ConditionMask>(rising & ~kNotDuringHoming);
  s.levels = static_cast<ConditionMask>((s.levels & ~kAxisLevels) | levels);

  // Warnings go with their condition; faults wait for the fault reset.
  const ConditionMask warnings = static_cast<ConditionMask>(s.active & ~s.faults & kAxisLevels);
  s.active = static_cast<ConditionMask>(s.active & ~(warnings & ~levels));

  // A driver fault reported while the power stage was off becomes the fault when it comes on.
  ConditionMask promoted = 0;
  if (conditions.power_enabled) promoted = static_cast<ConditionMask>(levels & s.active & ~s.faults);

  // Overtemperature is one condition in two steps. While the error is active (or rises now) the
  // pre-warning is part of it and sends nothing; its level is not remembered, so that it counts
  // as rising (and is reported) once the error has gone and the driver is still warm.
  constexpr ConditionMask kWarm = condition_bit(kOvertemperatureWarning);
  constexpr ConditionMask kHot = condition_bit(kOvertemperature);
  if ((rising & kWarm) != 0 && ((rising | s.active) & kHot) != 0) {
    rising = static_cast<ConditionMask>(rising & ~kWarm);
    s.levels = static_cast<ConditionMask>(s.levels & ~kWarm);
  }

  // Nothing rose and nothing is promoted: the usual tick of a healthy axis (the table walk below
  // was a tenth of a whole TMCM-3216 tick).
  if ((rising | promoted) == 0) return result;
  for (const EmergencyDefinition& row : kTable) {
    const ConditionMask bit = condition_bit(row.condition);
    if ((promoted & bit) != 0 && row.fault_needs_power) {
      s.active = static_cast<ConditionMask>(s.active & ~bit);  // reported anew, as the fault
      rising = static_cast<ConditionMask>(rising | bit);
    }
    if ((rising & bit) == 0) continue;
    EmergencyReaction reaction = row.reaction;
    if (row.condition == kStall && !conditions.stall_enters_fault) {
      reaction = EmergencyReaction::kWarning;  // 20A7 = 1: stop, no FAULT
      result.stop = true;
    }
    if (row.fault_needs_power && !conditions.power_enabled) reaction = EmergencyReaction::kWarning;
    if (reaction == EmergencyReaction::kFault) result.fault = true;
    raise(axis, row.condition, reaction, emcy, other_error_register, axis);
  }
  result.raised = rising;
  return result;
}

EmergencyResult Tmcm3216Emergencies::update_shutdown(bool active, canopen::EmergencyProducer& emcy,
                                                     uint8_t other_error_register) {
  EmergencyResult result;
  const bool rising = active && !shutdown_level_;
  shutdown_level_ = active;
  if (!rising) return result;
  const ConditionMask bit = condition_bit(kShutdownSwitch);
  bool already = true;  // still latched in every axis from the last opening: nothing new
  for (uint8_t axis = 0; axis < kEmergencyAxisCount; ++axis) {
    if ((axes_[axis].active & bit) == 0) already = false;
    raise(axis, kShutdownSwitch, EmergencyReaction::kFault, emcy, other_error_register, kEmergencyNoMotor);
  }
  result.fault = true;
  if (already) return result;
  result.raised = bit;
  const EmergencyDefinition& row = emergency_definition(kShutdownSwitch);
  send(emcy, row.code, row.sub, static_cast<uint8_t>(error_register() | other_error_register | kErrorRegisterAxisFault),
       kEmergencyNoMotor);
  return result;
}

bool Tmcm3216Emergencies::fault_reset(uint8_t axis, canopen::EmergencyProducer& emcy, uint8_t other_error_register) {
  if (axis >= kEmergencyAxisCount) return false;
  AxisState& s = axes_[axis];
  ConditionMask present = s.levels;
  if (shutdown_level_) present = static_cast<ConditionMask>(present | condition_bit(kShutdownSwitch));
  for (const EmergencyDefinition& row : kTable) {
    // Stall and following error are events the drive re-arms with the reset.
    if (row.cleared_by_reset) present = static_cast<ConditionMask>(present & ~condition_bit(row.condition));
  }
  s.active = static_cast<ConditionMask>(s.active & present);
  s.faults = static_cast<ConditionMask>(s.faults & present);
  // s.levels is kept: an event still flagged in this tick is no new one in the next update().
  if (s.faults == 0) {
    send(emcy, kEmcyFaultReset, 0, static_cast<uint8_t>(error_register() | other_error_register), axis);
    return true;
  }
  // The cause is still there: say so again, once per reset command.
  const uint8_t motor = axis;
  for (const EmergencyDefinition& row : kTable) {
    if ((s.faults & condition_bit(row.condition)) == 0) continue;
    const uint8_t byte2 = row.condition == kShutdownSwitch ? kEmergencyNoMotor : motor;
    // The axis goes back to FAULT with it (the caller's external_fault()).
    send(emcy, row.code, row.sub,
         static_cast<uint8_t>(error_register() | other_error_register | kErrorRegisterAxisFault), byte2);
  }
  return false;
}

}  // namespace motwin::modules::tmcm3216
