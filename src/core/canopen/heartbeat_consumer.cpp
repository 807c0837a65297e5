#include "core/canopen/heartbeat_consumer.h"

namespace motwin::canopen {

void HeartbeatConsumer::configure(uint32_t entry) {
  entry_ = entry;
  const uint8_t node = static_cast<uint8_t>(entry >> 16);
  const uint16_t time_ms = static_cast<uint16_t>(entry);
  state_ = node == 0 || node > 127 || time_ms == 0 ? State::kUnused : State::kWaitingForFirst;
  remaining_us_ = 0;
  received_ = false;
  recovered_ = false;
}

void HeartbeatConsumer::on_frame(const can::CanFrame& frame) {
  if (state_ == State::kUnused || frame.rtr || frame.extended || frame.dlc != 1) return;
  if (frame.id != 0x700u + producer()) return;
  received_ = true;
  remaining_us_ = static_cast<uint64_t>(static_cast<uint16_t>(entry_)) * 1000u;
  if (state_ == State::kTimedOut) recovered_ = true;
  state_ = State::kActive;
}

HeartbeatEvent HeartbeatConsumer::process(uint32_t elapsed_us) {
  if (recovered_) {
    recovered_ = false;
    return HeartbeatEvent::kRecovered;
  }
  if (received_) {  // the time starts with the frame just received
    received_ = false;
    return HeartbeatEvent::kNone;
  }
  if (state_ != State::kActive) return HeartbeatEvent::kNone;
  if (elapsed_us < remaining_us_) {
    remaining_us_ -= elapsed_us;
    return HeartbeatEvent::kNone;
  }
  state_ = State::kTimedOut;
  return HeartbeatEvent::kTimeout;
}

}  // namespace motwin::canopen
