#include "firmware/serial_tmcl_link.h"

#include <cstring>

namespace motwin::firmware {

bool SerialTmclLink::receive(uint8_t byte, uint64_t now_us) {
  if (held_.pending) return false;
  follow_power_up();
  if (!ascii_mode_) {
    if (decoder_.push(byte, now_us)) serve_frame(now_us);
    return true;
  }
  const tmcl::AsciiSettings settings = tmcl::ascii_settings(engine_.device());
  const bool line_complete = ascii_.push(byte, settings);
  if (ascii_.echo_length() > 0) output_.write(ascii_.echo(), ascii_.echo_length());
  if (line_complete) serve_line(now_us);
  return true;
}

void SerialTmclLink::serve_frame(uint64_t now_us) {
  const tmcl::SerialResponse response = tmcl::serve_serial_frame(engine_, decoder_.frame(), kChannel);
  std::memcpy(held_.bytes, response.bytes.data(), response.length);
  held_.length = response.length;
  held_.reset_after_send = response.reset_after_send;
  held_.enter_ascii = response.enter_ascii_mode;
  held_.leave_ascii = false;
  hold_or_send(response.delay_ms, now_us);
}

void SerialTmclLink::serve_line(uint64_t now_us) {
  const tmcl::AsciiResponse response = tmcl::serve_ascii_command(engine_, ascii_.command(), kChannel);
  std::memcpy(held_.bytes, response.bytes, response.length);
  held_.length = response.length;
  held_.reset_after_send = response.reset_after_send;
  held_.enter_ascii = false;
  held_.leave_ascii = response.leave_ascii_mode;
  hold_or_send(response.delay_ms, now_us);
}

void SerialTmclLink::hold_or_send(uint8_t delay_ms, uint64_t now_us) {
  held_.pending = true;
  // Command 137 powers up inside the engine: the link's mode follows before the reply goes out.
  follow_power_up();
  if (held_.length > 0 && delay_ms > 0) {
    held_.release_us = now_us + uint64_t{delay_ms} * 1000u;
    return;
  }
  send_held();
}

void SerialTmclLink::send_held() {
  held_.pending = false;
  if (held_.length > 0) output_.write(held_.bytes, held_.length);
  if (held_.enter_ascii) set_mode(true);
  if (held_.leave_ascii) set_mode(false);
  if (held_.reset_after_send) engine_.complete_reset();
  follow_power_up();
}

void SerialTmclLink::poll(uint64_t now_us) {
  if (held_.pending) {
    if (now_us < held_.release_us) return;  // events wait behind the held reply
    send_held();
  }
  follow_power_up();
  engine_.collect_events(*this);
}

void SerialTmclLink::deliver(tmcl::ChannelId channel, const tmcl::Reply& reply) {
  if (channel != kChannel) return;
  if (!ascii_mode_) {
    const tmcl::Frame frame = tmcl::encode_event_reply(engine_.device(), reply);
    output_.write(frame.data(), frame.size());
    return;
  }
  // "BA 128 1\r": the host's letter, the module's, the status and the value in decimal.
  const tmcl::SerialSettings settings = engine_.device().serial_settings();
  const auto letter = [](uint8_t address) {
    const char c = tmcl::ascii_address_letter(address);
    return static_cast<uint8_t>(c != '\0' ? c : '?');
  };
  uint8_t line[32];
  size_t length = 0;
  line[length++] = letter(settings.host_address);
  line[length++] = letter(settings.module_address);
  const auto put_number = [&](int64_t number) {
    line[length++] = ' ';
    if (number < 0) {
      line[length++] = '-';
      number = -number;
    }
    char digits[20];
    size_t count = 0;
    do {
      digits[count++] = static_cast<char>('0' + number % 10);
      number /= 10;
    } while (number > 0);
    while (count > 0) line[length++] = static_cast<uint8_t>(digits[--count]);
  };
  put_number(reply.status);
  put_number(reply.value);
  line[length++] = '\r';
  output_.write(line, length);
}

void SerialTmclLink::follow_power_up() {
  if (engine_.power_up_count() == power_ups_seen_) return;
  power_ups_seen_ = engine_.power_up_count();
  const tmcl::AsciiSettings settings = tmcl::ascii_settings(engine_.device());
  set_mode(settings.available && settings.start_in_ascii_mode);
}

void SerialTmclLink::set_mode(bool ascii) {
  ascii_mode_ = ascii;
  decoder_.reset();
  ascii_.reset();
}

}  // namespace motwin::firmware
