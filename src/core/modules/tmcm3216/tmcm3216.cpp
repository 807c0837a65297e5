#include "core/modules/tmcm3216/tmcm3216.h"

#include <cstring>
#include <type_traits>

namespace motwin::modules::tmcm3216 {

using canopen::NmtState;

namespace {

constexpr uint8_t kAllAxes = (1u << kAxisCount) - 1;

}  // namespace

void Tmcm3216::format_factory_image(uint8_t* image, size_t size) { canopen::StorageImage::format(image, size); }

Tmcm3216::Tmcm3216(board::NonVolatileMemory& nvm, board::CanController& can, const Tmcm3216Config& config)
    : Tmcm3216(nvm, can, own_board_, config) {}

Tmcm3216::Tmcm3216(board::NonVolatileMemory& nvm, board::CanController& can, board::Tmcm3216Board& board,
                   const Tmcm3216Config& config)
    : board_(board),
      dictionary_(*this, object_table(), kAxisCount),
      node_(dictionary_, nvm, can, *this, kNode, config, storage_scratch_) {}

void Tmcm3216::reset_application() {
  // The state behind every object of 2000h..9FFFh, value-initialised as at construction, so
  // that nothing a master wrote survives unless it was stored (CiA-301 reset application): the
  // stepper and profile objects of each axis, the drives' manufacturer objects, the I/O and the
  // node settings (2704/2705). The live state (PDS, ramps, the stepper's counters) is reset below.
  axes_touched_ = true;
  for (uint8_t axis = 0; axis < kAxisCount; ++axis) {
    steppers_[axis].objects = StepperObjects{};
    drives_[axis].objects = cia402::ProfileObjects{};
    drives_[axis].manufacturer = Tmcm3216DriveObjects{};
  }
  general_io_ = Tmcm3216GeneralIo{};
  node_.node_settings() = NodeSettings{};
  // Then what 1010 stored (or each object's default).
  canopen::StorageSelection application;
  application.axis_mask = kAllAxes;
  application.node_settings = true;
  node_.load_stored(application);
  reset_axes();
}

void Tmcm3216::on_bus_off() {
  // Table 365, 8140: at bus-off "the drive has been stopped and disabled": the master has lost
  // the axes, so each running one takes its fault reaction (605E ramp, then FAULT), as with
  // NMT stopped.
  for (Tmcm3216Drive& drive : drives_) {
    if (drive.pds().power_enabled()) drive.external_fault();
  }
}

// --- The drive -----------------------------------------------------------------------------------

void Tmcm3216::tick() {
  if (node_.tick(kTickUs)) axes_touched_ = true;
  run_axes(kTickUs);
}

void Tmcm3216::reset_axes() {
  for (uint8_t axis = 0; axis < kAxisCount; ++axis) {
    steppers_[axis].reset();
    drives_[axis].reset(0);
  }
  emergencies_.reset();
}

void Tmcm3216::on_sync() {
  for (Tmcm3216Drive& drive : drives_) drive.on_sync();
}

uint8_t Tmcm3216::axis_error_register() const {
  for (const Tmcm3216Drive& drive : drives_) {
    const cia402::PdsState state = drive.state();
    if (state == cia402::PdsState::kFault || state == cia402::PdsState::kFaultReactionActive) {
      return kErrorRegisterAxisFault;  // generic + device profile (table 11)
    }
  }
  return 0;
}

void Tmcm3216::run_axes(uint32_t dt_us) {
  general_io_.sample(board_.io);
  // The shutdown switch (5441) is one input for the module: opening it faults every axis (the
  // hardware has switched their drivers off already); a fault reset keeps them in FAULT while
  // it stays open.
  const uint8_t others = static_cast<uint8_t>(node_.communication_error_register() | axis_error_register());
  if (emergencies_.update_shutdown(!board_.io.enable_input, node_.emergency(), others).fault) {
    for (Tmcm3216Drive& drive : drives_) drive.external_fault();
    axes_touched_ = true;
  }
  bool brake_control[kAxisCount] = {};
  uint8_t brake_duty[kAxisCount] = {};
  for (uint8_t axis = 0; axis < kAxisCount; ++axis) {
    const board::StepperPowerStage& stage = board_.axes[axis];
    if (!axes_touched_ && axis_resting_[axis] && steppers_[axis].standstill_time_read_alike(dt_us) &&
        stage.feedback == resting_feedback_[axis] && stage.drive == resting_drive_[axis]) {
      drives_[axis].rest(dt_us);
      steppers_[axis].rest(dt_us);
    } else {
      run_axis_checking_rest(axis, dt_us);
    }
    brake_control[axis] = steppers_[axis].brake_control();
    brake_duty[axis] = steppers_[axis].brake_duty();
  }
  axes_touched_ = false;
  general_io_.drive(board_.io, brake_control, brake_duty);
}

void Tmcm3216::run_axis_checking_rest(uint8_t axis, uint32_t dt_us) {
  // The proof is by comparison: a full tick whose result equals rest() applied to the state
  // before it, with the same inputs, will do so again, as long as no part of the tick reads the
  // counters rest() advances differently. The SYNC timeout is read by set-point writes only,
  // which come through process(); the standstill time sets the standby current of a powered
  // motor, so a powered axis rests only while the standstill time stays on the same side of the
  // standby delay (2089), or once the power-down ramp has reached the standby current
  // (Tmcm3216Stepper::standstill_time_read_alike, checked again before every resting tick).
  static_assert(std::is_trivially_copyable_v<Tmcm3216Drive> && std::is_trivially_copyable_v<Tmcm3216Stepper> &&
                std::is_trivially_copyable_v<Tmcm3216Emergencies>);
  Tmcm3216Drive& drive = drives_[axis];
  Tmcm3216Stepper& stepper = steppers_[axis];
  const bool candidate = resting_enabled_ && stepper.standstill_time_read_alike(dt_us);
  if (candidate) {
    // Byte copies, so that the comparison below sees padding that the tick leaves alone as equal.
    std::memcpy(static_cast<void*>(&rest_check_drive_), &drive, sizeof(drive));
    std::memcpy(static_cast<void*>(&rest_check_stepper_), &stepper, sizeof(stepper));
    std::memcpy(static_cast<void*>(&rest_check_emergencies_), &emergencies_, sizeof(emergencies_));
    rest_check_drive_.rest(dt_us);
    rest_check_stepper_.rest(dt_us);
  }
  const board::StepperPowerStage& stage = board_.axes[axis];
  const board::StepperDrive drive_before = stage.drive;
  run_axis(axis, dt_us);
  axis_resting_[axis] = candidate && stepper.standstill_time_read_alike(dt_us) && stage.drive == drive_before &&
                        std::memcmp(&rest_check_drive_, &drive, sizeof(drive)) == 0 &&
                        std::memcmp(&rest_check_stepper_, &stepper, sizeof(stepper)) == 0 &&
                        std::memcmp(&rest_check_emergencies_, &emergencies_, sizeof(emergencies_)) == 0;
  resting_feedback_[axis] = stage.feedback;
  resting_drive_[axis] = stage.drive;
}

void Tmcm3216::run_axis(uint8_t axis, uint32_t dt_us) {
  Tmcm3216Drive& drive = drives_[axis];
  Tmcm3216Stepper& stepper = steppers_[axis];
  // NMT stopped takes the drive function away from a running axis: FAULT (issue 7).
  if (configured() && nmt_state() == NmtState::kStopped && drive.state() == cia402::PdsState::kOperationEnabled) {
    drive.external_fault();
  }
  // The stepper's readings of the previous tick (switches, encoder, stall, driver flags).
  cia402::AxisInputs inputs;
  const SwitchState switches = stepper.switches();
  inputs.encoder_position_usteps = stepper.encoder_position();
  inputs.left_limit = switches.left;
  inputs.right_limit = switches.right;
  inputs.home_switch = switches.home;
  inputs.index_events = stepper.index_events();
  inputs.index_position_usteps = stepper.index_position();
  // The module always has its encoder interface; without pulses an index search ends after two
  // revolutions (kIndexNotFound). The stepper's index_available() only says a pulse was seen.
  inputs.index_available = true;
  inputs.stall = stepper.stall_detected();
  inputs.stall_enters_fault = stepper.stall_enters_fault();
  inputs.power_stage_fault = (stepper.driver_error_flags() & kDriverFaultFlags) != 0;
  inputs.ready = stepper.ready();
  // Table 365 on the same readings and PDS state the drive sees in this step (after it, a
  // standing axis the drive has just faulted has its power stage off: a driver fault would pass
  // for a warning). The monitor is the single sender of the axis's EMCYs.
  const uint8_t others = static_cast<uint8_t>(node_.communication_error_register() | axis_error_register());  // 1001 besides the monitor's
  if (emergencies_.update(axis, conditions_of(stepper, drive), node_.emergency(), others).fault) drive.external_fault();
  drive.step(inputs, dt_us);
  const cia402::AxisDemand& demand = drive.demand();
  if (demand.clear_stall) stepper.clear_stall();
  int32_t position = 0;
  if (drive.take_position_assignment(position)) stepper.set_actual_position(position);
  drive.set_usteps_per_revolution(stepper.microsteps_per_full_step() * stepper.objects.full_steps_per_revolution);
  // Profile objects the stepper needs (608F sub 1 is bound to the stepper directly).
  stepper.objects.encoder_used = drive.objects.sensor_selection == 0;
  stepper.objects.velocity_in_chip_units = drive.manufacturer.velocity_dimension == kVelocityDimensionInternal;
  StepperDemand stepper_demand;
  stepper_demand.position_usteps = demand.position_usteps;
  stepper_demand.velocity_pps = demand.velocity_pps;
  stepper_demand.power_enabled = demand.power_enabled;
  stepper_demand.brake_released_request = demand.brake_released_request;
  stepper_demand.switch_on_disabled = demand.switch_on_disabled;
  stepper.tick(board_.axes[axis], stepper_demand, dt_us);
  // 200B sub 3: the encoder's position becomes the actual position at switch-on.
  if (stepper.take_position_initialization(position)) drive.assign_position(position);
  // The drive's own queue only tells of a fault reset (transition 15): the monitor sends 0000, or
  // the EMCY of a fault still present, and then the axis goes back to FAULT.
  cia402::AxisEmergency emcy;
  while (drive.take_emergency(emcy)) {
    if (emcy.code != kEmcyFaultReset) continue;
    const uint8_t now_others = static_cast<uint8_t>(node_.communication_error_register() | axis_error_register());
    if (!emergencies_.fault_reset(axis, node_.emergency(), now_others)) drive.external_fault();
  }
}

}  // namespace motwin::modules::tmcm3216

template class motwin::canopen::TableDictionary<motwin::modules::tmcm3216::Tmcm3216>;
