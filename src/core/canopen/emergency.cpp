#include "core/canopen/emergency.h"

#include "core/canopen/cob_id.h"

namespace motwin::canopen {

SdoAbort check_emcy_cob_id(uint32_t current, int64_t value, uint8_t node_id) {
  constexpr uint32_t kInvalid = 0x8000'0000;
  constexpr uint32_t kMask = 0x7FF;
  const uint32_t v = static_cast<uint32_t>(value);
  if ((v & 0x7FFF'F800) != 0) return SdoAbort::kInvalidValue;
  if ((v & kInvalid) != 0) return SdoAbort::kNone;
  if ((current & kInvalid) == 0 && ((v ^ current) & kMask) != 0) return SdoAbort::kInvalidValue;
  return restricted_can_id(v & kMask) && (v & kMask) != 0x80u + node_id ? SdoAbort::kInvalidValue : SdoAbort::kNone;
}

void EmergencyProducer::reset() {
  head_ = 0;
  count_ = 0;
  inhibit_remaining_us_ = 0;
}

bool EmergencyProducer::report(uint16_t error_code, uint8_t error_register, const uint8_t (&manufacturer)[5]) {
  if ((cob_id_ & 0x8000'0000u) != 0) return false;
  if (count_ == queue_.size()) {
    ++lost_;
    return false;
  }
  can::CanFrame frame;
  frame.id = cob_id_ & 0x7FF;
  frame.dlc = 8;
  frame.data[0] = static_cast<uint8_t>(error_code);
  frame.data[1] = static_cast<uint8_t>(error_code >> 8);
  frame.data[2] = error_register;
  for (int i = 0; i < 5; ++i) frame.data[3 + i] = manufacturer[i];
  queue_[(head_ + count_) % queue_.size()] = frame;
  ++count_;
  return true;
}

void EmergencyProducer::process(uint32_t elapsed_us) {
  inhibit_remaining_us_ = elapsed_us < inhibit_remaining_us_ ? inhibit_remaining_us_ - elapsed_us : 0;
  while (count_ > 0 && inhibit_remaining_us_ == 0) {
    can_.transmit(queue_[head_]);
    head_ = (head_ + 1) % queue_.size();
    --count_;
    inhibit_remaining_us_ = static_cast<uint64_t>(inhibit_100us_) * 100u;
  }
}

}  // namespace motwin::canopen
