// The parameter storage every TMCL module profile shares: SAP/GAP/STAP/RSAP over the axis
// table, SGP/GGP/STGP/RSGP over bank 0 and the user variables (bank 2), automatically stored
// (A) globals, the power-up restore from the EEPROM image, the factory image and command 137.
// A CRTP base: `Derived` (Tmcm1636, Tmcm142) provides
//   - static axis_parameters(), global_parameters() (params::ParameterTable<Derived>),
//     (a module whose axis rows depend on its firmware generation hides axis_table(), the
//     table of the running instance; the default is axis_parameters()),
//   - static constexpr kNvmLayout and kMotorCount,
//   - void clear_ram_state()        power-up: config and state structs back to their defaults,
// (the TMCL module base, tmcl_module.h, provides all but the tables) and may hide these defaults:
//   - before_axis_restore()         e.g. read a unit mode first that the other rows depend on,
//   - after_axis_restore(), after_restore(),
//   - skip_user_variable_restore()  GP 85,
//   - eeprom_locked()               GP 73 on the TMCM-142: stored writes answer status 5,
//   - set_bank_parameter / get_bank_parameter for banks other than 0 and 2 (bank 1 I/O).
// The hooks run per command or at power-up, never per control tick.
#pragma once

#include <array>
#include <cstddef>
#include <cstdint>
#include <cstring>

#include "board/non_volatile_memory.h"
#include "core/params/parameter_table.h"
#include "core/tmcl/device.h"
#include "core/tmcl/instruction.h"
#include "core/tmcl/nvm_layout.h"
#include "core/tmcl/program_memory.h"

namespace motwin::tmcl {

inline constexpr size_t kUserVariableCount = 256;  // bank 2 of every TMCL module
inline constexpr uint8_t kGlobalBank = 0;
inline constexpr uint8_t kUserVariableBank = 2;

inline bool is_stored_parameter(const params::ParameterInfo& info) {
  return params::has(info.access, params::Access::kEeprom | params::Access::kAutoStore);
}

template <class Derived>
class ModuleStorage : public TmclDevice {
 public:
  // Writes the factory image: every stored parameter at its default, user variables and
  // coordinates 0, program memory full of STOP (so autostart of an empty module stops at once).
  static void format_factory_image(uint8_t* image, size_t size) {
    format_factory_image(image, size, Derived::axis_parameters());
  }
  // The same for the axis rows of one firmware generation of the module.
  static void format_factory_image(uint8_t* image, size_t size, const params::ParameterTable<Derived>& axis_table) {
    constexpr NvmLayout layout = Derived::kNvmLayout;
    std::memset(image, 0, size);
    if (size < layout.total_size) return;
    format_factory_parameters(image, axis_table);
    for (uint32_t address = 0; address < layout.program_capacity; ++address) {
      encode_program_record(Instruction{command::kStop, 0, 0, 0},
                            image + layout.program_offset + address * kProgramRecordBytes);
    }
  }

  // The part before the program (parameters, user variables, coordinates) at factory values:
  // layout.program_offset bytes.
  static void format_factory_parameters(uint8_t* image, const params::ParameterTable<Derived>& axis_table) {
    constexpr NvmLayout layout = Derived::kNvmLayout;
    std::memset(image, 0, layout.program_offset);
    for (const auto& row : axis_table.rows()) {
      if (!is_stored_parameter(row.info)) continue;
      for (uint8_t motor = 0; motor < Derived::kMotorCount; ++motor) {
        put_le32(image + layout.axis_parameter(motor, static_cast<uint8_t>(row.info.number)),
                 static_cast<int32_t>(row.info.default_value));
      }
    }
    for (const auto& row : Derived::global_parameters().rows()) {
      if (!is_stored_parameter(row.info)) continue;
      put_le32(image + layout.global_parameter(static_cast<uint8_t>(row.info.number)),
               static_cast<int32_t>(row.info.default_value));
    }
  }

  // Starting one firmware generation on an image another generation wrote (a firmware update,
  // docs/tmcm-1636.md "EEPROM image and firmware changes"): each stored axis row of `running` that
  // `previous` lacks gets its factory default in its slot, so that whatever the other generation
  // left there is never taken for a setting. Rows both have, bank 0, user variables and the
  // program stay as stored. One write of the axis area; false when it failed.
  static bool update_image_for_firmware(board::NonVolatileMemory& nvm, const params::ParameterTable<Derived>& previous,
                                        const params::ParameterTable<Derived>& running) {
    constexpr NvmLayout layout = Derived::kNvmLayout;
    constexpr uint32_t kAxisAreaBytes = layout.global_parameters_offset - layout.axis_parameters_offset;
    if (nvm.size() < layout.total_size) return false;
    static uint8_t axis_area[kAxisAreaBytes];
    std::memcpy(axis_area, nvm.data() + layout.axis_parameters_offset, kAxisAreaBytes);
    for (const auto& row : running.rows()) {
      if (!is_stored_parameter(row.info) || previous.find(row.info.number) != nullptr) continue;
      for (uint8_t motor = 0; motor < Derived::kMotorCount; ++motor) {
        put_le32(axis_area + layout.axis_parameter(motor, static_cast<uint8_t>(row.info.number)) -
                     layout.axis_parameters_offset,
                 static_cast<int32_t>(row.info.default_value));
      }
    }
    return nvm.write(layout.axis_parameters_offset, axis_area, kAxisAreaBytes);
  }

