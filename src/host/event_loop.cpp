#include "host/event_loop.h"

#include <algorithm>
#include <cerrno>
#include <ctime>

namespace motwin::host {

uint64_t monotonic_now_us() {
  timespec now{};
  ::clock_gettime(CLOCK_MONOTONIC, &now);
  return static_cast<uint64_t>(now.tv_sec) * 1'000'000u + static_cast<uint64_t>(now.tv_nsec) / 1000u;
}

void EventLoop::watch(int fd, short events, FdCallback callback) {
  unwatch(fd);
  watchers_.push_back(std::make_shared<Watcher>(Watcher{fd, events, std::move(callback)}));
}

void EventLoop::set_events(int fd, short events) {
  for (auto& watcher : watchers_) {
    if (watcher->fd == fd) watcher->events = events;
  }
}

void EventLoop::unwatch(int fd) {
  for (auto& watcher : watchers_) {
    if (watcher->fd == fd) watcher->active = false;  // a snapshot in poll_once may still hold it
  }
  std::erase_if(watchers_, [fd](const auto& watcher) { return watcher->fd == fd; });
}

uint64_t EventLoop::quiet_seen_us(int fd) const {
  for (const auto& watcher : watchers_) {
    if (watcher->fd == fd) return watcher->quiet_seen_us;
  }
  return 0;
}

bool EventLoop::watching(int fd) const {
  return std::any_of(watchers_.begin(), watchers_.end(), [fd](const auto& watcher) { return watcher->fd == fd; });
}

EventLoop::TimerId EventLoop::add_timer_at(uint64_t due_wall_us, TimerCallback callback) {
  const TimerId id = next_timer_id_++;
  timers_.emplace(std::make_pair(due_wall_us, id), std::move(callback));
  return id;
}

void EventLoop::cancel_timer(TimerId id) {
  std::erase_if(timers_, [id](const auto& entry) { return entry.first.second == id; });
}

std::optional<uint64_t> EventLoop::next_timer_due_us() const {
  if (timers_.empty()) return std::nullopt;
  return timers_.begin()->first.first;
}

void EventLoop::defer(std::function<void()> work) { deferred_.push_back(std::move(work)); }

size_t EventLoop::run_deferred() {
  size_t ran = 0;
  // Work deferred by deferred work runs in the same call; each round is taken whole.
  while (!deferred_.empty()) {
    std::vector<std::function<void()>> round;
    round.swap(deferred_);
    for (auto& work : round) {
      work();
      ++ran;
    }
  }
  return ran;
}

size_t EventLoop::poll_once(uint64_t max_wait_us) {
  size_t ran = run_deferred();
  uint64_t wait_us = ran > 0 ? 0 : max_wait_us;
  if (!timers_.empty()) {
    const uint64_t now_us = monotonic_now_us();
    const uint64_t due_us = timers_.begin()->first.first;
    wait_us = std::min(wait_us, due_us > now_us ? due_us - now_us : 0);
  }

  poll_scratch_.clear();
  watcher_scratch_.clear();
  for (const auto& watcher : watchers_) {
    poll_scratch_.push_back(pollfd{watcher->fd, watcher->events, 0});
    watcher_scratch_.push_back(watcher);
  }
  // Input that arrived before this moment is reported by this poll: a descriptor without POLLIN
  // was quiet then.
  const uint64_t poll_start_us = monotonic_now_us();
  timespec timeout{};
  timeout.tv_sec = static_cast<time_t>(wait_us / 1'000'000u);
  timeout.tv_nsec = static_cast<long>((wait_us % 1'000'000u) * 1000u);
  const int ready = ::ppoll(poll_scratch_.data(), poll_scratch_.size(), wait_us == kWaitForever ? nullptr : &timeout,
                            nullptr);
  if (ready >= 0) {
    for (size_t i = 0; i < poll_scratch_.size(); ++i) {
      const short revents = poll_scratch_[i].revents;
      // The shared_ptr copy keeps the callback alive even if it unwatches itself.
      const std::shared_ptr<Watcher> watcher = watcher_scratch_[i];
      if ((poll_scratch_[i].events & POLLIN) != 0 && (revents & POLLIN) == 0) watcher->quiet_seen_us = poll_start_us;
      if (revents == 0 || !watcher->active) continue;
      if ((revents & POLLIN) != 0) ++input_event_count_;
      watcher->callback(revents);
      ++ran;
    }
  }
  // ready < 0 is EINTR (a signal): fall through to timers like a timeout.
  watcher_scratch_.clear();

  // Timers added by a timer callback wait for the next call, so a callback re-arming itself
  // with no delay cannot starve the descriptors.
  const uint64_t now_us = monotonic_now_us();
  std::vector<std::pair<uint64_t, TimerId>> due;
  for (const auto& entry : timers_) {
    if (entry.first.first > now_us) break;
    due.push_back(entry.first);
  }
  for (const auto& key : due) {
    const auto found = timers_.find(key);
    if (found == timers_.end()) continue;  // cancelled by an earlier callback
    TimerCallback callback = std::move(found->second);
    timers_.erase(found);
    callback();
    ++ran;
  }
  return ran + run_deferred();
}

}  // namespace motwin::host
