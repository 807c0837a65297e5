// Memory-mapped registers of the Cortex-M4 and of the MPS2 AN386 peripherals the board uses.
#pragma once

#include <cstdint>

namespace motwin::firmware::mps2_an386 {

inline volatile uint32_t& reg(uint32_t address) { return *reinterpret_cast<volatile uint32_t*>(address); }

// System control space (ARMv7-M architecture reference manual, B3).
inline constexpr uint32_t kSysTickCsr = 0xE000E010;  // control and status
inline constexpr uint32_t kSysTickRvr = 0xE000E014;  // reload value
inline constexpr uint32_t kSysTickCvr = 0xE000E018;  // current value
inline constexpr uint32_t kNvicIser0 = 0xE000E100;   // interrupt set-enable, IRQ 0..31
inline constexpr uint32_t kCpacr = 0xE000ED88;       // coprocessor access (the FPU is CP10, CP11)

// CMSDK APB UART0.
inline constexpr uint32_t kUart0Base = 0x40004000;
inline constexpr uint32_t kUartData = 0x00;
inline constexpr uint32_t kUartState = 0x04;  // bit 0 TX full, bit 1 RX full
inline constexpr uint32_t kUartCtrl = 0x08;   // bit 0 TX on, 1 RX on, 2 TX interrupt, 3 RX interrupt
inline constexpr uint32_t kUartIntStatus = 0x0C;  // write 1 to clear: bit 0 TX, bit 1 RX
inline constexpr uint32_t kUartBaudDiv = 0x10;
inline constexpr uint32_t kUartStateTxFull = 1u << 0;
inline constexpr uint32_t kUartStateRxFull = 1u << 1;
inline constexpr uint32_t kUart0RxIrq = 0;
inline constexpr uint32_t kUart0TxIrq = 1;

}  // namespace motwin::firmware::mps2_an386