  std::array<int32_t, kUserVariableCount>& user_variables() { return user_variables_; }
  // True when the last EEPROM write failed (reported by the host runtime).
  bool last_store_failed() const { return last_store_failed_; }

  // TmclDevice: parameters.
  // A motor the module does not have: status 4, as the engine answers it (these are reached
  // without the engine too: the datalogger, tools, the fuzz targets).
  Status set_axis_parameter(uint8_t number, uint8_t motor, int32_t value) override {
    if (motor >= Derived::kMotorCount) return Status::kInvalidValue;
    return derived().axis_table().write(derived(), motor, number, value);
  }

  Status get_axis_parameter(uint8_t number, uint8_t motor, int32_t& value) override {
    if (motor >= Derived::kMotorCount) return Status::kInvalidValue;
    return derived().axis_table().read(derived(), motor, number, value);
  }

  Status store_axis_parameter(uint8_t number, uint8_t motor) override {
    if (motor >= Derived::kMotorCount) return Status::kInvalidValue;
    const auto* row = derived().axis_table().find(number);
    if (row == nullptr || !params::has(row->info.access, params::Access::kEeprom)) return Status::kWrongType;
    return store_parameter(Derived::kNvmLayout.axis_parameter(motor, number), row->binding.get(derived(), motor));
  }

  Status restore_axis_parameter(uint8_t number, uint8_t motor) override {
    if (motor >= Derived::kMotorCount) return Status::kInvalidValue;
    const auto* row = derived().axis_table().find(number);
    if (row == nullptr || !params::has(row->info.access, params::Access::kEeprom)) return Status::kWrongType;
    const int32_t value = stored_value(Derived::kNvmLayout.axis_parameter(motor, number));
    if (!params::in_range(row->info, value)) return Status::kInvalidValue;
    return row->binding.set(derived(), motor, value);
  }

  Status set_global_parameter(uint8_t number, uint8_t bank, int32_t value) override {
    if (bank == kUserVariableBank) {
      user_variables_[number] = value;
      return Status::kOk;
    }
    if (bank != kGlobalBank) return derived().set_bank_parameter(number, bank, value);
    const auto& table = Derived::global_parameters();
    const auto* row = table.find(number);
    if (row == nullptr || !params::has(row->info.access, params::Access::kAutoStore)) {
      return table.write(derived(), bank, number, value);
    }
    // Automatically stored (A): RAM and EEPROM change together or not at all.
    if (derived().eeprom_locked()) return Status::kEepromLocked;
    const int32_t previous = row->binding.get != nullptr ? row->binding.get(derived(), bank) : 0;
    const Status status = table.write(derived(), bank, number, value);
    if (status != Status::kOk) return status;
    if (!store_value(Derived::kNvmLayout.global_parameter(number), value)) {
      row->binding.set(derived(), bank, previous);
      return Status::kEepromLocked;
    }
    return Status::kOk;
  }

  Status get_global_parameter(uint8_t number, uint8_t bank, int32_t& value) override {
    if (bank == kUserVariableBank) {
      value = user_variables_[number];
      return Status::kOk;
    }
    if (bank != kGlobalBank) return derived().get_bank_parameter(number, bank, value);
    return Derived::global_parameters().read(derived(), bank, number, value);
  }

  // STGP: user variables below the storable count, and bank-0 parameters that are stored anyway.
  Status store_global_parameter(uint8_t number, uint8_t bank) override {
    if (bank == kUserVariableBank) {
      if (number >= Derived::kNvmLayout.storable_user_variables) return Status::kWrongType;
      return store_parameter(Derived::kNvmLayout.user_variable(number), user_variables_[number]);
    }
    if (bank != kGlobalBank) return Status::kInvalidValue;
    const auto* row = Derived::global_parameters().find(number);
    if (row == nullptr || !is_stored_parameter(row->info)) return Status::kWrongType;
    return store_parameter(Derived::kNvmLayout.global_parameter(number), row->binding.get(derived(), bank));
  }

