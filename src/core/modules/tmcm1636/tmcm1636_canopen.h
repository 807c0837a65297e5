// The TMCM-1636 with its CANopen firmware (V1.12, as Trinamic's published EDS describes it): a
// CANopen node (core/canopen/node.h) with the EDS's identity, communication objects, PDO defaults
// and node guarding, and the application behind it: one CiA-402 drive (Tmcm1636Drive: pp, pv, hm,
// csp, csv, cst) whose demand the servo axis of the TMCL firmware follows (Tmcm1636Axis: the same
// FOC current, velocity and position regulators, hall/ABN/absolute commutation, encoder
// initialisation, brake, brake chopper and protections, on the same board seam), the manufacturer
// objects 2003..2140 bound to that axis' settings, and the I/O (2702, 2703, 270E, 60FD).
// docs/tmcm-1636-canopen.md.
#pragma once

#include <array>
#include <cstddef>
#include <cstdint>
#include <span>
#include <string_view>

#include "board/can_controller.h"
#include "board/modules/tmcm1636/tmcm1636_io.h"
#include "board/non_volatile_memory.h"
#include "core/canopen/node.h"
#include "core/canopen/object_dictionary.h"
#include "core/cia402/trinamic_conventions.h"
#include "core/modules/tmcm1636/tmcm1636_axis.h"
#include "core/modules/tmcm1636/tmcm1636_canopen_drive.h"
#include "core/modules/tmcm1636/tmcm1636_hardware.h"
#include "types/can_frame.h"

namespace motwin::modules::tmcm1636 {

inline constexpr uint8_t kCanopenPdoCount = 4;         // RPDO/TPDO 1..4 (EDS NrOfRXPDO, NrOfTXPDO)
inline constexpr uint8_t kCanopenMappedObjects = 3;    // mapping sub-indices 1..3

// The EDS's BaudRate_* keys: no 10 and no 100 kbit/s.
inline constexpr uint16_t kCanopenBitRatesKbit[] = {20, 50, 125, 250, 500, 800, 1000};

// 1010 / 1011 sub 1 all (restore: all but the node ID and bit rate, which would cut the module off
// its bus), sub 2 communication (store: with the node ID and bit rate 2704/2705, the TMCM-1690
// manual's procedure), sub 3 application (the manufacturer objects: motor, sensors, regulators,
// I/O), sub 4 axis 0 (its CiA-402 settings). docs/tmcm-1636-canopen.md "Storage".
inline constexpr canopen::StorageSubIndex kCanopenStorage[] = {
    {.store_name = "Save all Parameters",
     .restore_name = "Restore all Default Parameters",
     .store_supported = true,
     .store = {.communication = true, .node_settings = true, .application = true, .axis_mask = 1},
     .restore_supported = true,
     .restore = {.communication = true, .application = true, .axis_mask = 1}},
    {.store_name = "Save Communication Parameters",
     .restore_name = "Restore Communication Default Parameters",
     .store_supported = true,
     .store = {.communication = true, .node_settings = true},
     .restore_supported = true,
     .restore = {.communication = true}},
    {.store_name = "Save Application Parameters",
     .restore_name = "Restore Application Default Parameters",
     .store_supported = true,
     .store = {.application = true},
     .restore_supported = true,
     .restore = {.application = true}},
    {.store_name = "Save Axis 0 Parameters",
     .restore_name = "Restore Axis 0 Default Parameters",
     .store_supported = true,
     .store = {.axis_mask = 1},
     .restore_supported = true,
     .restore = {.axis_mask = 1}},
};

// 2101 Status Flags, the layout PyTrinamic's TMCM-1636 CANopen example decodes (with the family's
// other bits; docs/tmcm-1636-canopen.md "Status flags").
enum CanopenStatusFlag : uint32_t {
  kFlagOvercurrent = 1u << 0,
  kFlagUndervoltage = 1u << 1,
  kFlagOvervoltage = 1u << 2,
  kFlagOvertemperature = 1u << 3,
  kFlagMotorHalted = 1u << 4,
  kFlagHallError = 1u << 5,
  kFlagStopMode = 1u << 8,
  kFlagVelocityMode = 1u << 9,
  kFlagPositionMode = 1u << 10,
  kFlagTorqueMode = 1u << 11,
  kFlagPositionEnd = 1u << 14,
  kFlagInitialized = 1u << 15,
};

// The CANopen object bound to the same axis setting as a TMCL axis parameter (table 11 and the
// 1.13 additions): where a preset's start-up settings, given as axis parameters, go in this
// firmware's image (host/modules/tmcm1636/tmcm1636_startup_image.*).
struct AxisParameterObject {
  uint8_t axis_parameter;
  uint16_t index;
  uint8_t sub;
};
inline constexpr AxisParameterObject kAxisParameterObjects[] = {
    {5, 0x2060, 3},   {6, 0x2060, 4},   {10, 0x2056, 0},  {11, 0x2003, 0},  {12, 0x2004, 0},  {13, 0x2057, 0},
    {14, 0x2050, 0},  {15, 0x2055, 0},  {25, 0x2043, 3},  {26, 0x2042, 5},  {56, 0x2058, 0},  {70, 0x2041, 1},
    {71, 0x2041, 2},  {72, 0x2042, 1},  {73, 0x2042, 2},  {74, 0x2043, 1},  {90, 0x2070, 1},  {91, 0x2070, 2},
    {92, 0x2070, 3},  {93, 0x2070, 4},  {100, 0x2080, 2}, {101, 0x2080, 1}, {102, 0x2080, 3}, {140, 0x2006, 1},
    {141, 0x2006, 2}, {142, 0x2006, 3}, {160, 0x2085, 1}, {161, 0x2085, 3}, {162, 0x2085, 2}, {163, 0x2085, 4},
    {165, 0x2085, 5}, {166, 0x2085, 6}, {167, 0x2085, 7},
};

// The objects of the module that are neither the axis' settings nor the drive's.
struct Tmcm1636CanopenObjects {
  // 2005 (cia402/trinamic_conventions.h; the EDS's default 3: neither limit switch used).
  uint32_t switch_parameters = cia402::switch_parameter::kLeftDisabled | cia402::switch_parameter::kRightDisabled;
  uint32_t outputs = 0;        // 2703 sub 1 as written: bit n for GPO n
  uint32_t output_mask = 0;    // 2703 sub 2: which outputs a write of sub 1 switches
  uint32_t output_levels = 0;  // the levels GPO n is switched to (bit n)
};

// 2703 sub 1's bits: GPO0 and GPO1; others name no output and are refused.
inline constexpr uint32_t kCanopenOutputBits = (1u << board::Tmcm1636Io::kDigitalOutputCount) - 1;

class Tmcm1636Canopen final : private canopen::NodeApplication {
 public:
  using Dictionary = canopen::TableDictionary<Tmcm1636Canopen>;
  using Row = canopen::EntryRow<Tmcm1636Canopen>;

