// TMCL on the firmware's serial port: what host::TmclHostService does for one pseudo-terminal or
// TCP connection, for the one UART of a board, without a heap. Binary 9-byte frames with the
// core's framing rules (address filter, checksum, a partial frame dropped after a 5 ms pause:
// tmcl::SerialFrameDecoder), the ASCII interface where the module has it (command 139, BIN,
// GP 67), the telegram pause (GP 75) before a reply, command 138 events, and command 255's
// reset once its reply is sent. One request at a time: while a reply waits for its telegram
// pause, receive() refuses bytes and they wait in the UART's buffer (docs/firmware.md).
#pragma once

#include <cstddef>
#include <cstdint>

#include "core/tmcl/ascii_link.h"
#include "core/tmcl/engine.h"
#include "core/tmcl/serial_link.h"

namespace motwin::firmware {

// Where the link's bytes go: the UART's transmit buffer.
class ByteOutput {
 public:
  virtual void write(const uint8_t* bytes, size_t length) = 0;

 protected:
  ~ByteOutput() = default;
};

class SerialTmclLink final : public tmcl::ReplySink {
 public:
  static constexpr tmcl::ChannelId kChannel = 1;

  SerialTmclLink(tmcl::TmclEngine& engine, ByteOutput& output,
                 uint32_t resync_gap_us = tmcl::SerialFrameDecoder::kDefaultResyncGapUs)
      : engine_(engine), output_(output), decoder_(resync_gap_us) {
    follow_power_up();
  }

  // One received byte, stamped with the time it arrived. False: a reply is waiting for its
  // telegram pause; offer the byte again after poll() released it.
  bool receive(uint8_t byte, uint64_t now_us);
  // Sends a held reply whose pause is over and the engine's command 138 events.
  void poll(uint64_t now_us);

  bool ascii_mode() const { return ascii_mode_; }
  bool holding_reply() const { return held_.pending; }

  // tmcl::ReplySink: a command 138 event, as a frame or, in ASCII mode, a reply line.
  void deliver(tmcl::ChannelId channel, const tmcl::Reply& reply) override;

 private:
  static constexpr size_t kMaxReplyLength =
      tmcl::AsciiResponse::kMaxLength > tmcl::kFrameLength ? tmcl::AsciiResponse::kMaxLength : tmcl::kFrameLength;

  struct HeldReply {
    bool pending = false;
    uint8_t bytes[kMaxReplyLength] = {};
    uint8_t length = 0;
    bool reset_after_send = false;
    bool enter_ascii = false;
    bool leave_ascii = false;
    uint64_t release_us = 0;
  };

  void serve_frame(uint64_t now_us);
  void serve_line(uint64_t now_us);
  void hold_or_send(uint8_t delay_ms, uint64_t now_us);
  void send_held();
  void follow_power_up();
  void set_mode(bool ascii);

  tmcl::TmclEngine& engine_;
  ByteOutput& output_;
  tmcl::SerialFrameDecoder decoder_;
  tmcl::AsciiLink ascii_;
  bool ascii_mode_ = false;
  uint32_t power_ups_seen_ = UINT32_MAX;
  HeldReply held_;
};

}  // namespace motwin::firmware
