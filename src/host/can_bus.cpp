#include "host/can_bus.h"

#include <algorithm>

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

void CanBus::send(EndpointId from, const can::CanFrame& frame) {
  pending_.push_back(Pending{from, frame, now_us()});
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
