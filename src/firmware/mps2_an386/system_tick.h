// The control tick of the emulated board: SysTick, the Cortex-M's own timer, at 50 µs from the
// 25 MHz core clock of the MPS2 AN386. The interrupt only counts; the main loop runs one control
// tick of the module per count (docs/firmware.md, "Main loop").
#pragma once

#include <cstdint>

namespace motwin::firmware::mps2_an386 {

inline constexpr uint32_t kCoreClockHz = 25'000'000;

void system_tick_start(uint32_t period_us);
// SysTick interrupts since system_tick_start (wraps after 2^32 ticks, 59 hours at 50 µs).
uint32_t system_tick_count();

// Sleeps until the next interrupt unless `work_pending` says there is something to do; interrupts
// are masked while it checks, so an interrupt between the check and the sleep still wakes it.
template <class WorkPending>
void sleep_unless(const WorkPending& work_pending) {
  asm volatile("cpsid i" ::: "memory");
  if (!work_pending()) asm volatile("dsb\n\twfi" ::: "memory");
  asm volatile("cpsie i" ::: "memory");
}

}  // namespace motwin::firmware::mps2_an386
