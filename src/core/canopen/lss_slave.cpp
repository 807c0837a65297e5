#include "core/canopen/lss_slave.h"

namespace motwin::canopen {
namespace {

// Command specifiers (CiA-305).
constexpr uint8_t kSwitchStateGlobal = 0x04;
constexpr uint8_t kConfigureNodeId = 0x11;
constexpr uint8_t kConfigureBitTiming = 0x13;
constexpr uint8_t kActivateBitTiming = 0x15;
constexpr uint8_t kStoreConfiguration = 0x17;
constexpr uint8_t kSwitchSelectiveVendor = 0x40;
constexpr uint8_t kSwitchSelectiveSerial = 0x43;
constexpr uint8_t kSwitchSelectiveResponse = 0x44;
constexpr uint8_t kIdentifySlave = 0x4F;
constexpr uint8_t kFastscan = 0x51;
constexpr uint8_t kInquireVendor = 0x5A;
constexpr uint8_t kInquireSerial = 0x5D;
constexpr uint8_t kInquireNodeId = 0x5E;

constexpr uint8_t kFastscanReset = 0x80;
constexpr uint8_t kErrorOutOfRange = 1;    // configure node ID
constexpr uint8_t kErrorNotSupported = 1;  // configure bit timing
constexpr uint8_t kErrorStorage = 2;       // store configuration

uint32_t le32(const uint8_t* p) {
  return static_cast<uint32_t>(p[0]) | static_cast<uint32_t>(p[1]) << 8 | static_cast<uint32_t>(p[2]) << 16 |
         static_cast<uint32_t>(p[3]) << 24;
}

}  // namespace

uint16_t LssSlave::bit_rate_of_index(uint8_t index) {
  // CiA-305 table 0: 1000, 800, 500, 250, 125, (reserved, formerly 100), 50, 20, 10, automatic.
  // Index 5 is taken as 100 kbit/s, the one rate of the manual the table would otherwise lack.
  static constexpr uint16_t kTable[] = {1000, 800, 500, 250, 125, 100, 50, 20};
  return index < sizeof(kTable) / sizeof(kTable[0]) ? kTable[index] : 0;
}

void LssSlave::power_up(const LssIdentity& identity, uint8_t active_node_id, uint16_t bit_rate_kbit) {
  identity_ = identity;
  state_ = LssState::kWaiting;
  active_node_id_ = active_node_id;
  pending_node_id_ = active_node_id;
  node_id_configured_ = false;
  pending_bit_rate_kbit_ = bit_rate_kbit;
  selective_step_ = 0;
  fastscan_part_ = 0;
  activation_pending_ = false;
}

uint32_t LssSlave::identity_part(uint8_t part) const {
  switch (part) {
    case 0: return identity_.vendor_id;
    case 1: return identity_.product_code;
    case 2: return identity_.revision_number;
    default: return identity_.serial_number;
  }
}

LssRequest LssSlave::on_frame(const can::CanFrame& frame) {
  if (frame.extended || frame.rtr || frame.id != kLssMasterCobId || frame.dlc != 8) return LssRequest::kNone;
  const uint8_t* data = frame.data;
  const uint8_t command = data[0];
  if (command >= kSwitchSelectiveVendor && command <= kSwitchSelectiveSerial) {
    if (state_ == LssState::kWaiting) switch_selective(command, le32(data + 1));
    return LssRequest::kNone;
  }
  if (command == kSwitchStateGlobal) {
    if (data[1] == 1) {
      state_ = LssState::kConfiguration;
    } else if (data[1] == 0) {
      state_ = LssState::kWaiting;
      selective_step_ = 0;
      // An unconfigured node that got an ID starts with it now (CiA-305 8.3.2).
      if (active_node_id_ == kLssUnconfiguredNodeId && pending_node_id_ != kLssUnconfiguredNodeId) {
        return LssRequest::kResetCommunication;
      }
    }
    return LssRequest::kNone;
  }
  if (command == kFastscan) {
    if (state_ == LssState::kWaiting) fastscan(data);
    return LssRequest::kNone;
  }
  if (state_ != LssState::kConfiguration) return LssRequest::kNone;
  switch (command) {
    case kConfigureNodeId: {
      const uint8_t node_id = data[1];
      if ((node_id >= 1 && node_id <= 127) || node_id == kLssUnconfiguredNodeId) {
        pending_node_id_ = node_id;
        node_id_configured_ = true;
        answer(kConfigureNodeId, 0);
      } else {
        answer(kConfigureNodeId, kErrorOutOfRange);
      }
      break;
    }
    case kConfigureBitTiming: {
      const uint16_t bit_rate = data[1] == 0 ? bit_rate_of_index(data[2]) : 0;
      if (bit_rate != 0 && device_.lss_bit_rate_supported(bit_rate)) {
        pending_bit_rate_kbit_ = bit_rate;
        answer(kConfigureBitTiming, 0);
      } else {
        answer(kConfigureBitTiming, kErrorNotSupported);
      }
      break;
    }
    case kActivateBitTiming: {
      const uint16_t delay_ms = static_cast<uint16_t>(data[1] | data[2] << 8);
      activation_pending_ = true;
      activation_remaining_us_ = 2u * static_cast<uint64_t>(delay_ms) * 1000u;
      break;
    }
    case kStoreConfiguration:
      answer(kStoreConfiguration, device_.lss_store(pending_node_id_, pending_bit_rate_kbit_) ? 0 : kErrorStorage);
      break;
    case kInquireNodeId: answer(kInquireNodeId, active_node_id_); break;
    default:
      if (command >= kInquireVendor && command <= kInquireSerial) {
        answer_value(command, identity_part(static_cast<uint8_t>(command - kInquireVendor)));
      }
      break;
  }
  return LssRequest::kNone;
}

void LssSlave::switch_selective(uint8_t command, uint32_t value) {
  const uint8_t part = static_cast<uint8_t>(command - kSwitchSelectiveVendor);
  if (part != selective_step_ || value != identity_part(part)) {
    selective_step_ = 0;  // out of order or another slave's identity: start over
    return;
  }
  if (part < 3) {
    ++selective_step_;
    return;
  }
  selective_step_ = 0;
  state_ = LssState::kConfiguration;
  answer(kSwitchSelectiveResponse);
}

void LssSlave::fastscan(const uint8_t* data) {
  if (active_node_id_ != kLssUnconfiguredNodeId || pending_node_id_ != kLssUnconfiguredNodeId) return;
  const uint32_t id_number = le32(data + 1);
  const uint8_t bit_checked = data[5];
  const uint8_t lss_sub = data[6];
  const uint8_t lss_next = data[7];
  if (bit_checked == kFastscanReset) {
    fastscan_part_ = 0;
    answer(kIdentifySlave);
    return;
  }
  if (bit_checked > 31 || lss_sub > 3 || lss_next > 3 || lss_sub != fastscan_part_) return;
  const uint32_t mask = 0xFFFF'FFFFu << bit_checked;
  if (((id_number ^ identity_part(lss_sub)) & mask) != 0) return;
  answer(kIdentifySlave);
  if (bit_checked != 0) return;
  fastscan_part_ = lss_next;
  if (lss_next < lss_sub) {  // the whole identity matched
    fastscan_part_ = 0;
    state_ = LssState::kConfiguration;
  }
}

uint16_t LssSlave::process(uint32_t elapsed_us) {
  if (!activation_pending_) return 0;
  if (elapsed_us < activation_remaining_us_) {
    activation_remaining_us_ -= elapsed_us;
    return 0;
  }
  activation_pending_ = false;
  return pending_bit_rate_kbit_;
}

void LssSlave::answer(uint8_t command, uint8_t byte1, uint8_t byte2) {
  const uint8_t data[8] = {command, byte1, byte2, 0, 0, 0, 0, 0};
  can_.transmit(can::make_frame(kLssSlaveCobId, data, 8));
}

void LssSlave::answer_value(uint8_t command, uint32_t value) {
  const uint8_t data[8] = {command,
                           static_cast<uint8_t>(value),
                           static_cast<uint8_t>(value >> 8),
                           static_cast<uint8_t>(value >> 16),
                           static_cast<uint8_t>(value >> 24),
                           0,
                           0,
                           0};
  can_.transmit(can::make_frame(kLssSlaveCobId, data, 8));
}

}  // namespace motwin::canopen
