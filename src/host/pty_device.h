// A pseudo-terminal in raw mode with a symbolic link to its slave side, for the endpoints that
// look like a serial port (TMCL: pty_endpoint.h, SLCAN: can_device_endpoints.h), and PtyPort,
// its master side on the event loop. The master is
// non-blocking and in packet mode (each read starts with a status byte that reports a client's
// flushes); the slave stays open here so that clients may come and go without hangups.
#pragma once

#include <cstddef>
#include <cstdint>
#include <functional>
#include <string>
#include <vector>

#include "host/eeprom_file.h"
#include "host/event_loop.h"
#include "types/result.h"

namespace motwin::host {

struct PtyDevice {
  int master_fd = -1;
  int slave_fd = -1;
  int link_claim_fd = -1;   // held while the link is ours (claim_pty_link)
  std::string device_path;  // /dev/pts/N
};

// Claims the link name for this process: an abstract Unix socket named after the link's absolute
// path, which the kernel releases when the process ends however it ends (no file to go stale).
// The descriptor to hold, or an error naming the link when another live process holds it.
Result<int> claim_pty_link(const std::string& link_path);

// Creates the pty and the link. A link that another live motwin process owns (claim_pty_link)
// is refused. An existing symbolic link is otherwise replaced when it is stale or points into
// /dev/pts (left by an earlier run, killed perhaps); anything else at `link_path` is an error.
// A failure leaves nothing open.
Result<PtyDevice> open_pty_device(const std::string& link_path);

// Removes the link if it still points to `device_path` (another instance may own it now).
void remove_pty_link(const std::string& link_path, const std::string& device_path);


// A pty's master side on the event loop, shared by the TMCL and SLCAN pty endpoints: reads data
// (at most what the endpoint takes: back-pressure), reports a client's flushes, keeps a bounded
// output buffer (beyond it output is dropped, as on a serial line nobody listens to, and logged
// once), and pauses reading for a moment on an unexpected hangup instead of spinning.
class PtyPort {
 public:
  struct Handlers {
    std::function<size_t()> read_budget;                         // 0: do not read now
    std::function<void(const uint8_t* bytes, size_t length)> on_data;
    // The client flushed its input (drop what waits for it: done here) and/or its output.
    std::function<void(bool flushed_output)> on_flush;
  };

  // Takes over the descriptors of `device`; the link is removed and both closed at destruction.
  PtyPort(EventLoop& loop, const PtyDevice& device, std::string link_path, size_t max_pending_output_bytes,
          LogSink log, Handlers handlers);
  PtyPort(const PtyPort&) = delete;
  PtyPort& operator=(const PtyPort&) = delete;
  ~PtyPort();

  const std::string& link_path() const { return link_path_; }
  const std::string& device_path() const { return device_path_; }
  // When the loop last saw the pty without input (EventLoop::quiet_seen_us).
  uint64_t quiet_seen_us() const { return loop_.quiet_seen_us(master_fd_); }
  // Queues bytes for the client; false when they were dropped (nobody reads).
  bool write(const uint8_t* bytes, size_t length);
  // Re-reads the read budget and the output state into the poll events.
  void update_events();

 private:
  void on_events(short revents);
  void read_some();
  void flush();
  // After a client's input flush: what we wrote since it began is old too (pty_device.cpp).
  void discard_written_output();

  EventLoop& loop_;
  int master_fd_;
  int slave_fd_;
  int link_claim_fd_;
  std::string link_path_;
  std::string device_path_;
  size_t max_pending_output_bytes_;
  LogSink log_;
  Handlers handlers_;
  std::vector<uint8_t> output_;
  bool input_suspended_ = false;
  bool reported_dropped_output_ = false;
};

}  // namespace motwin::host
