// The control loop of a virtual module on its simulated board, the same for every module: per
// tick the board samples its sensors, the firmware ticks, the board moves the motors.
#pragma once

#include <cstdint>
#include <type_traits>

namespace motwin::host {

// Where a virtual module keeps its simulated I/O: `SimIo` for a board over I/O (it keeps a
// reference to it: the TMCM-1636's, the TMCM-142's), nothing for a board that holds its own (void:
// the TMCM-3216's).
struct NoSimIo {};
template <typename SimIo>
using SimIoStorage = std::conditional_t<std::is_void_v<SimIo>, NoSimIo, SimIo>;

// What stamps the module's output changes (run_board_ticks' `output_clock`): the I/O, else the board.
template <typename SimIo, typename Board>
auto& output_clock_of(SimIoStorage<SimIo>& io, Board& board) {
  if constexpr (std::is_void_v<SimIo>) {
    return board;
  } else {
    return io;
  }
}

// Runs `count` ticks, advancing the module's `tick_count` after each one: what reads the module's
// clock during a tick (the CAN bus stamping a frame the firmware sends, its bit-time and
// error-recovery accounting) sees the time of that tick, not of the batch's start. Output
// changes are stamped (through `output_clock.set_sim_time_us`) with the start of the tick that
// made them; afterwards the clock stands at the end of the last tick. `tick_s` is passed apart
// from `tick_us` so that each module integrates with the very constant its firmware uses.
template <typename SimBoard, typename Device, typename OutputClock>
void run_board_ticks(uint64_t count, uint64_t& tick_count, uint32_t tick_us, double tick_s, SimBoard& sim_board,
                     Device& device, OutputClock& output_clock) {
  for (uint64_t i = 0; i < count; ++i) {
    output_clock.set_sim_time_us(tick_count * tick_us);
    sim_board.before_tick();
    device.tick();
    sim_board.after_tick(tick_s);
    ++tick_count;
  }
  output_clock.set_sim_time_us(tick_count * tick_us);
}

}  // namespace motwin::host
