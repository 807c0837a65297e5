// The TMCM-3216 with its CANopen firmware V1.04: the communication area of the object dictionary
// (manual chapter 3), the node ID and bit rate objects 2704..2708 (4.2.62..4.2.66), NMT with
// boot-up and heartbeat, the SDO server, and store/restore through the board's non-volatile
// memory, the EMCY producer and the heartbeat consumer with the 1029 error behaviour, RPDOs and
// TPDOs with the manual's numbering and defaults, SYNC (consumer; producer as a Motwin extension)
// and the LSS slave; and the three-axis CiA-402 drive (Tmcm3216Drive per axis) on the
// stepper axes of its board (Tmcm3216Stepper, board/modules/tmcm3216/tmcm3216_board.h). docs/tmcm-3216-drive.md.
#pragma once

#include <array>
#include <cstddef>
#include <cstdint>
#include <span>
#include <string_view>

#include "board/can_controller.h"
#include "board/non_volatile_memory.h"
#include "board/modules/tmcm3216/tmcm3216_board.h"
#include "core/canopen/emergency.h"
#include "core/modules/tmcm3216/tmcm3216_drive.h"
#include "core/modules/tmcm3216/tmcm3216_emergencies.h"
#include "core/canopen/heartbeat_consumer.h"
#include "core/canopen/nmt.h"
#include "core/canopen/lss_slave.h"
#include "core/canopen/object_dictionary.h"
#include "core/canopen/pdo.h"
#include "core/canopen/sdo_server.h"
#include "core/canopen/storage.h"
#include "core/canopen/sync.h"
#include "core/modules/tmcm3216/tmcm3216_io.h"
#include "core/modules/tmcm3216/tmcm3216_stepper.h"
#include "types/can_frame.h"

namespace motwin::modules::tmcm3216 {

inline constexpr uint8_t kAxisCount = 3;
inline constexpr uint8_t kPdosPerAxis = 4;       // RPDO/TPDO 1..4, 65..68, 129..132 (manual 1.1)
inline constexpr uint8_t kMaxMappedObjects = 3;  // "dynamic mapping with max. three mapping entries"
inline constexpr uint16_t kPdoAxisStride = 0x40; // 1400 -> 1440 -> 1480 (manual 3.1.15)
inline constexpr size_t kPdoCount = kAxisCount * kPdosPerAxis;  // per direction; PDO K of axis n at n * 4 + K
// The motion tick (same as the TMCM-142): each tick the sim board senses, tick() runs the drives
// and steppers, the plants advance kTickUs. The CANopen services keep their millisecond timers:
// they run once per kServicePeriodUs of ticks (and at once whenever a frame arrives, so that an
// SDO request is answered within the tick or process() call that sees it).
inline constexpr uint32_t kTickUs = 50;
inline constexpr uint32_t kServicePeriodUs = 1000;

using PdoCommunication = canopen::PdoCommunication;
using PdoMapping = canopen::PdoMapping;  // entries 1..kMaxMappedObjects used

// The communication objects a master writes (1005..1029, 1400..1A03 of each axis).
struct CommunicationConfig {
  uint32_t sync_cob_id;              // 1005
  uint32_t sync_period_us;           // 1006
  uint32_t emcy_cob_id;              // 1014
  uint16_t emcy_inhibit_100us;       // 1015
  uint32_t consumer_heartbeat[1];    // 1016 sub 1
  uint16_t producer_heartbeat_ms;    // 1017
  uint8_t error_behavior[2];         // 1029 sub 1, 2
  PdoCommunication rpdo[kPdoCount];
  PdoMapping rpdo_mapping[kPdoCount];
  PdoCommunication tpdo[kPdoCount];
  PdoMapping tpdo_mapping[kPdoCount];
};

// 2704 / 2705: what applies after the next reset (2707 / 2708 show what applies now).
struct NodeSettings {
  uint16_t bit_rate_kbit;
  uint8_t node_id;  // 1..127, 255 = LSS unconfigured
};

struct Tmcm3216Config {
  // The module's address switches: 1..127 overrides the stored node ID (2705), as the manual
  // says switches do (4.2.63); 0 = no switches, 2705 decides.
  uint8_t node_id_switches = 0;
  uint32_t serial_number = 0;  // 1018 sub 4
  // Restart times in simulated µs: from power-up or NMT reset node, and from NMT reset
  // communication (also the one an LSS switch to waiting makes), to the boot-up message. The node
  // hears and sends nothing meanwhile. 0 boots at once (the protocol tests); `motwin serve` uses
  // Tmcm3216::kBootDelayUs and kCommunicationBootDelayUs (docs/canopen.md "Start-up timing").
  uint32_t boot_delay_us = 0;
  uint32_t communication_boot_delay_us = 0;
};

class Tmcm3216 final : private canopen::LssDevice {
 public:
  using Dictionary = canopen::TableDictionary<Tmcm3216>;
  using Row = canopen::EntryRow<Tmcm3216>;

