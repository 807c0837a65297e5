// A bus capture (`motwin serve --can-capture FILE`): every frame on the virtual bus, stamped with
// simulated time, as a pcap file with link type 227 (LINKTYPE_CAN_SOCKETCAN: Wireshark and
// `tshark -d "can.subdissector,canopen"` decode it) when FILE ends in .pcap, otherwise as a
// candump log (`candump -L` lines: "(SEC.USEC) can0 601#4000100000000000", replayable with
// canplayer and readable by python-can's CanutilsLogReader). Each frame is flushed as it comes.
#pragma once

#include <cstdint>
#include <cstdio>
#include <memory>
#include <string>

#include "host/can_bus.h"
#include "types/can_frame.h"
#include "types/result.h"

namespace motwin::host {

class CanCapture final : public CanBusEndpoint {
 public:
  enum class Format : uint8_t { kPcap, kCandump };

  // Creates (truncates) `path`; the format follows its extension.
  static Result<std::unique_ptr<CanCapture>> open(const std::string& path);
  ~CanCapture();
  CanCapture(const CanCapture&) = delete;
  CanCapture& operator=(const CanCapture&) = delete;

  void on_frame(const can::CanFrame& frame, uint64_t timestamp_us) override;
  Format format() const { return format_; }
  uint64_t frames() const { return frames_; }

 private:
  CanCapture(std::FILE* file, Format format) : file_(file), format_(format) {}
  std::FILE* file_;
  Format format_;
  uint64_t frames_ = 0;
};

// One `candump -L` line without its newline: "(12.000250) can0 601#4000100000000000",
// "(0.5) can0 12345678#" for an extended ID, "#R" for a remote frame.
std::string format_candump_line(const can::CanFrame& frame, uint64_t timestamp_us, const std::string& channel = "can0");

}  // namespace motwin::host
