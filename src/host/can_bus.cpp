#include "host/can_bus.h"

#include <algorithm>

#include "host/can_bit_timing.h"

namespace motwin::host {

std::string_view to_string(CanErrorState state) {
  switch (state) {
    case CanErrorState::kErrorActive: return "error-active";
    case CanErrorState::kErrorPassive: return "error-passive";
    case CanErrorState::kBusOff: return "bus-off";
  }
  return "?";
}

std::string format_node_bus_stats(std::string_view name, const CanNodeBusStats& node) {
  std::string text = " node " + std::string(name) + " bitrate " + std::to_string(node.bit_rate) +
                     (node.off_speed ? " off-speed " : " on-speed ") + std::string(to_string(node.error_state));
  text += " rec " + std::to_string(node.receive_errors) + " tec " + std::to_string(node.transmit_errors);
  text += " missed " + std::to_string(node.frames_missed) + " not-sent " + std::to_string(node.frames_not_sent);
  text += " bus-off " + std::to_string(node.bus_off_count);
  return text;
}

CanBus::EndpointId CanBus::attach(CanBusEndpoint& endpoint) {
  const EndpointId id = next_id_++;
  entries_.push_back(Entry{id, &endpoint, {}});
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

CanBus::Entry* CanBus::find(EndpointId id) {
  for (Entry& entry : entries_) {
    if (entry.id == id && entry.endpoint != nullptr) return &entry;
  }
  return nullptr;
}

void CanBus::update_error_state(CanNodeBusStats& node) {
  if (node.error_state == CanErrorState::kBusOff) return;  // left only by recovery
  if (node.transmit_errors >= CanNodeBusStats::kBusOffLimit) {
    node.error_state = CanErrorState::kBusOff;
    ++node.bus_off_count;
    return;
  }
  const bool passive = node.transmit_errors >= CanNodeBusStats::kPassiveLimit ||
                       node.receive_errors >= CanNodeBusStats::kPassiveLimit;
  node.error_state = passive ? CanErrorState::kErrorPassive : CanErrorState::kErrorActive;
}

bool CanBus::refresh(Entry& entry) {
  CanNodeBusStats& node = entry.node;
  const uint32_t rate = entry.endpoint->controller_bit_rate();
  if (rate != node.bit_rate) {
    // The controller was set up again (a reset or power-up of its module): counters start over.
    node.bit_rate = rate;
    node.receive_errors = 0;
    node.transmit_errors = 0;
    node.error_state = CanErrorState::kErrorActive;
  }
  node.off_speed = bit_rate_ != 0 && rate != 0 && rate != bit_rate_;
  if (node.error_state == CanErrorState::kBusOff) {
    const uint32_t recovery_rate = rate != 0 ? rate : bit_rate_;
    const uint64_t recovery_bit_us = uint64_t{CanNodeBusStats::kBusOffRecoveryBits} * 1'000'000u;
    const uint64_t recovery_us = recovery_rate == 0 ? 0 : (recovery_bit_us + recovery_rate - 1) / recovery_rate;
    if (now_us() >= node.bus_off_since_us + recovery_us) {
      node.receive_errors = 0;
      node.transmit_errors = 0;
      node.error_state = CanErrorState::kErrorActive;
    }
  }
  return !node.off_speed && node.error_state != CanErrorState::kBusOff;
}

void CanBus::count_receive_error(Entry& entry) {
  CanNodeBusStats& node = entry.node;
  ++node.frames_missed;
  if (node.error_state == CanErrorState::kBusOff) return;  // off the bus: sees nothing
  // A receiver never goes bus-off; its counter stops where it is far into error-passive.
  if (node.receive_errors < CanNodeBusStats::kBusOffLimit - 1) ++node.receive_errors;
  update_error_state(node);
}

void CanBus::count_transmit_error(Entry& entry) {
  CanNodeBusStats& node = entry.node;
  ++node.frames_not_sent;
  if (node.error_state == CanErrorState::kBusOff) return;  // the controller does not try
  node.transmit_errors = static_cast<uint16_t>(node.transmit_errors + 8);
  update_error_state(node);
  if (node.error_state == CanErrorState::kBusOff) node.bus_off_since_us = now_us();
}

bool CanBus::takes_part(EndpointId id) {
  Entry* entry = find(id);
  return entry == nullptr || refresh(*entry);
}

const CanNodeBusStats* CanBus::node_stats(EndpointId id) {
  Entry* entry = find(id);
  if (entry == nullptr) return nullptr;
  refresh(*entry);
  return &entry->node;
}

const CanNodeBusStats* CanBus::node_stats(const CanBusEndpoint& endpoint) {
  for (Entry& entry : entries_) {
    if (entry.endpoint == &endpoint) return node_stats(entry.id);
  }
  return nullptr;
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
  if (Entry* sender = find(from); sender != nullptr) {
    // A controller off speed gets no acknowledgement and sees bit errors: its frame never makes
    // it onto the bus, whoever listens (its retransmissions are not modelled: one attempt each).
    if (!refresh(*sender)) {
      count_transmit_error(*sender);
      return;
    }
    if (sender->node.transmit_errors > 0) --sender->node.transmit_errors;
    update_error_state(sender->node);
  }
  pending_.push_back(Pending{from, frame, account(frame)});
  if (delivering_) return;
  delivering_ = true;
  while (!pending_.empty()) {
    const Pending next = pending_.front();
    pending_.pop_front();
    ++frame_count_;
    // Index loop: endpoints attached meanwhile are appended and see later frames only. No
    // reference into entries_ is held across on_frame(), which may attach.
    const size_t count = entries_.size();
    for (size_t i = 0; i < count; ++i) {
      if (entries_[i].endpoint == nullptr || entries_[i].id == next.from) continue;
      if (!refresh(entries_[i])) {
        count_receive_error(entries_[i]);
        continue;
      }
      CanNodeBusStats& node = entries_[i].node;
      if (node.receive_errors > 0) {
        // ISO 11898-1: a good reception takes an error-passive counter back to 119..127.
        node.receive_errors = node.receive_errors >= CanNodeBusStats::kPassiveLimit
                                  ? uint16_t{127}
                                  : static_cast<uint16_t>(node.receive_errors - 1);
        update_error_state(node);
      }
      entries_[i].endpoint->on_frame(next.frame, next.timestamp_us);
    }
  }
  delivering_ = false;
  std::erase_if(entries_, [](const Entry& entry) { return entry.endpoint == nullptr; });
}

}  // namespace motwin::host