  static constexpr std::string_view kName = "tmcm-1636";
  static constexpr std::string_view kDeviceName = "TMCM-1636";   // 1008
  static constexpr std::string_view kHardwareVersion = "1.1";    // 1009: the EDS file's "Hw1.1"
  static constexpr std::string_view kSoftwareVersion = "1.12";   // 100A
  static constexpr std::string_view kFirmwareVersion = "CANopen V1.12";
  // 1000 as the EDS gives it: profile 402, servo drive (bit 17), bit 22 set.
  static constexpr uint32_t kDeviceType = 0x0042'0192;
  static constexpr uint32_t kSingleDeviceType = 0x0002'0192;  // 67FF
  static constexpr uint32_t kVendorId = 0x0000'0286;
  static constexpr uint32_t kProductCode = 0x664;  // 1636
  static constexpr uint32_t kRevisionNumber = 0x0001'000C;

  // Node guarding (100C / 100D), no LSS (the EDS's LSS_Supported=0); the EMCY bytes as the
  // family's (byte 4 = 255 for the communication errors, TMCM-1690 manual).
  static constexpr canopen::NodeDescription kNode{.identity = {kVendorId, kProductCode, kRevisionNumber},
                                                  .pdo_count = kCanopenPdoCount,
                                                  .bit_rates_kbit = kCanopenBitRatesKbit,
                                                  .storage = kCanopenStorage,
                                                  .communication_emcy_data = {0, 255, 0, 0, 0},
                                                  .node_guarding = true,
                                                  .lss = false};
  // The restart times `motwin serve` gives the module unless told otherwise (no source gives the
  // TMCM-1636's), and its storage image.
  static constexpr uint32_t kBootDelayUs = canopen::kDefaultBootDelayUs;
  static constexpr uint32_t kCommunicationBootDelayUs = canopen::kDefaultCommunicationBootDelayUs;
  static constexpr uint32_t kNvmLayoutVersion = 1;
  static constexpr size_t kNvmSize = canopen::StorageImage::size_for(512);

  // Every object of the dictionary (tmcm1636_canopen_objects.cpp).
  static std::span<const Row> object_table();
  // An image with nothing stored: every object at its default.
  static void format_factory_image(uint8_t* image, size_t size);

  Tmcm1636Canopen(board::NonVolatileMemory& nvm, board::CanController& can, board::Tmcm1636Io& io,
                  const canopen::NodeConfig& config = {});
  Tmcm1636Canopen(const Tmcm1636Canopen&) = delete;
  Tmcm1636Canopen& operator=(const Tmcm1636Canopen&) = delete;

