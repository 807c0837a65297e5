// What a non-blocking stream socket still has to send: bytes appended at the back, sent from the
// front as the socket takes them. Shared by the TCP servers' connections and the socketcand
// client, so that partial sends, EINTR and a full socket are handled in one place.
#pragma once

#include <cstddef>
#include <cstdint>
#include <string>
#include <string_view>
#include <vector>

namespace motwin::host {

class SocketOutput {
 public:
  enum class Sent {
    kAll,         // nothing left to send
    kSocketFull,  // the socket took what it could; wait for POLLOUT
    kFailed,      // the connection is broken; `error` says why
  };

  void append(const void* bytes, size_t length);
  void append(std::string_view text) { append(text.data(), text.size()); }

  // Sends what the socket takes now (MSG_DONTWAIT, no SIGPIPE).
  Sent send_to(int fd, std::string* error);

  size_t pending() const { return bytes_.size() - sent_; }
  bool empty() const { return pending() == 0; }
  void clear();

 private:
  std::vector<uint8_t> bytes_;
  size_t sent_ = 0;
};

}  // namespace motwin::host
