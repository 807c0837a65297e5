// SYNC (CiA-301 7.2.5), consumer and producer, in the shape of CANopenNode's CO_SYNC. 1005 holds
// the COB-ID (bits 10..0) and, in bit 30, whether this node produces the SYNC; 1006 the
// communication cycle period in µs. A SYNC is a frame on the COB-ID with no data (or one byte: a
// producer with a counter, 1019, which this node accepts but does not use). The producer sends
// one every 1006 µs in pre-operational and operational when bit 30 is set and 1006 != 0; the
// bus does not return a node's own frames, so process() reports the produced SYNC and the device
// treats it like a received one.
#pragma once

#include <cstdint>

#include "board/can_controller.h"
#include "core/canopen/sdo_abort.h"
#include "types/can_frame.h"

namespace motwin::canopen {

inline constexpr uint32_t kSyncProducerBit = 0x4000'0000;  // 1005 bit 30
inline constexpr uint32_t kSyncCobIdMask = 0x7FF;

// An SDO write of 1005 (`current` is its value now): 11-bit identifiers only (bit 29 refused),
// bit 30 makes the node the producer; the restricted identifiers the PDO and EMCY COB-IDs refuse
// too (CiA-301 7.3.5); bits 29..0 do not change while the node produces SYNC (CiA-301 7.5.2.5:
// a master clears bit 30 first, same identifier, then writes the new one).
SdoAbort check_sync_cob_id(uint32_t current, int64_t value);

class SyncService {
 public:
  explicit SyncService(board::CanController& can) : can_(can) {}

  void set_cob_id(uint32_t cob_id);             // 1005
  void set_cycle_period_us(uint32_t period_us); // 1006
  uint32_t cob_id() const { return cob_id_; }
  bool producer() const { return (cob_id_ & kSyncProducerBit) != 0 && period_us_ != 0; }

  // Whether a received frame is a SYNC.
  bool is_sync(const can::CanFrame& frame) const {
    return !frame.extended && !frame.rtr && frame.id == (cob_id_ & kSyncCobIdMask) && frame.dlc <= 1;
  }
  // The producer's timer; `active` is false outside pre-operational and operational. True when a
  // SYNC went out in this call.
  bool process(uint32_t elapsed_us, bool active);
  // Restarts the producer's period (reset communication).
  void reset() { remaining_us_ = period_us_; }

  uint64_t produced() const { return produced_; }

 private:
  board::CanController& can_;
  uint32_t cob_id_ = 0x80;
  uint32_t period_us_ = 0;
  uint64_t remaining_us_ = 0;
  uint64_t produced_ = 0;
};

}  // namespace motwin::canopen
