#include "core/canopen/emergency.h"

namespace motwin::canopen {

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
