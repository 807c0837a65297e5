// The TMCM-3216 with its CANopen firmware V1.04: a CANopen node (core/canopen/node.h: NMT with
// boot-up and heartbeat, SDO, PDO, SYNC, EMCY, heartbeat consumer, LSS, storage) with the
// manual's identity, communication objects (chapter 3, tmcm3216_objects.cpp), PDO numbering and
// defaults, node ID and bit rate objects 2704..2708 (4.2.62..4.2.66) and restart timing; and the
// application behind it: the three-axis CiA-402 drive (Tmcm3216Drive per axis) on the stepper
// axes of its board (Tmcm3216Stepper, board/modules/tmcm3216/tmcm3216_board.h) with the
// emergencies of table 365. docs/tmcm-3216-drive.md.
#pragma once

#include <array>
#include <cstddef>
#include <cstdint>
#include <span>
#include <string_view>

#include "board/can_controller.h"
#include "board/non_volatile_memory.h"
#include "board/modules/tmcm3216/tmcm3216_board.h"
#include "core/canopen/node.h"
#include "core/canopen/object_dictionary.h"
#include "core/modules/tmcm3216/tmcm3216_drive.h"
#include "core/modules/tmcm3216/tmcm3216_emergencies.h"
#include "core/modules/tmcm3216/tmcm3216_hardware.h"
#include "core/modules/tmcm3216/tmcm3216_io.h"
#include "core/modules/tmcm3216/tmcm3216_stepper.h"
#include "types/can_frame.h"

namespace motwin::modules::tmcm3216 {

inline constexpr uint8_t kPdosPerAxis = 4;       // RPDO/TPDO 1..4, 65..68, 129..132 (manual 1.1)
inline constexpr uint8_t kMaxMappedObjects = 3;  // "dynamic mapping with max. three mapping entries"
inline constexpr uint16_t kPdoAxisStride = 0x40; // 1400 -> 1440 -> 1480 (manual 3.1.15)
inline constexpr size_t kPdoCount = kAxisCount * kPdosPerAxis;  // per direction; PDO K of axis n at n * 4 + K
static_assert(kPdoCount <= canopen::kNodeMaxPdos);
// The motion tick is kTickUs (tmcm3216_hardware.h). The CANopen services keep their millisecond
// timers: they run once per kServicePeriodUs of ticks (and at once whenever a frame arrives, so
// that an SDO request is answered within the tick or process() call that sees it).
inline constexpr uint32_t kServicePeriodUs = canopen::Node::kServicePeriodUs;

using PdoCommunication = canopen::PdoCommunication;
using PdoMapping = canopen::PdoMapping;  // entries 1..kMaxMappedObjects used
// The communication objects a master writes and the stored node ID / bit rate (2704 / 2705) are
// the node's (core/canopen/node.h).
using CommunicationConfig = canopen::CommunicationConfig;
using NodeSettings = canopen::NodeSettings;
// The module's address switches, its serial number (1018 sub 4) and restart times: the node's
// config. `motwin serve` uses Tmcm3216::kBootDelayUs and kCommunicationBootDelayUs.
using Tmcm3216Config = canopen::NodeConfig;

// Manual table 177.
inline constexpr uint16_t kBitRatesKbit[] = {20, 50, 100, 125, 250, 500, 800, 1000};

// 1010 / 1011 (tables 23, 26): sub 1 everything (restore: all but the node ID and bit rate,
// which would cut the module off its bus), sub 2 the node settings 2704/2705 (restore: "no
// function", manual 3.1.8), sub 3 device profile parameters "not used", subs 4..6 motor n.
inline constexpr uint8_t kAllAxesMask = (1u << kAxisCount) - 1;
inline constexpr canopen::StorageSubIndex kStorageSubIndices[] = {
    {"Save all parameters", "Restore all parameters", true,
     {.communication = true, .node_settings = true, .axis_mask = kAllAxesMask}, true,
     {.communication = true, .axis_mask = kAllAxesMask}},
    {"Save communication parameters", "Restore communication parameters", true, {.node_settings = true}, true, {}},
    {"Save device profile parameters", "Restore device profile parameters", false, {}, false, {}},
    {"Save motor 0 parameters", "Restore motor 0 parameters", true, {.axis_mask = 1}, true, {.axis_mask = 1}},
    {"Save motor 1 parameters", "Restore motor 1 parameters", true, {.axis_mask = 2}, true, {.axis_mask = 2}},
    {"Save motor 2 parameters", "Restore motor 2 parameters", true, {.axis_mask = 4}, true, {.axis_mask = 4}},
};

class Tmcm3216 final : private canopen::NodeApplication {
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
  static constexpr uint32_t kSaveSignature = canopen::kSaveSignature;
  static constexpr uint32_t kLoadSignature = canopen::kLoadSignature;

  static constexpr uint32_t kNvmLayoutVersion = 1;
  static constexpr size_t kNvmRecordCapacity = 1024;
  static constexpr size_t kNvmSize = canopen::StorageImage::size_for(kNvmRecordCapacity);
  static constexpr size_t kReceiveQueueLength = canopen::Node::kReceiveQueueLength;
  // The restart times `motwin serve` gives the module unless told otherwise (Tmcm3216Config); the
  // manual gives none.
  static constexpr uint32_t kBootDelayUs = canopen::kDefaultBootDelayUs;
  static constexpr uint32_t kCommunicationBootDelayUs = canopen::kDefaultCommunicationBootDelayUs;

