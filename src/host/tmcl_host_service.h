// Serves TMCL frames from every host connection (TCP clients, the pseudo-terminal) to one
// module, the way a module on a serial bus does: one request at a time, in arrival order,
// each reply to the connection that asked, the telegram pause (GP 75) before a reply without
// blocking the loop, and the delayed replies of command 138 to the connection that asked.
#pragma once

#include <cstddef>
#include <cstdint>
#include <deque>
#include <map>
#include <optional>
#include <string>
#include <vector>

#include "core/tmcl/engine.h"
#include "core/tmcl/serial_link.h"
#include "host/event_loop.h"

namespace motwin::host {

// One host connection, as the transports implement it.
class ReplyChannel {
 public:
  // Queues bytes for the host; never blocks. A channel that cannot take them any more closes
  // itself (later, through EventLoop::defer) and calls TmclHostService::close_channel.
  virtual void send_reply(const uint8_t* bytes, size_t length) = 0;
  // One of this channel's requests was served and its reply (if any) handed to send_reply():
  // the channel may read again if it had stopped.
  virtual void on_request_served() {}

 protected:
  ~ReplyChannel() = default;
};

class TmclHostService final : public tmcl::ReplySink {
 public:
  // A connection with this many requests waiting stops being read until some are served, so
  // that a client flooding frames gets TCP back-pressure instead of growing our memory.
  static constexpr size_t kMaxQueuedRequestsPerChannel = 32;

  TmclHostService(tmcl::TmclEngine& engine, EventLoop& loop);
  TmclHostService(const TmclHostService&) = delete;
  TmclHostService& operator=(const TmclHostService&) = delete;
  ~TmclHostService();

  // Never returns 0 (channel 0 is what the engine uses for a stored program).
  tmcl::ChannelId open_channel(ReplyChannel& channel);
  // Requests already queued from this channel still run (their bytes arrived, as on a serial
  // line); their replies and any pending command 138 events of the channel are dropped.
  void close_channel(tmcl::ChannelId id);
  bool is_open(tmcl::ChannelId id) const { return channels_.count(id) != 0; }

  void submit(tmcl::ChannelId id, const tmcl::Frame& frame);
  size_t queued_requests(tmcl::ChannelId id) const;
  bool has_room(tmcl::ChannelId id) const { return queued_requests(id) < kMaxQueuedRequestsPerChannel; }
  size_t total_queued_requests() const { return queue_.size(); }

  // Serves queued requests in arrival order until the queue is empty or a reply is being held
  // for its telegram pause (the next request waits for it, as on a half-duplex bus).
  void serve_queued();
  // Sends the command 138 replies that have become due. Call after each tick batch.
  void deliver_events() { engine_.collect_events(*this); }

  bool reply_held() const { return held_.has_value(); }
  bool reply_held_for(tmcl::ChannelId id) const { return held_ && held_->channel == id; }
  uint64_t served_request_count() const { return served_request_count_; }

  // tmcl::ReplySink.
  void deliver(tmcl::ChannelId channel, const tmcl::Reply& reply) override;

 private:
  struct QueuedRequest {
    tmcl::ChannelId channel;
    tmcl::Frame frame;
  };
  struct HeldReply {
    tmcl::ChannelId channel;
    tmcl::Frame bytes;
    uint8_t length;
    bool reset_after_send;
    std::vector<tmcl::Frame> events_after;  // command 138 replies that must not overtake it
    EventLoop::TimerId timer;
  };

  void send_to(tmcl::ChannelId channel, const uint8_t* bytes, size_t length);
  void release_held_reply();
  void finish_request(tmcl::ChannelId channel);

  tmcl::TmclEngine& engine_;
  EventLoop& loop_;
  std::map<tmcl::ChannelId, ReplyChannel*> channels_;
  std::map<tmcl::ChannelId, size_t> queued_per_channel_;
  std::deque<QueuedRequest> queue_;
  std::optional<HeldReply> held_;
  tmcl::ChannelId next_channel_id_ = 1;
  uint64_t served_request_count_ = 0;
  bool serving_ = false;
};

}  // namespace motwin::host