  static constexpr std::string_view kName = "tmcm-3216";
  static constexpr std::string_view kDeviceName = "TMCM-3216";      // 1008
  static constexpr std::string_view kHardwareVersion = "1.00";      // 1009 (manual's example)
  static constexpr std::string_view kSoftwareVersion = "1.04";      // 100A: firmware V1.04
  static constexpr std::string_view kFirmwareVersion = "CANopen V1.04";
  // 1000: CiA-301's value for a multi-device module (upper 16 bits FFFF), profile 402; table 8
  // prints 0xFFFC0192 (docs/canopen.md "Decisions", issue 7). Each axis has its own 67FF.
  static constexpr uint32_t kDeviceType = 0xFFFF'0192;
  static constexpr uint32_t kVendorId = 0x0000'0286;
  static constexpr uint32_t kProductCode = 3216;
  static constexpr uint32_t kRevisionNumber = 0x0001'0004;  // major << 16 | minor, "20003h for 2.3"
  static constexpr uint32_t kSaveSignature = 0x6576'6173;   // "save"
  static constexpr uint32_t kLoadSignature = 0x6461'6F6C;   // "load"

  static constexpr uint32_t kNvmLayoutVersion = 1;
  static constexpr size_t kNvmRecordCapacity = 1024;
  static constexpr size_t kNvmSize = canopen::StorageImage::size_for(kNvmRecordCapacity);
  static constexpr size_t kReceiveQueueLength = 32;
  // The restart times `motwin serve` gives the module unless told otherwise (Tmcm3216Config).
  // The manual gives none: a Motwin decision (docs/canopen.md "Start-up timing"). A reset node
  // restarts the processor like a power-up (bootloader, three driver chips and the stored
  // parameters set up again); a reset communication only sets up the CANopen stack again.
  static constexpr uint32_t kBootDelayUs = 300'000;
  static constexpr uint32_t kCommunicationBootDelayUs = 50'000;

  // Every object of the dictionary (tmcm3216_objects.cpp).
  static std::span<const Row> object_table();
  // An image with nothing stored: every object at its default.
  static void format_factory_image(uint8_t* image, size_t size);

  Tmcm3216(board::NonVolatileMemory& nvm, board::CanController& can, board::Tmcm3216Board& board,
           const Tmcm3216Config& config = {});
  // Without a board: the module on a board of its own with nothing attached (communication tests).
  Tmcm3216(board::NonVolatileMemory& nvm, board::CanController& can, const Tmcm3216Config& config = {});
  Tmcm3216(const Tmcm3216&) = delete;
  Tmcm3216& operator=(const Tmcm3216&) = delete;

  // Power-on: every object from the NVM (or its default); after the boot delay the boot-up
  // message and pre-operational.
  void power_up();
  // A frame from the bus (the CAN receive interrupt): queued for the next process() call.
  // false: the queue was full and the frame is lost.
  bool receive(const can::CanFrame& frame);
  // Handles the queued frames, then advances the services' timers by `elapsed_us`.
  void process(uint32_t elapsed_us);
  // One motion tick: queued frames, the services once per kServicePeriodUs, then every axis
  // (drive, stepper) and the I/O against the board.
  void tick();

  uint8_t node_id() const { return node_id_; }            // active (2708)
  uint16_t bit_rate_kbit() const { return bit_rate_kbit_; }  // active (2707)
  bool configured() const { return node_id_ >= 1 && node_id_ <= 127; }
  // Between a power-up or NMT reset and the boot-up (Tmcm3216Config's delays): frames received
  // are dropped, nothing is sent.
  bool restarting() const { return restarting_; }
  canopen::NmtState nmt_state() const { return nmt_.state(); }
  // 1001: communication bits, the FAULT bits of the axes, the active conditions of table 365.
  uint8_t error_register() const {
    const uint8_t parameter = parameter_error_ ? canopen::kErrorRegisterGeneric : 0;
    return static_cast<uint8_t>(error_register_ | parameter | axis_error_register() | emergencies_.error_register());
  }
  uint64_t dropped_frames() const { return dropped_frames_; }
  // Communication errors now active (kCommError* bits); 1001 bit 4 while any is.
  uint8_t communication_errors() const { return communication_errors_; }
  static constexpr uint8_t kCommErrorHeartbeat = 0x01;
  static constexpr uint8_t kCommErrorCanOverrun = 0x02;
  static constexpr uint8_t kCommErrorPdoLength = 0x04;
  static constexpr uint8_t kCommErrorPdoLengthExceeded = 0x08;
  static constexpr uint8_t kCommErrorCanController = 0x10;  // error-passive, bus-off, just recovered

