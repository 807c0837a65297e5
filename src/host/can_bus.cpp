#include "host/can_bus.h"

#include <algorithm>

#include "host/can_bit_timing.h"

namespace motwin::host {

CanBus::EndpointId CanBus::attach(CanBusEndpoint& endpoint) {
  const EndpointId id = next_id_++;
  entries_.push_back(Entry{id, &endpoint});
  return id;
}

void CanBus::detach(EndpointId id) {
  for (Entry& entry : entries_) {
    if (entry.id == id) entry.endpoint = nullptr;
  }
  if (!delivering_) {
    std::erase_if(entries_, [](const Entry& entry) { return entry.endpoint == nullptr; });
  }
}

size_t CanBus::endpoint_count() const {
  return static_cast<size_t>(
      std::count_if(entries_.begin(), entries_.end(), [](const Entry& entry) { return entry.endpoint != nullptr; }));
}

uint64_t CanBus::account(const can::CanFrame& frame) {
  const uint64_t sent_us = now_us();
  const uint32_t bits = can_frame_bits(frame);
  ++stats_.frames;
  stats_.bits += bits;
  if (bit_rate_ == 0) return sent_us;
  const uint64_t sent_ns = sent_us * 1000u;
  const uint64_t start_ns = std::max(sent_ns, busy_until_ns_);
  const uint64_t duration_ns = uint64_t{bits} * 1'000'000'000u / bit_rate_;
  busy_until_ns_ = start_ns + duration_ns;
  stats_.busy_ns += duration_ns;
  const uint64_t delay_ns = start_ns - sent_ns;
  stats_.total_queue_delay_ns += delay_ns;
  stats_.max_queue_delay_ns = std::max(stats_.max_queue_delay_ns, delay_ns);
  return busy_until_ns_ / 1000u;
}

void CanBus::send(EndpointId from, const can::CanFrame& frame) {
  pending_.push_back(Pending{from, frame, account(frame)});
  if (delivering_) return;
  delivering_ = true;
  while (!pending_.empty()) {
    const Pending next = pending_.front();
    pending_.pop_front();
    ++frame_count_;
    // Index loop: endpoints attached meanwhile are appended and see later frames only.
    const size_t count = entries_.size();
    for (size_t i = 0; i < count; ++i) {
      CanBusEndpoint* endpoint = entries_[i].endpoint;
      if (endpoint == nullptr || entries_[i].id == next.from) continue;
      endpoint->on_frame(next.frame, next.timestamp_us);
    }
  }
  delivering_ = false;
  std::erase_if(entries_, [](const Entry& entry) { return entry.endpoint == nullptr; });
}

}  // namespace motwin::host
