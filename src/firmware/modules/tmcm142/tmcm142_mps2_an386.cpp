// The TMCM-142 firmware on the MPS2 AN386 board (qemu-system-arm -M mps2-an386): the core's
// module driving a stepper power stage that nothing reads back (open loop, as a stepper runs
// without an encoder: the position is the module's own microstep count), its EEPROM image in the
// board's flash region, TMCL binary and ASCII on UART0 and a 50 µs SysTick control tick
// (docs/firmware.md).
#include <cstdint>

#include "board/modules/tmcm142/tmcm142_io.h"
#include "board/stepper_drive.h"
#include "core/modules/tmcm142/tmcm142.h"
#include "firmware/banked_nvm.h"
#include "firmware/mps2_an386/cmsdk_uart.h"
#include "firmware/mps2_an386/tmcl_main_loop.h"

namespace {

using namespace motwin;
using modules::tmcm142::Tmcm142;
namespace an386 = firmware::mps2_an386;

// The emulated board has no ADC and no switches: open inputs.
class BenchIo final : public board::Tmcm142Io {
 public:
  bool digital_input(uint8_t) const override { return false; }
  uint16_t analog_input(uint8_t) const override { return 0; }
  void set_digital_output(uint8_t port, bool on) override {
    if (port < kDigitalOutputCount) outputs_ = on ? outputs_ | (1u << port) : outputs_ & ~(1u << port);
  }
  bool digital_output(uint8_t port) const override { return (outputs_ >> port) & 1u; }

 private:
  uint32_t outputs_ = 0;
};

using Eeprom = firmware::BankedNvm<Tmcm142::kNvmLayout.total_size>;
__attribute__((section(".eeprom"))) uint8_t g_eeprom_region[Eeprom::kRegionSize];

Eeprom g_eeprom(g_eeprom_region);
BenchIo g_io;
// The driver stage: the 24 V supply the feedback starts with, no encoder, no switches.
board::StepperPowerStage g_stage;
an386::Uart0Output g_uart;

}  // namespace

extern "C" [[noreturn]] void firmware_main() {
  an386::uart0_init(an386::kDefaultBaud);
  g_eeprom.open([](uint8_t* image, size_t size) { Tmcm142::format_factory_image(image, size); });
  static Tmcm142 module(g_eeprom, g_stage, g_io);
  an386::run_tmcl_module(module, g_uart);
}
