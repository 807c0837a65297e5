// Node guarding and life guarding, the slave's side (CiA-301 7.2.8.3.1; objects 100C guard time
// in ms and 100D life time factor), in the shape of CANopenNode's CO_NodeGuarding: the master asks
// with a remote frame on 700h + node ID; the node answers at once with one byte, the toggle bit 7
// and its NMT state, the toggle alternating from 0 (back to 0 at every reset communication). Life
// guarding starts with the first request when 100C and 100D are both non-zero: no request within
// 100C x 100D ms is a life guarding event, reported once by process(); the next request ends it.
// A node whose producer heartbeat time (1017) is not 0 uses the heartbeat and leaves requests
// unanswered (CiA-301: one error control protocol at a time).
#pragma once

#include <cstdint>

#include "board/can_controller.h"
#include "core/canopen/nmt.h"
#include "types/can_frame.h"

namespace motwin::canopen {

enum class GuardingEvent : uint8_t { kNone, kLifeGuardingLost, kRecovered };

class NodeGuarding {
 public:
  explicit NodeGuarding(board::CanController& can) : can_(can) {}

  void set_guard_time_ms(uint16_t guard_time_ms) { guard_time_ms_ = guard_time_ms; }  // 100C
  void set_life_time_factor(uint8_t factor) { life_time_factor_ = factor; }             // 100D
  // Reset communication: toggle 0, no monitoring until the next request.
  void reset();

  // Whether `frame` is a guarding request for `node_id`.
  static bool is_request(const can::CanFrame& frame, uint8_t node_id) {
    return frame.rtr && !frame.extended && frame.id == kHeartbeatCobIdBase + node_id;
  }
  // A request: the answer goes out now (not while the heartbeat is produced).
  void on_request(uint8_t node_id, NmtState state, bool heartbeat_produced);
  GuardingEvent process(uint32_t elapsed_us);

 private:
  uint64_t life_time_us() const { return static_cast<uint64_t>(guard_time_ms_) * life_time_factor_ * 1000u; }

  board::CanController& can_;
  uint16_t guard_time_ms_ = 0;
  uint8_t life_time_factor_ = 0;
  bool toggle_ = false;
  bool monitoring_ = false;  // a request came since the reset
  bool lost_ = false;        // the life time passed without a request
  bool recovered_ = false;   // a request after a loss, to report
  uint64_t remaining_us_ = 0;
};

}  // namespace motwin::canopen
