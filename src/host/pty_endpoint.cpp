#include "host/pty_endpoint.h"

namespace motwin::host {

Result<std::unique_ptr<TmclPtyEndpoint>> TmclPtyEndpoint::open(EventLoop& loop, TmclHostService& service,
                                                               const std::string& link_path, LogSink log,
                                                               LineEcho echo) {
  const Result<PtyDevice> pty = open_pty_device(link_path);
  if (!pty) return Error{pty.error()};
  return std::unique_ptr<TmclPtyEndpoint>(new TmclPtyEndpoint(loop, service, *pty, link_path, std::move(log), echo));
}

TmclPtyEndpoint::TmclPtyEndpoint(EventLoop& loop, TmclHostService& service, const PtyDevice& device,
                                 std::string link_path, LogSink log, LineEcho echo)
    : service_(service), echo_(echo) {
  channel_ = service_.open_channel(*this, tmcl::SerialFrameDecoder::kDefaultResyncGapUs, ChannelTraffic::kHost, echo);
  PtyPort::Handlers handlers;
  handlers.read_budget = [this] { return service_.input_room(channel_); };
  // Frames or ASCII lines, whichever mode the link is in (the echo comes back through send_reply).
  handlers.on_data = [this](const uint8_t* bytes, size_t length) {
    service_.receive(channel_, bytes, length, monotonic_now_us(), port_->quiet_seen_us());
  };
  // The client discarded what it was sending: a partial frame or line goes too.
  handlers.on_flush = [this](bool flushed_output) {
    if (flushed_output) service_.discard_partial_input(channel_);
  };
  port_ = std::make_unique<PtyPort>(loop, device, std::move(link_path), kMaxPendingOutputBytes, std::move(log),
                                    std::move(handlers));
}

TmclPtyEndpoint::~TmclPtyEndpoint() {
  port_.reset();
  service_.close_channel(channel_);
}

void TmclPtyEndpoint::send_reply(const uint8_t* bytes, size_t length) { port_->write(bytes, length); }

}  // namespace motwin::host
