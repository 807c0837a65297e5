// The TMCM-1636 module profile: its parameter tables, its axis and its I/O on the TMCL module
// base (core/tmcl/tmcl_module.h), behind the TmclDevice interface the TMCL engine dispatches
// into. Two firmware generations (docs/tmcm-1636.md "Firmware generations"): 1636V109, the
// manual Motwin follows and the default, and 1636V113, the later revision PyTrinamic's TMCM1636
// class targets. A generation is const configuration chosen at construction: its identity and
// its axis-parameter rows; the code is the same.
#pragma once

#include <array>
#include <cstddef>
#include <cstdint>
#include <string_view>

#include "board/non_volatile_memory.h"
#include "board/modules/tmcm1636/tmcm1636_io.h"
#include "core/modules/tmcm1636/tmcm1636_axis.h"
#include "core/modules/tmcm1636/tmcm1636_hardware.h"
#include "core/params/parameter_table.h"
#include "core/tmcl/device.h"
#include "core/tmcl/engine.h"
#include "core/tmcl/module_storage.h"
#include "core/tmcl/nvm_layout.h"
#include "core/tmcl/program_memory.h"
#include "core/tmcl/module_datalogger.h"
#include "core/tmcl/ramdebug.h"
#include "core/tmcl/tmcl_module.h"

namespace motwin::modules::tmcm1636 {

// Bank 0 settings (manual table 13). GP 66/76 defaults follow docs/decisions.md
// "Errata in the manuals" (1 and 2).
struct GlobalConfig {
  int32_t serial_baud_rate_code = 7;   // GP 65, 115200 bit/s; no effect on a pseudo-terminal
  int32_t serial_address = 1;          // GP 66
  int32_t ascii_mode = 0;              // GP 67 (Motwin extension): ASCII interface start mode and echo
  int32_t can_bit_rate_code = 8;       // GP 69, 1000 kbit/s
  int32_t can_send_id = 2;             // GP 70
  int32_t can_receive_id = 1;          // GP 71
  int32_t telegram_pause_ms = 0;       // GP 75
  int32_t serial_host_address = 2;     // GP 76
  int32_t auto_start_mode = 1;         // GP 77
  int32_t skip_user_variable_restore = 0;  // GP 85 (manual 6.4): 1 = user variables start at 0
};

inline constexpr size_t kUserVariableCount = tmcl::kUserVariableCount;  // bank 2
inline constexpr size_t kStorableUserVariables = 56;  // 0..55 (manual 4.2)
inline constexpr size_t kProgramCapacity = 2048;      // instructions

// The firmware generations, oldest first.
enum class Firmware : uint8_t { kV109, kV113 };

inline constexpr tmcl::FirmwareIdentity kIdentityV113{1636, 1, 13, "1636V113"};

// The datalogger (command 142, docs/datalogger.md). The TMCM-1636's own figures are not public;
// these are what the sister module TMCM-1617 reports in PyTrinamic's hardware test: a 2000 Hz
// base rate, 8192 words of buffer, 4 channels. The base rate divides the 20 kHz control tick.
inline constexpr uint32_t kRamDebugBaseRateHz = 2000;
inline constexpr size_t kRamDebugBufferWords = 8192;
inline constexpr uint32_t kRamDebugChannels = 4;
inline constexpr uint32_t kControlTicksPerRamDebugTick = 1'000'000 / kControlTickUs / kRamDebugBaseRateHz;
static_assert(kControlTicksPerRamDebugTick * kRamDebugBaseRateHz * kControlTickUs == 1'000'000,
              "the datalogger's base rate divides the control tick rate");
inline constexpr tmcl::RamDebugConfig kRamDebugConfig{kRamDebugChannels, kRamDebugBaseRateHz,
                                                      kControlTicksPerRamDebugTick};

inline constexpr tmcl::ModuleFacts kFacts{
    .name = "tmcm-1636",
    .identity = {1636, 1, 9, "1636V109"},
    .nvm_layout = tmcl::make_nvm_layout(1, kStorableUserVariables, kProgramCapacity),
    .nvm_layout_version = 1,
    .control_tick_us = kControlTickUs,
    // ROR/ROL write the target velocity (AP 40) in rpm, MVP the target position (AP 50)
    // (docs/tmcm-1636.md).
    .motion = {.target_position = 50, .target_velocity = 40},
};

// Runtime, tick timer, program memory, engine, I/O banks and the common motion commands come
// from tmcl::TmclModule, the parameter commands, storage and power-up from tmcl::ModuleStorage;
// the module adds its tables, the tick of its axis and the datalogger (commands 142 and 157, in
// both firmware generations: docs/datalogger.md).
class Tmcm1636 final : public tmcl::TmclModule<Tmcm1636, Tmcm1636Axis, GlobalConfig, board::Tmcm1636Io, kFacts> {
 public:
  Tmcm1636(board::NonVolatileMemory& nvm, board::Tmcm1636Io& io, Firmware firmware = Firmware::kV109)
      : TmclModule(nvm, io), firmware_(firmware), axis_table_(&axis_parameters(firmware)) {
    axis().set_position_scaler_applies(firmware == Firmware::kV113);
  }

  // Firmware 1.09's axis parameters (manual table 11), and those of a generation.
  static const Table& axis_parameters() { return axis_parameters(Firmware::kV109); }
  static const Table& axis_parameters(Firmware firmware);
  static const Table& global_parameters();  // bank 0, the same in every generation
  static const tmcl::FirmwareIdentity& identity_of(Firmware firmware) {
    return firmware == Firmware::kV113 ? kIdentityV113 : kIdentity;
  }
  // format_factory_image(image, size[, axis table]): tmcl::ModuleStorage.

  Firmware firmware() const { return firmware_; }
  // tmcl::ModuleStorage hook: the rows of this instance's generation.
  const Table& axis_table() const { return *axis_table_; }
  // TmclDevice: command 136 of this generation.
  const tmcl::FirmwareIdentity& identity() const override { return identity_of(firmware_); }
  // tmcl::TmclModule hook: MVP REL adds to the position as AP 52 reads it (on 1.13 in the host's
  // direction, AP 13, and units, AP 56).
  int32_t host_actual_position(uint8_t motor) {
    int32_t position = 0;
    (void)axis_table().read(*this, motor, 52, position);
    return position;
  }

  // tmcl::TmclModule hook: one 50 µs control tick of the axis, then the datalogger samples
  // what this tick computed.
  void tick_axis() {
    axis().tick(io(), static_cast<double>(kControlTickUs) * 1e-6);
    datalogger_.control_tick();
  }

  // tmcl::ModuleStorage hooks.
  void clear_ram_state() {
    TmclModule::clear_ram_state();
    datalogger_.init();
  }
  void after_axis_restore() { axis().finish_restore(); }  // later writes are host commands

  // TmclDevice: commands 142 and 157.
  tmcl::Status ram_debug(uint8_t type, uint8_t motor, int32_t& value) override {
    return datalogger_.ram_debug().execute(type, motor, value);
  }
  tmcl::Status get_info(uint8_t type, uint8_t /*motor*/, int32_t& value) override { return firmware_info(type, value); }

 private:
  Firmware firmware_;
  const Table* axis_table_;
  tmcl::ModuleDatalogger<Tmcm1636, kRamDebugBufferWords> datalogger_{*this, kRamDebugConfig};
};

}  // namespace motwin::modules::tmcm1636