  Status restore_global_parameter(uint8_t number, uint8_t bank) override {
    if (bank == kUserVariableBank) {
      if (number >= Derived::kNvmLayout.storable_user_variables) return Status::kWrongType;
      user_variables_[number] = stored_value(Derived::kNvmLayout.user_variable(number));
      return Status::kOk;
    }
    if (bank != kGlobalBank) return Status::kInvalidValue;
    const auto* row = Derived::global_parameters().find(number);
    if (row == nullptr || !is_stored_parameter(row->info)) return Status::kWrongType;
    const int32_t value = stored_value(Derived::kNvmLayout.global_parameter(number));
    if (!params::in_range(row->info, value)) return Status::kInvalidValue;
    return row->binding.set(derived(), bank, value);
  }

  // Power-up (and command 255): RAM state cleared, every stored parameter restored from the
  // EEPROM image. A stored value outside its row's range (an image from elsewhere) is skipped
  // and the default kept, so a bad image can never put the module into an invalid state.
  void power_up() override {
    constexpr NvmLayout layout = Derived::kNvmLayout;
    derived().clear_ram_state();
    user_variables_.fill(0);
    if (nvm_.size() < layout.total_size) return;
    derived().before_axis_restore();
    for (const auto& row : derived().axis_table().rows()) {
      if (!is_stored_parameter(row.info)) continue;
      for (uint8_t motor = 0; motor < Derived::kMotorCount; ++motor) {
        const int32_t value = stored_value(layout.axis_parameter(motor, static_cast<uint8_t>(row.info.number)));
        if (params::in_range(row.info, value)) row.binding.set(derived(), motor, value);
      }
    }
    derived().after_axis_restore();
    for (const auto& row : Derived::global_parameters().rows()) {
      if (!is_stored_parameter(row.info)) continue;
      const int32_t value = stored_value(layout.global_parameter(static_cast<uint8_t>(row.info.number)));
      if (params::in_range(row.info, value)) row.binding.set(derived(), kGlobalBank, value);
    }
    if (!derived().skip_user_variable_restore()) {
      for (uint8_t i = 0; i < layout.storable_user_variables; ++i) user_variables_[i] = stored_value(layout.user_variable(i));
    }
    derived().after_restore();
  }

  // Command 137: the parameter part of the image (parameters, user variables, coordinates)
  // back to factory values; a stored TMCL program is kept (docs/decisions.md). The engine
  // powers the module up afterwards.
  void restore_factory_defaults() override {
    // Only the part that is rewritten, in one write (atomic); static, so that the firmware's RAM
    // use is known at link time rather than at the deepest stack.
    static uint8_t parameters[Derived::kNvmLayout.program_offset];
    format_factory_parameters(parameters, derived().axis_table());
    last_store_failed_ = !nvm_.write(0, parameters, sizeof parameters);
  }

  // Default hooks; Derived hides the ones it needs.
  const auto& axis_table() const { return Derived::axis_parameters(); }
  void before_axis_restore() {}
  void after_axis_restore() {}
  void after_restore() {}
  bool skip_user_variable_restore() const { return false; }
  bool eeprom_locked() const { return false; }
  Status set_bank_parameter(uint8_t /*number*/, uint8_t /*bank*/, int32_t /*value*/) { return Status::kInvalidValue; }
  Status get_bank_parameter(uint8_t /*number*/, uint8_t /*bank*/, int32_t& /*value*/) { return Status::kInvalidValue; }

 protected:
  explicit ModuleStorage(board::NonVolatileMemory& nvm) : nvm_(nvm) {}
  ~ModuleStorage() = default;

  // One 32-bit slot of the image. False when the EEPROM could not be written.
  bool store_value(uint32_t offset, int32_t value) {
    uint8_t bytes[4];
    put_le32(bytes, value);
    last_store_failed_ = !nvm_.write(offset, bytes, sizeof bytes);
    return !last_store_failed_;
  }

  // A stored setting: refused with status 5 while the EEPROM is locked or when the write fails.
  Status store_parameter(uint32_t offset, int32_t value) {
    if (derived().eeprom_locked()) return Status::kEepromLocked;
    return store_value(offset, value) ? Status::kOk : Status::kEepromLocked;
  }

  int32_t stored_value(uint32_t offset) const {
    if (nvm_.size() < offset + 4) return 0;
    return get_le32(nvm_.data() + offset);
  }

  board::NonVolatileMemory& nvm_;

 private:
  Derived& derived() { return static_cast<Derived&>(*this); }

  std::array<int32_t, kUserVariableCount> user_variables_{};
  bool last_store_failed_ = false;
};

}  // namespace motwin::tmcl
