#include "core/tmcl/can_link.h"

#include "core/tmcl/serial_link.h"

namespace motwin::tmcl {
namespace {

// The CAN data are the serial frame without its first byte (address) and its checksum: the
// serial link's encoders do the packing.
void copy_frame_body(const Frame& serial_reply, uint8_t* data) {
  for (size_t i = 0; i < kCanRequestLength; ++i) data[i] = serial_reply[1 + i];
}

}  // namespace

bool read_can_settings(TmclDevice& device, CanSettings& settings) {
  int32_t receive_id = 0;
  int32_t send_id = 0;
  if (device.get_global_parameter(can_parameter::kReceiveId, 0, receive_id) != Status::kOk ||
      device.get_global_parameter(can_parameter::kSendId, 0, send_id) != Status::kOk) {
    return false;
  }
  int32_t bit_rate_code = 8;
  if (device.get_global_parameter(can_parameter::kBitRate, 0, bit_rate_code) != Status::kOk) bit_rate_code = 8;
  settings.receive_id = static_cast<uint32_t>(receive_id) & can::kMaxExtendedId;
  settings.send_id = static_cast<uint32_t>(send_id) & can::kMaxExtendedId;
  settings.bit_rate_code = static_cast<uint8_t>(bit_rate_code);
  return true;
}

uint32_t can_bit_rate_from_code(int32_t code) {
  switch (code) {
    case 2: return 20'000;
    case 3: return 50'000;
    case 4: return 100'000;
    case 5: return 125'000;
    case 6: return 250'000;
    case 7: return 500'000;
    case 8: return 1'000'000;
    default: return 0;
  }
}

can::CanFrame encode_can_reply(const CanSettings& settings, const Reply& reply, uint8_t length, bool extended) {
  can::CanFrame frame;
  frame.id = settings.send_id;
  frame.extended = extended || settings.send_id > can::kMaxStandardId;
  frame.dlc = length == kCanLongRequestLength ? kCanLongRequestLength : kCanRequestLength;
  // Reply layout: receive ID's low byte, status, command, value: the serial reply after its
  // host address byte.
  copy_frame_body(encode_reply(0, static_cast<uint8_t>(settings.receive_id & 0xFF), reply), frame.data);
  return frame;
}

can::CanFrame encode_can_request(uint32_t receive_id, const Instruction& instruction, uint8_t length) {
  can::CanFrame frame;
  frame.id = receive_id;
  frame.extended = receive_id > can::kMaxStandardId;
  frame.dlc = length == kCanLongRequestLength ? kCanLongRequestLength : kCanRequestLength;
  const Frame serial = encode_request(static_cast<uint8_t>(receive_id), instruction);
  copy_frame_body(serial, frame.data);
  // An 8th byte is the serial checksum (over the address byte and the seven), as PyTrinamic sends it.
  if (frame.dlc == kCanLongRequestLength) frame.data[7] = serial[8];
  return frame;
}

CanResponse serve_can_frame(TmclEngine& engine, const can::CanFrame& frame, ChannelId channel) {
  CanResponse response;
  CanSettings settings;
  if (frame.rtr || !read_can_settings(engine.device(), settings) || frame.id != settings.receive_id) return response;
  response.addressed = true;
  response.has_reply = true;
  const uint8_t reply_length = frame.dlc >= kCanLongRequestLength ? kCanLongRequestLength : kCanRequestLength;
  if (frame.dlc < kCanRequestLength) {
    const uint8_t command_byte = frame.dlc > 0 ? frame.data[0] : 0;
    response.reply = encode_can_reply(settings, Reply{to_byte(Status::kInvalidCommand), command_byte, 0}, reply_length,
                                      frame.extended);
    return response;
  }
  Frame serial{};
  for (size_t i = 0; i < kCanRequestLength; ++i) serial[1 + i] = frame.data[i];
  const Instruction instruction = decode_instruction(serial);
  if (instruction.command == command::kEnterAsciiMode) {
    // There are no text lines on CAN: the request changes nothing.
    response.reply = encode_can_reply(settings, Reply{to_byte(Status::kNotAvailable), instruction.command,
                                                      instruction.value}, reply_length, frame.extended);
    return response;
  }
  const CommandResult result = engine.execute(instruction, Origin::kHost, channel);
  // SGP 70/71 take effect at once: the reply to that very SGP uses the new IDs.
  CanSettings now = settings;
  read_can_settings(engine.device(), now);
  switch (result.kind) {
    case ReplyKind::kNone:
      response.has_reply = false;
      return response;
    case ReplyKind::kVersionString: {
      // The 8 version characters are the data, whatever the request's length
      // (docs/tmcl-protocol.md "CAN framing").
      response.reply.id = now.send_id;
      response.reply.extended = frame.extended || now.send_id > can::kMaxStandardId;
      response.reply.dlc = 8;
      for (uint8_t i = 0; i < 8; ++i) {
        response.reply.data[i] = static_cast<uint8_t>(engine.device().identity().version_string[i]);
      }
      return response;
    }
    case ReplyKind::kThenReset:
      response.reset_after_send = true;
      break;
    case ReplyKind::kThenAsciiMode:
    case ReplyKind::kNormal:
      break;
  }
  const uint8_t reply_command =
      result.reply_command >= 0 ? static_cast<uint8_t>(result.reply_command) : instruction.command;
  response.reply =
      encode_can_reply(now, Reply{to_byte(result.status), reply_command, result.value}, reply_length, frame.extended);
  return response;
}

}  // namespace motwin::tmcl
