// The SLCAN (Lawicel ASCII) protocol of a CAN adapter, as python-can's `interface='slcan'` and
// slcand speak it to a USB-serial dongle: commands and frames end with CR; the adapter answers CR
// (ok) or BEL (error). Pure text handling: SlcanSession turns the host's bytes into replies and
// bus frames, and bus frames into text.
//   O / L      open (L: listen only)           C      close
//   S0..S8     bit rate (closed only)           sXXYY  BTR registers (closed only)
//   tIIILDD..  standard frame                   TIIIIIIIILDD..  extended frame
//   rIIIL      standard RTR                     RIIIIIIIIL      extended RTR
//   V -> V1013 N -> NMOTW   F -> F00   Z0/Z1 (timestamps: accepted, never added)
// A frame is answered `z` / `Z` before the CR (Lawicel "auto poll"), which python-can ignores.
#pragma once

#include <cstdint>
#include <functional>
#include <optional>
#include <string>
#include <string_view>

#include "types/can_frame.h"

namespace motwin::host {

class SlcanSession {
 public:
  static constexpr size_t kMaxLineLength = 64;
  using FrameSink = std::function<void(const can::CanFrame& frame)>;

  explicit SlcanSession(FrameSink to_bus) : to_bus_(std::move(to_bus)) {}

  // Feeds bytes from the host; appends replies to `reply`. LF and NUL are ignored; an overlong
  // line is answered with BEL.
  void push(std::string_view bytes, std::string& reply);
  // Frames go to the host only while the channel is open.
  bool open() const { return open_; }
  bool listen_only() const { return listen_only_; }
  uint8_t bit_rate_code() const { return bit_rate_code_; }

 private:
  void command(std::string_view line, std::string& reply);

  FrameSink to_bus_;
  std::string line_;
  bool overlong_ = false;
  bool open_ = false;
  bool listen_only_ = false;
  uint8_t bit_rate_code_ = 8;  // S8: 1 Mbit/s, the TMCM-3216 default
};

// A frame as the adapter sends it to the host: "t1230\r", "T000001232AABB\r", "r1232\r".
std::string format_slcan_frame(const can::CanFrame& frame);
// "t123..." / "T..." / "r..." / "R..." (without CR) into a frame; nullopt if malformed.
std::optional<can::CanFrame> parse_slcan_frame(std::string_view line);

}  // namespace motwin::host
