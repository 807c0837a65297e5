// Serves TMCL from every host connection (TCP clients, the pseudo-terminal) to one module, the
// way a module on a serial bus does: one request at a time, each reply to the connection that
// asked, the telegram pause (GP 75) before a reply without blocking the loop, and the delayed
// replies of command 138 to the connection that asked. Each connection's requests are served in
// its order; connections with requests waiting take turns, one request each (round robin), so a
// client flooding frames delays another client's request by at most one of its own, not by its
// whole queue (docs/host-runtime.md, "Serving order").
//
// Each connection is a link of its own, in binary mode (9-byte frames) or ASCII mode (text
// lines, core/tmcl/ascii_link.h): command 139 switches it to ASCII once its binary reply is
// out, the line BIN back to binary once its reply is out. Bytes that arrive while such a switch
// may be pending (after a 139 frame, after each ASCII line until it is answered) wait here and
// are read in the mode that follows. Every connection starts in the mode GP 67 bit 0 says, and
// returns to it whenever the module powers up (255, 137).
#pragma once

#include <cstddef>
#include <cstdint>
#include <deque>
#include <map>
#include <optional>
#include <string>
#include <vector>

#include "core/tmcl/ascii_link.h"
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

enum class LinkMode : uint8_t { kBinary, kAscii };

// Whether a channel's served requests count as a host talking (served_host_request_count(): the
// host runtime's busy-poll window after a request). A host over TCP or a pty sends its next
// request within microseconds of a reply; the web console's reads of subscribed values come at
// their period, and a page's own requests already arrive as input on a descriptor.
enum class ChannelTraffic : uint8_t { kHost, kBackground };

// What the host hears of its own bytes. On RS485 the transceiver's receiver stays on while the
// host transmits, so every byte the host sends comes straight back to it, ahead of any reply;
// Zephyr's TMCM RS485 bus driver waits for each byte's echo before it sends the next. The
// transceiver knows nothing of TMCL: garbage and ASCII lines come back too.
enum class LineEcho : uint8_t { kNone, kTransceiver };

class TmclHostService final : public tmcl::ReplySink {
 public:
  // A connection with this many requests waiting stops being read until some are served, so
  // that a client flooding frames gets TCP back-pressure instead of growing our memory.
  static constexpr size_t kMaxQueuedRequestsPerChannel = 32;
  // Received bytes not yet read as frames or lines (waiting for a reply that may switch the
  // link's mode); a connection with this many is not read until they are.
  static constexpr size_t kMaxPendingInputBytes = 4096;
  // The least resync gap of a channel with LineEcho::kTransceiver. A host that waits for each
  // byte's echo before it sends the next puts a round trip through the transport and two
  // schedulers into every gap between its bytes: on a loaded machine more than a serial line's
  // 5 ms, and more than 200 ms has been seen (docs/host-runtime.md, "RS485 echo"). 1 s is the
  // longest Zephyr's driver waits for a byte (of a reply); a host that gives up on a frame
  // pauses that long before its next one is read afresh.
  static constexpr uint32_t kEchoResyncGapUs = 1'000'000;

  TmclHostService(tmcl::TmclEngine& engine, EventLoop& loop);
  TmclHostService(const TmclHostService&) = delete;
  TmclHostService& operator=(const TmclHostService&) = delete;
  ~TmclHostService();

  // Never returns 0 (channel 0 is what the engine uses for a stored program). `resync_gap_us`:
  // a pause this long between two bytes discards a partial binary frame. `echo`: whether the
  // bytes the channel receives go back to it at once (an RS485 transceiver, LineEcho); with the
  // echo the gap is at least kEchoResyncGapUs.
  tmcl::ChannelId open_channel(ReplyChannel& channel,
                               uint32_t resync_gap_us = tmcl::SerialFrameDecoder::kDefaultResyncGapUs,
                               ChannelTraffic traffic = ChannelTraffic::kHost, LineEcho echo = LineEcho::kNone);
  // Requests already queued from this channel still run (their bytes arrived, as on a serial
  // line); their replies and any pending command 138 events of the channel are dropped.
  void close_channel(tmcl::ChannelId id);
  bool is_open(tmcl::ChannelId id) const { return channels_.count(id) != 0; }

  // A channel of a link that frames its own requests (TMCL over CAN, host/tmcl_can_node.h) and
  // only needs its command 138 replies routed back to `sink`. Never returns 0.
  tmcl::ChannelId open_event_channel(tmcl::ReplySink& sink);
  void close_event_channel(tmcl::ChannelId id);

