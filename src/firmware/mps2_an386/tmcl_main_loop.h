// The main loop of a TMCL module's firmware on the MPS2 AN386 board, the same for every module:
// each SysTick is one control tick of the module, received bytes go to the TMCL link with the
// tick they arrived in, and the core sleeps (wfi) when there is nothing to do. The module's
// image (firmware/modules/<module>/) opens its EEPROM image and constructs the module first.
//
// The SysTick interrupt only counts and the control tick runs here, in thread mode, so that the
// tick and the TMCL commands never run at once (the core is not reentrant); a pass that takes
// longer than a tick catches up with the ticks it missed (docs/firmware.md, "Main loop").
#pragma once

#include <cstdint>

#include "firmware/mps2_an386/cmsdk_uart.h"
#include "firmware/mps2_an386/system_tick.h"
#include "firmware/serial_tmcl_link.h"

namespace motwin::firmware::mps2_an386 {

// The serial port at the modules' default (GP 65 code 7).
inline constexpr uint32_t kDefaultBaud = 115200;

// One control tick, never inlined: its entry is one address, where bench/firmware_figures.py
// starts each tick's instruction count (docs/firmware.md, "Per-tick figures").
template <class Module>
[[gnu::noinline]] void run_control_tick(Module& module) {
  module.tick();
}

template <class Module>
[[noreturn]] void run_tmcl_module(Module& module, Uart0Output& uart) {
  module.engine().power_up();
  static SerialTmclLink link(module.engine(), uart);
  system_tick_start(Module::kControlTickUs);
  uint32_t ticks_run = 0;
  for (;;) {
    while (ticks_run != system_tick_count()) {
      run_control_tick(module);
      ++ticks_run;
    }
    const uint64_t now_us = module.tick_count() * Module::kControlTickUs;
    ReceivedByte received;
    while (uart0_peek(received)) {
      if (!link.receive(received.byte, uint64_t{received.tick} * Module::kControlTickUs)) break;
      uart0_drop();
    }
    link.poll(now_us);
    sleep_unless([&] {
      ReceivedByte next;
      return ticks_run != system_tick_count() || (!link.holding_reply() && uart0_peek(next));
    });
  }
}

}  // namespace motwin::firmware::mps2_an386
