// The TMCM-3216 with its TMCL firmware on its simulated board (ideal motors; on every axis left
// and right limit switches, a home cam and the encoder's null channel placed where a reference
// search finds them) on a RAM EEPROM with the factory image, powered up and ticked once (the
// switches read): for tmcm3216_tmcl_engine, one per input (fuzz::fresh_rig<Tmcm3216TmclRig>()).
#pragma once

#include <bit>
#include <cstring>
#include <optional>
#include <string>
#include <vector>

#include "fuzz_support.h"

#include "board/ram_non_volatile_memory.h"
#include "core/modules/tmcm3216/tmcm3216_tmcl.h"
#include "core/tmcl/engine.h"
#include "sim/modules/tmcm3216/tmcm3216_sim_board.h"

namespace motwin::fuzz {

using Tmcm3216Tmcl = modules::tmcm3216::Tmcm3216Tmcl;
using Tmcm3216TmclNvm = board::RamNonVolatileMemory<Tmcm3216Tmcl::kNvmLayout.total_size>;

struct Tmcm3216TmclRig {
  sim::Tmcm3216SimBoard board;
  Tmcm3216TmclNvm nvm;
  std::optional<Tmcm3216Tmcl> module;

  Tmcm3216TmclRig() {
    const auto& image = factory_image<Tmcm3216Tmcl, Tmcm3216Tmcl::kNvmLayout.total_size>();
    std::memcpy(nvm.mutable_data(), image.data(), image.size());
    for (int axis = 0; axis < modules::tmcm3216::kAxisCount; ++axis) {
      const std::string prefix = "AXIS" + std::to_string(axis) + "_";
      board.set_input(prefix + "REF_L_AT", -0.5);
      board.set_input(prefix + "REF_R_AT", 0.5);
      board.set_input(prefix + "REF_H_FROM", 0.1);
      board.set_input(prefix + "REF_H_TO", 0.2);
      board.set_input(prefix + "ENCODER_INDEX_AT", 0.25);
    }
    module.emplace(nvm, board.board());
    module->engine().power_up();
    tick();
  }
  // The parameters, the EEPROM image and where the rotors are: what a fresh rig is compared by.
  std::vector<int32_t> state() {
    std::vector<int32_t> values = module_state(*module, nvm);
    for (uint8_t axis = 0; axis < modules::tmcm3216::kAxisCount; ++axis) {
      const auto rotor = std::bit_cast<uint64_t>(board.rotor_revolutions(axis));
      values.push_back(static_cast<int32_t>(rotor));
      values.push_back(static_cast<int32_t>(rotor >> 32));
    }
    return values;
  }
  tmcl::TmclEngine& engine() { return module->engine(); }
  void tick() {
    board.before_tick();
    module->tick();
    board.after_tick(modules::tmcm3216::kTickUs * 1e-6);
  }
};

}  // namespace motwin::fuzz
