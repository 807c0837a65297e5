#include "core/tmcl/serial_link.h"

namespace motwin::tmcl {
namespace {

void put_value(uint8_t* out, int32_t value) {
  const auto v = static_cast<uint32_t>(value);
  out[0] = static_cast<uint8_t>(v >> 24);
  out[1] = static_cast<uint8_t>(v >> 16);
  out[2] = static_cast<uint8_t>(v >> 8);
  out[3] = static_cast<uint8_t>(v);
}

}  // namespace

Frame encode_request(uint8_t module_address, const Instruction& in) {
  Frame f{module_address, in.command, in.type, in.motor_bank, 0, 0, 0, 0, 0};
  put_value(&f[4], in.value);
  f[8] = checksum(f.data(), 8);
  return f;
}

Instruction decode_instruction(const Frame& f) {
  const uint32_t value = (static_cast<uint32_t>(f[4]) << 24) | (static_cast<uint32_t>(f[5]) << 16) |
                         (static_cast<uint32_t>(f[6]) << 8) | f[7];
  return Instruction{f[1], f[2], f[3], static_cast<int32_t>(value)};
}

Frame encode_reply(uint8_t host_address, uint8_t module_address, const Reply& reply) {
  Frame f{host_address, module_address, reply.status, reply.command, 0, 0, 0, 0, 0};
  put_value(&f[4], reply.value);
  f[8] = checksum(f.data(), 8);
  return f;
}

bool SerialFrameDecoder::push(uint8_t byte, uint64_t now_us) {
  if (fill_ > 0 && now_us - last_byte_us_ > resync_gap_us_) fill_ = 0;
  last_byte_us_ = now_us;
  frame_[fill_++] = byte;
  if (fill_ < kFrameLength) return false;
  fill_ = 0;
  return true;
}

SerialResponse serve_serial_frame(TmclEngine& engine, const Frame& frame, ChannelId channel) {
  TmclDevice& device = engine.device();
  const SerialSettings settings = device.serial_settings();
  SerialResponse response;
  // Several modules share an RS485 bus: a frame for another address is not ours to answer.
  if (frame[0] != settings.module_address) return response;
  response.delay_ms = settings.telegram_pause_ms;
  response.length = kFrameLength;
  if (checksum(frame.data(), 8) != frame[8]) {
    response.bytes = encode_reply(settings.host_address, settings.module_address,
                                  Reply{to_byte(Status::kChecksumError), 0, 0});
    return response;
  }
  const Instruction instruction = decode_instruction(frame);
  const CommandResult result = engine.execute(instruction, Origin::kHost, channel);
  // The addresses may just have been changed by this very command (SGP 66/76): the reply
  // already uses the new ones, as they "take effect at once".
  const SerialSettings now = device.serial_settings();
  switch (result.kind) {
    case ReplyKind::kNone:
      response.length = 0;
      return response;
    case ReplyKind::kVersionString: {
      // Special reply: host address, then the 8 version characters, no checksum.
      response.bytes[0] = now.host_address;
      for (size_t i = 0; i < 8; ++i) response.bytes[1 + i] = static_cast<uint8_t>(device.identity().version_string[i]);
      return response;
    }
    case ReplyKind::kThenReset:
      response.reset_after_send = true;
      break;
    case ReplyKind::kThenAsciiMode:
      response.enter_ascii_mode = true;
      break;
    case ReplyKind::kNormal:
      break;
  }
  const uint8_t reply_command =
      result.reply_command >= 0 ? static_cast<uint8_t>(result.reply_command) : instruction.command;
  response.bytes = encode_reply(now.host_address, now.module_address, Reply{to_byte(result.status), reply_command, result.value});
  return response;
}

Frame encode_event_reply(TmclDevice& device, const Reply& reply) {
  const SerialSettings settings = device.serial_settings();
  return encode_reply(settings.host_address, settings.module_address, reply);
}

}  // namespace motwin::tmcl
