#include "core/canopen/sync.h"

#include "core/canopen/cob_id.h"

namespace motwin::canopen {

SdoAbort check_sync_cob_id(uint32_t current, int64_t value) {
  const uint32_t v = static_cast<uint32_t>(value);
  const uint32_t allowed = kSyncCobIdMask | kSyncProducerBit;
  if ((v & ~allowed) != 0) return SdoAbort::kInvalidValue;
  if (restricted_can_id(v & kSyncCobIdMask)) return SdoAbort::kInvalidValue;
  constexpr uint32_t kIdentifierBits = 0x3FFF'FFFF;
  if ((current & kSyncProducerBit) != 0 && ((v ^ current) & kIdentifierBits) != 0) return SdoAbort::kInvalidValue;
  return SdoAbort::kNone;
}

void SyncService::set_cob_id(uint32_t cob_id) {
  const bool was_producer = producer();
  cob_id_ = cob_id;
  if (!was_producer && producer()) remaining_us_ = period_us_;
}

void SyncService::set_cycle_period_us(uint32_t period_us) {
  period_us_ = period_us;
  remaining_us_ = period_us;
}

bool SyncService::process(uint32_t elapsed_us, bool active) {
  if (!active || !producer()) return false;
  if (elapsed_us < remaining_us_) {
    remaining_us_ -= elapsed_us;
    return false;
  }
  // Keep the phase, never a burst after a long gap (as the heartbeat).
  const uint64_t late_us = elapsed_us - remaining_us_;
  remaining_us_ = late_us < period_us_ ? period_us_ - late_us : period_us_;
  can::CanFrame frame;
  frame.id = cob_id_ & kSyncCobIdMask;
  frame.dlc = 0;
  can_.transmit(frame);
  ++produced_;
  return true;
}

}  // namespace motwin::canopen
