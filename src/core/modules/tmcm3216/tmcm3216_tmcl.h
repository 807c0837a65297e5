// The TMCM-3216 with its TMCL firmware (docs/tmcm-3216-tmcl.md): three stepper axes
// (Tmcm3216TmclAxis: the CANopen firmware's stepper and EightPoint ramp, driven by TMCL motion
// commands) on the same board seam (board::Tmcm3216Board), on the TMCL module base with three
// motors. No public manual gives this firmware's parameters: the numbers and names are those of
// PyTrinamic's TMCM3216 class and Zephyr's tmcm3216_reg.h, ranges and defaults those of the
// CANopen firmware's objects of the same meaning (manual V1.04), each choice a decision in the docs.
#pragma once

#include <array>
#include <cstddef>
#include <cstdint>

#include "board/modules/tmcm3216/tmcm3216_board.h"
#include "core/modules/tmcm3216/tmcm3216_hardware.h"
#include "core/modules/tmcm3216/tmcm3216_tmcl_axis.h"
#include "core/tmcl/module_datalogger.h"
#include "core/tmcl/tmcl_module.h"

namespace motwin::modules::tmcm3216 {

// Bank 0 (PyTrinamic's GP0 list; ranges and defaults as the TMCM-142's, docs "Decisions").
struct TmclGlobalConfig {
  int32_t serial_baud_rate_code = 0;       // GP 65: RS485, 0 = 9600 bit/s
  int32_t serial_address = 1;              // GP 66
  int32_t serial_heartbeat_ms = 0;         // GP 68 (stored)
  int32_t can_bit_rate_code = 8;           // GP 69: 1000 kbit/s
  int32_t can_reply_id = 2;                // GP 70
  int32_t can_id = 1;                      // GP 71
  int32_t telegram_pause_ms = 0;           // GP 75
  int32_t serial_host_address = 2;         // GP 76
  int32_t auto_start_mode = 0;             // GP 77
  int32_t code_protection = 0;             // GP 81 (stored)
  int32_t can_heartbeat_ms = 0;            // GP 82 (stored)
  int32_t can_secondary_id = 0;            // GP 83 (stored)
  int32_t coordinate_storage = 0;          // GP 84 (stored)
  int32_t skip_user_variable_restore = 0;  // GP 85
  int32_t serial_secondary_address = 0;    // GP 86 (stored)
};

// The general I/O as the TMCL banks see it (PyTrinamic's IO map): outputs OUT0..3 (bank 2) are
// the four DIO pins driven push-pull; inputs IN0..3 are bank 0 ports 2..5 (the DIO levels),
// ports 0 and 1 the analog inputs read as levels (at least half scale: high); bank 1 ports 0, 1
// the analog inputs, 12 bit.
class Tmcm3216TmclIo {
 public:
  static constexpr uint8_t kDigitalInputCount = 2 + board::Tmcm3216Io::kDioCount;
  static constexpr uint8_t kAnalogInputCount = board::Tmcm3216Io::kAnalogInputCount;
  static constexpr uint8_t kDigitalOutputCount = board::Tmcm3216Io::kDioCount;
  static constexpr uint16_t kAnalogHighLevel = 2048;  // half of the 12-bit scale

  explicit Tmcm3216TmclIo(board::Tmcm3216Io& io) : io_(io) {}

  bool digital_input(uint8_t port) const {
    return port < kAnalogInputCount ? io_.analog_inputs[port] >= kAnalogHighLevel : io_.dio_levels[port - 2];
  }
  uint16_t analog_input(uint8_t port) const { return io_.analog_inputs[port]; }
  void set_digital_output(uint8_t port, bool on) {
    io_.output_mode[port] = true;
    io_.push_pull[port] = true;
    io_.output_levels[port] = on;
  }
  bool digital_output(uint8_t port) const { return io_.output_mode[port] && io_.output_levels[port]; }

 private:
  board::Tmcm3216Io& io_;
};

inline constexpr size_t kTmclStorableUserVariables = 56;  // as the TMCM-142 (docs "Decisions")
inline constexpr size_t kTmclProgramCapacity = 2048;

// The datalogger (commands 142, 157) as the TMCM-1636's [Motwin decision: PyTrinamic's RAMDebug
// talks to any TMCL module that answers 142]: 4 channels at 2 kHz (every 10th control tick), a
// buffer of 8192 words.
inline constexpr uint32_t kTmclRamDebugBaseRateHz = 2000;
inline constexpr size_t kTmclRamDebugBufferWords = 8192;
inline constexpr tmcl::RamDebugConfig kTmclRamDebugConfig{4, kTmclRamDebugBaseRateHz,
                                                          1'000'000 / kTickUs / kTmclRamDebugBaseRateHz};

inline constexpr tmcl::ModuleFacts kTmclFacts{
    .name = "tmcm-3216",
    .identity = {3216, 1, 0, "3216V100"},
    .nvm_layout = tmcl::make_nvm_layout(kAxisCount, kTmclStorableUserVariables, kTmclProgramCapacity),
    .nvm_layout_version = 1,
    .control_tick_us = kTickUs,
    // ROR/ROL write the target velocity (AP 2), MVP the target position (AP 0), both in µsteps.
    .motion = {.target_position = 0, .target_velocity = 2},
};

class Tmcm3216Tmcl final
    : public tmcl::TmclModule<Tmcm3216Tmcl, Tmcm3216TmclAxis, TmclGlobalConfig, Tmcm3216TmclIo, kTmclFacts> {
 public:
  Tmcm3216Tmcl(board::NonVolatileMemory& nvm, board::Tmcm3216Board& board)
      : TmclModule(nvm, io_adapter_), board_(board), io_adapter_(board.io) {}

  static const Table& axis_parameters();
  static const Table& global_parameters();  // bank 0

  // tmcl::TmclModule hook: one 50 µs tick of the three axes, the outputs they drive, then the
  // datalogger samples what this tick computed.
  void tick_axis();
  // tmcl::ModuleStorage hook: power-up also stops the datalogger.
  void clear_ram_state() {
    TmclModule::clear_ram_state();
    datalogger_.init();
  }

  // TmclDevice: command 142.
  tmcl::Status ram_debug(uint8_t type, uint8_t motor, int32_t& value) override {
    return datalogger_.ram_debug().execute(type, motor, value);
  }

  // TmclDevice: PyTrinamic's GP3 list names vectors 39..42 Input_0..3, which are GIO ports 2..5.
  uint8_t first_interrupt_input_port() const override { return 2; }
  // TmclDevice: command 157.
  tmcl::Status get_info(uint8_t type, uint8_t /*motor*/, int32_t& value) override { return firmware_info(type, value); }

 private:
  board::Tmcm3216Board& board_;
  Tmcm3216TmclIo io_adapter_;
  tmcl::ModuleDatalogger<Tmcm3216Tmcl, kTmclRamDebugBufferWords> datalogger_{*this, kTmclRamDebugConfig};
};

}  // namespace motwin::modules::tmcm3216
