#include "core/canopen/node.h"

namespace motwin::canopen {

Node::Node(RowDictionary& dictionary, board::NonVolatileMemory& nvm, board::CanController& can,
           NodeApplication& application, const NodeDescription& description, const NodeConfig& config,
           std::span<uint8_t> storage_scratch)
    : dictionary_(dictionary),
      can_(can),
      application_(application),
      description_(description),
      config_(config),
      nmt_(can),
      sdo_(dictionary, can),
      emergency_(can),
      node_guarding_(can),
      sync_(can),
      pdos_(dictionary, can, std::span(communication_.rpdo, description.pdo_count),
            std::span(communication_.rpdo_mapping, description.pdo_count),
            std::span(communication_.tpdo, description.pdo_count),
            std::span(communication_.tpdo_mapping, description.pdo_count)),
      lss_(can, *this),
      storage_(dictionary, nvm, storage_scratch.data(), storage_scratch.size()) {}

LssIdentity Node::identity() const {
  const NodeIdentity& id = description_.identity;
  return LssIdentity{id.vendor_id, id.product_code, id.revision_number, config_.serial_number};
}

bool Node::supports_bit_rate(uint16_t bit_rate_kbit) const {
  for (const uint16_t supported : description_.bit_rates_kbit) {
    if (supported == bit_rate_kbit) return true;
  }
  return false;
}

void Node::power_up() {
  receive_head_ = 0;
  receive_count_ = 0;
  reported_dropped_frames_ = dropped_frames_;
  lss_bit_rate_kbit_ = 0;
  // Bus-off recoveries before this power-up are not this run's to report.
  bus_off_recoveries_ = can_.status().bus_off_recoveries;
  lss_.power_up(identity(), kLssUnconfiguredNodeId, 0);  // forget an LSS-configured node ID
  reset_node();
  lss_.power_up(identity(), node_id_, bit_rate_kbit_);
}

void Node::reset_node() {
  // The processor restarts as at power-up: application, then communication; the boot-up
  // follows after the restart time.
  application_.reset_application();
  error_register_ = 0;
  reset_communication(config_.boot_delay_us);
}

void Node::reset_communication(uint32_t boot_delay_us) {
  nmt_.initialize();
  sdo_.reset();
  emergency_.reset();
  error_register_ = 0;
  parameter_error_ = false;
  reported_refused_writes_ = pdos_.refused_writes();
  reported_rpdo_writes_ = pdos_.rpdo_writes();
  // Node ID and bit rate first: the "$NODEID+" defaults of the communication objects use it.
  // They come from the NVM (TMCM-3216 manual 4.2.62/4.2.63: write, store with 2706, reset); the
  // node-settings objects belong to the application and keep what a master wrote.
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
  node_guarding_.reset();
  restarting_ = true;
  restart_remaining_us_ = boot_delay_us;
  service_elapsed_us_ = 0;  // the restart time counts from the reset, not from the last service tick
  if (boot_delay_us == 0) finish_restart();
}

void Node::finish_restart() {
  restarting_ = false;
  restart_remaining_us_ = 0;
  // An LSS-unconfigured node (stored node ID 255) stays silent: only LSS reaches it.
  if (configured()) nmt_.boot();
}

bool Node::receive(const can::CanFrame& frame) {
  if (receive_count_ == receive_queue_.size()) {
    ++dropped_frames_;
    return false;
  }
  receive_queue_[(receive_head_ + receive_count_) % receive_queue_.size()] = frame;
  ++receive_count_;
  return true;
}

void Node::process(uint32_t elapsed_us) {
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
  run_node_guarding(elapsed_us);
  const NmtState state = nmt_.state();
  if (state == NmtState::kPreOperational || state == NmtState::kOperational) {
    run_sync(elapsed_us);
    if (nmt_.state() == NmtState::kOperational) pdos_.process(elapsed_us);
    sdo_.process(elapsed_us);
    emergency_.process(elapsed_us);  // EMCY is not sent in stopped (CiA-301 table 86)
  }
}

void Node::on_sync() {
  if (nmt_.state() == NmtState::kOperational) {
    pdos_.on_sync();
    check_rpdo_values();
  }
  application_.on_sync();
}

void Node::run_sync(uint32_t elapsed_us) {
  // The node's own SYNC does not come back from the bus: it is acted on here.
  if (sync_.process(elapsed_us, true)) on_sync();
}

void Node::check_receive_overrun(uint32_t elapsed_us) {
  // Frames lost in a full receive queue: EMCY 8110 once; cleared after a tick without losses.
  if (dropped_frames_ != reported_dropped_frames_) {
    reported_dropped_frames_ = dropped_frames_;
    raise_error(kCommErrorCanOverrun, kEmcyCanOverflow);
  } else if (elapsed_us > 0) {
    clear_error(kCommErrorCanOverrun);
  }
}

void Node::raise_error(uint8_t error, uint16_t emcy_code) {
  if ((communication_errors_ & error) != 0) return;
  report_error(error, emcy_code);
}

void Node::report_error(uint8_t error, uint16_t emcy_code) {
  communication_errors_ |= error;
  error_register_ |= kErrorRegisterCommunication | kErrorRegisterGeneric;
  // The whole 1001 as this report leaves it (the application's bits too).
  emergency_.report(emcy_code, error_register(), description_.communication_emcy_data);
}

void Node::clear_error(uint8_t error) {
  if ((communication_errors_ & error) == 0) return;
  communication_errors_ = static_cast<uint8_t>(communication_errors_ & ~error);
  if (communication_errors_ == 0) {
    error_register_ = static_cast<uint8_t>(error_register_ & ~kErrorRegisterCommunication);
    if (error_register_ == kErrorRegisterGeneric) error_register_ = 0;
  }
  emergency_.report(kEmcyErrorReset, error_register(), description_.communication_emcy_data);
}

void Node::check_can_controller() {
  const board::CanControllerStatus status = can_.status();
  // A count that went down is another controller (the node moved to another bus): no event.
  const bool recovered = status.bus_off_recoveries > bus_off_recoveries_;
  bus_off_recoveries_ = status.bus_off_recoveries;
  const bool bus_off = status.error_state == board::CanErrorState::kBusOff;
  // At bus-off the master has lost the node: the application reacts (the TMCM-3216 stops its
  // running axes, table 365 8140). Also when a bus-off began and ended between two polls.
  if (bus_off || recovered) application_.on_bus_off();
  if (recovered) {
    // Bus-on again: 8140 is the controller's first message (a bus-off node sends nothing).
    can_controller_error_ = CanControllerError::kRecovered;
    report_error(kCommErrorCanController, kEmcyCanBusOffRecovered);
    return;
  }
  switch (status.error_state) {
    case board::CanErrorState::kBusOff:
      // Nothing reaches the bus: the error stays set (1001 bit 4), silently; 8140 follows.
      can_controller_error_ = CanControllerError::kBusOff;
      communication_errors_ |= kCommErrorCanController;
      error_register_ |= kErrorRegisterCommunication | kErrorRegisterGeneric;
      return;
    case board::CanErrorState::kErrorPassive:
      // An error-passive node still transmits (with a longer pause): 8120 goes out now.
      if (can_controller_error_ != CanControllerError::kErrorPassive) {
        can_controller_error_ = CanControllerError::kErrorPassive;
        report_error(kCommErrorCanController, kEmcyCanErrorPassive);
      }
      return;
    case board::CanErrorState::kErrorActive:
      // Error-active again, or one service tick after 8140: 0000 (like 8110).
      can_controller_error_ = CanControllerError::kNone;
      clear_error(kCommErrorCanController);
      return;
  }
}

void Node::handle_pdo(const can::CanFrame& frame) {
  switch (pdos_.on_frame(frame)) {
    case RpdoReception::kNotPdo: return;
    case RpdoReception::kAccepted:
      clear_error(kCommErrorPdoLength);
      clear_error(kCommErrorPdoLengthExceeded);
      check_rpdo_values();
      return;
    case RpdoReception::kTooShort: raise_error(kCommErrorPdoLength, kEmcyPdoLength); return;
    case RpdoReception::kTooLong:
      raise_error(kCommErrorPdoLengthExceeded, kEmcyPdoLengthExceeded);
      check_rpdo_values();
      return;
  }
}

void Node::check_rpdo_values() {
  // The data in a received PDO is wrong or cannot be accepted in the application's present state
  // (TMCM-3216 table 365, 6320 "parameter error"). Like 8210: once per episode, 0000 when an RPDO
  // is written whole again. A synchronous RPDO is judged at its SYNC.
  const uint64_t refused = pdos_.refused_writes();
  const uint64_t written = pdos_.rpdo_writes();
  const bool any_refused = refused != reported_refused_writes_;
  const bool any_written = written != reported_rpdo_writes_;
  reported_refused_writes_ = refused;
  reported_rpdo_writes_ = written;
  if (any_refused) {
    if (!parameter_error_) {
      parameter_error_ = true;
      emergency_.report(description_.rpdo_value_emcy, error_register(), description_.communication_emcy_data);
    }
  } else if (any_written && parameter_error_) {
    parameter_error_ = false;
    emergency_.report(kEmcyErrorReset, error_register(), description_.communication_emcy_data);
  }
}

bool Node::lss_store(uint8_t node_id, uint16_t bit_rate_kbit) {
  // LSS store configuration writes what the node-settings objects and their store would.
  const NodeSettings before = node_settings_;
  node_settings_.node_id = node_id;
  node_settings_.bit_rate_kbit = bit_rate_kbit;
  StorageSelection selection;
  selection.node_settings = true;
  if (storage_.save(selection) == SdoAbort::kNone) return true;
  node_settings_ = before;
  return false;
}

void Node::run_heartbeat_consumer(uint32_t elapsed_us) {
  switch (heartbeat_consumer_.process(elapsed_us)) {
    case HeartbeatEvent::kNone: return;
    case HeartbeatEvent::kTimeout: lose_master(); return;
    case HeartbeatEvent::kRecovered: clear_error(kCommErrorHeartbeat); return;
  }
}

void Node::run_node_guarding(uint32_t elapsed_us) {
  switch (node_guarding_.process(elapsed_us)) {
    case GuardingEvent::kNone: return;
    case GuardingEvent::kLifeGuardingLost: lose_master(); return;
    case GuardingEvent::kRecovered: clear_error(kCommErrorHeartbeat); return;
  }
}

void Node::lose_master() {
  raise_error(kCommErrorHeartbeat, kEmcyHeartbeat);
  // Out before a change to stopped would hold it back (unless an inhibit time is running).
  if (nmt_.state() != NmtState::kStopped) emergency_.process(0);
  // 1029 sub 1 (TMCM-3216 manual 3.1.14, table 39): in operational, 0 "enter stopped state",
  // 1 "remain in current state", 2 stopped (CiA-301).
  if (nmt_.state() == NmtState::kOperational && communication_.error_behavior[0] != 1) {
    nmt_.enter(NmtState::kStopped);
    sdo_.reset();
  }
}

void Node::handle_frame(const can::CanFrame& frame) {
  if (frame.extended) return;  // 11-bit COB-IDs only
  if (frame.id == kLssMasterCobId) {  // in every state, configured or not
    if (!description_.lss) return;
    if (lss_.on_frame(frame) == LssRequest::kResetCommunication) {
      reset_communication(config_.communication_boot_delay_us);
    }
    return;
  }
  if (!configured()) return;
  if (frame.id == kNmtCobId) {
    nmt_.on_command(frame);
    run_nmt(0);
    return;
  }
  if (NodeGuarding::is_request(frame, node_id_)) {
    // In every NMT state but initialising: the master guards a stopped node too.
    if (description_.node_guarding) node_guarding_.on_request(node_id_, nmt_.state(), nmt_.heartbeat_period_ms() != 0);
    return;
  }
  if (frame.id > kHeartbeatCobIdBase && frame.id <= kHeartbeatCobIdBase + 127) {
    heartbeat_consumer_.on_frame(frame);
    return;
  }
  const NmtState state = nmt_.state();
  if (sync_.is_sync(frame)) {
    if (state == NmtState::kOperational || state == NmtState::kPreOperational) on_sync();
    return;
  }
  if (frame.id == sdo_.request_cob_id() && (state == NmtState::kPreOperational || state == NmtState::kOperational)) {
    sdo_.on_request(frame);
    sdo_.process(0);
    return;
  }
  if (state == NmtState::kOperational) handle_pdo(frame);
}

void Node::run_nmt(uint32_t elapsed_us) {
  const NmtState before = nmt_.state();
  switch (nmt_.process(elapsed_us)) {
    case NmtReset::kNode: reset_node(); return;
    case NmtReset::kCommunication: reset_communication(config_.communication_boot_delay_us); return;
    case NmtReset::kNone: break;
  }
  // Stopped: only NMT and heartbeat; a transfer in progress is dropped (as CANopenNode does).
  if (nmt_.state() == NmtState::kStopped && before != NmtState::kStopped) sdo_.reset();
  // Entering operational: event-driven TPDOs go out once, SYNC counting starts.
  if (nmt_.state() == NmtState::kOperational && before != NmtState::kOperational) pdos_.enter_operational();
}

SdoAbort Node::store_parameters(uint8_t sub, uint32_t signature) {
  if (signature != kSaveSignature) return SdoAbort::kDataTransfer;
  if (sub == 0 || sub > description_.storage.size()) return SdoAbort::kDataTransfer;
  const StorageSubIndex& entry = description_.storage[sub - 1];
  if (!entry.store_supported) return SdoAbort::kDataTransfer;
  return storage_.save(entry.store);
}

SdoAbort Node::restore_parameters(uint8_t sub, uint32_t signature) {
  if (signature != kLoadSignature) return SdoAbort::kDataTransfer;
  if (sub == 0 || sub > description_.storage.size()) return SdoAbort::kDataTransfer;
  const StorageSubIndex& entry = description_.storage[sub - 1];
  if (!entry.restore_supported) return SdoAbort::kDataTransfer;
  const StorageSelection& selection = entry.restore;
  if (selection.empty()) return SdoAbort::kNone;
  return storage_.restore_defaults(selection);
}

SdoAbort Node::store_node_settings(uint32_t signature) {
  if (signature != kSaveSignature) return SdoAbort::kDataTransfer;
  StorageSelection selection;
  selection.node_settings = true;
  return storage_.save(selection);
}

}  // namespace motwin::canopen