  // Bytes a connection received, in arrival order; at most input_room(id) of them. On a channel
  // with LineEcho::kTransceiver they go back to it first, all of them, before anything they
  // cause. Complete frames and lines become requests; the echo of ASCII mode goes out at once. `now_us`: when
  // they were read; `quiet_seen_us`: when the loop last saw the connection quiet before them
  // (EventLoop::quiet_seen_us). Only that silence counts towards the resync gap of binary
  // framing; without it the whole time since the previous bytes does.
  void receive(tmcl::ChannelId id, const uint8_t* bytes, size_t length, uint64_t now_us,
               std::optional<uint64_t> quiet_seen_us = std::nullopt);
  // How many bytes the connection may hand to receive() now; 0: stop reading (back-pressure).
  size_t input_room(tmcl::ChannelId id) const;
  bool has_room(tmcl::ChannelId id) const { return input_room(id) > 0; }
  // The host discarded what it was sending (a pty client flushed its output): a partial frame
  // or line is dropped.
  void discard_partial_input(tmcl::ChannelId id);
  std::optional<LinkMode> link_mode(tmcl::ChannelId id) const;

  size_t queued_requests(tmcl::ChannelId id) const;
  size_t total_queued_requests() const { return total_queued_; }

  // Serves one round: one request of each connection that has requests waiting (connections in
  // turn), stopping early when a reply is being held for its telegram pause (the next request
  // waits for it, as on a half-duplex bus). The caller polls its descriptors between rounds, so
  // that a request arriving during a flood joins the next round instead of waiting for every
  // request queued before it (docs/host-runtime.md, "Serving order").
  void serve_queued();
  // Sends the command 138 replies that have become due. Call after each tick batch. Also
  // notices a power-up that another link caused (255 over CAN), so every link returns to its
  // start mode.
  void deliver_events() {
    follow_power_ups();
    engine_.collect_events(*this);
  }

  bool reply_held() const { return held_.has_value(); }
  bool reply_held_for(tmcl::ChannelId id) const { return held_ && held_->channel == id; }
  uint64_t served_request_count() const { return served_request_count_; }
  // Served requests of kHost channels only.
  uint64_t served_host_request_count() const { return served_host_request_count_; }

  // tmcl::ReplySink.
  void deliver(tmcl::ChannelId channel, const tmcl::Reply& reply) override;

 private:
  struct PendingByte {
    uint8_t byte;
    uint64_t arrival_us;  // on the channel's line clock: for the resynchronisation gap of binary framing
  };
  struct Channel {
    ReplyChannel* sink = nullptr;
    LinkMode mode = LinkMode::kBinary;
    ChannelTraffic traffic = ChannelTraffic::kHost;
    LineEcho echo = LineEcho::kNone;
    tmcl::SerialFrameDecoder decoder;
    tmcl::AsciiLink ascii;
    std::deque<PendingByte> input;
    // A 139 frame or an ASCII line is queued or being answered: its reply may switch the mode,
    // so the bytes after it wait in `input`.
    bool awaiting_reply = false;
    // The line clock advances by the silence seen between two receive() calls, not by the
    // server's own stalls (see receive()).
    uint64_t line_clock_us = 0;
    uint64_t last_receive_us = 0;
  };
  struct QueuedRequest {
    tmcl::ChannelId channel;
    bool ascii;                 // which of the two below
    tmcl::Frame frame;
    tmcl::AsciiCommand command;
  };
  // A reply ready to go, and what follows once it is sent.
  struct Outgoing {
    std::vector<uint8_t> bytes;
    bool reset_after_send = false;
    std::optional<LinkMode> mode_after;
  };
  struct HeldReply {
    tmcl::ChannelId channel;
    Outgoing reply;
    std::vector<std::vector<uint8_t>> events_after;  // command 138 replies that must not overtake it
    EventLoop::TimerId timer;
  };

  void enqueue(tmcl::ChannelId id, QueuedRequest request);
  // Reads the channel's waiting input as frames or lines until it runs out, a reply must be
  // awaited, or the request queue is full.
  void process_input(tmcl::ChannelId id);
  void send_to(tmcl::ChannelId channel, const uint8_t* bytes, size_t length);
  void complete(tmcl::ChannelId channel, const Outgoing& reply);
  void release_held_reply();
  void finish_request(tmcl::ChannelId channel);
  void set_mode(Channel& channel, LinkMode mode);
  // After a power-up every link returns to its start mode (GP 67 bit 0).
  void follow_power_ups();
  LinkMode start_mode() const;
  std::vector<uint8_t> encode_event(LinkMode mode, const tmcl::Reply& reply) const;

  tmcl::TmclEngine& engine_;
  EventLoop& loop_;
  std::map<tmcl::ChannelId, Channel> channels_;
  std::map<tmcl::ChannelId, tmcl::ReplySink*> event_channels_;
  // Each connection's waiting requests, and the connections that have some, in the order of
  // their next turn.
  std::map<tmcl::ChannelId, std::deque<QueuedRequest>> queues_;
  std::deque<tmcl::ChannelId> turns_;
  size_t total_queued_ = 0;
  std::optional<HeldReply> held_;
  tmcl::ChannelId next_channel_id_ = 1;
  uint64_t served_request_count_ = 0;
  uint64_t served_host_request_count_ = 0;
  uint32_t power_ups_seen_ = 0;
  bool serving_ = false;
};

}  // namespace motwin::host
