// The base of the TMCL module profiles (TMCM-1636, TMCM-142: one motor; a module with several:
// as many as its EEPROM layout has, kNvmLayout.motors): everything they share beyond the
// parameter storage of module_storage.h, so that each module keeps only what differs (its axes,
// its tables, its I/O and its hooks). It owns
//   - the axes (one Axis per motor), the bank-0 settings (Globals) and the general I/O seam (Io),
//   - the TMCL registers (TmclRuntime), the control tick counter and the GP 132 tick timer,
//   - the program memory with its RAM mirror, at the program slots of the EEPROM layout,
//   - the engine: command dispatcher and interpreter (engine.h),
// and answers the commands that are the same on these modules: ROR/ROL/MST and MVP ABS/REL
// through the axis parameter table of the motor addressed (the engine has checked its number), SIO/GIO over the three I/O banks, the serial settings and
// autostart from the bank-0 settings, the switch conditions of WAIT and the interrupts, and
// GP 128..132 (program_status_rows(), listed in each module's bank-0 table). The helpers its
// parameter tables are written with come from module_rows.h.
//
// A CRTP base. The module passes its parts' types and its ModuleFacts (name, identity, EEPROM
// layout, tick period, motion parameters); besides what ModuleStorage asks for (its tables),
// `Derived` provides
//   - void tick_axis(): one control tick of its axes, called by tick() without a virtual call;
// it may hide clear_ram_state() to clear more (calling this one first) and override the
// TmclDevice commands it answers differently (MVP COORD on the TMCM-142).
// What the base reads of its parts:
//   - Axis: config, state.{left,right,home}_switch_active, reset_state(), position_reached(),
//     actual_position();
//   - Globals: serial_address, serial_host_address, telegram_pause_ms (GP 66, 76, 75),
//     auto_start_mode (GP 77), skip_user_variable_restore (GP 85);
//   - Io: kDigitalInputCount, kAnalogInputCount, kDigitalOutputCount, digital_input(),
//     analog_input(), set_digital_output(), digital_output().
#pragma once

#include <array>
#include <concepts>
#include <cstddef>
#include <cstdint>
#include <string_view>

#include "board/non_volatile_memory.h"
#include "core/params/parameter.h"
#include "core/params/parameter_table.h"
#include "core/tmcl/device.h"
#include "core/tmcl/engine.h"
#include "core/tmcl/instruction.h"
#include "core/tmcl/module_rows.h"
#include "core/tmcl/module_storage.h"
#include "core/tmcl/nvm_layout.h"
#include "core/tmcl/program_memory.h"
#include "core/tmcl/ramdebug.h"
#include "core/tmcl/runtime.h"

namespace motwin::tmcl {

// The axis parameters the motion commands write, so that range checks and side effects are
// those of SAP.
struct MotionParameters {
  uint8_t target_position;  // MVP ABS writes it, MVP REL the actual position plus the value
  uint8_t target_velocity;  // ROR writes it, ROL its negation, MST 0
};

// The constants of a module that the base needs, one declaration next to the module's class.
struct ModuleFacts {
  char name[16];                // "tmcm-1636": how the host and the CLI call the module
  FirmwareIdentity identity;    // command 136
  NvmLayout nvm_layout;         // make_nvm_layout(): parameters, user variables, program
  uint32_t nvm_layout_version;  // bumped whenever nvm_layout or the meaning of a stored value changes
  uint32_t control_tick_us;     // the period of tick()
  MotionParameters motion;
};

// GIO/SIO banks (TMCM-1636 manual 2.6.13/2.6.14; the TMCM-142 numbers them the same).
namespace io_bank {
inline constexpr uint8_t kDigitalInputs = 0;
inline constexpr uint8_t kAnalogInputs = 1;
inline constexpr uint8_t kDigitalOutputs = 2;
}  // namespace io_bank

template <class Derived, class Axis, class Globals, class Io, ModuleFacts kFacts>
class TmclModule : public ModuleStorage<Derived>, public ModuleRows<Derived, Axis, Globals> {
 public:
  static constexpr std::string_view kName = kFacts.name;
  static constexpr FirmwareIdentity kIdentity = kFacts.identity;
  static constexpr NvmLayout kNvmLayout = kFacts.nvm_layout;
  static constexpr uint8_t kMotorCount = static_cast<uint8_t>(kNvmLayout.motors);
  static constexpr bool kAxisHasReferenceSearch = requires(Axis& a) {
    { a.start_reference_search() } -> std::same_as<Status>;
    a.stop_reference_search();
  };
  static_assert(kMotorCount >= 1 && kMotorCount <= 8, "a TMCL module has 1..8 motors (command 138's mask)");
  static constexpr uint32_t kNvmLayoutVersion = kFacts.nvm_layout_version;
  static constexpr uint32_t kControlTickUs = kFacts.control_tick_us;

