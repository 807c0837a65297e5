// A single-threaded poll() loop: file descriptors with callbacks, wall-clock timers and
// deferred work. The host runtime interleaves it with simulation tick batches; nothing in
// Motwin runs on another thread.
#pragma once

#include <cstddef>
#include <cstdint>
#include <functional>
#include <map>
#include <memory>
#include <optional>
#include <utility>
#include <vector>

#include <poll.h>

namespace motwin::host {

// CLOCK_MONOTONIC in microseconds: the wall clock of pacing, timers and resync gaps.
uint64_t monotonic_now_us();

class EventLoop {
 public:
  using FdCallback = std::function<void(short revents)>;
  using TimerCallback = std::function<void()>;
  using TimerId = uint64_t;
  static constexpr uint64_t kWaitForever = UINT64_MAX;

  EventLoop() = default;
  EventLoop(const EventLoop&) = delete;
  EventLoop& operator=(const EventLoop&) = delete;

  // `events` as for poll() (POLLIN, POLLOUT); POLLHUP and POLLERR are always reported.
  // A callback may watch, unwatch or close any descriptor, its own included.
  void watch(int fd, short events, FdCallback callback);
  void set_events(int fd, short events);
  void unwatch(int fd);
  bool watching(int fd) const;
  size_t watch_count() const { return watchers_.size(); }

  TimerId add_timer_at(uint64_t due_wall_us, TimerCallback callback);
  TimerId add_timer_after(uint64_t delay_us, TimerCallback callback) {
    return add_timer_at(monotonic_now_us() + delay_us, std::move(callback));
  }
  void cancel_timer(TimerId id);
  std::optional<uint64_t> next_timer_due_us() const;

  // Runs `work` after the callbacks of the current poll_once() (or at the start of the next):
  // the place to destroy an object whose own callback is running.
  void defer(std::function<void()> work);

  // Waits at most `max_wait_us` for a descriptor event or a due timer, then runs the callbacks
  // of what happened, the due timers and the deferred work. Returns how many callbacks ran.
  size_t poll_once(uint64_t max_wait_us);
  // Descriptor callbacks run so far with input ready (POLLIN): how the host runtime tells that a
  // client has talked to it (a request, a CAN frame, a connection), whatever the protocol.
  uint64_t input_event_count() const { return input_event_count_; }
  // When the loop last saw `fd` quiet: the start of the latest poll_once() that watched it for
  // input (POLLIN) and found none (0: never). Bytes read from it later arrived after that. The
  // resync gaps of TMCL framing count only this silence, so that a stall of the server itself (a
  // loaded machine), with the client's bytes waiting in the kernel, is never taken for a pause
  // of the line.
  uint64_t quiet_seen_us(int fd) const;

  void request_stop() { stop_requested_ = true; }
  bool stop_requested() const { return stop_requested_; }

 private:
  struct Watcher {
    int fd;
    short events;
    FdCallback callback;
    bool active = true;
    uint64_t quiet_seen_us = 0;
  };

  size_t run_deferred();

  std::vector<std::shared_ptr<Watcher>> watchers_;
  std::map<std::pair<uint64_t, TimerId>, TimerCallback> timers_;
  TimerId next_timer_id_ = 1;
  std::vector<std::function<void()>> deferred_;
  std::vector<pollfd> poll_scratch_;
  std::vector<std::shared_ptr<Watcher>> watcher_scratch_;
  bool stop_requested_ = false;
  uint64_t input_event_count_ = 0;
};

}  // namespace motwin::host
