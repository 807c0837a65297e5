// The TMCM-1636 module profile (firmware 1636V109): its parameter tables, its axis and its
// I/O, behind the TmclDevice interface the TMCL engine dispatches into.
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

namespace motwin::modules::tmcm1636 {

// Bank 0 settings (manual table 13). GP 66/76 defaults follow DESIGN.md errata (1 and 2).
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

// Parameter commands, storage and power-up come from tmcl::ModuleStorage.
class Tmcm1636 final : public tmcl::ModuleStorage<Tmcm1636> {
 public:
  static constexpr std::string_view kName = "tmcm-1636";
  static constexpr tmcl::FirmwareIdentity kIdentity{1636, 1, 9, "1636V109"};
  static constexpr uint8_t kMotorCount = 1;
  static constexpr tmcl::NvmLayout kNvmLayout = tmcl::make_nvm_layout(kMotorCount, kStorableUserVariables, kProgramCapacity);
  // Bumped whenever kNvmLayout or the meaning of a stored value changes.
  static constexpr uint32_t kNvmLayoutVersion = 1;

  using Table = params::ParameterTable<Tmcm1636>;
  static const Table& axis_parameters();
  static const Table& global_parameters();  // bank 0

  // format_factory_image(image, size): tmcl::ModuleStorage.

  // Does not touch `nvm` beyond reading it: call engine().power_up() to start.
  Tmcm1636(board::NonVolatileMemory& nvm, board::Tmcm1636Io& io);
  Tmcm1636(const Tmcm1636&) = delete;
  Tmcm1636& operator=(const Tmcm1636&) = delete;

  // The TMCL firmware of this module: command dispatcher and interpreter.
  tmcl::TmclEngine& engine() { return engine_; }

  // One 50 µs control tick: the axis, then at most one instruction of a running program.
  void tick();
  uint64_t tick_count() const { return tick_count_; }
  uint32_t tick_timer_ms() const { return tick_timer_ms_; }

  Tmcm1636Axis& axis() { return axis_; }
  const Tmcm1636Axis& axis() const { return axis_; }
  GlobalConfig& global_config() { return global_; }
  board::Tmcm1636Io& io() { return io_; }

  // TmclDevice.
  const tmcl::FirmwareIdentity& identity() const override { return kIdentity; }
  uint8_t motor_count() const override { return kMotorCount; }
  tmcl::SerialSettings serial_settings() const override;
  tmcl::TmclRuntime& runtime() override { return runtime_; }
  tmcl::Status rotate(uint8_t motor, int32_t velocity_rpm) override;
  tmcl::Status stop(uint8_t motor) override;
  tmcl::Status move(uint8_t motor, uint8_t move_type, int32_t value) override;
  bool position_reached(uint8_t motor) const override;
  tmcl::Status set_output(uint8_t port, uint8_t bank, int32_t value) override;
  tmcl::Status get_input(uint8_t port, uint8_t bank, int32_t& value) override;
  tmcl::ProgramMemory* program_memory() override { return &program_; }
  bool autostart() const override { return global_.auto_start_mode != 0; }
  bool home_switch_active(uint8_t motor) const override;
  bool stop_switch_active(uint8_t motor, bool left) const override;

  // Used by the table bindings.
  void set_tick_timer_ms(uint32_t ms) { tick_timer_ms_ = ms; tick_fraction_ = 0; }

  // tmcl::ModuleStorage hooks.
  void clear_ram_state();
  void after_axis_restore() { axis_.finish_restore(); }  // later writes are host commands
  bool skip_user_variable_restore() const { return global_.skip_user_variable_restore != 0; }

 private:
  board::Tmcm1636Io& io_;
  Tmcm1636Axis axis_;
  GlobalConfig global_;
  tmcl::TmclRuntime runtime_;
  uint64_t tick_count_ = 0;
  uint32_t tick_timer_ms_ = 0;
  uint32_t tick_fraction_ = 0;
  std::array<uint8_t, kProgramCapacity * tmcl::kProgramRecordBytes> program_mirror_{};
  tmcl::ProgramMemory program_{nvm_, kNvmLayout.program_offset, kProgramCapacity, program_mirror_.data()};
  // Last: it refers to the members above.
  tmcl::TmclEngine engine_{*this};
};

}  // namespace motwin::modules::tmcm1636