  using Table = params::ParameterTable<Derived>;

  // GP 128 application status, 129 download mode, 130 program counter and 132 tick timer.
  static constexpr std::array<params::ParameterRow<Derived>, 4> program_status_rows();

  // The TMCL firmware of the module: command dispatcher and interpreter.
  TmclEngine& engine() { return engine_; }

  // One control tick: the axis (Derived::tick_axis()), the tick timer, then at most one
  // instruction of a running program.
  void tick() {
    constexpr uint32_t kTicksPerMillisecond = 1000 / kControlTickUs;
    derived().tick_axis();
    ++tick_count_;
    if (++tick_fraction_ == kTicksPerMillisecond) {
      tick_fraction_ = 0;
      ++tick_timer_ms_;
    }
    engine_.tick(tick_count_ * kControlTickUs);
  }
  uint64_t tick_count() const { return tick_count_; }
  // GP 132: milliseconds since power-up; a write restarts the running millisecond.
  uint32_t tick_timer_ms() const { return tick_timer_ms_; }
  void set_tick_timer_ms(uint32_t ms) {
    tick_timer_ms_ = ms;
    tick_fraction_ = 0;
  }

  // The axis of `motor` (0..kMotorCount-1; the engine checked the number a host sent).
  Axis& axis(uint8_t motor = 0) { return axes_[motor]; }
  const Axis& axis(uint8_t motor = 0) const { return axes_[motor]; }
  Globals& global_config() { return globals_; }
  const Globals& global_config() const { return globals_; }
  Io& io() { return io_; }

  // TmclDevice.
  const FirmwareIdentity& identity() const override { return kIdentity; }
  uint8_t motor_count() const override { return kMotorCount; }
  SerialSettings serial_settings() const override {
    return SerialSettings{static_cast<uint8_t>(globals_.serial_address),
                          static_cast<uint8_t>(globals_.serial_host_address),
                          static_cast<uint8_t>(globals_.telegram_pause_ms)};
  }
  TmclRuntime& runtime() override { return runtime_; }
  // A motor the module does not have: status 4 (the engine checks first; this guards direct
  // callers), no position reached and no switch active.
  Status rotate(uint8_t motor, int32_t velocity) override {
    if (motor >= kMotorCount) return Status::kInvalidValue;
    return derived().axis_table().write(derived(), motor, kFacts.motion.target_velocity, velocity);
  }
  // MST: velocity mode with target 0, stopping with the ramp, as ROR 0.
  Status stop(uint8_t motor) override { return rotate(motor, 0); }
  // MVP ABS and REL. REL is relative to the actual position and wraps at 32 bits like the
  // position counter.
  Status move(uint8_t motor, uint8_t type, int32_t value) override {
    if (motor >= kMotorCount) return Status::kInvalidValue;
    switch (type) {
      case move_type::kAbsolute:
        return move_to(motor, value);
      case move_type::kRelative:
        return move_to(motor, static_cast<int32_t>(static_cast<uint32_t>(derived().relative_move_origin(motor)) +
                                                   static_cast<uint32_t>(value)));
      default:
        return Status::kWrongType;
    }
  }
  bool position_reached(uint8_t motor) const override {
    return motor < kMotorCount && axes_[motor].position_reached();
  }
  Status set_output(uint8_t port, uint8_t bank, int32_t value) override {
    if (bank != io_bank::kDigitalOutputs) return Status::kInvalidValue;
    if (port >= Io::kDigitalOutputCount) return Status::kWrongType;
    if (value != 0 && value != 1) return Status::kInvalidValue;
    io_.set_digital_output(port, value != 0);
    return Status::kOk;
  }
  Status get_input(uint8_t port, uint8_t bank, int32_t& value) override {
    switch (bank) {
      case io_bank::kDigitalInputs:
        if (port >= Io::kDigitalInputCount) return Status::kWrongType;
        value = io_.digital_input(port) ? 1 : 0;
        return Status::kOk;
      case io_bank::kAnalogInputs:
        if (port >= Io::kAnalogInputCount) return Status::kWrongType;
        value = io_.analog_input(port);
        return Status::kOk;
      case io_bank::kDigitalOutputs:
        if (port >= Io::kDigitalOutputCount) return Status::kWrongType;
        value = io_.digital_output(port) ? 1 : 0;
        return Status::kOk;
      default:
        return Status::kInvalidValue;
    }
  }
  ProgramMemory* program_memory() override { return &program_; }
  bool autostart() const override { return globals_.auto_start_mode != 0; }
  bool home_switch_active(uint8_t motor) const override {
    return motor < kMotorCount && axes_[motor].state.home_switch_active != 0;
  }
  // RFS for modules whose axis has a reference search: tmcl::Status start_reference_search()
  // (status 4 for settings it cannot run with), stop_reference_search(), and
  // reference_search_running(). Others answer status 2 (TmclDevice).
  bool reference_search_running(uint8_t motor) const override {
    if constexpr (kAxisHasReferenceSearch) {
      return motor < kMotorCount && axes_[motor].reference_search_running();
    } else {
      return false;
    }
  }
  Status reference_search(uint8_t motor, uint8_t type, int32_t& value) override {
    if constexpr (kAxisHasReferenceSearch) {
      if (motor >= kMotorCount) return Status::kInvalidValue;
      switch (type) {
        case rfs_type::kStart: return axes_[motor].start_reference_search();
        case rfs_type::kStop: axes_[motor].stop_reference_search(); return Status::kOk;
        case rfs_type::kStatus: value = axes_[motor].reference_search_running() ? 1 : 0; return Status::kOk;
        default: return Status::kWrongType;
      }
    } else {
      return TmclDevice::reference_search(motor, type, value);
    }
  }
  bool stop_switch_active(uint8_t motor, bool left) const override {
    if (motor >= kMotorCount) return false;
    const Axis& axis = axes_[motor];
    return (left ? axis.state.left_switch_active : axis.state.right_switch_active) != 0;
  }

