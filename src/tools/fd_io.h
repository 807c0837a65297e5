// Blocking reads and writes on a file descriptor (socket, pseudo-terminal, pipe) with a
// deadline, retried across EINTR and short transfers. Shared by the TMCL client, the loopback
// frame server and the child-process helper.
#pragma once

#include <chrono>
#include <cstddef>
#include <cstdint>

namespace motwin::tools {

using SteadyClock = std::chrono::steady_clock;

enum class IoStatus : uint8_t {
  kOk,
  kTimeout,  // the deadline passed first
  kClosed,   // end of file / peer closed the connection
  kError,    // see error_number
};

struct IoResult {
  IoStatus status = IoStatus::kOk;
  size_t transferred = 0;  // bytes moved before the status was reached
  int error_number = 0;
};

// Waits for readability with poll(); `deadline` = time_point::max() waits forever.
IoResult read_exact(int fd, uint8_t* out, size_t length, SteadyClock::time_point deadline);

// Sockets are written with MSG_NOSIGNAL so that a closed peer is an error, not SIGPIPE.
IoResult write_all(int fd, const uint8_t* bytes, size_t length, bool is_socket);

// Reads and drops whatever is readable right now without waiting.
void discard_readable_bytes(int fd);

// Milliseconds from now until `deadline` for poll(): -1 = forever, 0 when passed.
int poll_timeout_ms(SteadyClock::time_point deadline);

}  // namespace motwin::tools
