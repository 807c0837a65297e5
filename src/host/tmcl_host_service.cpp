#include "host/tmcl_host_service.h"

namespace motwin::host {

TmclHostService::TmclHostService(tmcl::TmclEngine& engine, EventLoop& loop) : engine_(engine), loop_(loop) {}

TmclHostService::~TmclHostService() {
  if (held_) loop_.cancel_timer(held_->timer);
}

tmcl::ChannelId TmclHostService::open_channel(ReplyChannel& channel) {
  // Skip ids still in use, or with requests or a held reply from a connection that just went.
  for (uint32_t attempt = 0; attempt <= UINT16_MAX; ++attempt) {
    const tmcl::ChannelId id = next_channel_id_;
    next_channel_id_ = static_cast<tmcl::ChannelId>(next_channel_id_ == UINT16_MAX ? 1 : next_channel_id_ + 1);
    if (id == 0 || channels_.count(id) != 0 || queued_requests(id) != 0 || (held_ && held_->channel == id)) continue;
    channels_[id] = &channel;
    return id;
  }
  // 65535 simultaneous connections: the transports limit their clients far below that.
  return 0;
}

void TmclHostService::close_channel(tmcl::ChannelId id) {
  channels_.erase(id);
  engine_.forget_channel(id);
}

void TmclHostService::submit(tmcl::ChannelId id, const tmcl::Frame& frame) {
  queue_.push_back(QueuedRequest{id, frame});
  ++queued_per_channel_[id];
}

size_t TmclHostService::queued_requests(tmcl::ChannelId id) const {
  const auto found = queued_per_channel_.find(id);
  return found == queued_per_channel_.end() ? 0 : found->second;
}

void TmclHostService::serve_queued() {
  // A reply callback may end up here again (a channel closing); one loop is enough.
  if (serving_) return;
  serving_ = true;
  while (!held_ && !queue_.empty()) {
    const QueuedRequest request = queue_.front();
    queue_.pop_front();
    if (--queued_per_channel_[request.channel] == 0) queued_per_channel_.erase(request.channel);
    const tmcl::SerialResponse response = tmcl::serve_serial_frame(engine_, request.frame, request.channel);
    ++served_request_count_;
    if (response.length > 0 && response.delay_ms > 0) {
      // Telegram pause (GP 75): wall-clock time, like the bus turnaround it stands for.
      held_ = HeldReply{request.channel, response.bytes, response.length, response.reset_after_send, {}, 0};
      held_->timer = loop_.add_timer_after(uint64_t{response.delay_ms} * 1000u, [this] { release_held_reply(); });
      continue;  // finished when released
    }
    if (response.length > 0) {
      send_to(request.channel, response.bytes.data(), response.length);
      if (response.reset_after_send) engine_.complete_reset();
    }
    finish_request(request.channel);
  }
  serving_ = false;
}

void TmclHostService::finish_request(tmcl::ChannelId channel) {
  const auto found = channels_.find(channel);
  if (found == channels_.end()) {
    // The connection is gone: a command 138 it just sent must not stay pending.
    engine_.forget_channel(channel);
    return;
  }
  found->second->on_request_served();
}

void TmclHostService::release_held_reply() {
  HeldReply held = std::move(*held_);
  held_.reset();
  send_to(held.channel, held.bytes.data(), held.length);
  if (held.reset_after_send) engine_.complete_reset();
  for (const tmcl::Frame& event : held.events_after) send_to(held.channel, event.data(), event.size());
  finish_request(held.channel);
  serve_queued();
}

void TmclHostService::deliver(tmcl::ChannelId channel, const tmcl::Reply& reply) {
  if (channels_.count(channel) == 0) return;
  const tmcl::Frame frame = tmcl::encode_event_reply(engine_.device(), reply);
  if (held_ && held_->channel == channel) {
    held_->events_after.push_back(frame);
    return;
  }
  send_to(channel, frame.data(), frame.size());
}

void TmclHostService::send_to(tmcl::ChannelId channel, const uint8_t* bytes, size_t length) {
  const auto found = channels_.find(channel);
  if (found != channels_.end()) found->second->send_reply(bytes, length);
}

}  // namespace motwin::host
