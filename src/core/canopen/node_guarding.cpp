#include "core/canopen/node_guarding.h"

namespace motwin::canopen {

void NodeGuarding::reset() {
  toggle_ = false;
  monitoring_ = false;
  lost_ = false;
  recovered_ = false;
  remaining_us_ = 0;
}

void NodeGuarding::on_request(uint8_t node_id, NmtState state, bool heartbeat_produced) {
  if (heartbeat_produced) return;
  const uint8_t data[1] = {static_cast<uint8_t>((toggle_ ? 0x80u : 0u) | static_cast<uint8_t>(state))};
  can_.transmit(can::make_frame(kHeartbeatCobIdBase + node_id, data, 1));
  toggle_ = !toggle_;
  monitoring_ = true;
  remaining_us_ = life_time_us();
  if (lost_) {
    lost_ = false;
    recovered_ = true;
  }
}

GuardingEvent NodeGuarding::process(uint32_t elapsed_us) {
  if (recovered_) {
    recovered_ = false;
    return GuardingEvent::kRecovered;
  }
  if (!monitoring_ || lost_ || life_time_us() == 0) return GuardingEvent::kNone;
  if (elapsed_us < remaining_us_) {
    remaining_us_ -= elapsed_us;
    return GuardingEvent::kNone;
  }
  remaining_us_ = 0;
  lost_ = true;
  return GuardingEvent::kLifeGuardingLost;
}

}  // namespace motwin::canopen
