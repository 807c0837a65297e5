// What the TMCL engine needs from a module profile (TMCM-1636, TMCM-142 ...). The engine owns
// the command semantics shared by every TMCL module; the profile owns its parameter tables,
// motion and I/O. Called per command, never per control tick, so virtual calls are fine here.
#pragma once

#include <cstdint>

#include "core/tmcl/program_memory.h"
#include "core/tmcl/runtime.h"
#include "core/tmcl/status.h"

namespace motwin::tmcl {

struct FirmwareIdentity {
  uint16_t module_number;     // 1636
  uint8_t version_major;      // 1
  uint8_t version_minor;      // 9
  char version_string[9];     // "1636V109": 8 characters, never containing 'B'

  // Command 136 type 1: module << 16 | major << 8 | minor (docs/tmcl-protocol.md
  // "Firmware version").
  constexpr int32_t binary_version() const {
    return static_cast<int32_t>((static_cast<uint32_t>(module_number) << 16) |
                                (static_cast<uint32_t>(version_major) << 8) | version_minor);
  }
};

// Serial-line settings the framing layer needs (GP 66, 76, 75). They take effect at once.
struct SerialSettings {
  uint8_t module_address;
  uint8_t host_address;
  uint8_t telegram_pause_ms;
};

class TmclDevice {
 public:
  virtual const FirmwareIdentity& identity() const = 0;
  virtual uint8_t motor_count() const = 0;
  virtual SerialSettings serial_settings() const = 0;
  virtual TmclRuntime& runtime() = 0;

  // Motion. motor < motor_count() is checked by the engine. velocity is signed: ROL negates.
  virtual Status rotate(uint8_t motor, int32_t velocity) = 0;
  virtual Status stop(uint8_t motor) = 0;
  virtual Status move(uint8_t motor, uint8_t move_type, int32_t value) = 0;
  virtual bool position_reached(uint8_t motor) const = 0;

  // Axis parameters (SAP, GAP, STAP, RSAP).
  virtual Status set_axis_parameter(uint8_t number, uint8_t motor, int32_t value) = 0;
  virtual Status get_axis_parameter(uint8_t number, uint8_t motor, int32_t& value) = 0;
  virtual Status store_axis_parameter(uint8_t number, uint8_t motor) = 0;
  virtual Status restore_axis_parameter(uint8_t number, uint8_t motor) = 0;

  // Global parameters (SGP, GGP, STGP, RSGP). Bank checking is the profile's.
  virtual Status set_global_parameter(uint8_t number, uint8_t bank, int32_t value) = 0;
  virtual Status get_global_parameter(uint8_t number, uint8_t bank, int32_t& value) = 0;
  virtual Status store_global_parameter(uint8_t number, uint8_t bank) = 0;
  virtual Status restore_global_parameter(uint8_t number, uint8_t bank) = 0;

  // I/O (SIO, GIO).
  virtual Status set_output(uint8_t port, uint8_t bank, int32_t value) = 0;
  virtual Status get_input(uint8_t port, uint8_t bank, int32_t& value) = 0;

  // Command 137: every stored setting back to its factory default in the EEPROM image (the
  // engine then powers the module up, so RAM follows).
  virtual void restore_factory_defaults() = 0;
  // Command 255 and power-up: RAM state cleared, parameters restored from the EEPROM image.
  virtual void power_up() = 0;

  // Standalone mode. nullptr: the module has no program memory.
  virtual ProgramMemory* program_memory() { return nullptr; }
  // GP 77: start the stored program after power-up.
  virtual bool autostart() const { return false; }
  // Conditions of WAIT REFSW / LIMSW / RFS and the stop-switch interrupts.
  virtual bool home_switch_active(uint8_t /*motor*/) const { return false; }
  virtual bool stop_switch_active(uint8_t /*motor*/, bool /*left*/) const { return false; }
  virtual bool reference_search_running(uint8_t /*motor*/) const { return false; }
  // The GIO bank-0 port of input interrupt vector 39 (the next vectors take the next ports).
  virtual uint8_t first_interrupt_input_port() const { return 0; }

  // RFS (13): type 0 START, 1 STOP, 2 STATUS (value 0 when done, non-zero while running).
  // Modules without a reference search answer status 2 (invalid command).
  virtual Status reference_search(uint8_t /*motor*/, uint8_t /*type*/, int32_t& /*value*/) {
    return Status::kInvalidCommand;
  }

  // Coordinates (TMCM-142 generation, docs/tmcl-protocol.md "Interpreter model"): SCO 30, GCO 31,
  // CCO 32, ACO 39 (ACO is set_coordinate with the accumulator). motor 255 selects the special
  // forms `SCO n, 255, 0` (RAM to EEPROM) and `GCO n, 255, 0` (EEPROM to RAM). Modules without
  // coordinates answer status 2 (invalid command).
  virtual Status set_coordinate(uint8_t /*number*/, uint8_t /*motor*/, int32_t /*position*/) {
    return Status::kInvalidCommand;
  }
  virtual Status get_coordinate(uint8_t /*number*/, uint8_t /*motor*/, int32_t& /*position*/) {
    return Status::kInvalidCommand;
  }
  virtual Status capture_coordinate(uint8_t /*number*/, uint8_t /*motor*/) { return Status::kInvalidCommand; }

  // Command 142, the datalogger (docs/datalogger.md): type = sub-command, motor = its byte
  // operand, value in (request) and out (reply; left alone, the reply echoes the request).
  // Modules without it answer status 2 (invalid command).
  virtual Status ram_debug(uint8_t /*type*/, uint8_t /*motor*/, int32_t& /*value*/) { return Status::kInvalidCommand; }
  // Command 157, get info: type = entry id, value out. Modules without it answer status 2.
  virtual Status get_info(uint8_t /*type*/, uint8_t /*motor*/, int32_t& /*value*/) { return Status::kInvalidCommand; }

 protected:
  ~TmclDevice() = default;
};

}  // namespace motwin::tmcl
