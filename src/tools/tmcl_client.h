// A blocking TMCL host: sends one 9-byte request frame and reads its reply, over TCP (as
// PyTrinamic's socket interface does) or a serial device / pseudo-terminal (raw, 115200 bit/s).
// One request at a time, as the manual requires ("do not send the next command before having
// received the reply", 2.2).
#pragma once

#include <chrono>
#include <cstdint>
#include <string>
#include <string_view>

#include "core/tmcl/instruction.h"
#include "core/tmcl/serial_link.h"
#include "tools/unique_fd.h"
#include "types/result.h"

namespace motwin::tools {

inline constexpr std::chrono::milliseconds kDefaultReplyTimeout{1000};
inline constexpr uint8_t kDefaultModuleAddress = 1;  // docs/decisions.md "Errata in the manuals": module 1, host 2

enum class ReplyKind : uint8_t {
  kNormal,
  kVersionString,  // command 136 type 0: host address + 8 ASCII characters, no checksum
  kNone,           // command 137 sends no reply
};

struct TmclReply {
  ReplyKind kind = ReplyKind::kNormal;
  uint8_t host_address = 0;
  uint8_t module_address = 0;  // 0 for kVersionString and kNone: those carry no module address
  // kVersionString and kNone carry no status either; they count as 100 (ok), as a module that
  // answered (or, for 137, accepted the frame) did what was asked.
  uint8_t status = 100;
  uint8_t command = 0;
  int32_t value = 0;
  std::string version_string;  // kVersionString only
};

// What a request's reply looks like (docs/tmcl-protocol.md "Firmware version", "Control commands").
ReplyKind expected_reply_kind(const tmcl::Instruction& request);

// Checks and decodes the reply bytes to `request`: checksum, and that a normal reply answers
// the request's command (a checksum-error reply, status 1, carries command 0; a successful
// reply to 134 carries the opcode of the instruction read from program memory).
Result<TmclReply> decode_reply(const tmcl::Frame& bytes, const tmcl::Instruction& request);

// "02 01 64 06 00 00 00 2A 91".
std::string hex_bytes(const uint8_t* bytes, size_t length);

// A blocking TCP socket connected to `host_and_port` ("127.0.0.1:5000", "[::1]:5000"), with
// TCP_NODELAY (small requests leave at once); an unreachable address fails within the timeout.
Result<UniqueFd> connect_tcp_socket(std::string_view host_and_port, std::chrono::milliseconds connect_timeout);

class TmclClient {
 public:
  // `host_and_port`: "127.0.0.1:5000", "localhost:5000" or "[::1]:5000".
  static Result<TmclClient> connect_tcp(std::string_view host_and_port,
                                        std::chrono::milliseconds connect_timeout = kDefaultReplyTimeout);
  // A serial device or the pseudo-terminal of `motwin serve`, switched to raw 8N1 at 115200.
  static Result<TmclClient> open_serial(const std::string& device_path);

  void set_reply_timeout(std::chrono::milliseconds timeout) { reply_timeout_ = timeout; }
  // "tcp 127.0.0.1:5000" or "serial /dev/pts/3", for messages.
  const std::string& peer_name() const { return peer_name_; }

  // Sends `request` to `module_address` and waits up to the reply timeout for the answer.
  Result<TmclReply> request(const tmcl::Instruction& request, uint8_t module_address = kDefaultModuleAddress);

 private:
  TmclClient(UniqueFd fd, bool is_socket, std::string peer_name)
      : fd_(std::move(fd)), is_socket_(is_socket), peer_name_(std::move(peer_name)) {}

  Result<tmcl::Frame> exchange(const tmcl::Frame& request_bytes, size_t reply_length);
  void discard_stale_input();

  UniqueFd fd_;
  bool is_socket_ = false;
  std::string peer_name_;
  std::chrono::milliseconds reply_timeout_ = kDefaultReplyTimeout;
  // After a timeout or a bad reply, a late reply may still arrive; drop it before the next
  // request so that replies and requests stay paired.
  bool stale_input_possible_ = false;
};

}  // namespace motwin::tools
