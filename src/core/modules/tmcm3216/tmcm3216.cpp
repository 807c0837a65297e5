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
      storage_(dictionary_, nvm, storage_scratch_.data(), storage_scratch_.size()) {}

void Tmcm3216::power_up() {
  receive_head_ = 0;
  receive_count_ = 0;
  reset_node();
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
  bit_rate_kbit_ = node_settings_.bit_rate_kbit;
  dictionary_.set_node_id(configured() ? node_id_ : 0);
  nmt_.set_node_id(node_id_);
  sdo_.set_node_id(node_id_);
  StorageSelection communication;
  communication.communication = true;
  storage_.load(communication);  // 1014..1017 reach emergency_, heartbeat_consumer_, nmt_ by their bindings
  // An LSS-unconfigured node (2705 = 255) stays silent until LSS gives it an ID (not yet).
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
  run_nmt(elapsed_us);
  run_heartbeat_consumer(elapsed_us);
  const NmtState state = nmt_.state();
  if (state == NmtState::kPreOperational || state == NmtState::kOperational) {
    sdo_.process(elapsed_us);
    emergency_.process(elapsed_us);  // EMCY is not sent in stopped (CiA-301 table 86)
  }
}

void Tmcm3216::run_heartbeat_consumer(uint32_t elapsed_us) {
  // Manual table 365: byte 2 of 8130 is 255 (no motor).
  static constexpr uint8_t kNoMotor[5] = {0, 255, 0, 0, 0};
  switch (heartbeat_consumer_.process(elapsed_us)) {
    case canopen::HeartbeatEvent::kNone: return;
    case canopen::HeartbeatEvent::kTimeout:
      error_register_ |= canopen::kErrorRegisterCommunication | canopen::kErrorRegisterGeneric;
      emergency_.report(canopen::kEmcyHeartbeat, error_register_, kNoMotor);
      // Out before a change to stopped would hold it back (unless an inhibit time is running).
      if (nmt_.state() != NmtState::kStopped) emergency_.process(0);
      // 1029 sub 1 (manual 3.1.14, table 39): in operational, 0 "enter stopped state",
      // 1 "remain in current state", 2 stopped (CiA-301).
      if (nmt_.state() == NmtState::kOperational && communication_.error_behavior[0] != 1) {
        nmt_.enter(NmtState::kStopped);
        sdo_.reset();
      }
      return;
    case canopen::HeartbeatEvent::kRecovered:
      error_register_ = static_cast<uint8_t>(error_register_ & ~canopen::kErrorRegisterCommunication);
      if (error_register_ == canopen::kErrorRegisterGeneric) error_register_ = 0;
      emergency_.report(canopen::kEmcyErrorReset, error_register_, kNoMotor);
      return;
  }
}

void Tmcm3216::handle_frame(const can::CanFrame& frame) {
  if (frame.extended || !configured()) return;  // 11-bit COB-IDs only (manual 1.1)
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
  if (frame.id == sdo_.request_cob_id() && (state == NmtState::kPreOperational || state == NmtState::kOperational)) {
    sdo_.on_request(frame);
    sdo_.process(0);
  }
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
