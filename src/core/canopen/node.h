// A CANopen node (CiA-301): the services of one device wired together, in the shape of
// CANopenNode's CO_CANopen. The node owns the data behind the communication objects
// (CommunicationConfig: 1005..1029 and the PDO parameters; NodeSettings: the stored node ID and
// bit rate), the CAN receive queue, the restart timing (boot-up after a reset), the active node ID
// and bit rate (address switches, stored settings, LSS), the communication errors with their EMCYs
// (8110, 8120, 8130, 8140, 8210, 8220, the RPDO value error) and the heartbeat consumer's error
// behaviour (1029). Each service is one file beside this one (nmt, sdo_server, pdo, sync,
// emergency, heartbeat_consumer, lss_slave, storage); the rows that bind the communication
// objects to the node are in communication_objects.h.
//
// What a module gives (docs/canopen.md "The node and its modules"):
//   NodeDescription  const, per firmware: identity (1018), PDO count, bit rates, what each
//                    1010/1011 sub-index stores and restores, its EMCY details;
//   NodeConfig       per instance: address switches, serial number, restart times;
//   NodeApplication  the application behind the objects 2000h..9FFFh: its reset (NMT reset node),
//                    what a SYNC does to it, what a bus-off does to it, its bits of 1001;
//   its dictionary   (a RowDictionary over the module's table, communication rows included) and
//                    the NVM the objects are stored in.
// The module's tick calls tick(); frames from the bus go to receive().
#pragma once

#include <array>
#include <cstddef>
#include <cstdint>
#include <span>
#include <string_view>

#include "board/can_controller.h"
#include "board/non_volatile_memory.h"
#include "core/canopen/emergency.h"
#include "core/canopen/heartbeat_consumer.h"
#include "core/canopen/lss_slave.h"
#include "core/canopen/nmt.h"
#include "core/canopen/node_guarding.h"
#include "core/canopen/object_dictionary.h"
#include "core/canopen/pdo.h"
#include "core/canopen/sdo_server.h"
#include "core/canopen/storage.h"
#include "core/canopen/sync.h"
#include "types/can_frame.h"

namespace motwin::canopen {

inline constexpr size_t kNodeMaxPdos = PdoService::kMaxPdos;  // per direction
inline constexpr uint32_t kSaveSignature = 0x6576'6173;      // "save" (1010, 2706)
inline constexpr uint32_t kLoadSignature = 0x6461'6F6C;      // "load" (1011)

// The restart times `motwin serve` gives a module whose manual gives none (NodeConfig): a Motwin
// decision (docs/canopen.md "Start-up timing"). A reset node restarts the processor like a power-up
// (bootloader, driver chips and the stored parameters set up again); a reset communication only
// sets up the CANopen stack again.
inline constexpr uint32_t kDefaultBootDelayUs = 300'000;
inline constexpr uint32_t kDefaultCommunicationBootDelayUs = 50'000;

// The communication objects a master writes (1005..1029, 1400..1A03), as the node's services
// use them. A module declares the objects it has (communication_objects.h); the others keep
// these values.
struct CommunicationConfig {
  uint32_t sync_cob_id;              // 1005
  uint32_t sync_period_us;           // 1006
  uint32_t emcy_cob_id;              // 1014
  uint16_t emcy_inhibit_100us;       // 1015
  uint32_t consumer_heartbeat[1];    // 1016 sub 1
  uint16_t producer_heartbeat_ms;    // 1017
  uint8_t error_behavior[2];         // 1029 sub 1, 2
  uint16_t guard_time_ms;            // 100C
  uint8_t life_time_factor;          // 100D
  PdoCommunication rpdo[kNodeMaxPdos];
  PdoMapping rpdo_mapping[kNodeMaxPdos];
  PdoCommunication tpdo[kNodeMaxPdos];
  PdoMapping tpdo_mapping[kNodeMaxPdos];
};

// The stored node ID and bit rate (TMCM-3216: 2704 / 2705): what applies after the next reset;
// Node::node_id() and bit_rate_kbit() say what applies now.
struct NodeSettings {
  uint16_t bit_rate_kbit;
  uint8_t node_id;  // 1..127, 255 = LSS unconfigured
};

// 1018 subs 1..3 (sub 4, the serial number, is the instance's: NodeConfig).
struct NodeIdentity {
  uint32_t vendor_id;
  uint32_t product_code;
  uint32_t revision_number;  // major << 16 | minor
};

// One sub-index of 1010 (store) and of 1011 (restore): what a write with the signature selects.
// Reading it gives 1 where the function is supported, 0 where a write is refused (08000020).
struct StorageSubIndex {
  std::string_view store_name;    // 1010's sub-index name
  std::string_view restore_name;  // 1011's
  bool store_supported;
  StorageSelection store;
  bool restore_supported;
  StorageSelection restore;  // empty and supported: accepted with no effect ("no function")
};

// What a firmware tells its node; constant.
struct NodeDescription {
  NodeIdentity identity;
  uint8_t pdo_count;                          // per direction, at most kNodeMaxPdos
  std::span<const uint16_t> bit_rates_kbit;   // the bit rates the module supports (LSS, its objects)
  std::span<const StorageSubIndex> storage;   // 1010 / 1011 sub 1..n
  // Bytes 3..7 of the node's own EMCYs (communication errors, the RPDO value error).
  uint8_t communication_emcy_data[5] = {};
  uint16_t rpdo_value_emcy = 0x6320;  // an RPDO value refused: CiA-402's "parameter error"
  bool node_guarding = false;         // answers guarding requests (100C/100D); else RTR is ignored
  bool lss = true;                    // a CiA-305 LSS slave; else LSS frames are ignored
};

// An instance's settings.
struct NodeConfig {
  // The module's address switches: 1..127 overrides the stored node ID, as the TMCM-3216 manual
  // says switches do (4.2.63); 0 = no switches, the stored node ID decides.
  uint8_t node_id_switches = 0;
  uint32_t serial_number = 0;  // 1018 sub 4
  // Restart times in simulated µs: from power-up or NMT reset node, and from NMT reset
  // communication (also the one an LSS switch to waiting makes), to the boot-up message. The node
  // hears and sends nothing meanwhile. 0 boots at once (the protocol tests); `motwin serve` uses
  // the module's own (docs/canopen.md "Start-up timing").
  uint32_t boot_delay_us = 0;
  uint32_t communication_boot_delay_us = 0;
};

// The application behind the node: the module's side of resets, SYNC and bus-off.
class NodeApplication {
 public:
  // NMT reset node (and power-up): every object of 2000h..9FFFh to its power-on value, or its
  // stored one (Node::load_stored), the application's live state reset.
  virtual void reset_application() = 0;
  // A SYNC received or produced in pre-operational or operational, after the synchronous RPDOs
  // were written.
  virtual void on_sync() = 0;
  // The CAN controller is bus-off, or was since the last service tick: the master has lost the
  // node (TMCM-3216 table 365, 8140: running axes are stopped).
  virtual void on_bus_off() = 0;
  // The application's bits of 1001 (axis faults, device errors).
  virtual uint8_t application_error_register() const = 0;

