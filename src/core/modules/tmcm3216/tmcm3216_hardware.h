// Fixed facts of the TMCM-3216 board that both its firmwares (CANopen: tmcm3216.h, TMCL:
// tmcm3216_tmcl.h) build on.
#pragma once

#include <cstdint>

#include "board/modules/tmcm3216/tmcm3216_board.h"

namespace motwin::modules::tmcm3216 {

inline constexpr uint8_t kAxisCount = board::kTmcm3216AxisCount;
// The motion tick (same as the TMCM-142): each tick the sim board senses, the firmware runs its
// axes, the plants advance kTickUs.
inline constexpr uint32_t kTickUs = 50;

}  // namespace motwin::modules::tmcm3216