  // ModuleStorage hooks. Power-up: the live state and every setting back to the defaults,
  // before the restore.
  void clear_ram_state() {
    for (Axis& axis : axes_) {
      axis.reset_state();
      axis.config = {};
    }
    globals_ = Globals{};
    runtime_ = TmclRuntime{};
    set_tick_timer_ms(0);
  }
  bool skip_user_variable_restore() const { return globals_.skip_user_variable_restore != 0; }
  // Command 157 (get info) from the module's identity, for a module that answers it
  // (docs/datalogger.md "Command 157"): 0 module number, 1 version (major << 16 | minor),
  // 2 capabilities (TMCL only: Motwin has no bootloader), 3 release type (0, public), 20 the
  // bit width of AP numbers (8). The bootloader, register and git entries and unknown ids:
  // status 3, as Trinamic's eval firmware answers an entry it lacks.
  Status firmware_info(uint8_t entry, int32_t& value) const {
    const FirmwareIdentity& id = static_cast<const Derived&>(*this).identity();
    switch (entry) {
      case 0: value = id.module_number; return Status::kOk;
      case 1: value = static_cast<int32_t>((uint32_t{id.version_major} << 16) | id.version_minor); return Status::kOk;
      case 2: value = kCapabilityTmcl; return Status::kOk;
      case 3: value = 0; return Status::kOk;
      case 20: value = 8; return Status::kOk;
      default: return Status::kWrongType;
    }
  }

  // The datalogger's channels over the module's parameter tables, for a module with a
  // datalogger (RamDebugChannels): an axis parameter (select: axis << 24 | number) or a global
  // parameter (bank << 24 | number; bank 0 or the user variables of bank 2) is found once, here;
  // each sample then costs the row's getter, the read GAP/GGP do. A motor or bank out of range:
  // status 4, an unknown or unreadable parameter: status 3, as GAP/GGP answer; a channel type
  // Motwin does not sample (registers, analog inputs): status 9 (docs/datalogger.md "Errors").
  Status resolve_parameter_channel(uint8_t type, uint32_t select, RamDebugProbe& probe) {
    const auto index = static_cast<uint8_t>(select >> 24);
    const auto number = static_cast<uint16_t>(select & 0xFFFF);
    switch (type) {
      case ram_debug::channel_type::kAxisParameter: {
        if (index >= kMotorCount) return Status::kInvalidValue;
        const auto* row = derived().axis_table().find(number);
        if (!readable(row)) return Status::kWrongType;
        probe = RamDebugProbe{row, kProbeAxisRow, index};
        return Status::kOk;
      }
      case ram_debug::channel_type::kGlobalParameter: {
        if (index == kUserVariableBank) {
          if (number >= kUserVariableCount) return Status::kWrongType;
          probe = RamDebugProbe{nullptr, kProbeUserVariable, static_cast<uint8_t>(number)};
          return Status::kOk;
        }
        if (index != kGlobalBank) return Status::kInvalidValue;
        const auto* row = Derived::global_parameters().find(number);
        if (!readable(row)) return Status::kWrongType;
        probe = RamDebugProbe{row, kProbeGlobalRow, index};
        return Status::kOk;
      }
      case ram_debug::channel_type::kSystick:
        probe = RamDebugProbe{nullptr, kProbeTickTimer, 0};
        return Status::kOk;
      default:
        return Status::kMaxExceeded;
    }
  }
  int32_t read_parameter_channel(const RamDebugProbe& probe) {
    switch (probe.kind) {
      case kProbeAxisRow:
      case kProbeGlobalRow:
        return static_cast<const params::ParameterRow<Derived>*>(probe.source)->binding.get(derived(), probe.index);
      case kProbeUserVariable:
        return this->user_variables()[probe.index];
      default:
        return static_cast<int32_t>(tick_timer_ms_);
    }
  }

