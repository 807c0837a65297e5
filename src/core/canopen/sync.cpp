#include "core/canopen/sync.h"

namespace motwin::canopen {

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
