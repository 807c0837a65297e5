#include "host/tmcl_host_service.h"

#include <algorithm>
#include <string>

namespace motwin::host {

TmclHostService::TmclHostService(tmcl::TmclEngine& engine, EventLoop& loop)
    : engine_(engine), loop_(loop), power_ups_seen_(engine.power_up_count()) {}

TmclHostService::~TmclHostService() {
  if (held_) loop_.cancel_timer(held_->timer);
}

LinkMode TmclHostService::start_mode() const {
  const tmcl::AsciiSettings settings = tmcl::ascii_settings(engine_.device());
  return settings.available && settings.start_in_ascii_mode ? LinkMode::kAscii : LinkMode::kBinary;
}

tmcl::ChannelId TmclHostService::open_channel(ReplyChannel& channel, uint32_t resync_gap_us, ChannelTraffic traffic,
                                              LineEcho echo) {
  // Skip ids still in use, or with requests or a held reply from a connection that just went.
  for (uint32_t attempt = 0; attempt <= UINT16_MAX; ++attempt) {
    const tmcl::ChannelId id = next_channel_id_;
    next_channel_id_ = static_cast<tmcl::ChannelId>(next_channel_id_ == UINT16_MAX ? 1 : next_channel_id_ + 1);
    if (id == 0 || channels_.count(id) != 0 || event_channels_.count(id) != 0 || queued_requests(id) != 0 ||
        (held_ && held_->channel == id)) {
      continue;
    }
    if (echo == LineEcho::kTransceiver) resync_gap_us = std::max(resync_gap_us, kEchoResyncGapUs);
    channels_.emplace(
        id, Channel{&channel, start_mode(), traffic, echo, tmcl::SerialFrameDecoder(resync_gap_us), {}, {}, false});
    return id;
  }
  // 65535 simultaneous connections: the transports limit their clients far below that.
  return 0;
}

tmcl::ChannelId TmclHostService::open_event_channel(tmcl::ReplySink& sink) {
  for (uint32_t attempt = 0; attempt <= UINT16_MAX; ++attempt) {
    const tmcl::ChannelId id = next_channel_id_;
    next_channel_id_ = static_cast<tmcl::ChannelId>(next_channel_id_ == UINT16_MAX ? 1 : next_channel_id_ + 1);
    if (id == 0 || channels_.count(id) != 0 || event_channels_.count(id) != 0 || queued_requests(id) != 0) continue;
    event_channels_.emplace(id, &sink);
    return id;
  }
  return 0;
}

void TmclHostService::close_event_channel(tmcl::ChannelId id) {
  event_channels_.erase(id);
  engine_.forget_channel(id);
}

void TmclHostService::close_channel(tmcl::ChannelId id) {
  channels_.erase(id);
  engine_.forget_channel(id);
}

std::optional<LinkMode> TmclHostService::link_mode(tmcl::ChannelId id) const {
  const auto found = channels_.find(id);
  if (found == channels_.end()) return std::nullopt;
  return found->second.mode;
}

size_t TmclHostService::queued_requests(tmcl::ChannelId id) const {
  const auto found = queues_.find(id);
  return found == queues_.end() ? 0 : found->second.size();
}

size_t TmclHostService::input_room(tmcl::ChannelId id) const {
  const auto found = channels_.find(id);
  if (found == channels_.end()) return 0;
  const Channel& channel = found->second;
  const size_t queued = queued_requests(id);
  if (queued >= kMaxQueuedRequestsPerChannel || channel.input.size() >= kMaxPendingInputBytes) return 0;
  const size_t room = kMaxPendingInputBytes - channel.input.size();
  // Binary: no more frames than the queue takes, so that the rest waits in the kernel.
  if (channel.mode == LinkMode::kBinary && !channel.awaiting_reply) {
    return std::min(room, (kMaxQueuedRequestsPerChannel - queued) * tmcl::kFrameLength);
  }
  return room;
}

void TmclHostService::receive(tmcl::ChannelId id, const uint8_t* bytes, size_t length, uint64_t now_us,
                              std::optional<uint64_t> quiet_seen_us) {
  const auto echoing = channels_.find(id);
  if (echoing != channels_.end() && echoing->second.echo == LineEcho::kTransceiver) {
    // The transceiver hands the bytes back as they pass, before the module has read them.
    send_to(id, bytes, length);
  }
  // Sending may have closed the channel.
  const auto found = channels_.find(id);
  if (found == channels_.end()) return;
  Channel& channel = found->second;
  // A byte written 1 ms after the previous one but read 20 ms later, because the server did not
  // run meanwhile (a loaded machine), followed it without a pause on the line.
  const uint64_t quiet_until_us = quiet_seen_us.value_or(now_us);
  if (quiet_until_us > channel.last_receive_us) channel.line_clock_us += quiet_until_us - channel.last_receive_us;
  channel.last_receive_us = now_us;
  for (size_t i = 0; i < length; ++i) channel.input.push_back(PendingByte{bytes[i], channel.line_clock_us});
  process_input(id);
}

void TmclHostService::discard_partial_input(tmcl::ChannelId id) {
  const auto found = channels_.find(id);
  if (found == channels_.end()) return;
  found->second.decoder.reset();
  found->second.ascii.reset();
}

void TmclHostService::enqueue(tmcl::ChannelId id, QueuedRequest request) {
  std::deque<QueuedRequest>& queue = queues_[id];
  if (queue.empty()) turns_.push_back(id);  // its turn comes after every connection waiting now
  queue.push_back(std::move(request));
  ++total_queued_;
}

void TmclHostService::process_input(tmcl::ChannelId id) {
  std::vector<uint8_t> echo;
  {
    const auto found = channels_.find(id);
    if (found == channels_.end()) return;
    Channel& channel = found->second;
    std::optional<tmcl::AsciiSettings> settings;
    while (!channel.awaiting_reply && !channel.input.empty() && queued_requests(id) < kMaxQueuedRequestsPerChannel) {
      const PendingByte next = channel.input.front();
      channel.input.pop_front();
      if (channel.mode == LinkMode::kBinary) {
        if (!channel.decoder.push(next.byte, next.arrival_us)) continue;
        const tmcl::Frame& frame = channel.decoder.frame();
        enqueue(id, QueuedRequest{id, false, frame, {}});
        // Command 139 may switch this link to ASCII: what follows waits for its reply.
        if (frame[1] == tmcl::command::kEnterAsciiMode) channel.awaiting_reply = true;
        continue;
      }
      if (!settings) settings = tmcl::ascii_settings(engine_.device());
      const bool line_complete = channel.ascii.push(next.byte, *settings);
      echo.insert(echo.end(), channel.ascii.echo(), channel.ascii.echo() + channel.ascii.echo_length());
      if (line_complete) {
        enqueue(id, QueuedRequest{id, true, {}, channel.ascii.command()});
        // One line at a time, as the firmware reads them: the next line's echo follows this
        // line's reply, and BIN switches what follows to binary.
        channel.awaiting_reply = true;
      }
    }
  }
  // Last: sending may close the channel.
  if (!echo.empty()) send_to(id, echo.data(), echo.size());
}

void TmclHostService::serve_queued() {
  // A reply callback may end up here again (a channel closing); one loop is enough.
  if (serving_) return;
  serving_ = true;
  // Connections that join the round while it runs (their first request read now) wait for the next.
  for (size_t round = turns_.size(); round > 0 && !held_ && !turns_.empty(); --round) {
    const tmcl::ChannelId turn = turns_.front();
    turns_.pop_front();
    const auto queue = queues_.find(turn);
    const QueuedRequest request = queue->second.front();
    queue->second.pop_front();
    --total_queued_;
    if (queue->second.empty()) {
      queues_.erase(queue);
    } else {
      turns_.push_back(turn);  // one request per turn
    }
    Outgoing reply;
    uint8_t delay_ms = 0;
    if (request.ascii) {
      const tmcl::AsciiResponse response = tmcl::serve_ascii_command(engine_, request.command, request.channel);
      reply.bytes.assign(response.bytes, response.bytes + response.length);
      reply.reset_after_send = response.reset_after_send;
      if (response.leave_ascii_mode) reply.mode_after = LinkMode::kBinary;
      delay_ms = response.delay_ms;
    } else {
      const tmcl::SerialResponse response = tmcl::serve_serial_frame(engine_, request.frame, request.channel);
      reply.bytes.assign(response.bytes.begin(), response.bytes.begin() + response.length);
      reply.reset_after_send = response.reset_after_send;
      if (response.enter_ascii_mode) reply.mode_after = LinkMode::kAscii;
      delay_ms = response.delay_ms;
    }
    ++served_request_count_;
    const auto served_channel = channels_.find(request.channel);
    if (served_channel == channels_.end() || served_channel->second.traffic == ChannelTraffic::kHost) {
      ++served_host_request_count_;
    }
    follow_power_ups();  // command 137 powers up inside execute()
    if (!reply.bytes.empty() && delay_ms > 0) {
      // Telegram pause (GP 75): wall-clock time, like the bus turnaround it stands for.
      held_ = HeldReply{request.channel, std::move(reply), {}, 0};
      held_->timer = loop_.add_timer_after(uint64_t{delay_ms} * 1000u, [this] { release_held_reply(); });
      continue;  // finished when released
    }
    complete(request.channel, reply);
    finish_request(request.channel);
  }
  serving_ = false;
}

void TmclHostService::complete(tmcl::ChannelId channel, const Outgoing& reply) {
  if (!reply.bytes.empty()) send_to(channel, reply.bytes.data(), reply.bytes.size());
  if (reply.mode_after) {
    const auto found = channels_.find(channel);
    if (found != channels_.end()) set_mode(found->second, *reply.mode_after);
  }
  if (reply.reset_after_send) engine_.complete_reset();
  follow_power_ups();
}

void TmclHostService::set_mode(Channel& channel, LinkMode mode) {
  channel.mode = mode;
  channel.decoder.reset();
  channel.ascii.reset();
}

void TmclHostService::follow_power_ups() {
  if (engine_.power_up_count() == power_ups_seen_) return;
  power_ups_seen_ = engine_.power_up_count();
  const LinkMode mode = start_mode();
  for (auto& [id, channel] : channels_) set_mode(channel, mode);
}

void TmclHostService::finish_request(tmcl::ChannelId channel) {
  const auto found = channels_.find(channel);
  if (found == channels_.end()) {
    // The connection is gone: a command 138 it just sent must not stay pending.
    engine_.forget_channel(channel);
    return;
  }
  // Only when nothing else of this channel is queued: an earlier 139 or line may still be.
  if (queued_requests(channel) == 0) found->second.awaiting_reply = false;
  process_input(channel);
  const auto still_open = channels_.find(channel);
  if (still_open != channels_.end()) still_open->second.sink->on_request_served();
}

void TmclHostService::release_held_reply() {
  HeldReply held = std::move(*held_);
  held_.reset();
  complete(held.channel, held.reply);
  for (const std::vector<uint8_t>& event : held.events_after) send_to(held.channel, event.data(), event.size());
  finish_request(held.channel);
  serve_queued();
}

std::vector<uint8_t> TmclHostService::encode_event(LinkMode mode, const tmcl::Reply& reply) const {
  if (mode == LinkMode::kBinary) {
    const tmcl::Frame frame = tmcl::encode_event_reply(engine_.device(), reply);
    return std::vector<uint8_t>(frame.begin(), frame.end());
  }
  // In ASCII mode the event is a reply line like any other: "BA 128 1".
  const tmcl::SerialSettings settings = engine_.device().serial_settings();
  const auto letter = [](uint8_t address) {
    const char c = tmcl::ascii_address_letter(address);
    return c != '\0' ? c : '?';
  };
  std::string line{letter(settings.host_address), letter(settings.module_address)};
  line += " " + std::to_string(reply.status) + " " + std::to_string(reply.value) + "\r";
  return std::vector<uint8_t>(line.begin(), line.end());
}

void TmclHostService::deliver(tmcl::ChannelId channel, const tmcl::Reply& reply) {
  if (const auto external = event_channels_.find(channel); external != event_channels_.end()) {
    external->second->deliver(channel, reply);
    return;
  }
  const auto found = channels_.find(channel);
  if (found == channels_.end()) return;
  std::vector<uint8_t> bytes = encode_event(found->second.mode, reply);
  if (held_ && held_->channel == channel) {
    held_->events_after.push_back(std::move(bytes));
    return;
  }
  send_to(channel, bytes.data(), bytes.size());
}

void TmclHostService::send_to(tmcl::ChannelId channel, const uint8_t* bytes, size_t length) {
  const auto found = channels_.find(channel);
  if (found != channels_.end()) found->second.sink->send_reply(bytes, length);
}

}  // namespace motwin::host