  // What the node knows of the firmware: identity, PDOs, bit rates, storage, and the EMCY bytes of
  // table 365 (byte 2 the motor, 255 for the communication errors; 6320 for a refused RPDO value).
  // An LSS slave; no node guarding (manual 1.1: RTR frames are not answered).
  static constexpr canopen::NodeDescription kNode{.identity = {kVendorId, kProductCode, kRevisionNumber},
                                                  .pdo_count = kPdoCount,
                                                  .bit_rates_kbit = kBitRatesKbit,
                                                  .storage = kStorageSubIndices,
                                                  .communication_emcy_data = {0, 255, 0, 0, 0}};
  static_assert(kNode.rpdo_value_emcy == kEmcyPdoParameter);
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
  void power_up() {
    axes_touched_ = true;
    node_.power_up();
  }
  // A frame from the bus (the CAN receive interrupt): queued for the next process() call.
  // false: the queue was full and the frame is lost.
  bool receive(const can::CanFrame& frame) { return node_.receive(frame); }
  // Handles the queued frames, then advances the services' timers by `elapsed_us`.
  void process(uint32_t elapsed_us) {
    axes_touched_ = true;  // whatever the services do to the axes, their next tick is a full one
    node_.process(elapsed_us);
  }
  // One motion tick: queued frames, the services once per kServicePeriodUs, then every axis
  // (drive, stepper) and the I/O against the board.
  void tick();

  // The CANopen node (CiA-301 services, communication objects).
  canopen::Node& node() { return node_; }
  uint8_t node_id() const { return node_.node_id(); }              // active (2708)
  uint16_t bit_rate_kbit() const { return node_.bit_rate_kbit(); }  // active (2707)
  bool configured() const { return node_.configured(); }
  // Between a power-up or NMT reset and the boot-up (Tmcm3216Config's delays): frames received
  // are dropped, nothing is sent.
  bool restarting() const { return node_.restarting(); }
  canopen::NmtState nmt_state() const { return node_.nmt_state(); }
  // 1001: communication bits, the FAULT bits of the axes, the active conditions of table 365.
  uint8_t error_register() const { return node_.error_register(); }
  uint64_t dropped_frames() const { return node_.dropped_frames(); }
  // Communication errors now active (kCommError* bits); 1001 bit 4 while any is.
  uint8_t communication_errors() const { return node_.communication_errors(); }
  static constexpr uint8_t kCommErrorHeartbeat = canopen::Node::kCommErrorHeartbeat;
  static constexpr uint8_t kCommErrorCanOverrun = canopen::Node::kCommErrorCanOverrun;
  static constexpr uint8_t kCommErrorPdoLength = canopen::Node::kCommErrorPdoLength;
  static constexpr uint8_t kCommErrorPdoLengthExceeded = canopen::Node::kCommErrorPdoLengthExceeded;
  static constexpr uint8_t kCommErrorCanController = canopen::Node::kCommErrorCanController;

  // The accessors that let a caller change the axes' objects or state directly wake the resting
  // axes (run_axes()) as a frame does.
  Dictionary& dictionary() {
    axes_touched_ = true;
    return dictionary_;
  }
  canopen::NmtSlave& nmt() { return node_.nmt(); }
  canopen::SdoServer& sdo() { return node_.sdo(); }
  canopen::EmergencyProducer& emergency() { return node_.emergency(); }
  canopen::HeartbeatConsumer& heartbeat_consumer() { return node_.heartbeat_consumer(); }
  canopen::PdoService& pdos() { return node_.pdos(); }
  canopen::SyncService& sync() { return node_.sync(); }
  canopen::LssSlave& lss() { return node_.lss(); }
  CommunicationConfig& communication() { return node_.communication(); }
  NodeSettings& node_settings() { return node_.node_settings(); }
  const Tmcm3216Config& config() const { return node_.config(); }
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
  canopen::SdoAbort store_parameters(uint8_t sub, uint32_t signature) { return node_.store_parameters(sub, signature); }
  canopen::SdoAbort restore_parameters(uint8_t sub, uint32_t signature) {
    return node_.restore_parameters(sub, signature);
  }
  canopen::SdoAbort store_node_settings(uint32_t signature) { return node_.store_node_settings(signature); }

 private:
  // canopen::NodeApplication. NMT reset node (and power-up): every object of 2000h..9FFFh as
  // power-on builds it: the objects' structs value-initialised, the stored values loaded on top,
  // the axes' live state reset.
  void reset_application() override;
  // A SYNC seen or produced: csp/csv set-points of every axis (after the synchronous RPDOs).
  void on_sync() override;
  // Table 365, 8140: at bus-off "the drive has been stopped and disabled".
  void on_bus_off() override;
  // The FAULT bits of the axes and the active conditions of table 365.
  uint8_t application_error_register() const override {
    return static_cast<uint8_t>(axis_error_register() | emergencies_.error_register());
  }

  void reset_axes();
  void run_axes(uint32_t dt_us);
  // run_axis(), and whether it changed nothing but what rest() changes (the axis then rests).
  void run_axis_checking_rest(uint8_t axis, uint32_t dt_us);
  void run_axis(uint8_t axis, uint32_t dt_us);
  // 1001 bits of the axes: generic + device profile while an axis is in FAULT (or reacting).
  uint8_t axis_error_register() const;

  board::Tmcm3216Board own_board_{};  // used by the constructor without a board
  board::Tmcm3216Board& board_;

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
  std::array<uint8_t, kNvmSize> storage_scratch_{};
  canopen::Node node_;
};

}  // namespace motwin::modules::tmcm3216

// Instantiated once, in tmcm3216.cpp: the object rows' mapping checks look objects up too, and a
// second copy of the lookup would cost the core's text.
extern template class motwin::canopen::TableDictionary<motwin::modules::tmcm3216::Tmcm3216>;
