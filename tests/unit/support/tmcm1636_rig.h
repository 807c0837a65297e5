// A TMCM-1636 on a RAM EEPROM and a scripted I/O board, with the TMCL engine in front:
// what the core tests drive.
#pragma once

#include <array>
#include <initializer_list>

#include "board/ram_non_volatile_memory.h"
#include "board/modules/tmcm1636/tmcm1636_io.h"
#include "core/modules/tmcm1636/tmcm1636.h"
#include "core/tmcl/engine.h"
#include "core/tmcl/serial_link.h"

namespace motwin::testing {

class ScriptedTmcm1636Io final : public board::Tmcm1636Io {
 public:
  std::array<bool, kDigitalInputCount> digital_inputs{};
  std::array<uint16_t, kAnalogInputCount> analog_inputs{0, 0, 745, 14894};  // 24.0 V, 25 °C
  std::array<bool, kDigitalOutputCount> outputs{};
  std::array<bool, 3> reference_switch_levels{};

  bool digital_input(uint8_t port) const override { return digital_inputs[port]; }
  uint16_t analog_input(uint8_t channel) const override { return analog_inputs[channel]; }
  void set_digital_output(uint8_t port, bool on) override { outputs[port] = on; }
  bool digital_output(uint8_t port) const override { return outputs[port]; }
  bool reference_switch_level(board::ReferenceSwitch which) const override {
    return reference_switch_levels[static_cast<size_t>(which)];
  }
};

using Tmcm1636 = modules::tmcm1636::Tmcm1636;
using Tmcm1636Nvm = board::RamNonVolatileMemory<Tmcm1636::kNvmLayout.total_size>;

struct Tmcm1636Rig {
  Tmcm1636Nvm nvm;
  ScriptedTmcm1636Io io;
  Tmcm1636 module;
  tmcl::TmclEngine& engine{module.engine()};

  // A factory image of the generation's rows, as `motwin serve --firmware` makes it.
  explicit Tmcm1636Rig(modules::tmcm1636::Firmware firmware = modules::tmcm1636::Firmware::kV109)
      : module(nvm, io, firmware) {
    Tmcm1636::format_factory_image(nvm.mutable_data(), nvm.size(), Tmcm1636::axis_parameters(firmware));
    engine.power_up();
  }

  tmcl::SerialResponse send(const tmcl::Frame& frame, tmcl::ChannelId channel = 0) {
    return tmcl::serve_serial_frame(engine, frame, channel);
  }
  tmcl::SerialResponse send(std::initializer_list<uint8_t> bytes, tmcl::ChannelId channel = 0) {
    tmcl::Frame frame{};
    size_t i = 0;
    for (uint8_t b : bytes) frame[i++] = b;
    return send(frame, channel);
  }
  // Sends an instruction to address 1 and returns the decoded reply.
  tmcl::Reply command(uint8_t cmd, uint8_t type, uint8_t motor, int32_t value) {
    const auto response = send(tmcl::encode_request(1, tmcl::Instruction{cmd, type, motor, value}));
    const auto& b = response.bytes;
    const uint32_t v = (uint32_t{b[4]} << 24) | (uint32_t{b[5]} << 16) | (uint32_t{b[6]} << 8) | b[7];
    return tmcl::Reply{b[2], b[3], static_cast<int32_t>(v)};
  }
  int32_t gap(uint8_t number) { return command(6, number, 0, 0).value; }
  void run_ms(uint32_t ms) {
    for (uint32_t i = 0; i < ms * modules::tmcm1636::kTicksPerMillisecond; ++i) module.tick();
  }
};

}  // namespace motwin::testing
