#include "firmware/mps2_an386/cmsdk_uart.h"

#include "firmware/mps2_an386/registers.h"
#include "firmware/mps2_an386/system_tick.h"

namespace motwin::firmware::mps2_an386 {
namespace {

// Single producer, single consumer: the interrupt writes `head`, the main loop `tail` (or the
// other way round for sending); a power of two so that the indices may wrap.
template <class Entry, uint32_t kCapacity>
struct Ring {
  static_assert((kCapacity & (kCapacity - 1)) == 0);
  Entry entries[kCapacity];
  volatile uint32_t head = 0;
  volatile uint32_t tail = 0;
  bool empty() const { return head == tail; }
  bool full() const { return head - tail == kCapacity; }
  Entry& at(uint32_t index) { return entries[index & (kCapacity - 1)]; }
};

Ring<ReceivedByte, 256> g_received;
Ring<uint8_t, 512> g_sending;
volatile uint32_t g_overruns = 0;

volatile uint32_t& uart(uint32_t offset) { return reg(kUart0Base + offset); }

// Feeds the transmitter while it takes bytes. Called with the transmit interrupt unable to run
// (from it, or with interrupts masked).
void feed_transmitter() {
  while (!g_sending.empty() && (uart(kUartState) & kUartStateTxFull) == 0) {
    uart(kUartData) = g_sending.at(g_sending.tail);
    g_sending.tail = g_sending.tail + 1;
  }
}

}  // namespace

void uart0_init(uint32_t baud) {
  uart(kUartBaudDiv) = kCoreClockHz / baud;
  uart(kUartCtrl) = 0xF;  // TX, RX and their interrupts on
  reg(kNvicIser0) = (1u << kUart0RxIrq) | (1u << kUart0TxIrq);
}

bool uart0_peek(ReceivedByte& received) {
  if (g_received.empty()) return false;
  received = g_received.at(g_received.tail);
  return true;
}

void uart0_drop() { g_received.tail = g_received.tail + 1; }

uint32_t uart0_overruns() { return g_overruns; }

void Uart0Output::write(const uint8_t* bytes, size_t length) {
  for (size_t i = 0; i < length; ++i) {
    for (;;) {
      asm volatile("cpsid i" ::: "memory");
      const bool room = !g_sending.full();
      if (room) {
        g_sending.at(g_sending.head) = bytes[i];
        g_sending.head = g_sending.head + 1;
      }
      feed_transmitter();
      asm volatile("cpsie i" ::: "memory");
      if (room) break;
    }
  }
}

}  // namespace motwin::firmware::mps2_an386

extern "C" void Uart0Rx_Handler() {
  using namespace motwin::firmware::mps2_an386;
  uart(kUartIntStatus) = 1u << 1;
  while (uart(kUartState) & kUartStateRxFull) {
    const auto byte = static_cast<uint8_t>(uart(kUartData));
    if (g_received.full()) {
      g_overruns = g_overruns + 1;
      continue;
    }
    g_received.at(g_received.head) = ReceivedByte{byte, system_tick_count()};
    g_received.head = g_received.head + 1;
  }
}

extern "C" void Uart0Tx_Handler() {
  using namespace motwin::firmware::mps2_an386;
  uart(kUartIntStatus) = 1u << 0;
  feed_transmitter();
}