 protected:
  ~NodeApplication() = default;
};

class Node final : private LssDevice {
 public:
  static constexpr size_t kReceiveQueueLength = 32;
  // The services keep millisecond timers: tick() runs them once per kServicePeriodUs (and at once
  // whenever a frame waits, so that an SDO request is answered within the tick that sees it).
  static constexpr uint32_t kServicePeriodUs = 1000;

  // Communication errors now active (communication_errors()); 1001 bit 4 while any is.
  static constexpr uint8_t kCommErrorHeartbeat = 0x01;
  static constexpr uint8_t kCommErrorCanOverrun = 0x02;
  static constexpr uint8_t kCommErrorPdoLength = 0x04;
  static constexpr uint8_t kCommErrorPdoLengthExceeded = 0x08;
  static constexpr uint8_t kCommErrorCanController = 0x10;  // error-passive, bus-off, just recovered

  // `storage_scratch` (at least the NVM's size) is where a new storage image is assembled.
  Node(RowDictionary& dictionary, board::NonVolatileMemory& nvm, board::CanController& can,
       NodeApplication& application, const NodeDescription& description, const NodeConfig& config,
       std::span<uint8_t> storage_scratch);
  Node(const Node&) = delete;
  Node& operator=(const Node&) = delete;

  // Power-on: every object from the NVM (or its default); after the boot delay the boot-up
  // message and pre-operational.
  void power_up();
  // A frame from the bus (the CAN receive interrupt): queued for the next process() call.
  // false: the queue was full and the frame is lost.
  bool receive(const can::CanFrame& frame);
  // Handles the queued frames, then advances the services' timers by `elapsed_us`.
  void process(uint32_t elapsed_us);
  // One motion tick of `tick_us`: process() when a frame waits or a service period has passed.
  // True when it ran.
  bool tick(uint32_t tick_us) {
    service_elapsed_us_ += tick_us;
    if (receive_count_ == 0 && service_elapsed_us_ < kServicePeriodUs) return false;
    const uint32_t elapsed = service_elapsed_us_;
    service_elapsed_us_ = 0;
    process(elapsed);
    return true;
  }

  uint8_t node_id() const { return node_id_; }              // active
  uint16_t bit_rate_kbit() const { return bit_rate_kbit_; }  // active
  bool configured() const { return node_id_ >= 1 && node_id_ <= 127; }
  // Between a power-up or NMT reset and the boot-up (NodeConfig's delays): frames received are
  // dropped, nothing is sent.
  bool restarting() const { return restarting_; }
  NmtState nmt_state() const { return nmt_.state(); }
  // 1001: the communication bits, the RPDO value error, the application's bits.
  uint8_t error_register() const {
    const uint8_t parameter = parameter_error_ ? kErrorRegisterGeneric : 0;
    return static_cast<uint8_t>(error_register_ | parameter | application_.application_error_register());
  }
  // The communication bits of 1001 alone (what the application adds its reports to).
  uint8_t communication_error_register() const { return error_register_; }
  uint64_t dropped_frames() const { return dropped_frames_; }
  uint8_t communication_errors() const { return communication_errors_; }
  bool supports_bit_rate(uint16_t bit_rate_kbit) const;

