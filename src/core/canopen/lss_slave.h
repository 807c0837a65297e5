// LSS slave (CiA-305), in the shape of CANopenNode's CO_LSSslave. The master sends on 0x7E5, the
// slave answers on 0x7E4 (8 bytes, byte 0 = the command specifier). LSS works in every NMT state
// and also while the node has no node ID (255, "unconfigured").
//
// States: kWaiting (after power-up) and kConfiguration.
//   04 switch state global     byte 1: 0 waiting, 1 configuration. No answer. Going to waiting
//                              with a new node ID configured while the active one is 255 makes
//                              the device reset communication with it (the node boots).
//   40..43 switch selective    vendor, product, revision, serial (1018 sub 1..4) in this order;
//                              when all four match: answer 44, configuration state. Waiting only.
//   11 configure node ID       1..127 or 255; answer 11 [error: 0 ok, 1 out of range]. The new ID
//                              is pending: it applies at the next reset communication / node.
//   13 configure bit timing    byte 1 table selector (0: CiA-305 table), byte 2 index; answer 13
//                              [error: 0 ok, 1 not supported]. Pending until activated.
//   15 activate bit timing     bytes 1-2 switch delay in ms: after twice the delay the pending
//                              bit rate is active. No answer.
//   17 store configuration     pending node ID and bit rate into the device's non-volatile
//                              memory; answer 17 [0 ok, 2 storage media access error].
//   5A..5D inquire identity    answer with the 1018 value; 5E inquire node ID (the active one).
//   51 fastscan                bytes 1-4 IDNumber, 5 BitChecked, 6 LSSSub, 7 LSSNext. Only an
//                              unconfigured slave (active and pending ID 255) in waiting takes
//                              part. BitChecked 0x80 restarts the scan (answer 4F); otherwise the
//                              slave answers 4F when bits 31..BitChecked of IDNumber equal those
//                              of identity part LSSSub and LSSSub is the part it is at; with
//                              BitChecked 0 it moves on to part LSSNext, and enters configuration
//                              when LSSNext < LSSSub (all four parts matched).
// Commands of the wrong state, unknown specifiers and frames other than 8 bytes are ignored.
#pragma once

#include <cstdint>

#include "board/can_controller.h"
#include "types/can_frame.h"

namespace motwin::canopen {

inline constexpr uint32_t kLssMasterCobId = 0x7E5;
inline constexpr uint32_t kLssSlaveCobId = 0x7E4;
inline constexpr uint8_t kLssUnconfiguredNodeId = 255;

struct LssIdentity {
  uint32_t vendor_id;
  uint32_t product_code;
  uint32_t revision_number;
  uint32_t serial_number;
};

// What the slave needs from its device.
class LssDevice {
 public:
  // Whether the device can run at this bit rate (kbit/s).
  virtual bool lss_bit_rate_supported(uint16_t bit_rate_kbit) const = 0;
  // Store configuration: false when the non-volatile memory could not be written.
  virtual bool lss_store(uint8_t node_id, uint16_t bit_rate_kbit) = 0;

 protected:
  ~LssDevice() = default;
};

enum class LssState : uint8_t { kWaiting, kConfiguration };

// What on_frame() asks the device to do.
enum class LssRequest : uint8_t { kNone, kResetCommunication };

class LssSlave {
 public:
  LssSlave(board::CanController& can, LssDevice& device) : can_(can), device_(device) {}

  // Power-up: waiting state, the active node ID and bit rate become the pending ones.
  void power_up(const LssIdentity& identity, uint8_t active_node_id, uint16_t bit_rate_kbit);
  // The node ID in use after a reset communication.
  void set_active_node_id(uint8_t node_id) { active_node_id_ = node_id; }

  LssRequest on_frame(const can::CanFrame& frame);
  // The activate-bit-timing delay. Returns the newly active bit rate, or 0.
  uint16_t process(uint32_t elapsed_us);

  LssState state() const { return state_; }
  uint8_t pending_node_id() const { return pending_node_id_; }
  // Whether a configure node ID since power-up changed the pending node ID.
  bool node_id_configured() const { return node_id_configured_; }
  uint16_t pending_bit_rate_kbit() const { return pending_bit_rate_kbit_; }

  // CiA-305 bit timing table 0; 0 = not supported by this device (10 kbit/s, automatic).
  static uint16_t bit_rate_of_index(uint8_t index);

 private:
  void answer(uint8_t command, uint8_t byte1 = 0, uint8_t byte2 = 0);
  void answer_value(uint8_t command, uint32_t value);
  void switch_selective(uint8_t command, uint32_t value);
  void fastscan(const uint8_t* data);
  uint32_t identity_part(uint8_t part) const;

  board::CanController& can_;
  LssDevice& device_;
  LssIdentity identity_{};
  LssState state_ = LssState::kWaiting;
  uint8_t active_node_id_ = kLssUnconfiguredNodeId;
  uint8_t pending_node_id_ = kLssUnconfiguredNodeId;
  bool node_id_configured_ = false;
  uint16_t pending_bit_rate_kbit_ = 0;
  uint8_t selective_step_ = 0;     // switch state selective: parts matched so far
  uint8_t fastscan_part_ = 0;      // fastscan: LSSSub this slave is at
  bool activation_pending_ = false;
  uint64_t activation_remaining_us_ = 0;
};

}  // namespace motwin::canopen
