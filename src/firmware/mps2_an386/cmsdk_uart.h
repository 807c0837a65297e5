// The CMSDK APB UART of the MPS2 board (ARM Cortex-M System Design Kit technical reference,
// "APB UART"; qemu: hw/char/cmsdk-apb-uart.c): UART0 at 0x40004000, receive interrupt IRQ 0,
// transmit interrupt IRQ 1. Received bytes go into a ring buffer with the control tick they
// arrived in (the frame decoder's pause rule needs it); sent bytes leave from another ring as the
// transmitter takes them.
#pragma once

#include <cstddef>
#include <cstdint>

#include "firmware/serial_tmcl_link.h"

namespace motwin::firmware::mps2_an386 {

struct ReceivedByte {
  uint8_t byte;
  uint32_t tick;  // SysTick count when it arrived
};

// Interrupts on, transmitter and receiver on at `baud` from the 25 MHz peripheral clock.
void uart0_init(uint32_t baud);

// The oldest received byte not dropped yet; false when there is none.
bool uart0_peek(ReceivedByte& received);
void uart0_drop();
// Bytes lost because the receive ring was full.
uint32_t uart0_overruns();

// Queues bytes for sending; when the ring is full it waits for the transmitter.
class Uart0Output final : public ByteOutput {
 public:
  void write(const uint8_t* bytes, size_t length) override;
};

}  // namespace motwin::firmware::mps2_an386
