#include <gtest/gtest.h>

#include <unistd.h>

#include <string>
#include <vector>

#include "host/event_loop.h"
#include "support/host_test_support.h"

namespace motwin::host {
namespace {

using testing::Pipe;

TEST(EventLoop, timers_fire_in_due_order_and_cancelled_ones_never) {
  EventLoop loop;
  std::vector<std::string> fired;
  const uint64_t now = monotonic_now_us();
  loop.add_timer_at(now + 2, [&] { fired.push_back("second"); });
  loop.add_timer_at(now + 1, [&] { fired.push_back("first"); });
  const EventLoop::TimerId cancelled = loop.add_timer_at(now + 1, [&] { fired.push_back("cancelled"); });
  loop.cancel_timer(cancelled);
  EXPECT_EQ(loop.next_timer_due_us(), now + 1);
  while (fired.size() < 2) loop.poll_once(EventLoop::kWaitForever);  // the timers bound the wait
  EXPECT_EQ(fired, (std::vector<std::string>{"first", "second"}));
  EXPECT_EQ(loop.next_timer_due_us(), std::nullopt);
}

TEST(EventLoop, a_timer_never_fires_before_its_time) {
  EventLoop loop;
  const uint64_t start = monotonic_now_us();
  uint64_t fired_at = 0;
  loop.add_timer_after(20'000, [&] { fired_at = monotonic_now_us(); });
  while (fired_at == 0) loop.poll_once(EventLoop::kWaitForever);
  EXPECT_GE(fired_at - start, 20'000u);
}

TEST(EventLoop, readable_descriptors_run_their_callback) {
  EventLoop loop;
  Pipe pipe;
  std::string received;
  loop.watch(pipe.read_fd, POLLIN, [&](short revents) {
    EXPECT_TRUE(revents & POLLIN);
    char buffer[16];
    const ssize_t n = ::read(pipe.read_fd, buffer, sizeof(buffer));
    received.append(buffer, static_cast<size_t>(n));
  });
  EXPECT_EQ(loop.poll_once(0), 0u);  // nothing to read yet
  ASSERT_EQ(::write(pipe.write_fd, "hi", 2), 2);
  EXPECT_EQ(loop.poll_once(1'000'000), 1u);
  EXPECT_EQ(received, "hi");
  loop.set_events(pipe.read_fd, 0);
  ASSERT_EQ(::write(pipe.write_fd, "x", 1), 1);
  EXPECT_EQ(loop.poll_once(0), 0u);  // not interested in input any more
}

TEST(EventLoop, a_callback_may_unwatch_itself_and_another_descriptor) {
  EventLoop loop;
  Pipe first;
  Pipe second;
  int calls = 0;
  loop.watch(first.read_fd, POLLIN, [&](short) {
    ++calls;
    loop.unwatch(first.read_fd);
    loop.unwatch(second.read_fd);
  });
  loop.watch(second.read_fd, POLLIN, [&](short) { ++calls; });
  ASSERT_EQ(::write(first.write_fd, "a", 1), 1);
  ASSERT_EQ(::write(second.write_fd, "b", 1), 1);
  loop.poll_once(1'000'000);
  EXPECT_EQ(calls, 1);  // the second was unwatched before its turn
  EXPECT_EQ(loop.watch_count(), 0u);
}

TEST(EventLoop, deferred_work_runs_after_the_callbacks) {
  EventLoop loop;
  Pipe pipe;
  std::vector<std::string> order;
  loop.watch(pipe.read_fd, POLLIN, [&](short) {
    loop.defer([&] { order.push_back("deferred"); });
    order.push_back("callback");
    char byte;
    EXPECT_EQ(::read(pipe.read_fd, &byte, 1), 1);
  });
  ASSERT_EQ(::write(pipe.write_fd, "a", 1), 1);
  loop.poll_once(1'000'000);
  EXPECT_EQ(order, (std::vector<std::string>{"callback", "deferred"}));
}

TEST(EventLoop, stop_is_a_flag_the_runner_checks) {
  EventLoop loop;
  EXPECT_FALSE(loop.stop_requested());
  loop.request_stop();
  EXPECT_TRUE(loop.stop_requested());
}

}  // namespace
}  // namespace motwin::host