  // The actual position of `motor` as the host reads it, which MVP REL adds to; a module whose
  // parameter rows transform it (the TMCM-1636's motor direction, AP 13 of firmware 1.13) hides this.
  int32_t host_actual_position(uint8_t motor) const { return axes_[motor].actual_position(); }
  // MVP REL adds to this: the actual position, unless the axis has an origin option (the
  // TMCM-3216's AP 127).
  int32_t relative_move_origin(uint8_t motor) {
    if constexpr (requires(const Axis& a) { a.relative_move_origin(); }) {
      return axes_[motor].relative_move_origin();
    } else {
      return derived().host_actual_position(motor);
    }
  }

 protected:
  // Does not touch `nvm` beyond reading it: call engine().power_up() to start.
  TmclModule(board::NonVolatileMemory& nvm, Io& io) : ModuleStorage<Derived>(nvm), io_(io) {}
  ~TmclModule() = default;
  // The engine and the program memory refer to this object.
  TmclModule(const TmclModule&) = delete;
  TmclModule& operator=(const TmclModule&) = delete;

  // Command 157 entry 2: bit 1, TMCL (bit 0 bootloader, 2 CANopen, 3 EtherCAT, 4 IO-Link).
  static constexpr int32_t kCapabilityTmcl = 0x02;
  // RamDebugProbe::kind of the channels resolve_parameter_channel() makes.
  static constexpr uint8_t kProbeAxisRow = 1;
  static constexpr uint8_t kProbeGlobalRow = 2;
  static constexpr uint8_t kProbeUserVariable = 3;
  static constexpr uint8_t kProbeTickTimer = 4;
  static bool readable(const params::ParameterRow<Derived>* row) {
    return row != nullptr && params::has(row->info.access, params::Access::kRead) && row->binding.get != nullptr;
  }

  // MVP to an absolute position: a write of the target position parameter.
  Status move_to(uint8_t motor, int32_t position) {
    return derived().axis_table().write(derived(), motor, kFacts.motion.target_position, position);
  }

 private:
  Derived& derived() { return static_cast<Derived&>(*this); }

  Io& io_;
  std::array<Axis, kMotorCount> axes_{};
  Globals globals_;
  TmclRuntime runtime_;
  uint64_t tick_count_ = 0;
  uint32_t tick_timer_ms_ = 0;
  uint32_t tick_fraction_ = 0;  // control ticks since the tick timer last counted a millisecond
  std::array<uint8_t, kNvmLayout.program_capacity * kProgramRecordBytes> program_mirror_{};
  ProgramMemory program_{this->nvm_, kNvmLayout.program_offset, kNvmLayout.program_capacity, program_mirror_.data()};
  // Last: it refers to the members above (its interpreter keeps a reference to runtime_).
  TmclEngine engine_{*this};
};

template <class Derived, class Axis, class Globals, class Io, ModuleFacts kFacts>
constexpr std::array<params::ParameterRow<Derived>, 4>
TmclModule<Derived, Axis, Globals, Io, kFacts>::program_status_rows() {
  using params::access;
  using params::Unit;
  constexpr int64_t kMaxU32 = UINT32_MAX;
  return {{
      {{128, "application status", 0, 3, 0, access("R"), Unit::kNone, "0 stop, 1 run, 2 step, 3 reset"},
       {[](Derived& m, uint8_t) { return static_cast<int32_t>(m.runtime().application_status); }, nullptr}},
      {{129, "download mode", 0, 1, 0, access("R"), Unit::kNone, "1 while the module is in download mode (command 132)"},
       {[](Derived& m, uint8_t) { return int32_t{m.runtime().download_mode ? 1 : 0}; }, nullptr}},
      {{130, "program counter", 0, kMaxU32, 0, access("R"), Unit::kNone, "TMCL program counter"},
       {[](Derived& m, uint8_t) { return static_cast<int32_t>(m.runtime().program_counter); }, nullptr}},
      {{132, "tick timer", 0, kMaxU32, 0, access("RW"), Unit::kMillisecond, "TMCL tick timer, milliseconds since power-up"},
       {[](Derived& m, uint8_t) { return static_cast<int32_t>(m.tick_timer_ms()); },
        [](Derived& m, uint8_t, int32_t value) {
          m.set_tick_timer_ms(static_cast<uint32_t>(value));
          return Status::kOk;
        }}},
  }};
}

}  // namespace motwin::tmcl
