#include "core/modules/tmcm3216/tmcm3216.h"

#include <cstring>
#include <type_traits>

namespace motwin::modules::tmcm3216 {

using canopen::NmtReset;
using canopen::NmtState;
using canopen::SdoAbort;
using canopen::StorageSelection;

namespace {

constexpr uint8_t kAllAxes = (1u << kAxisCount) - 1;

}  // namespace

void Tmcm3216::format_factory_image(uint8_t* image, size_t size) { canopen::StorageImage::format(image, size); }

Tmcm3216::Tmcm3216(board::NonVolatileMemory& nvm, board::CanController& can, const Tmcm3216Config& config)
    : Tmcm3216(nvm, can, own_board_, config) {}

Tmcm3216::Tmcm3216(board::NonVolatileMemory& nvm, board::CanController& can, board::Tmcm3216Board& board,
                   const Tmcm3216Config& config)
    : nvm_(nvm),
      can_(can),
      board_(board),
      config_(config),
      dictionary_(*this, object_table(), kAxisCount),
      nmt_(can),
      sdo_(dictionary_, can),
      emergency_(can),
      sync_(can),
      pdos_(dictionary_, can, communication_.rpdo, communication_.rpdo_mapping, communication_.tpdo,
            communication_.tpdo_mapping),
      lss_(can, *this),
      storage_(dictionary_, nvm, storage_scratch_.data(), storage_scratch_.size()) {}

canopen::LssIdentity Tmcm3216::identity() const {
  return canopen::LssIdentity{kVendorId, kProductCode, kRevisionNumber, config_.serial_number};
}

void Tmcm3216::power_up() {
  axes_touched_ = true;
  receive_head_ = 0;
  receive_count_ = 0;
  reported_dropped_frames_ = dropped_frames_;
  lss_bit_rate_kbit_ = 0;
  // Bus-off recoveries before this power-up are not this run's to report.
  bus_off_recoveries_ = can_.status().bus_off_recoveries;
  lss_.power_up(identity(), canopen::kLssUnconfiguredNodeId, 0);  // forget an LSS-configured node ID
  reset_node();
  lss_.power_up(identity(), node_id_, bit_rate_kbit_);
}

void Tmcm3216::reset_node() {
  // The processor restarts as at power-up: application, then communication; the boot-up
  // follows after the restart time.
  reset_application();
  reset_communication(config_.boot_delay_us);
}

void Tmcm3216::reset_application() {
  // The state behind every object of 2000h..9FFFh, value-initialised as at construction, so
  // that nothing a master wrote survives unless it was stored (CiA-301 reset application): the
  // stepper and profile objects of each axis, the drives' manufacturer objects, the I/O and the
  // node settings (2704/2705). The live state (PDS, ramps, the stepper's counters) is reset below.
  for (uint8_t axis = 0; axis < kAxisCount; ++axis) {
    steppers_[axis].objects = StepperObjects{};
    drives_[axis].objects = cia402::ProfileObjects{};
    drives_[axis].manufacturer = Tmcm3216DriveObjects{};
  }
  general_io_ = Tmcm3216GeneralIo{};
  node_settings_ = NodeSettings{};
  // Then what 1010 stored (or each object's default).
  StorageSelection application;
  application.axis_mask = kAllAxes;
  application.node_settings = true;
  storage_.load(application);
  error_register_ = 0;
  reset_axes();
}

void Tmcm3216::reset_communication() { reset_communication(config_.communication_boot_delay_us); }

void Tmcm3216::reset_communication(uint32_t boot_delay_us) {
  nmt_.initialize();
  sdo_.reset();
  emergency_.reset();
  error_register_ = 0;
  parameter_error_ = false;
  reported_refused_writes_ = pdos_.refused_writes();
  reported_rpdo_writes_ = pdos_.rpdo_writes();
  // Node ID and bit rate first: the "$NODEID+" defaults of the communication objects use it.
  // They come from the NVM (manual 4.2.62/4.2.63: write, store with 2706, reset); the objects
  // 2704/2705 belong to the application and keep what a master wrote.
  const NodeSettings written = node_settings_;
  StorageSelection node;
  node.node_settings = true;
  storage_.load(node);
  const NodeSettings stored = node_settings_;
  node_settings_ = written;
  const uint8_t switches = config_.node_id_switches;
  node_id_ = switches >= 1 && switches <= 127 ? switches : stored.node_id;
  // A node ID configured by LSS since power-up applies at every reset, even over the switches
  // (the master that configured it expects the node there).
  if (lss_.node_id_configured()) node_id_ = lss_.pending_node_id();
  // Likewise a bit rate activated by LSS stays until power-up.
  bit_rate_kbit_ = lss_bit_rate_kbit_ != 0 ? lss_bit_rate_kbit_ : stored.bit_rate_kbit;
  dictionary_.set_node_id(configured() ? node_id_ : 0);
  nmt_.set_node_id(node_id_);
  sdo_.set_node_id(node_id_);
  lss_.set_active_node_id(node_id_);
  communication_errors_ = 0;
  can_controller_error_ = CanControllerError::kNone;  // a state that lasts is reported anew
  StorageSelection communication;
  communication.communication = true;
  storage_.load(communication);  // 1005..1017 reach sync_, emergency_, heartbeat_consumer_, nmt_ by their bindings
  pdos_.reset();
  sync_.reset();
  restarting_ = true;
  restart_remaining_us_ = boot_delay_us;
  service_elapsed_us_ = 0;  // the restart time counts from the reset, not from the last service tick
  if (boot_delay_us == 0) finish_restart();
}

void Tmcm3216::finish_restart() {
  restarting_ = false;
  restart_remaining_us_ = 0;
  // An LSS-unconfigured node (2705 = 255) stays silent: only LSS reaches it.
  if (configured()) nmt_.boot();
}

bool Tmcm3216::receive(const can::CanFrame& frame) {
  if (receive_count_ == receive_queue_.size()) {
    ++dropped_frames_;
    return false;
  }
  receive_queue_[(receive_head_ + receive_count_) % receive_queue_.size()] = frame;
  ++receive_count_;
  return true;
}

void Tmcm3216::process(uint32_t elapsed_us) {
  axes_touched_ = true;  // whatever the services do to the axes, their next tick is a full one
  const bool was_restarting = restarting_;
  while (receive_count_ > 0) {
    const can::CanFrame frame = receive_queue_[receive_head_];
    receive_head_ = (receive_head_ + 1) % receive_queue_.size();
    --receive_count_;
    if (restarting_) continue;  // a restarting node hears nothing (not even NMT or LSS)
    handle_frame(frame);
  }
  // A restart that a frame of this call began counts from now: the frames came at the end of
  // the interval `elapsed_us` stands for.
  if (restarting_ && !was_restarting) elapsed_us = 0;
  if (restarting_) {
    if (elapsed_us < restart_remaining_us_) {
      restart_remaining_us_ -= elapsed_us;
      return;
    }
    finish_restart();
    elapsed_us = 0;  // the services start from the boot-up
  }
  if (const uint16_t bit_rate = lss_.process(elapsed_us); bit_rate != 0) {
    lss_bit_rate_kbit_ = bit_rate;
    bit_rate_kbit_ = bit_rate;
  }
  if (!configured()) return;
  check_receive_overrun(elapsed_us);
  if (elapsed_us > 0) check_can_controller();
  run_nmt(elapsed_us);
  run_heartbeat_consumer(elapsed_us);
  const NmtState state = nmt_.state();
  if (state == NmtState::kPreOperational || state == NmtState::kOperational) {
    run_sync(elapsed_us);
    if (nmt_.state() == NmtState::kOperational) pdos_.process(elapsed_us);
    sdo_.process(elapsed_us);
    emergency_.process(elapsed_us);  // EMCY is not sent in stopped (CiA-301 table 86)
  }
}

void Tmcm3216::run_sync(uint32_t elapsed_us) {
  // The node's own SYNC does not come back from the bus: it is acted on here.
  if (sync_.process(elapsed_us, true)) {
    if (nmt_.state() == NmtState::kOperational) {
      pdos_.on_sync();
      check_rpdo_values();
    }
    sync_axes();
  }
}

void Tmcm3216::check_receive_overrun(uint32_t elapsed_us) {
  // Frames lost in a full receive queue: EMCY 8110 once; cleared after a tick without losses.
  if (dropped_frames_ != reported_dropped_frames_) {
    reported_dropped_frames_ = dropped_frames_;
    raise_error(kCommErrorCanOverrun, canopen::kEmcyCanOverflow);
  } else if (elapsed_us > 0) {
    clear_error(kCommErrorCanOverrun);
  }
}

void Tmcm3216::raise_error(uint8_t error, uint16_t emcy_code) {
  if ((communication_errors_ & error) != 0) return;
  report_error(error, emcy_code);
}

void Tmcm3216::report_error(uint8_t error, uint16_t emcy_code) {
  // Manual table 365: byte 2 is the motor, 255 for the communication errors.
  static constexpr uint8_t kNoMotor[5] = {0, 255, 0, 0, 0};
  communication_errors_ |= error;
  error_register_ |= canopen::kErrorRegisterCommunication | canopen::kErrorRegisterGeneric;
  // The whole 1001 as this report leaves it (the axes' bits too).
  emergency_.report(emcy_code, error_register(), kNoMotor);
}

void Tmcm3216::clear_error(uint8_t error) {
  static constexpr uint8_t kNoMotor[5] = {0, 255, 0, 0, 0};
  if ((communication_errors_ & error) == 0) return;
  communication_errors_ = static_cast<uint8_t>(communication_errors_ & ~error);
  if (communication_errors_ == 0) {
    error_register_ = static_cast<uint8_t>(error_register_ & ~canopen::kErrorRegisterCommunication);
    if (error_register_ == canopen::kErrorRegisterGeneric) error_register_ = 0;
  }
  emergency_.report(canopen::kEmcyErrorReset, error_register(), kNoMotor);
}

void Tmcm3216::check_can_controller() {
  const board::CanControllerStatus status = can_.status();
  // A count that went down is another controller (the node moved to another bus): no event.
  const bool recovered = status.bus_off_recoveries > bus_off_recoveries_;
  bus_off_recoveries_ = status.bus_off_recoveries;
  const bool bus_off = status.error_state == board::CanErrorState::kBusOff;
  // Table 365, 8140: at bus-off "the drive has been stopped and disabled": the master has lost
  // the axes, so each running one takes its fault reaction (605E ramp, then FAULT), as with
  // NMT stopped. Also when a bus-off began and ended between two polls.
  if (bus_off || recovered) {
    for (Tmcm3216Drive& drive : drives_) {
      if (drive.pds().power_enabled()) drive.external_fault();
    }
  }
  if (recovered) {
    // Bus-on again: 8140 is the controller's first message (a bus-off node sends nothing).
    can_controller_error_ = CanControllerError::kRecovered;
    report_error(kCommErrorCanController, canopen::kEmcyCanBusOffRecovered);
    return;
  }
  switch (status.error_state) {
    case board::CanErrorState::kBusOff:
      // Nothing reaches the bus: the error stays set (1001 bit 4), silently; 8140 follows.
      can_controller_error_ = CanControllerError::kBusOff;
      communication_errors_ |= kCommErrorCanController;
      error_register_ |= canopen::kErrorRegisterCommunication | canopen::kErrorRegisterGeneric;
      return;
    case board::CanErrorState::kErrorPassive:
      // An error-passive node still transmits (with a longer pause): 8120 goes out now.
      if (can_controller_error_ != CanControllerError::kErrorPassive) {
        can_controller_error_ = CanControllerError::kErrorPassive;
        report_error(kCommErrorCanController, canopen::kEmcyCanErrorPassive);
      }
      return;
    case board::CanErrorState::kErrorActive:
      // Error-active again, or one service tick after 8140: 0000 (like 8110).
      can_controller_error_ = CanControllerError::kNone;
      clear_error(kCommErrorCanController);
      return;
  }
}

void Tmcm3216::handle_pdo(const can::CanFrame& frame) {
  switch (pdos_.on_frame(frame)) {
    case canopen::RpdoReception::kNotPdo: return;
    case canopen::RpdoReception::kAccepted:
      clear_error(kCommErrorPdoLength);
      clear_error(kCommErrorPdoLengthExceeded);
      check_rpdo_values();
      return;
    case canopen::RpdoReception::kTooShort: raise_error(kCommErrorPdoLength, canopen::kEmcyPdoLength); return;
    case canopen::RpdoReception::kTooLong:
      raise_error(kCommErrorPdoLengthExceeded, canopen::kEmcyPdoLengthExceeded);
      check_rpdo_values();
      return;
  }
}

void Tmcm3216::check_rpdo_values() {
  // Manual table 365, 6320 "parameter error": the data in a received PDO is wrong or cannot be
  // accepted in the drive's present state; byte 2 = 255 (no motor). Like 8210: once per episode,
  // 0000 when an RPDO is written whole again. A synchronous RPDO is judged at its SYNC.
  static constexpr uint8_t kNoMotor[5] = {0, 255, 0, 0, 0};
  const uint64_t refused = pdos_.refused_writes();
  const uint64_t written = pdos_.rpdo_writes();
  const bool any_refused = refused != reported_refused_writes_;
  const bool any_written = written != reported_rpdo_writes_;
  reported_refused_writes_ = refused;
  reported_rpdo_writes_ = written;
  if (any_refused) {
    if (!parameter_error_) {
      parameter_error_ = true;
      emergency_.report(kEmcyPdoParameter, error_register(), kNoMotor);
    }
  } else if (any_written && parameter_error_) {
    parameter_error_ = false;
    emergency_.report(canopen::kEmcyErrorReset, error_register(), kNoMotor);
  }
}

bool Tmcm3216::lss_bit_rate_supported(uint16_t bit_rate_kbit) const {
  switch (bit_rate_kbit) {
    case 20: case 50: case 100: case 125: case 250: case 500: case 800: case 1000: return true;  // table 177
    default: return false;
  }
}

bool Tmcm3216::lss_store(uint8_t node_id, uint16_t bit_rate_kbit) {
  // LSS store configuration writes what 2705 / 2704 + 2706 would.
  const NodeSettings before = node_settings_;
  node_settings_.node_id = node_id;
  node_settings_.bit_rate_kbit = bit_rate_kbit;
  StorageSelection selection;
  selection.node_settings = true;
  if (storage_.save(selection) == SdoAbort::kNone) return true;
  node_settings_ = before;
  return false;
}

void Tmcm3216::run_heartbeat_consumer(uint32_t elapsed_us) {
  switch (heartbeat_consumer_.process(elapsed_us)) {
    case canopen::HeartbeatEvent::kNone: return;
    case canopen::HeartbeatEvent::kTimeout:
      raise_error(kCommErrorHeartbeat, canopen::kEmcyHeartbeat);
      // Out before a change to stopped would hold it back (unless an inhibit time is running).
      if (nmt_.state() != NmtState::kStopped) emergency_.process(0);
      // 1029 sub 1 (manual 3.1.14, table 39): in operational, 0 "enter stopped state",
      // 1 "remain in current state", 2 stopped (CiA-301).
      if (nmt_.state() == NmtState::kOperational && communication_.error_behavior[0] != 1) {
        nmt_.enter(NmtState::kStopped);
        sdo_.reset();
      }
      return;
    case canopen::HeartbeatEvent::kRecovered: clear_error(kCommErrorHeartbeat); return;
  }
}

void Tmcm3216::handle_frame(const can::CanFrame& frame) {
  if (frame.extended) return;  // 11-bit COB-IDs only (manual 1.1)
  if (frame.id == canopen::kLssMasterCobId) {  // in every state, configured or not
    if (lss_.on_frame(frame) == canopen::LssRequest::kResetCommunication) reset_communication();
    return;
  }
  if (!configured()) return;
  if (frame.id == canopen::kNmtCobId) {
    nmt_.on_command(frame);
    run_nmt(0);
    return;
  }
  if (frame.id > canopen::kHeartbeatCobIdBase && frame.id <= canopen::kHeartbeatCobIdBase + 127) {
    heartbeat_consumer_.on_frame(frame);
    return;
  }
  const NmtState state = nmt_.state();
  if (sync_.is_sync(frame)) {
    if (state == NmtState::kOperational) {
      pdos_.on_sync();
      check_rpdo_values();
    }
    if (state == NmtState::kOperational || state == NmtState::kPreOperational) sync_axes();
    return;
  }
  if (frame.id == sdo_.request_cob_id() && (state == NmtState::kPreOperational || state == NmtState::kOperational)) {
    sdo_.on_request(frame);
    sdo_.process(0);
    return;
  }
  if (state == NmtState::kOperational) handle_pdo(frame);
}

void Tmcm3216::run_nmt(uint32_t elapsed_us) {
  const NmtState before = nmt_.state();
  switch (nmt_.process(elapsed_us)) {
    case NmtReset::kNode: reset_node(); return;
    case NmtReset::kCommunication: reset_communication(); return;
    case NmtReset::kNone: break;
  }
  // Stopped: only NMT and heartbeat; a transfer in progress is dropped (as CANopenNode does).
  if (nmt_.state() == NmtState::kStopped && before != NmtState::kStopped) sdo_.reset();
  // Entering operational: event-driven TPDOs go out once, SYNC counting starts.
  if (nmt_.state() == NmtState::kOperational && before != NmtState::kOperational) pdos_.enter_operational();
}

SdoAbort Tmcm3216::store_parameters(uint8_t sub, uint32_t signature) {
  if (signature != kSaveSignature) return SdoAbort::kDataTransfer;
  StorageSelection selection;
  switch (sub) {
    case 1:  // everything
      selection.communication = true;
      selection.node_settings = true;
      selection.axis_mask = kAllAxes;
      break;
    case 2: selection.node_settings = true; break;  // manual 3.1.7: 2704 and 2705
    case 4:
    case 5:
    case 6: selection.axis_mask = static_cast<uint8_t>(1u << (sub - 4)); break;
    default: return SdoAbort::kDataTransfer;  // 3: device profile parameters, "not used"
  }
  return storage_.save(selection);
}

SdoAbort Tmcm3216::restore_parameters(uint8_t sub, uint32_t signature) {
  if (signature != kLoadSignature) return SdoAbort::kDataTransfer;
  StorageSelection selection;
  switch (sub) {
    case 1:  // all, except node ID and bit rate: those would cut the module off its bus
      selection.communication = true;
      selection.axis_mask = kAllAxes;
      break;
    case 2: return SdoAbort::kNone;  // manual 3.1.8: "no function"
    case 4:
    case 5:
    case 6: selection.axis_mask = static_cast<uint8_t>(1u << (sub - 4)); break;
    default: return SdoAbort::kDataTransfer;
  }
  return storage_.restore_defaults(selection);
}

SdoAbort Tmcm3216::store_node_settings(uint32_t signature) {
  if (signature != kSaveSignature) return SdoAbort::kDataTransfer;
  StorageSelection selection;
  selection.node_settings = true;
  return storage_.save(selection);
}

// --- The drive -----------------------------------------------------------------------------------

void Tmcm3216::tick() {
  service_elapsed_us_ += kTickUs;
  if (receive_count_ > 0 || service_elapsed_us_ >= kServicePeriodUs) {
    const uint32_t elapsed = service_elapsed_us_;
    service_elapsed_us_ = 0;
    process(elapsed);
  }
  run_axes(kTickUs);
}

void Tmcm3216::reset_axes() {
  for (uint8_t axis = 0; axis < kAxisCount; ++axis) {
    steppers_[axis].reset();
    drives_[axis].reset(0);
  }
  emergencies_.reset();
}

void Tmcm3216::sync_axes() {
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
  const uint8_t others = static_cast<uint8_t>(error_register_ | axis_error_register());
  if (emergencies_.update_shutdown(!board_.io.enable_input, emergency_, others).fault) {
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
  if (configured() && nmt_.state() == NmtState::kStopped && drive.state() == cia402::PdsState::kOperationEnabled) {
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
  const uint8_t others = static_cast<uint8_t>(error_register_ | axis_error_register());  // 1001 besides the monitor's
  if (emergencies_.update(axis, conditions_of(stepper, drive), emergency_, others).fault) drive.external_fault();
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
    const uint8_t now_others = static_cast<uint8_t>(error_register_ | axis_error_register());
    if (!emergencies_.fault_reset(axis, emergency_, now_others)) drive.external_fault();
  }
}

}  // namespace motwin::modules::tmcm3216

template class motwin::canopen::TableDictionary<motwin::modules::tmcm3216::Tmcm3216>;
