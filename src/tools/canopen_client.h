// A small CANopen master for the command line (`motwin sdo`, `motwin nmt`): a blocking
// socketcand client (the same protocol python-can speaks, host/socketcand_server.h) and an SDO
// client doing expedited and segmented transfers with raw frames.
#pragma once

#include <cstdint>
#include <memory>
#include <optional>
#include <span>
#include <string>
#include <vector>

#include "types/can_frame.h"
#include "types/result.h"

namespace motwin::tools {

struct ReceivedFrame {
  can::CanFrame frame;
  uint64_t timestamp_us = 0;  // the server's stamp (Motwin: simulated time)
};

class SocketcandClient {
 public:
  // Connects, waits for `< hi >`, opens `channel` and enters raw mode.
  static Result<std::unique_ptr<SocketcandClient>> connect(const std::string& host, uint16_t port,
                                                           int timeout_ms = 2000, const std::string& channel = "can0");
  ~SocketcandClient();
  SocketcandClient(const SocketcandClient&) = delete;
  SocketcandClient& operator=(const SocketcandClient&) = delete;

  // Fails with "cannot send to the socketcand server" when the connection refuses the frame.
  Result<void> send(const can::CanFrame& frame);
  // Several frames in one write (a master's round of SYNC and PDOs).
  Result<void> send(std::span<const can::CanFrame> frames);
  // The next frame from the bus, or nullopt after `timeout_ms`.
  std::optional<can::CanFrame> receive(int timeout_ms);
  std::optional<ReceivedFrame> receive_stamped(int timeout_ms);
  // false once the server closed the connection.
  bool connected() const { return !closed_; }

 private:
  explicit SocketcandClient(int fd) : fd_(fd) {}
  // The next `< ... >` element's inner text, or nullopt after `timeout_ms`.
  std::optional<std::string> element(int timeout_ms);

  int fd_;
  std::string buffer_;
  bool closed_ = false;
};

// Not a Result: a server's abort code is an answer the caller reports as such (its own exit
// status), not a failure of the transfer.
struct SdoResult {
  bool ok = false;
  uint32_t abort_code = 0;     // set when the server aborted
  std::string error;           // set on a timeout or a protocol error (no abort code)
  std::vector<uint8_t> data;   // upload
};

SdoResult sdo_upload(SocketcandClient& bus, uint8_t node, uint16_t index, uint8_t sub, int timeout_ms = 1000);
SdoResult sdo_download(SocketcandClient& bus, uint8_t node, uint16_t index, uint8_t sub,
                       const std::vector<uint8_t>& data, int timeout_ms = 1000);

}  // namespace motwin::tools
