// The TMCM-142 module profile (firmware 142V1.06): single-axis stepper with the TMC457 feature set
// (S-ramps, up to 1024 microsteps, ABN encoder with easyPID, reference search, coordinates) and the
// TMCL ASCII interface, on the TMCL module base (core/tmcl/tmcl_module.h). Parameter numbers follow
// docs/tmcm-142.md "Sources"; the ones Motwin had to number are marked in the tables
// (docs/tmcm-142.md).
#pragma once

#include <array>
#include <cstddef>
#include <cstdint>
#include <string_view>

#include "board/non_volatile_memory.h"
#include "board/stepper_drive.h"
#include "board/modules/tmcm142/tmcm142_io.h"
#include "core/modules/tmcm142/tmcm142_axis.h"
#include "core/modules/tmcm142/tmcm142_hardware.h"
#include "core/params/parameter_table.h"
#include "core/tmcl/device.h"
#include "core/tmcl/engine.h"
#include "core/tmcl/module_storage.h"
#include "core/tmcl/nvm_layout.h"
#include "core/tmcl/program_memory.h"
#include "core/tmcl/tmcl_module.h"

namespace motwin::modules::tmcm142 {

// GP 84: where coordinates 1..20 live.
enum class CoordinateStorage : int32_t { kRam = 0, kEeprom = 1 };

// Bank 0 settings (docs/tmcm-142.md "Global parameters (bank 0)", TMCM-351 V4.45 as the same
// generation's stand-in).
struct GlobalConfig {
  int32_t eeprom_magic = 228;          // GP 64: another value re-initialises the image at power-up
  int32_t serial_baud_rate_code = 0;   // GP 65: 9600 bit/s (manual 5.1); no effect on a pseudo-terminal
  int32_t serial_address = 1;          // GP 66
  int32_t ascii_mode = 0;              // GP 67: bit 0 start in ASCII mode, bits 4-5 echo
  int32_t can_bit_rate_code = 8;       // GP 69
  int32_t can_reply_id = 2;            // GP 70
  int32_t can_id = 1;                  // GP 71
  int32_t telegram_pause_ms = 0;       // GP 75
  int32_t serial_host_address = 2;     // GP 76
  int32_t auto_start_mode = 1;         // GP 77
  CoordinateStorage coordinate_storage = CoordinateStorage::kRam;  // GP 84: RAM copies on request
  int32_t skip_user_variable_restore = 0;  // GP 85
  // Stored only (docs/tmcm-142.md "Global parameters (bank 0)").
  int32_t serial_heartbeat_ms = 0;       // GP 68
  int32_t code_protection = 0;           // GP 81
  int32_t can_heartbeat_ms = 0;          // GP 82
  int32_t can_secondary_id = 0;          // GP 83
  int32_t serial_secondary_address = 0;  // GP 87
};

inline constexpr size_t kStorableUserVariables = 56;  // 0..55
inline constexpr size_t kProgramCapacity = 2048;      // manual 2: "Memory for 2048 TMCL commands"
inline constexpr uint8_t kCoordinateCount = 21;       // 0..20; 0 is RAM only
inline constexpr int32_t kEepromMagic = 228;          // GP 64 of a valid image
inline constexpr int32_t kLockCode = 1234;            // GP 73
inline constexpr int32_t kUnlockCode = 4321;

inline constexpr tmcl::ModuleFacts kFacts{
    .name = "tmcm-142",
    .identity = {142, 1, 6, "142V1.06"},
    .nvm_layout = tmcl::make_nvm_layout(1, kStorableUserVariables, kProgramCapacity, kCoordinateCount),
    // 2: the real module's numbering (docs/tmcm-142.md "EEPROM image"); migrate_image() takes 1.
    .nvm_layout_version = 2,
    .control_tick_us = kControlTickUs,
    // ROR/ROL write the target speed (AP 2) in the units of AP 255, MVP the target position (AP 0).
    .motion = {.target_position = 0, .target_velocity = 2},
};

// Runtime, tick timer, program memory, engine, I/O banks and the common motion commands come
// from tmcl::TmclModule, the parameter commands, storage and power-up from tmcl::ModuleStorage;
// the module adds its tables, the power stage, the EEPROM lock, the coordinates, the reference
// search and GP 133.
class Tmcm142 final : public tmcl::TmclModule<Tmcm142, Tmcm142Axis, GlobalConfig, board::Tmcm142Io, kFacts> {
 public:
  Tmcm142(board::NonVolatileMemory& nvm, board::StepperPowerStage& stage, board::Tmcm142Io& io)
      : TmclModule(nvm, io), stage_(stage) {}

  static const Table& axis_parameters();
  static const Table& global_parameters();  // bank 0
  // Brings an image of an older NVM layout (`from_layout_version`) to kNvmLayoutVersion in place:
  // layout 1 numbered four bows AP 16..19, the encoder direction AP 46 and the standby delay
  // AP 214. False for a version it does not know or an image of the wrong size (left unchanged).
  static bool migrate_image(uint32_t from_layout_version, uint8_t* image, size_t size);
  // format_factory_image(image, size): tmcl::ModuleStorage.

  board::StepperPowerStage& power_stage() { return stage_; }
  bool eeprom_locked() const { return eeprom_locked_; }
  int32_t coordinate(uint8_t number) const { return coordinates_[number]; }

  // tmcl::TmclModule hook: one 50 µs control tick of the axis (feedback in, drive out). The
  // board fills stage.feedback before and applies stage.drive after.
  void tick_axis() {
    axis().tick(stage_);
    if (axis().take_deviation_event()) runtime().error_flags |= tmcl::kErrorDeviation;
  }

  // TmclDevice: what the TMCL module base does not answer, or answers differently.
  tmcl::Status move(uint8_t motor, uint8_t move_type, int32_t value) override;
  tmcl::Status set_coordinate(uint8_t number, uint8_t motor, int32_t position) override;
  tmcl::Status get_coordinate(uint8_t number, uint8_t motor, int32_t& position) override;
  tmcl::Status capture_coordinate(uint8_t number, uint8_t motor) override;

  // Used by the table bindings.
  // GP 73: 1234 locks, 4321 unlocks (stored at once, even while locked); other values status 4.
  tmcl::Status set_eeprom_lock(int32_t code);
  int32_t next_random();  // GP 133

  // tmcl::ModuleStorage hooks.
  void clear_ram_state();
  void before_axis_restore();
  void after_restore();

 private:
  tmcl::Status store_coordinate(uint8_t number);
  void load_coordinate(uint8_t number);

  board::StepperPowerStage& stage_;
  bool eeprom_locked_ = false;
  std::array<int32_t, kCoordinateCount> coordinates_{};
  uint32_t random_state_ = 0x142142u;
};

}  // namespace motwin::modules::tmcm142
