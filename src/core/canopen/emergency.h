// EMCY producer (CiA-301 7.2.7, TMCM-3216 manual chapter 11), in the shape of CANopenNode's
// CO_Emergency: report() queues an emergency, process() sends it, never two closer together than
// the inhibit time 1015 (100 µs units). A message is always 8 bytes: error code (little-endian),
// error register 1001, five manufacturer-specific bytes that the module fills (the TMCM-3216
// puts the motor in byte 2).
// COB-ID 1014 with bit 31 set switches the producer off (reports are dropped).
#pragma once

#include <array>
#include <cstddef>
#include <cstdint>

#include "board/can_controller.h"
#include "core/canopen/sdo_abort.h"
#include "types/can_frame.h"

namespace motwin::canopen {

// Error codes of CiA-301 (table 21) for the communication part.
inline constexpr uint16_t kEmcyErrorReset = 0x0000;
inline constexpr uint16_t kEmcyCanOverflow = 0x8110;
inline constexpr uint16_t kEmcyCanErrorPassive = 0x8120;
inline constexpr uint16_t kEmcyHeartbeat = 0x8130;
inline constexpr uint16_t kEmcyCanBusOffRecovered = 0x8140;

// 1001 bits (CiA-301 table 47).
inline constexpr uint8_t kErrorRegisterGeneric = 0x01;
inline constexpr uint8_t kErrorRegisterCurrent = 0x02;
inline constexpr uint8_t kErrorRegisterVoltage = 0x04;
inline constexpr uint8_t kErrorRegisterTemperature = 0x08;
inline constexpr uint8_t kErrorRegisterCommunication = 0x10;
inline constexpr uint8_t kErrorRegisterDeviceProfile = 0x20;
inline constexpr uint8_t kErrorRegisterManufacturer = 0x80;

// An SDO write of 1014 (`current` is its value now) on node `node_id`: bit 31 switches EMCY off;
// 11-bit identifiers only; the ID does not change while valid; no restricted identifier but the
// node's own default 80h + node ID.
SdoAbort check_emcy_cob_id(uint32_t current, int64_t value, uint8_t node_id);

class EmergencyProducer {
 public:
  static constexpr size_t kQueueLength = 8;

  explicit EmergencyProducer(board::CanController& can) : can_(can) {}

  void set_cob_id(uint32_t cob_id) { cob_id_ = cob_id; }
  void set_inhibit_time_100us(uint16_t inhibit) { inhibit_100us_ = inhibit; }
  // Drops queued messages and the inhibit timer (resets).
  void reset();

  // Queues an emergency. false: the producer is off or the queue is full (the message is lost).
  bool report(uint16_t error_code, uint8_t error_register, const uint8_t (&manufacturer)[5]);
  // Sends what is queued, one message per inhibit time.
  void process(uint32_t elapsed_us);

  size_t queued() const { return count_; }
  uint64_t lost() const { return lost_; }

 private:
  board::CanController& can_;
  uint32_t cob_id_ = 0x8000'0000;
  uint16_t inhibit_100us_ = 0;
  uint64_t inhibit_remaining_us_ = 0;
  std::array<can::CanFrame, kQueueLength> queue_{};
  size_t head_ = 0;
  size_t count_ = 0;
  uint64_t lost_ = 0;
};

}  // namespace motwin::canopen