  // The accessors that let a caller change the axes' objects or state directly wake the resting
  // axes (run_axes()) as a frame does.
  Dictionary& dictionary() {
    axes_touched_ = true;
    return dictionary_;
  }
  canopen::NmtSlave& nmt() { return nmt_; }
  canopen::SdoServer& sdo() { return sdo_; }
  canopen::EmergencyProducer& emergency() { return emergency_; }
  canopen::HeartbeatConsumer& heartbeat_consumer() { return heartbeat_consumer_; }
  canopen::PdoService& pdos() { return pdos_; }
  canopen::SyncService& sync() { return sync_; }
  canopen::LssSlave& lss() { return lss_; }
  CommunicationConfig& communication() { return communication_; }
  NodeSettings& node_settings() { return node_settings_; }
  const Tmcm3216Config& config() const { return config_; }
  Tmcm3216Drive& drive(uint8_t axis) {
    axes_touched_ = true;
    return drives_[axis];
  }
  Tmcm3216Stepper& stepper(uint8_t axis) {
    axes_touched_ = true;
    return steppers_[axis];
  }
  const Tmcm3216Drive& drive(uint8_t axis) const { return drives_[axis]; }
  const Tmcm3216Stepper& stepper(uint8_t axis) const { return steppers_[axis]; }
  // Whether the axis rests: its last full tick changed nothing but the time counters, and it is
  // stepped by rest() until a frame, a service tick or its board feedback changes (run_axes()).
  bool axis_resting(uint8_t axis) const { return axis_resting_[axis]; }
  // Tests: false makes every tick a full one (the reference for the resting axes' tests).
  void set_resting_axes_enabled(bool enabled) {
    resting_enabled_ = enabled;
    axes_touched_ = true;
  }
  Tmcm3216GeneralIo& general_io() { return general_io_; }
  const Tmcm3216Emergencies& emergencies() const { return emergencies_; }
  board::Tmcm3216Board& board() { return board_; }

  // 1010 / 1011 / 2706 sub-index `sub` written with `signature`.
  canopen::SdoAbort store_parameters(uint8_t sub, uint32_t signature);
  canopen::SdoAbort restore_parameters(uint8_t sub, uint32_t signature);
  canopen::SdoAbort store_node_settings(uint32_t signature);

 private:
  // NMT reset node (and power-up): the application objects (manufacturer and profile areas) to
  // their power-on values, or the stored ones, then the communication reset.
  void reset_node();
  // Every object of 2000h..9FFFh as power-on builds it: the objects' structs value-initialised,
  // the stored values loaded on top, the axes' live state reset.
  void reset_application();
  void reset_axes();
  void run_axes(uint32_t dt_us);
  // run_axis(), and whether it changed nothing but what rest() changes (the axis then rests).
  void run_axis_checking_rest(uint8_t axis, uint32_t dt_us);
  void run_axis(uint8_t axis, uint32_t dt_us);
  // A SYNC seen or produced: csp/csv set-points of every axis (after the synchronous RPDOs).
  void sync_axes();
  // 1001 bits of the axes: generic + device profile while an axis is in FAULT (or reacting).
  uint8_t axis_error_register() const;
  // NMT reset communication: the objects 1000h..1FFFh to their stored values or defaults, the
  // node ID and bit rate as stored (2704/2705 themselves untouched), the services reset; the
  // boot-up follows after `boot_delay_us`.
  void reset_communication();
  void reset_communication(uint32_t boot_delay_us);
  // The restart ends: boot-up (when configured), pre-operational.
  void finish_restart();
  void handle_frame(const can::CanFrame& frame);
  void run_nmt(uint32_t elapsed_us);
  void run_heartbeat_consumer(uint32_t elapsed_us);
  void run_sync(uint32_t elapsed_us);
  void handle_pdo(const can::CanFrame& frame);
  // EMCY 6320 when RPDO writes since the last check had a value refused; 0000 when the next
  // RPDO is written whole.
  void check_rpdo_values();
  void check_receive_overrun(uint32_t elapsed_us);
  // The CAN controller's fault confinement (board::CanController::status()), once per service
  // tick: EMCY 8120 while error-passive, the running axes stopped at bus-off, 8140 once back.
  void check_can_controller();
  // Sets / clears one kCommError* bit, with its EMCY (code, or 0000 when it clears).
  void raise_error(uint8_t error, uint16_t emcy_code);
  void clear_error(uint8_t error);
  // Sets a kCommError* bit and sends `emcy_code` even if the bit was set already.
  void report_error(uint8_t error, uint16_t emcy_code);
  canopen::LssIdentity identity() const;
  // canopen::LssDevice.
  bool lss_bit_rate_supported(uint16_t bit_rate_kbit) const override;
  bool lss_store(uint8_t node_id, uint16_t bit_rate_kbit) override;

