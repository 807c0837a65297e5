#include "core/canopen/nmt.h"

namespace motwin::canopen {

void NmtSlave::initialize() {
  state_ = NmtState::kInitializing;
  command_pending_ = false;
  heartbeat_now_ = false;
}

void NmtSlave::boot() {
  send_state(0x00);  // boot-up
  state_ = NmtState::kPreOperational;
  heartbeat_remaining_us_ = static_cast<uint64_t>(heartbeat_period_ms_) * 1000u;
  heartbeat_now_ = false;
}

void NmtSlave::on_command(const can::CanFrame& frame) {
  if (frame.rtr || frame.extended || frame.dlc != 2) return;
  if (frame.data[1] != 0 && frame.data[1] != node_id_) return;
  switch (frame.data[0]) {
    case static_cast<uint8_t>(NmtCommand::kStart):
    case static_cast<uint8_t>(NmtCommand::kStop):
    case static_cast<uint8_t>(NmtCommand::kEnterPreOperational):
    case static_cast<uint8_t>(NmtCommand::kResetNode):
    case static_cast<uint8_t>(NmtCommand::kResetCommunication):
      command_pending_ = true;
      pending_command_ = frame.data[0];
      break;
    default: break;  // unknown command specifier: ignored
  }
}

void NmtSlave::set_heartbeat_period_ms(uint16_t period_ms) {
  heartbeat_period_ms_ = period_ms;
  heartbeat_remaining_us_ = 0;
  heartbeat_now_ = period_ms != 0 && state_ != NmtState::kInitializing;
}

void NmtSlave::enter(NmtState state) {
  if (state == state_) return;
  state_ = state;
  if (heartbeat_period_ms_ != 0) heartbeat_now_ = true;
}

NmtReset NmtSlave::process(uint32_t elapsed_us) {
  if (command_pending_) {
    command_pending_ = false;
    switch (static_cast<NmtCommand>(pending_command_)) {
      case NmtCommand::kStart: enter(NmtState::kOperational); break;
      case NmtCommand::kStop: enter(NmtState::kStopped); break;
      case NmtCommand::kEnterPreOperational: enter(NmtState::kPreOperational); break;
      case NmtCommand::kResetNode: return NmtReset::kNode;
      case NmtCommand::kResetCommunication: return NmtReset::kCommunication;
    }
  }
  if (state_ == NmtState::kInitializing || heartbeat_period_ms_ == 0) return NmtReset::kNone;
  const uint64_t period_us = static_cast<uint64_t>(heartbeat_period_ms_) * 1000u;
  if (heartbeat_now_) {
    heartbeat_now_ = false;
    send_state(static_cast<uint8_t>(state_));
    heartbeat_remaining_us_ = period_us;
    return NmtReset::kNone;
  }
  if (elapsed_us < heartbeat_remaining_us_) {
    heartbeat_remaining_us_ -= elapsed_us;
    return NmtReset::kNone;
  }
  // Due: keep the phase (the next one is one period after this one was due), but never send a
  // burst after a long gap.
  const uint64_t late_us = elapsed_us - heartbeat_remaining_us_;
  send_state(static_cast<uint8_t>(state_));
  heartbeat_remaining_us_ = late_us < period_us ? period_us - late_us : period_us;
  return NmtReset::kNone;
}

void NmtSlave::send_state(uint8_t value) {
  can::CanFrame frame;
  frame.id = kHeartbeatCobIdBase + node_id_;
  frame.dlc = 1;
  frame.data[0] = value;
  can_.transmit(frame);
}

}  // namespace motwin::canopen
