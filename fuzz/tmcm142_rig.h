// A TMCM-142 on its simulated board (ideal motor; left and right limit switches and a home cam
// placed where a reference search finds them) on a RAM EEPROM with the factory image, powered up:
// shared by the targets that drive its TMCL engine (tmcm142_engine, tmcl_ascii), one per input
// (fuzz::fresh_rig<Tmcm142Rig>()). Needs motwin_sim.
#pragma once

#include <bit>
#include <cstring>
#include <optional>
#include <vector>

#include "fuzz_support.h"

#include "board/ram_non_volatile_memory.h"
#include "core/modules/tmcm142/tmcm142.h"
#include "core/tmcl/engine.h"
#include "sim/modules/tmcm142/tmcm142_sim_board.h"
#include "sim/modules/tmcm142/tmcm142_sim_io.h"

namespace motwin::fuzz {

using Tmcm142 = modules::tmcm142::Tmcm142;
using Tmcm142Nvm = board::RamNonVolatileMemory<Tmcm142::kNvmLayout.total_size>;

struct Tmcm142Rig {
  sim::Tmcm142SimIo io;
  sim::Tmcm142SimBoard board{io};
  Tmcm142Nvm nvm;
  std::optional<Tmcm142> module;

  Tmcm142Rig() {
    const auto& image = factory_image<Tmcm142, Tmcm142::kNvmLayout.total_size>();
    std::memcpy(nvm.mutable_data(), image.data(), image.size());
    // Switches a reference search can find: left below, right above, a home cam between.
    board.set_input("REF_L_AT", -0.5);
    board.set_input("REF_R_AT", 0.5);
    board.set_input("REF_H_FROM", 0.1);
    board.set_input("REF_H_TO", 0.2);
    board.before_tick();
    module.emplace(nvm, board.power_stage(), io);
    module->engine().power_up();
  }
  // The parameters, the EEPROM image and where the rotor is: what a fresh rig is compared by.
  std::vector<int32_t> state() {
    std::vector<int32_t> values = module_state(*module, nvm);
    const auto rotor = std::bit_cast<uint64_t>(board.rotor_revolutions());
    values.push_back(static_cast<int32_t>(rotor));
    values.push_back(static_cast<int32_t>(rotor >> 32));
    values.push_back(board.power_stage().feedback.encoder_count);
    return values;
  }
  tmcl::TmclEngine& engine() { return module->engine(); }
  void tick() {
    board.before_tick();
    module->tick();
    board.after_tick(modules::tmcm142::kControlTickS);
  }
};

}  // namespace motwin::fuzz
