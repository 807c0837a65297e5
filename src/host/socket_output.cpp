#include "host/socket_output.h"

#include <cerrno>
#include <cstring>

#include <sys/socket.h>

namespace motwin::host {
namespace {

// Sent bytes are dropped from the front once this much has piled up, so a slow reader costs one
// move per 64 KiB rather than one per send.
constexpr size_t kCompactBytes = 64 * 1024;

}  // namespace

void SocketOutput::append(const void* bytes, size_t length) {
  const auto* first = static_cast<const uint8_t*>(bytes);
  bytes_.insert(bytes_.end(), first, first + length);
}

SocketOutput::Sent SocketOutput::send_to(int fd, std::string* error) {
  Sent result = Sent::kAll;
  while (sent_ < bytes_.size()) {
    const ssize_t n = ::send(fd, bytes_.data() + sent_, bytes_.size() - sent_, MSG_NOSIGNAL | MSG_DONTWAIT);
    if (n > 0) {
      sent_ += static_cast<size_t>(n);
    } else if (n < 0 && errno == EINTR) {
      continue;
    } else if (n < 0 && (errno == EAGAIN || errno == EWOULDBLOCK)) {
      result = Sent::kSocketFull;
      break;
    } else {
      if (error != nullptr) *error = n < 0 ? std::strerror(errno) : "send failed";
      return Sent::kFailed;
    }
  }
  if (sent_ == bytes_.size()) {
    clear();
  } else if (sent_ > kCompactBytes) {
    bytes_.erase(bytes_.begin(), bytes_.begin() + static_cast<std::ptrdiff_t>(sent_));
    sent_ = 0;
  }
  return result;
}

void SocketOutput::clear() {
  bytes_.clear();
  sent_ = 0;
}

}  // namespace motwin::host
