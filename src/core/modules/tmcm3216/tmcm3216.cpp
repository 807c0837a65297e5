#include "core/modules/tmcm3216/tmcm3216.h"

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
    : nvm_(nvm),
      can_(can),
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
  receive_head_ = 0;
  receive_count_ = 0;
  reported_dropped_frames_ = dropped_frames_;
  lss_bit_rate_kbit_ = 0;
  lss_.power_up(identity(), canopen::kLssUnconfiguredNodeId, 0);  // forget an LSS-configured node ID
  reset_node();
  lss_.power_up(identity(), node_id_, bit_rate_kbit_);
}

void Tmcm3216::reset_node() {
  // Application (motor) parameters, then the communication reset that ends with the boot-up.
  StorageSelection application;
  application.axis_mask = kAllAxes;
  storage_.load(application);
  error_register_ = 0;
  reset_communication();
}

void Tmcm3216::reset_communication() {
  nmt_.initialize();
  sdo_.reset();
  emergency_.reset();
  error_register_ = 0;
  // Node ID and bit rate first: the "$NODEID+" defaults of the communication objects use it.
  StorageSelection node;
  node.node_settings = true;
  storage_.load(node);
  const uint8_t switches = config_.node_id_switches;
  node_id_ = switches >= 1 && switches <= 127 ? switches : node_settings_.node_id;
  // A node ID configured by LSS since power-up applies at every reset, even over the switches
  // (the master that configured it expects the node there).
  if (lss_.node_id_configured()) node_id_ = lss_.pending_node_id();
  // Likewise a bit rate activated by LSS stays until power-up.
  bit_rate_kbit_ = lss_bit_rate_kbit_ != 0 ? lss_bit_rate_kbit_ : node_settings_.bit_rate_kbit;
  dictionary_.set_node_id(configured() ? node_id_ : 0);
  nmt_.set_node_id(node_id_);
  sdo_.set_node_id(node_id_);
  lss_.set_active_node_id(node_id_);
  communication_errors_ = 0;
  StorageSelection communication;
  communication.communication = true;
  storage_.load(communication);  // 1005..1017 reach sync_, emergency_, heartbeat_consumer_, nmt_ by their bindings
  pdos_.reset();
  sync_.reset();
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
  while (receive_count_ > 0) {
    const can::CanFrame frame = receive_queue_[receive_head_];
    receive_head_ = (receive_head_ + 1) % receive_queue_.size();
    --receive_count_;
    handle_frame(frame);
  }
  if (const uint16_t bit_rate = lss_.process(elapsed_us); bit_rate != 0) {
    lss_bit_rate_kbit_ = bit_rate;
    bit_rate_kbit_ = bit_rate;
  }
  if (!configured()) return;
  check_receive_overrun(elapsed_us);
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
  if (sync_.process(elapsed_us, true) && nmt_.state() == NmtState::kOperational) pdos_.on_sync();
}

void Tmcm3216::check_receive_overrun(uint32_t elapsed_us) {
  // Frames lost in a full receive queue: EMCY 8110 once; cleared after a tick without losses.
  if (dropped_frames_ != reported_dropped_frames_) {
    reported_dropped_frames_ = dropped_frames_;
  lss_bit_rate_kbit_ = 0;
    raise_error(kCommErrorCanOverrun, canopen::kEmcyCanOverflow);
  } else if (elapsed_us > 0) {
    clear_error(kCommErrorCanOverrun);
  }
}

void Tmcm3216::raise_error(uint8_t error, uint16_t emcy_code) {
  // Manual table 365: byte 2 is the motor, 255 for the communication errors.
  static constexpr uint8_t kNoMotor[5] = {0, 255, 0, 0, 0};
  if ((communication_errors_ & error) != 0) return;
  communication_errors_ |= error;
  error_register_ |= canopen::kErrorRegisterCommunication | canopen::kErrorRegisterGeneric;
  emergency_.report(emcy_code, error_register_, kNoMotor);
}

void Tmcm3216::clear_error(uint8_t error) {
  static constexpr uint8_t kNoMotor[5] = {0, 255, 0, 0, 0};
  if ((communication_errors_ & error) == 0) return;
  communication_errors_ = static_cast<uint8_t>(communication_errors_ & ~error);
  if (communication_errors_ == 0) {
    error_register_ = static_cast<uint8_t>(error_register_ & ~canopen::kErrorRegisterCommunication);
    if (error_register_ == canopen::kErrorRegisterGeneric) error_register_ = 0;
  }
  emergency_.report(canopen::kEmcyErrorReset, error_register_, kNoMotor);
}

void Tmcm3216::handle_pdo(const can::CanFrame& frame) {
  switch (pdos_.on_frame(frame)) {
    case canopen::RpdoReception::kNotPdo: return;
    case canopen::RpdoReception::kAccepted:
      clear_error(kCommErrorPdoLength);
      clear_error(kCommErrorPdoLengthExceeded);
      return;
    case canopen::RpdoReception::kTooShort: raise_error(kCommErrorPdoLength, canopen::kEmcyPdoLength); return;
    case canopen::RpdoReception::kTooLong:
      raise_error(kCommErrorPdoLengthExceeded, canopen::kEmcyPdoLengthExceeded);
      return;
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
    if (state == NmtState::kOperational) pdos_.on_sync();
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

}  // namespace motwin::modules::tmcm3216
