#include "firmware/mps2_an386/system_tick.h"

#include "firmware/mps2_an386/registers.h"

namespace motwin::firmware::mps2_an386 {
namespace {

volatile uint32_t g_tick_count = 0;

}  // namespace

void system_tick_start(uint32_t period_us) {
  reg(kSysTickRvr) = kCoreClockHz / 1'000'000 * period_us - 1;
  reg(kSysTickCvr) = 0;
  reg(kSysTickCsr) = 7;  // the core clock, the interrupt, on
}

uint32_t system_tick_count() { return g_tick_count; }

}  // namespace motwin::firmware::mps2_an386

extern "C" void SysTick_Handler() {
  using motwin::firmware::mps2_an386::g_tick_count;
  g_tick_count = g_tick_count + 1;
}
