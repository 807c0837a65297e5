#include "tools/fd_io.h"

#include <poll.h>
#include <sys/socket.h>
#include <unistd.h>

#include <cerrno>
#include <limits>

namespace motwin::tools {

int poll_timeout_ms(SteadyClock::time_point deadline) {
  if (deadline == SteadyClock::time_point::max()) return -1;
  const auto now = SteadyClock::now();
  if (deadline <= now) return 0;
  // Round up so that a wait never ends just before the deadline and spins.
  const auto remaining_ms = std::chrono::ceil<std::chrono::milliseconds>(deadline - now).count();
  return remaining_ms > std::numeric_limits<int>::max() ? std::numeric_limits<int>::max()
                                                        : static_cast<int>(remaining_ms);
}

IoResult read_exact(int fd, uint8_t* out, size_t length, SteadyClock::time_point deadline) {
  IoResult result;
  while (result.transferred < length) {
    pollfd poll_entry{fd, POLLIN, 0};
    const int ready = ::poll(&poll_entry, 1, poll_timeout_ms(deadline));
    if (ready < 0) {
      if (errno == EINTR) continue;
      return {IoStatus::kError, result.transferred, errno};
    }
    if (ready == 0) return {IoStatus::kTimeout, result.transferred, 0};
    const ssize_t n = ::read(fd, out + result.transferred, length - result.transferred);
    if (n < 0) {
      if (errno == EINTR || errno == EAGAIN) continue;
      // A pseudo-terminal whose other side closed reads EIO.
      if (errno == EIO) return {IoStatus::kClosed, result.transferred, errno};
      return {IoStatus::kError, result.transferred, errno};
    }
    if (n == 0) return {IoStatus::kClosed, result.transferred, 0};
    result.transferred += static_cast<size_t>(n);
  }
  return result;
}

IoResult write_all(int fd, const uint8_t* bytes, size_t length, bool is_socket) {
  IoResult result;
  while (result.transferred < length) {
    const size_t left = length - result.transferred;
    const ssize_t n = is_socket ? ::send(fd, bytes + result.transferred, left, MSG_NOSIGNAL)
                                : ::write(fd, bytes + result.transferred, left);
    if (n < 0) {
      if (errno == EINTR) continue;
      if (errno == EPIPE || errno == ECONNRESET) return {IoStatus::kClosed, result.transferred, errno};
      return {IoStatus::kError, result.transferred, errno};
    }
    result.transferred += static_cast<size_t>(n);
  }
  return result;
}

void discard_readable_bytes(int fd) {
  uint8_t scratch[256];
  for (;;) {
    pollfd poll_entry{fd, POLLIN, 0};
    if (::poll(&poll_entry, 1, 0) <= 0 || (poll_entry.revents & POLLIN) == 0) return;
    if (::read(fd, scratch, sizeof scratch) <= 0) return;
  }
}

}  // namespace motwin::tools
