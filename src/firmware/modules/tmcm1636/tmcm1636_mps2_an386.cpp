// The TMCM-1636 firmware on the MPS2 AN386 board (qemu-system-arm -M mps2-an386): the core's
// module with the ideal motor (no power stage attached: the axis follows its ramp generator,
// core/modules/tmcm1636/tmcm1636_axis.h), its EEPROM image in the board's flash region, TMCL on
// UART0 and a 50 µs SysTick control tick (docs/firmware.md). Built twice, as a real module is
// flashed with one firmware generation: tmcm1636.elf is 1636V109 (the manual's),
// tmcm1636_v113.elf is 1636V113 (what PyTrinamic's TMCM1636 class targets), chosen by
// MOTWIN_TMCM1636_FIRMWARE (src/firmware/CMakeLists.txt).
#include <cstdint>

#include "board/modules/tmcm1636/tmcm1636_io.h"
#include "core/modules/tmcm1636/tmcm1636.h"
#include "core/modules/tmcm1636/tmcm1636_hardware.h"
#include "firmware/banked_nvm.h"
#include "firmware/mps2_an386/cmsdk_uart.h"
#include "firmware/mps2_an386/tmcl_main_loop.h"

namespace {

using namespace motwin;
using modules::tmcm1636::Tmcm1636;
namespace hw = modules::tmcm1636;
namespace an386 = firmware::mps2_an386;

// The emulated board has no ADC and no switches: a bench supply of 24 V, 25 °C, open inputs
// (the simulated board's defaults, sim/modules/tmcm1636/tmcm1636_sim_io.h).
class BenchIo final : public board::Tmcm1636Io {
 public:
  bool digital_input(uint8_t) const override { return false; }
  uint16_t analog_input(uint8_t channel) const override {
    if (channel == kAnalogSupplyChannel) return hw::supply_adc_from_millivolt(24'000);
    if (channel == kAnalogTemperatureChannel) return hw::temperature_adc_from_celsius(25.0);
    return 0;
  }
  void set_digital_output(uint8_t port, bool on) override {
    if (port < kDigitalOutputCount) outputs_ = on ? outputs_ | (1u << port) : outputs_ & ~(1u << port);
  }
  bool digital_output(uint8_t port) const override { return (outputs_ >> port) & 1u; }
  bool reference_switch_level(board::ReferenceSwitch) const override { return false; }

 private:
  uint32_t outputs_ = 0;
};

#ifndef MOTWIN_TMCM1636_FIRMWARE
#define MOTWIN_TMCM1636_FIRMWARE kV109
#endif
constexpr hw::Firmware kFirmware = hw::Firmware::MOTWIN_TMCM1636_FIRMWARE;

using Eeprom = firmware::BankedNvm<Tmcm1636::kNvmLayout.total_size>;
__attribute__((section(".eeprom"))) uint8_t g_eeprom_region[Eeprom::kRegionSize];

Eeprom g_eeprom(g_eeprom_region);
BenchIo g_io;
an386::Uart0Output g_uart;

}  // namespace

extern "C" [[noreturn]] void firmware_main() {
  an386::uart0_init(an386::kDefaultBaud);
  g_eeprom.open([](uint8_t* image, size_t size) {
    Tmcm1636::format_factory_image(image, size, Tmcm1636::axis_parameters(kFirmware));
  });
  // Constructed once the image is open: the module reads it at power-up.
  static Tmcm1636 module(g_eeprom, g_io, kFirmware);
  an386::run_tmcl_module(module, g_uart);
}