  RowDictionary& dictionary() { return dictionary_; }
  NmtSlave& nmt() { return nmt_; }
  SdoServer& sdo() { return sdo_; }
  EmergencyProducer& emergency() { return emergency_; }
  HeartbeatConsumer& heartbeat_consumer() { return heartbeat_consumer_; }
  NodeGuarding& node_guarding() { return node_guarding_; }
  PdoService& pdos() { return pdos_; }
  SyncService& sync() { return sync_; }
  LssSlave& lss() { return lss_; }
  CommunicationConfig& communication() { return communication_; }
  NodeSettings& node_settings() { return node_settings_; }
  const NodeConfig& config() const { return config_; }
  const NodeDescription& description() const { return description_; }
  LssIdentity identity() const;

  // 1010 / 1011 sub-index `sub` written with `signature`; the stored node settings (2706).
  SdoAbort store_parameters(uint8_t sub, uint32_t signature);
  SdoAbort restore_parameters(uint8_t sub, uint32_t signature);
  SdoAbort store_node_settings(uint32_t signature);
  // The selected objects to their stored values or defaults (the application's reset).
  void load_stored(const StorageSelection& selection) { storage_.load(selection); }

 private:
  // NMT reset node (and power-up): the application, then the communication reset.
  void reset_node();
  // NMT reset communication: the objects 1000h..1FFFh to their stored values or defaults, the
  // node ID and bit rate as stored (the node-settings objects themselves untouched), the
  // services reset; the boot-up follows after `boot_delay_us`.
  void reset_communication(uint32_t boot_delay_us);
  // The restart ends: boot-up (when configured), pre-operational.
  void finish_restart();
  void handle_frame(const can::CanFrame& frame);
  void run_nmt(uint32_t elapsed_us);
  void run_heartbeat_consumer(uint32_t elapsed_us);
  void run_node_guarding(uint32_t elapsed_us);
  // A heartbeat or life guarding event (kCommErrorHeartbeat, EMCY 8130): the 1029 sub 1 reaction.
  void lose_master();
  void run_sync(uint32_t elapsed_us);
  void on_sync();
  void handle_pdo(const can::CanFrame& frame);
  // The RPDO value EMCY when RPDO writes since the last check had a value refused; 0000 when the
  // next RPDO is written whole.
  void check_rpdo_values();
  void check_receive_overrun(uint32_t elapsed_us);
  // The CAN controller's fault confinement (board::CanController::status()), once per service
  // tick: EMCY 8120 while error-passive, the application told at bus-off, 8140 once back.
  void check_can_controller();
  // Sets / clears one kCommError* bit, with its EMCY (code, or 0000 when it clears).
  void raise_error(uint8_t error, uint16_t emcy_code);
  void clear_error(uint8_t error);
  // Sets a kCommError* bit and sends `emcy_code` even if the bit was set already.
  void report_error(uint8_t error, uint16_t emcy_code);
  // LssDevice.
  bool lss_bit_rate_supported(uint16_t bit_rate_kbit) const override { return supports_bit_rate(bit_rate_kbit); }
  bool lss_store(uint8_t node_id, uint16_t bit_rate_kbit) override;

  RowDictionary& dictionary_;
  board::CanController& can_;
  NodeApplication& application_;
  const NodeDescription& description_;
  NodeConfig config_;
  CommunicationConfig communication_{};
  NodeSettings node_settings_{};
  uint8_t node_id_ = 1;
  uint16_t bit_rate_kbit_ = 1000;
  uint16_t lss_bit_rate_kbit_ = 0;  // activated by LSS since power-up (0: none)
  uint8_t error_register_ = 0;
  uint64_t reported_refused_writes_ = 0;
  uint64_t reported_rpdo_writes_ = 0;
  bool parameter_error_ = false;  // the RPDO value EMCY sent, not yet cleared
  uint32_t service_elapsed_us_ = 0;
  bool restarting_ = false;
  uint32_t restart_remaining_us_ = 0;

  NmtSlave nmt_;
  SdoServer sdo_;
  EmergencyProducer emergency_;
  HeartbeatConsumer heartbeat_consumer_;
  NodeGuarding node_guarding_;
  SyncService sync_;
  PdoService pdos_;
  LssSlave lss_;
  ObjectStorage storage_;
  uint8_t communication_errors_ = 0;
  // What kCommErrorCanController stands for now (the last state reported).
  enum class CanControllerError : uint8_t { kNone, kErrorPassive, kBusOff, kRecovered };
  CanControllerError can_controller_error_ = CanControllerError::kNone;
  uint32_t bus_off_recoveries_ = 0;  // board::CanControllerStatus::bus_off_recoveries seen

  std::array<can::CanFrame, kReceiveQueueLength> receive_queue_{};
  size_t receive_head_ = 0;
  size_t receive_count_ = 0;
  uint64_t dropped_frames_ = 0;
  uint64_t reported_dropped_frames_ = 0;
};

}  // namespace motwin::canopen
