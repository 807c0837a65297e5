// Heartbeat consumer (CiA-301 7.2.8.3.2, TMCM-3216 manual 3.1.11, object 1016 sub 1: node ID in
// bits 23..16, time in ms in bits 15..0). Monitoring starts with the first heartbeat (or boot-up)
// of the producer, as the manual says; no heartbeat within the time is a timeout, reported once
// by process(); the next heartbeat ends it (process() then reports the recovery) and a boot-up of
// the producer starts over. Time 0 or node 0 switches the entry off.
#pragma once

#include <cstdint>

#include "core/canopen/sdo_abort.h"
#include "types/can_frame.h"

namespace motwin::canopen {

enum class HeartbeatEvent : uint8_t { kNone, kTimeout, kRecovered };

// An SDO write of a 1016 entry: bits 31..24 reserved, node ID 1..127 in bits 23..16 (or 0: unused).
constexpr SdoAbort check_consumer_heartbeat_entry(int64_t value) {
  const uint32_t v = static_cast<uint32_t>(value);
  return (v >> 24) != 0 || ((v >> 16) & 0xFF) > 127 ? SdoAbort::kInvalidValue : SdoAbort::kNone;
}

class HeartbeatConsumer {
 public:
  enum class State : uint8_t { kUnused, kWaitingForFirst, kActive, kTimedOut };

  void configure(uint32_t entry);
  void reset() { configure(entry_); }
  // A frame on 0x700 + the producer's node ID (others are ignored).
  void on_frame(const can::CanFrame& frame);
  HeartbeatEvent process(uint32_t elapsed_us);

  State state() const { return state_; }
  uint8_t producer() const { return static_cast<uint8_t>(entry_ >> 16); }

 private:
  uint32_t entry_ = 0;
  State state_ = State::kUnused;
  uint64_t remaining_us_ = 0;
  bool received_ = false;
  bool recovered_ = false;
};

}  // namespace motwin::canopen
