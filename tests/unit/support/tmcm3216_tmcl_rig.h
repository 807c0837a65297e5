// The TMCM-3216 TMCL firmware core on the simulated board, driven by TMCL frames as a host
// sends them (tests of core/modules/tmcm3216/tmcm3216_tmcl.h).
#pragma once

#include <cstdint>
#include <memory>

#include "board/ram_non_volatile_memory.h"
#include "core/modules/tmcm3216/tmcm3216_tmcl.h"
#include "core/tmcl/engine.h"
#include "core/tmcl/serial_link.h"
#include "sim/modules/tmcm3216/tmcm3216_sim_board.h"
#include "tmcl_serial_command.h"

namespace motwin::testing {

using modules::tmcm3216::Tmcm3216Tmcl;

// TMCL command numbers the tests send.
inline constexpr uint8_t kRor = 1, kRol = 2, kMst = 3, kMvp = 4, kSap = 5, kGap = 6, kStap = 7, kSio = 14, kGio = 15;

struct Tmcm3216TmclRig {
  using Nvm = board::RamNonVolatileMemory<Tmcm3216Tmcl::kNvmLayout.total_size>;
  static constexpr uint32_t kTickUs = modules::tmcm3216::kTickUs;

  std::unique_ptr<Nvm> nvm = std::make_unique<Nvm>();
  sim::Tmcm3216SimBoard board;
  std::unique_ptr<Tmcm3216Tmcl> module;

  Tmcm3216TmclRig() { format_and_power_up(); }
  // Every axis on a physical motor (StallGuard, steps lost against an obstacle).
  explicit Tmcm3216TmclRig(const sim::StepperMotorDescription& motor) : board(motor) { format_and_power_up(); }
  void format_and_power_up() {
    Tmcm3216Tmcl::format_factory_image(nvm->mutable_data(), nvm->size());
    power_up();
  }
  void power_up() {
    module = std::make_unique<Tmcm3216Tmcl>(*nvm, board.board());
    module->engine().power_up();
  }
  tmcl::Reply command(uint8_t cmd, uint8_t type, uint8_t motor, int32_t value) {
    return serial_command(module->engine(), cmd, type, motor, value);
  }
  int32_t gap(uint8_t number, uint8_t motor = 0) { return command(kGap, number, motor, 0).value; }
  uint8_t sap(uint8_t number, uint8_t motor, int32_t value) { return command(kSap, number, motor, value).status; }
  void tick(uint64_t n = 1) {
    for (uint64_t i = 0; i < n; ++i) {
      board.before_tick();
      module->tick();
      board.after_tick(kTickUs * 1e-6);
    }
  }
  void run_ms(double ms) { tick(static_cast<uint64_t>(ms * 1000 / kTickUs)); }
  // Ticks until AP 8 of `motor` reads 1, at most `limit_ms`; the milliseconds it took, or -1.
  double ms_until_reached(uint8_t motor, double limit_ms) {
    for (double ms = 0; ms < limit_ms; ms += 1.0) {
      if (gap(8, motor) == 1) return ms;
      run_ms(1.0);
    }
    return -1;
  }
};

}  // namespace motwin::testing
