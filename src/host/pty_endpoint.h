// TMCL over a pseudo-terminal, for host software that expects a serial port (pyserial,
// TMCL-IDE under Wine, terminal programs): `motwin serve --tmcl-pty /tmp/tmcm1636` creates a
// pty and a symbolic link to its slave side (/dev/pts/N).
//
// The endpoint keeps a descriptor of the slave open itself, so that clients may open and close
// the device as often as they like: without it the master reports a hangup (POLLHUP, EIO)
// whenever no client has the slave open, and a poll() loop would spin on it. The slave is in
// raw mode; the baud rate a client sets (and GP 65) has no effect on a pty. The master is in
// packet mode so that a client flushing its input (pyserial does on open) also discards the
// replies still waiting here: a new client never receives an old client's replies. Frames are
// decoded with serial timing (5 ms resync gap); command 139 switches the link to ASCII lines
// (TmclHostService).
#pragma once

#include <cstddef>
#include <cstdint>
#include <memory>
#include <string>
#include <vector>

#include "core/tmcl/serial_link.h"
#include "host/eeprom_file.h"
#include "host/pty_device.h"
#include "host/event_loop.h"
#include "host/tmcl_host_service.h"
#include "types/result.h"

namespace motwin::host {

class TmclPtyEndpoint final : public ReplyChannel {
 public:
  // Replies nobody reads pile up in the pty, then here; beyond this they are dropped (a serial
  // line with no listener loses them too), and a client's input flush drops them all.
  static constexpr size_t kMaxPendingOutputBytes = 64 * 1024;

  // Creates the pty and the link. An existing symbolic link is replaced when it is stale or
  // points into /dev/pts (left by an earlier run); anything else at `link_path` is an error.
  // `echo`: the client's bytes go back to it as they arrive (an RS485 transceiver, LineEcho).
  static Result<std::unique_ptr<TmclPtyEndpoint>> open(EventLoop& loop, TmclHostService& service,
                                                       const std::string& link_path, LogSink log = log_to_stderr,
                                                       LineEcho echo = LineEcho::kNone);

  TmclPtyEndpoint(const TmclPtyEndpoint&) = delete;
  TmclPtyEndpoint& operator=(const TmclPtyEndpoint&) = delete;
  // Removes the link (if it still points to our pty) and closes the pty.
  ~TmclPtyEndpoint();

  const std::string& link_path() const { return port_->link_path(); }
  const std::string& device_path() const { return port_->device_path(); }
  tmcl::ChannelId channel() const { return channel_; }
  LineEcho echo() const { return echo_; }

  // ReplyChannel.
  void send_reply(const uint8_t* bytes, size_t length) override;
  void on_request_served() override { port_->update_events(); }

 private:
  TmclPtyEndpoint(EventLoop& loop, TmclHostService& service, const PtyDevice& device, std::string link_path,
                  LogSink log, LineEcho echo);

  TmclHostService& service_;
  LineEcho echo_;
  tmcl::ChannelId channel_ = 0;
  std::unique_ptr<PtyPort> port_;
};

}  // namespace motwin::host
