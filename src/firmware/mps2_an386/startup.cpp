// Start-up of the MPS2 AN386 images: the vector table at address 0 (initial stack pointer, reset
// and the exceptions and interrupts the board uses), Reset_Handler (the FPU on, .data copied from
// flash, .bss cleared, constructors run, then main) and the few runtime hooks a C++ image without
// the C++ library needs.
#include <cstdint>

#include "firmware/mps2_an386/registers.h"

extern "C" {
extern uint32_t _estack, _sidata, _sdata, _edata, _sbss, _ebss;
extern void (*__preinit_array_start[])();
extern void (*__preinit_array_end[])();
extern void (*__init_array_start[])();
extern void (*__init_array_end[])();
// The image's firmware (firmware/modules/<module>/): never returns.
[[noreturn]] void firmware_main();

void SysTick_Handler();
void Uart0Rx_Handler();
void Uart0Tx_Handler();

// Faults and unexpected interrupts stop here: a debugger (qemu -s) shows where.
[[noreturn]] void Default_Handler() {
  for (;;) asm volatile("bkpt 0");
}

// What the unused stack holds (docs/firmware.md, "Per-tick figures").
constexpr uint32_t kStackPaint = 0x5AC3A55Cu;

[[noreturn]] void Reset_Handler() {
  using namespace motwin::firmware::mps2_an386;
  // Full access to CP10 and CP11 before any floating-point instruction runs.
  reg(kCpacr) = reg(kCpacr) | (0xFu << 20);
  asm volatile("dsb\n\tisb" ::: "memory");
  for (uint32_t *from = &_sidata, *to = &_sdata; to < &_edata;) *to++ = *from++;
  for (uint32_t* to = &_sbss; to < &_ebss;) *to++ = 0;
  // The free stack painted with kStackPaint, up to a little below this function's own frame:
  // the words still painted later show the stack's high-water mark (bench/firmware_figures.py
  // reads them through qemu's monitor; docs/firmware.md, "Per-tick figures").
  uint32_t* stack_pointer;
  asm volatile("mov %0, sp" : "=r"(stack_pointer));
  for (uint32_t* to = &_ebss; to < stack_pointer - 16;) *to++ = kStackPaint;
  for (auto* init = __preinit_array_start; init < __preinit_array_end; ++init) (*init)();
  for (auto* init = __init_array_start; init < __init_array_end; ++init) (*init)();
  firmware_main();
}

// Static objects live until power-off: their destructors are never registered.
void* __dso_handle = nullptr;
int __aeabi_atexit(void*, void (*)(void*), void*) { return 0; }
[[noreturn]] void __cxa_pure_virtual() { Default_Handler(); }
}

namespace {

using Handler = void (*)();
constexpr uint32_t kExceptionCount = 16;
constexpr uint32_t kInterruptCount = 2;  // UART0 receive and transmit

}  // namespace

__attribute__((section(".isr_vector"), used)) const Handler g_vector_table[kExceptionCount + kInterruptCount] = {
    reinterpret_cast<Handler>(&_estack),
    Reset_Handler,
    Default_Handler,  // NMI
    Default_Handler,  // HardFault
    Default_Handler,  // MemManage
    Default_Handler,  // BusFault
    Default_Handler,  // UsageFault
    nullptr, nullptr, nullptr, nullptr,
    Default_Handler,  // SVCall
    Default_Handler,  // DebugMonitor
    nullptr,
    Default_Handler,  // PendSV
    SysTick_Handler,
    Uart0Rx_Handler,  // IRQ 0
    Uart0Tx_Handler,  // IRQ 1
};
