#include "tools/lss_client.h"

#include <algorithm>
#include <chrono>

namespace motwin::tools {
namespace {

constexpr uint8_t kSwitchGlobal = 0x04;
constexpr uint8_t kConfigureNodeId = 0x11;
constexpr uint8_t kConfigureBitTiming = 0x13;
constexpr uint8_t kActivateBitTiming = 0x15;
constexpr uint8_t kStoreConfiguration = 0x17;
constexpr uint8_t kSwitchSelectiveVendor = 0x40;
constexpr uint8_t kSwitchSelectiveAnswer = 0x44;
constexpr uint8_t kIdentifySlave = 0x4F;
constexpr uint8_t kFastscan = 0x51;
constexpr uint8_t kFastscanReset = 0x80;
// Quiet time that ends the draining of stale answers before a request. Fastscan drains longer:
// a tenth of its step timeout, which a user raises on a slow or loaded host (--step-timeout).
constexpr int kSettleMs = 2;

int64_t now_ms() {
  return std::chrono::duration_cast<std::chrono::milliseconds>(std::chrono::steady_clock::now().time_since_epoch())
      .count();
}

void put_u32(std::array<uint8_t, 8>& data, size_t at, uint32_t value) {
  for (size_t i = 0; i < 4; ++i) data[at + i] = static_cast<uint8_t>(value >> (8 * i));
}

uint32_t get_u32(const can::CanFrame& frame, size_t at) {
  uint32_t value = 0;
  for (size_t i = 0; i < 4; ++i) value |= static_cast<uint32_t>(frame.data[at + i]) << (8 * i);
  return value;
}

// The outcome of a service CiA-305 leaves unanswered: whether its frame went out.
LssResult sent_only(const Result<void>& sent) {
  LssResult result;
  result.ok = sent.ok();
  result.error = sent.error();
  return result;
}

}  // namespace

Result<void> LssMaster::send(const std::array<uint8_t, 8>& data, int settle_ms) {
  // Answers that arrived late (several slaves answer one fastscan probe, or a configure) must
  // not pass for answers to this request. Over TCP each answer is a write of its own, so on a
  // loaded host the server may be held up between the answers of two slaves.
  while (bus_.receive(settle_ms)) {
  }
  return bus_.send(can::make_frame(kLssMasterId, data.data(), 8));
}

std::optional<can::CanFrame> LssMaster::await(uint8_t command, int timeout_ms) {
  const int64_t deadline = now_ms() + timeout_ms;
  for (;;) {
    const int64_t remaining = deadline - now_ms();
    if (remaining <= 0) return std::nullopt;
    const std::optional<can::CanFrame> frame = bus_.receive(static_cast<int>(remaining));
    if (!frame) return std::nullopt;
    if (frame->id == kLssSlaveId && !frame->extended && frame->dlc == 8 && frame->data[0] == command) return frame;
  }
}

LssResult LssMaster::confirmed(const std::array<uint8_t, 8>& request, const char* what) {
  LssResult result;
  if (const Result<void> sent = send(request); !sent) {
    result.error = sent.error();
    return result;
  }
  const std::optional<can::CanFrame> answer = await(request[0], timeout_ms_);
  if (!answer) {
    result.error = std::string("no answer to ") + what + " (is a slave in configuration state?)";
    return result;
  }
  result.error_code = answer->data[1];
  result.ok = result.error_code == 0;
  if (!result.ok) {
    result.error = std::string(what) + " refused with error " + std::to_string(result.error_code) +
                   (result.error_code == 1   ? " (not supported or out of range)"
                    : result.error_code == 2 ? " (storage media access error)"
                                             : "");
  }
  return result;
}

LssResult LssMaster::switch_global(bool configuration) {
  return sent_only(send({kSwitchGlobal, static_cast<uint8_t>(configuration ? 1 : 0), 0, 0, 0, 0, 0, 0}));
}

LssResult LssMaster::switch_selective(const LssIdentityNumbers& identity) {
  LssResult result;
  const uint32_t parts[4] = {identity.vendor_id, identity.product_code, identity.revision_number, identity.serial_number};
  for (uint8_t i = 0; i < 4; ++i) {
    std::array<uint8_t, 8> data{static_cast<uint8_t>(kSwitchSelectiveVendor + i)};
    put_u32(data, 1, parts[i]);
    if (const Result<void> sent = send(data); !sent) {
      result.error = sent.error();
      return result;
    }
  }
  if (!await(kSwitchSelectiveAnswer, timeout_ms_)) {
    result.error = "no slave with this identity answered switch state selective";
    return result;
  }
  result.ok = true;
  return result;
}

LssResult LssMaster::configure_node_id(uint8_t node_id) {
  return confirmed({kConfigureNodeId, node_id, 0, 0, 0, 0, 0, 0}, "configure node ID");
}

LssResult LssMaster::configure_bit_timing(uint8_t table_index) {
  return confirmed({kConfigureBitTiming, 0, table_index, 0, 0, 0, 0, 0}, "configure bit timing");
}

LssResult LssMaster::activate_bit_timing(uint16_t switch_delay_ms) {
  return sent_only(send({kActivateBitTiming, static_cast<uint8_t>(switch_delay_ms),
                         static_cast<uint8_t>(switch_delay_ms >> 8), 0, 0, 0, 0, 0}));
}

LssResult LssMaster::store_configuration() {
  return confirmed({kStoreConfiguration, 0, 0, 0, 0, 0, 0, 0}, "store configuration");
}

LssResult LssMaster::inquire(uint8_t command) {
  LssResult result;
  if (const Result<void> sent = send({command, 0, 0, 0, 0, 0, 0, 0}); !sent) {
    result.error = sent.error();
    return result;
  }
  const std::optional<can::CanFrame> answer = await(command, timeout_ms_);
  if (!answer) {
    result.error = "no answer to the inquiry (is a slave in configuration state?)";
    return result;
  }
  result.value = command == 0x5E ? answer->data[1] : get_u32(*answer, 1);
  result.ok = true;
  return result;
}

Result<LssIdentityNumbers> LssMaster::fastscan(int step_timeout_ms) {
  const int settle_ms = std::max(kSettleMs, step_timeout_ms / 10);
  const auto probe = [this, step_timeout_ms, settle_ms](uint32_t id_number, uint8_t bit_checked, uint8_t sub,
                                                        uint8_t next, int timeout_ms) {
    std::array<uint8_t, 8> data{kFastscan};
    put_u32(data, 1, id_number);
    data[5] = bit_checked;
    data[6] = sub;
    data[7] = next;
    if (!send(data, settle_ms)) return false;
    return await(kIdentifySlave, timeout_ms > 0 ? timeout_ms : step_timeout_ms).has_value();
  };
  // Reset: every unconfigured slave in waiting state answers. The first probe may wait behind a
  // fresh connection's start-up, so it gets the long timeout.
  if (!probe(0, kFastscanReset, 0, 0, timeout_ms_)) return Error{"no unconfigured LSS slave answered the fastscan"};
  uint32_t parts[4] = {};
  for (uint8_t sub = 0; sub < 4; ++sub) {
    uint32_t id_number = 0;
    // Bit by bit from the top: a probe with the bit 0 that nobody answers means the bit is 1.
    for (int bit = 31; bit >= 0; --bit) {
      if (!probe(id_number, static_cast<uint8_t>(bit), sub, sub, 0)) id_number |= uint32_t{1} << bit;
    }
    // The whole part, confirmed, and the slave moves on to the next part (after the serial
    // number LSSNext 0 < LSSSub puts it into configuration state).
    const uint8_t next = static_cast<uint8_t>((sub + 1) % 4);
    if (!probe(id_number, 0, sub, next, timeout_ms_)) {
      return Error{"fastscan lost the slave at part " + std::to_string(sub) + " (two slaves with one identity?)"};
    }
    parts[sub] = id_number;
  }
  return LssIdentityNumbers{parts[0], parts[1], parts[2], parts[3]};
}

std::optional<uint8_t> LssMaster::bit_timing_index(uint32_t bit_rate_kbit) {
  switch (bit_rate_kbit) {
    case 1000: return 0;
    case 800: return 1;
    case 500: return 2;
    case 250: return 3;
    case 125: return 4;
    case 50: return 6;
    case 20: return 7;
    case 10: return 8;
    default: return std::nullopt;
  }
}

}  // namespace motwin::tools
