#include "host/tmcl_can_node.h"

namespace motwin::host {

void TmclCanNode::connect(CanBus& bus) {
  disconnect();
  bus_ = &bus;
  bus_id_ = bus.attach(*this);
  follow_power_up();
}

void TmclCanNode::disconnect() {
  if (bus_ != nullptr) bus_->detach(bus_id_);
  bus_ = nullptr;
  bus_id_ = 0;
}

tmcl::CanSettings TmclCanNode::settings() const {
  tmcl::CanSettings settings;
  tmcl::read_can_settings(engine_.device(), settings);
  return settings;
}

void TmclCanNode::follow_power_up() {
  if (engine_.power_up_count() == power_ups_seen_) return;
  power_ups_seen_ = engine_.power_up_count();
  active_bit_rate_ = tmcl::can_bit_rate_from_code(settings().bit_rate_code);
}

bool TmclCanNode::on_speed() const {
  return bus_ == nullptr || bus_->takes_part(bus_id_);
}

void TmclCanNode::on_frame(const can::CanFrame& frame, uint64_t /*timestamp_us*/) {
  follow_power_up();
  if (!on_speed()) return;
  const tmcl::CanResponse response = tmcl::serve_can_frame(engine_, frame, channel_);
  if (!response.addressed) return;
  ++served_requests_;
  if (frame.data[0] == tmcl::command::kRequestPositionReachedEvent) {
    event_reply_length_ = response.reply.dlc;
    event_reply_extended_ = response.reply.extended;
  }
  if (response.has_reply) transmit(response.reply);
  // Command 255: the reply is on the bus (queued behind the current delivery), then the power-up.
  if (response.reset_after_send) engine_.complete_reset();
  follow_power_up();
}

void TmclCanNode::deliver(tmcl::ChannelId /*channel*/, const tmcl::Reply& reply) {
  transmit(tmcl::encode_can_reply(settings(), reply, event_reply_length_, event_reply_extended_));
}

void TmclCanNode::transmit(const can::CanFrame& frame) {
  // Off speed, the bus drops the frame and counts it (host/can_bus.h).
  if (bus_ != nullptr) bus_->send(bus_id_, frame);
}

}  // namespace motwin::host
