// A TMCM-1636 with a physical motor: the firmware core on a RAM EEPROM, the simulated board
// with the motor plant behind the power-stage seam, and TMCL commands through the engine.
// What the servo tests drive (the ideal-motor tests use tmcm1636_rig.h).
#pragma once

#include <cstdint>
#include <functional>

#include "board/ram_non_volatile_memory.h"
#include "core/modules/tmcm1636/tmcm1636.h"
#include "core/tmcl/engine.h"
#include "core/tmcl/serial_link.h"
#include "host/modules/tmcm1636/tmcm1636_startup_image.h"
#include "sim/modules/tmcm1636/motor_description.h"
#include "sim/modules/tmcm1636/tmcm1636_sim_board.h"
#include "sim/modules/tmcm1636/tmcm1636_sim_io.h"

namespace motwin::testing {

struct Tmcm1636ServoRig {
  using Module = modules::tmcm1636::Tmcm1636;
  static constexpr double kTickS = modules::tmcm1636::kControlTickUs * 1e-6;

  board::RamNonVolatileMemory<Module::kNvmLayout.total_size> nvm;
  sim::Tmcm1636SimIo io;
  sim::Tmcm1636SimBoard board;
  Module module{nvm, io};

  // With `startup` the image holds the motor's start-up settings, as a fresh image of
  // `motwin serve --motor` does; without, the factory defaults of table 11.
  explicit Tmcm1636ServoRig(const sim::MotorDescription& motor, bool startup = true,
                            uint64_t seed = sim::Tmcm1636SimBoard::kDefaultNoiseSeed,
                            int sub_steps = sim::Tmcm1636Plant::kDefaultSubSteps)
      : board(io, motor, seed, sub_steps) {
    Module::format_factory_image(nvm.mutable_data(), nvm.size());
    if (startup) host::write_tmcm1636_startup_image(motor, nvm.mutable_data(), nvm.size());
    module.axis().attach_power_stage(board.power_stage());
    module.engine().power_up();
  }
  static sim::MotorDescription preset(const char* name) { return *sim::motor_preset(name); }

  sim::Tmcm1636Plant& plant() { return *board.plant(); }

  tmcl::Reply command(uint8_t cmd, uint8_t type, uint8_t motor, int32_t value) {
    const auto response =
        tmcl::serve_serial_frame(module.engine(), tmcl::encode_request(1, tmcl::Instruction{cmd, type, motor, value}), 0);
    const auto& b = response.bytes;
    const uint32_t v = (uint32_t{b[4]} << 24) | (uint32_t{b[5]} << 16) | (uint32_t{b[6]} << 8) | b[7];
    return tmcl::Reply{b[2], b[3], static_cast<int32_t>(v)};
  }
  uint8_t sap(uint8_t number, int32_t value) { return command(5, number, 0, value).status; }
  int32_t gap(uint8_t number) { return command(6, number, 0, 0).value; }
  uint8_t ror(int32_t rpm) { return command(1, 0, 0, rpm).status; }
  uint8_t mst() { return command(3, 0, 0, 0).status; }
  uint8_t mvp(int32_t position) { return command(4, 0, 0, position).status; }

  void tick() {
    board.before_tick();
    module.tick();
    board.after_tick(kTickS);
  }
  void run_ticks(uint64_t ticks) {
    for (uint64_t i = 0; i < ticks; ++i) tick();
  }
  void run_ms(double ms) { run_ticks(static_cast<uint64_t>(ms * modules::tmcm1636::kTicksPerMillisecond + 0.5)); }
  // Runs until `done` (checked every tick) or `max_ms`; returns the simulated milliseconds taken.
  double run_until(const std::function<bool()>& done, double max_ms) {
    const uint64_t max_ticks = static_cast<uint64_t>(max_ms * modules::tmcm1636::kTicksPerMillisecond);
    for (uint64_t i = 0; i < max_ticks; ++i) {
      if (done()) return static_cast<double>(i) / modules::tmcm1636::kTicksPerMillisecond;
      tick();
    }
    return max_ms;
  }
  double speed_rpm() { return plant().speed_rpm(); }
  void set(const char* signal, double value) { board.set_input(signal, value); }
};

}  // namespace motwin::testing