  board::NonVolatileMemory& nvm_;
  board::CanController& can_;
  board::Tmcm3216Board own_board_{};  // used by the constructor without a board
  board::Tmcm3216Board& board_;
  Tmcm3216Config config_;
  CommunicationConfig communication_{};
  NodeSettings node_settings_{};
  uint8_t node_id_ = 1;
  uint16_t bit_rate_kbit_ = 1000;
  uint16_t lss_bit_rate_kbit_ = 0;  // activated by LSS since power-up (0: none)
  uint8_t error_register_ = 0;
  uint64_t reported_refused_writes_ = 0;
  uint64_t reported_rpdo_writes_ = 0;
  bool parameter_error_ = false;  // EMCY 6320 sent, not yet cleared
  uint32_t service_elapsed_us_ = 0;
  bool restarting_ = false;
  uint32_t restart_remaining_us_ = 0;

  std::array<Tmcm3216Stepper, kAxisCount> steppers_{};
  std::array<Tmcm3216Drive, kAxisCount> drives_{};
  Tmcm3216GeneralIo general_io_{};
  Tmcm3216Emergencies emergencies_{};  // table 365 per axis: the single sender of the axes' EMCYs
  // Resting axes (docs/tmcm-3216-drive.md "Idle ticks"): an axis whose full tick changed nothing
  // but its time counters, with its power stage off or its motor standing still (within or past
  // the standby delay as in that tick), is stepped by rest() while nothing that run_axis() reads
  // changes: no process() call (frames, service ticks), no call of a mutable accessor, the same
  // board feedback, the board's drive as the axis left it.
  bool resting_enabled_ = true;
  bool axes_touched_ = true;
  std::array<bool, kAxisCount> axis_resting_{};
  std::array<board::StepperFeedback, kAxisCount> resting_feedback_{};
  std::array<board::StepperDrive, kAxisCount> resting_drive_{};
  // The state before a full tick with rest() applied, to compare with the state after it.
  Tmcm3216Drive rest_check_drive_{};
  Tmcm3216Stepper rest_check_stepper_{};
  Tmcm3216Emergencies rest_check_emergencies_{};

  Dictionary dictionary_;
  canopen::NmtSlave nmt_;
  canopen::SdoServer sdo_;
  canopen::EmergencyProducer emergency_;
  canopen::HeartbeatConsumer heartbeat_consumer_;
  canopen::SyncService sync_;
  canopen::PdoService pdos_;
  canopen::LssSlave lss_;
  uint8_t communication_errors_ = 0;
  // What kCommErrorCanController stands for now (the last state reported).
  enum class CanControllerError : uint8_t { kNone, kErrorPassive, kBusOff, kRecovered };
  CanControllerError can_controller_error_ = CanControllerError::kNone;
  uint32_t bus_off_recoveries_ = 0;  // board::CanControllerStatus::bus_off_recoveries seen
  std::array<uint8_t, kNvmSize> storage_scratch_{};
  canopen::ObjectStorage<Tmcm3216> storage_;

  std::array<can::CanFrame, kReceiveQueueLength> receive_queue_{};
  size_t receive_head_ = 0;
  size_t receive_count_ = 0;
  uint64_t dropped_frames_ = 0;
  uint64_t reported_dropped_frames_ = 0;
};

}  // namespace motwin::modules::tmcm3216

// Instantiated once, in tmcm3216.cpp: the object rows' mapping checks look objects up too, and a
// second copy of the lookup would cost the core's text.
extern template class motwin::canopen::TableDictionary<motwin::modules::tmcm3216::Tmcm3216>;