  // Power-on: every object from the NVM (or its default); after the boot delay the boot-up.
  void power_up() { node_.power_up(); }
  bool receive(const can::CanFrame& frame) { return node_.receive(frame); }
  void process(uint32_t elapsed_us) { node_.process(elapsed_us); }
  // One 50 µs control tick: the node's services (once per millisecond, or at once for a frame),
  // the drive once per kDrivePeriodUs, the axis' regulators every tick.
  void tick();
  // The CiA-402 drive (profile generator, PDS, monitoring) runs once a millisecond, as a servo
  // drive's application loop does above its current loop; the axis moves its reference on with the
  // demand's velocity in between (Tmcm1636Axis::follow_position). docs/tmcm-1636-canopen.md.
  static constexpr uint32_t kDrivePeriodUs = 1000;
  static constexpr uint32_t kDriveTicks = kDrivePeriodUs / kControlTickUs;

  canopen::Node& node() { return node_; }
  uint8_t node_id() const { return node_.node_id(); }
  uint16_t bit_rate_kbit() const { return node_.bit_rate_kbit(); }
  bool configured() const { return node_.configured(); }
  canopen::NmtState nmt_state() const { return node_.nmt_state(); }
  uint8_t error_register() const { return node_.error_register(); }
  Dictionary& dictionary() { return dictionary_; }
  Tmcm1636Drive& drive(uint8_t /*axis*/ = 0) { return drive_; }
  const Tmcm1636Drive& drive(uint8_t /*axis*/ = 0) const { return drive_; }
  Tmcm1636Axis& axis() { return axis_; }
  const Tmcm1636Axis& axis() const { return axis_; }
  board::Tmcm1636Io& io() { return io_; }
  Tmcm1636CanopenObjects& objects() { return objects_; }

  // Positions, velocities and torques between the drive's frame (2058 units per revolution, the
  // host's direction, 2057) and the axis' (AP 100 = 2080:2 counts per revolution, the motor's).
  int32_t drive_position(int32_t axis_counts) const;
  int32_t axis_position(int32_t drive_units) const;
  // The drive's demand position as the axis' position reference: its distance from where the
  // reference stands, taken in the drive's frame and converted, added to the reference. Both
  // counters wrap at 32 bits, the drive's in 2058 units and the axis' in its counts, so an absolute
  // conversion loses turns: with 2058 = 65536 and 2080:2 = 8192, 2^31 units are 2^28 counts, and an
  // axis beyond 32768 revolutions from its zero got a reference 65536 revolutions away (fuzz/README.md
  // "Findings"). A distance converts alike in any turn.
  int32_t axis_reference(int32_t drive_units) const;
  double drive_velocity(double axis_counts_per_s) const;
  double axis_velocity(double drive_units_per_s) const;
  int32_t directed(int32_t value) const {
    return axis_.config.motor_direction != 0 ? static_cast<int32_t>(0u - static_cast<uint32_t>(value)) : value;
  }

  // 2101: the axis' state in the firmware family's layout.
  uint32_t status_flags() const;
  // 60FD: bit 0 negative (left) limit switch, 1 positive (right), 2 home switch (active, as 2005
  // configures them), bits 16..19 GPI 0..3.
  uint32_t digital_inputs() const;
  // 2702: the general-purpose inputs' levels, bit n = GPI n.
  uint32_t device_digital_inputs() const;
  // 2703 sub 1 written (bits of kCanopenOutputBits only, the dictionary refuses others): it reads
  // back as written, and the outputs whose bit the mask (sub 2) sets switch to its bits, the
  // others keep their level (docs/canopen.md "2703 sub 1", the family's rule).
  void write_outputs(uint32_t value);

 private:
  // canopen::NodeApplication.
  void reset_application() override;
  void on_sync() override { drive_.on_sync(); }
  void on_bus_off() override;
  uint8_t application_error_register() const override;

  void run_drive(uint32_t dt_us);
  // The velocity factors between the drive's and the axis' frames, derived again when 2058 or
  // 2080:2 changed (not a division per tick).
  void refresh_frames();
  cia402::AxisInputs axis_inputs() const;
  void carry_out(const cia402::AxisDemand& demand);
  void report_drive_emergencies();
  void apply_outputs();

  board::Tmcm1636Io& io_;
  Tmcm1636Axis axis_{};
  Tmcm1636Drive drive_{};
  Tmcm1636CanopenObjects objects_{};
  bool driver_enabled_ = false;  // what the axis was last told (AP 255)
  uint32_t drive_ticks_ = 0;     // control ticks since the drive ran
  uint32_t reported_protections_ = 0;  // status_flag bits of the protections whose EMCY went out
  struct Frames {
    int32_t position_scaler = 0;
    int32_t encoder_steps = -1;  // never a setting: the first refresh derives the factors
    double drive_units_per_count = 0.0;
    double counts_per_drive_unit = 0.0;
  } frames_;

  Dictionary dictionary_;
  std::array<uint8_t, kNvmSize> storage_scratch_{};
  canopen::Node node_;
};

}  // namespace motwin::modules::tmcm1636

extern template class motwin::canopen::TableDictionary<motwin::modules::tmcm1636::Tmcm1636Canopen>;
