// A firmware-like image of all three modules for the size report (scripts/bench.sh,
// scripts/core_size.py --image): the core's modules on boards that are plain memory, driven
// through the entry points the host runtime uses (power-up, tick, TMCL over serial, ASCII and
// CAN with command 138 events, CANopen frames, the factory image and the TMCM-142's migration of
// older images). Diagnostics only the host prints (stop reasons, homing failure names) and the
// encoders of a TMCL client are left out, as a firmware would leave them. Linked with --gc-sections from a core compiled with
// a section per function, the image keeps what a firmware of the three modules would; the
// archive sum also counts what none of them calls. Inputs come from argc so that nothing folds
// away; it runs a few ticks and exits.
#include <cstddef>
#include <cstdint>

#include "board/ram_non_volatile_memory.h"
#include "core/modules/tmcm142/tmcm142.h"
#include "core/modules/tmcm1636/tmcm1636.h"
#include "core/modules/tmcm3216/tmcm3216.h"
#include "core/tmcl/ascii_link.h"
#include "core/tmcl/can_link.h"
#include "core/tmcl/serial_link.h"

namespace {

using namespace motwin;

// Digital and analog inputs that read as a quiet board; outputs kept.
template <class Io>
class QuietIo final : public Io {
 public:
  bool digital_input(uint8_t) const override { return false; }
  uint16_t analog_input(uint8_t) const override { return 0; }
  void set_digital_output(uint8_t port, bool on) override { outputs_ = on ? outputs_ | (1u << port) : outputs_; }
  bool digital_output(uint8_t port) const override { return (outputs_ >> port) & 1u; }
  uint32_t outputs_ = 0;
};

class Tmcm1636QuietIo final : public board::Tmcm1636Io {
 public:
  bool digital_input(uint8_t) const override { return false; }
  uint16_t analog_input(uint8_t) const override { return 0; }
  void set_digital_output(uint8_t port, bool on) override { outputs_ = on ? outputs_ | (1u << port) : outputs_; }
  bool digital_output(uint8_t port) const override { return (outputs_ >> port) & 1u; }
  bool reference_switch_level(board::ReferenceSwitch) const override { return false; }
  uint32_t outputs_ = 0;
};

class CountingCan final : public board::CanController {
 public:
  bool transmit(const can::CanFrame& frame) override {
    sum_ += frame.id;
    return true;
  }
  uint32_t sum_ = 0;
};

class CountingSink final : public tmcl::ReplySink {
 public:
  // As the host's serial links send a command 138 event.
  void deliver(tmcl::ChannelId, const tmcl::Reply& reply) override { sum_ += tmcl::encode_event_reply(*device_, reply)[8]; }
  tmcl::TmclDevice* device_ = nullptr;
  uint32_t sum_ = 0;
};

// What a TMCL module's firmware does: power-up, ticks, and requests over each of its links.
template <class Module>
uint32_t run_tmcl_module(Module& module, uint8_t seed) {
  tmcl::TmclEngine& engine = module.engine();
  engine.power_up();
  CountingSink sink;
  sink.device_ = &engine.device();
  tmcl::SerialFrameDecoder decoder;
  tmcl::AsciiLink ascii;
  const tmcl::AsciiSettings settings = tmcl::ascii_settings(engine.device());
  uint32_t sum = 0;
  for (uint8_t i = 0; i < 16; ++i) {
    module.tick();
    const auto byte = static_cast<uint8_t>(seed + i);
    if (decoder.push(byte, i)) {
      const tmcl::SerialResponse response = tmcl::serve_serial_frame(engine, decoder.frame(), 1);
      if (response.reset_after_send) engine.complete_reset();
      sum += response.length;
    }
    if (ascii.push(byte, settings)) sum += tmcl::serve_ascii_command(engine, ascii.command(), 2).length;
    can::CanFrame frame;
    frame.id = seed;
    frame.dlc = 7;
    frame.data[0] = byte;
    sum += tmcl::serve_can_frame(engine, frame, 3).reply.id;
    engine.collect_events(sink);
  }
  return sum + sink.sum_;
}

}  // namespace

int main(int argc, char** argv) {
  const auto seed = static_cast<uint8_t>(argc + (argv[0] != nullptr ? argv[0][0] : 0));
  uint32_t sum = 0;

  static board::RamNonVolatileMemory<modules::tmcm142::Tmcm142::kNvmLayout.total_size> nvm142;
  modules::tmcm142::Tmcm142::format_factory_image(nvm142.mutable_data(), nvm142.size());
  // An image of the older layout is migrated at power-up (docs/tmcm-142.md "EEPROM image").
  if (seed == 0) modules::tmcm142::Tmcm142::migrate_image(1, nvm142.mutable_data(), nvm142.size());
  static board::StepperPowerStage stage142;
  static QuietIo<board::Tmcm142Io> io142;
  static modules::tmcm142::Tmcm142 tmcm142(nvm142, stage142, io142);
  sum += run_tmcl_module(tmcm142, seed);

  static board::RamNonVolatileMemory<modules::tmcm1636::Tmcm1636::kNvmLayout.total_size> nvm1636;
  modules::tmcm1636::Tmcm1636::format_factory_image(nvm1636.mutable_data(), nvm1636.size());
  static Tmcm1636QuietIo io1636;
  static board::Tmcm1636PowerStage stage1636;
  static modules::tmcm1636::Tmcm1636 tmcm1636(nvm1636, io1636,
                                              seed & 1 ? modules::tmcm1636::Firmware::kV113 : modules::tmcm1636::Firmware::kV109);
  tmcm1636.axis().attach_power_stage(&stage1636);
  sum += run_tmcl_module(tmcm1636, seed);

  static board::RamNonVolatileMemory<modules::tmcm3216::Tmcm3216::kNvmSize> nvm3216;
  static CountingCan can3216;
  static board::Tmcm3216Board board3216;
  static modules::tmcm3216::Tmcm3216 tmcm3216(nvm3216, can3216, board3216, modules::tmcm3216::Tmcm3216Config{});
  tmcm3216.power_up();
  for (uint8_t i = 0; i < 16; ++i) {
    can::CanFrame frame;
    frame.id = static_cast<uint32_t>(seed) * 16 + i;
    frame.dlc = 8;
    frame.data[0] = static_cast<uint8_t>(seed + i);
    tmcm3216.receive(frame);
    tmcm3216.process(1000);
    tmcm3216.tick();
  }
  sum += can3216.sum_;
  return static_cast<int>(sum & 1);
}
