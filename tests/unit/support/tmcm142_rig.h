// A TMCM-142 on a RAM EEPROM, a scripted I/O board and the stepper power-stage seam, with either
// the ideal stepper (exact positions) or the physical NEMA23 model behind it, and the motor-side
// sensors (encoder, switches) of sim/stepper_plant.h: what the TMCM-142 core tests drive.
#pragma once

#include <array>
#include <cstdint>

#include "board/ram_non_volatile_memory.h"
#include "board/stepper_drive.h"
#include "board/modules/tmcm142/tmcm142_io.h"
#include "core/modules/tmcm142/tmcm142.h"
#include "core/tmcl/engine.h"
#include "core/tmcl/serial_link.h"
#include "sim/stepper_plant.h"

namespace motwin::testing {

class ScriptedTmcm142Io final : public board::Tmcm142Io {
 public:
  std::array<bool, kDigitalInputCount> digital_inputs{};
  std::array<uint16_t, kAnalogInputCount> analog_inputs{};
  std::array<bool, kDigitalOutputCount> outputs{};

  bool digital_input(uint8_t port) const override { return digital_inputs[port]; }
  uint16_t analog_input(uint8_t channel) const override { return analog_inputs[channel]; }
  void set_digital_output(uint8_t port, bool on) override { outputs[port] = on; }
  bool digital_output(uint8_t port) const override { return outputs[port]; }
};

using Tmcm142 = modules::tmcm142::Tmcm142;
using Tmcm142Nvm = board::RamNonVolatileMemory<Tmcm142::kNvmLayout.total_size>;

// Microsteps per revolution at the default resolution (1024) of a 200-step motor.
inline constexpr double kMicrostepsPerRevolution = 200.0 * 1024.0;

enum class StepperMotor : uint8_t { kIdeal, kPhysical };

struct Tmcm142Rig {
  Tmcm142Nvm nvm;
  ScriptedTmcm142Io io;
  board::StepperPowerStage stage;
  sim::IdealStepper ideal;
  sim::StepperPlant plant{sim::StepperMotorDescription::nema23()};
  sim::StepperSensors sensors;
  StepperMotor motor;
  Tmcm142 module{nvm, stage, io};
  tmcl::TmclEngine& engine{module.engine()};

  explicit Tmcm142Rig(StepperMotor which = StepperMotor::kIdeal) : motor(which) {
    Tmcm142::format_factory_image(nvm.mutable_data(), nvm.size());
    engine.power_up();
  }

  // Switches placed at rotor positions given in microsteps (1024 per full step): a right limit
  // switch pressed beyond `right_at`, a left one below `left_at`.
  void place_limit_switches(double left_at, double right_at) {
    auto config = sensors.config();
    config.right = {true, right_at / kMicrostepsPerRevolution, 1e300, true};
    config.left = {true, -1e300, left_at / kMicrostepsPerRevolution, true};
    sensors.set_config(config);
  }
  // A left switch that is a cam: pressed between `from` and `to` microsteps only.
  void place_left_cam(double from, double to) {
    auto config = sensors.config();
    config.left = {true, from / kMicrostepsPerRevolution, to / kMicrostepsPerRevolution, true};
    sensors.set_config(config);
  }

  double rotor_revolutions() const {
    return motor == StepperMotor::kIdeal ? ideal.position_revolutions() : plant.position_revolutions();
  }
  double rotor_microsteps() const { return rotor_revolutions() * kMicrostepsPerRevolution; }

  void tick() {
    sensors.sense(rotor_revolutions(), stage.feedback);
    module.tick();
    if (motor == StepperMotor::kIdeal) {
      ideal.advance(stage.drive, modules::tmcm142::kControlTickS);
    } else {
      plant.advance(stage.drive, stage.feedback.supply_millivolt * 1e-3, modules::tmcm142::kControlTickS);
    }
  }
  void run_ms(uint32_t ms) {
    for (uint32_t i = 0; i < ms * modules::tmcm142::kTicksPerMillisecond; ++i) tick();
  }
  // Runs until `done` holds or `max_ms` passed; returns the simulated milliseconds it took.
  template <class Predicate>
  uint32_t run_until(Predicate done, uint32_t max_ms) {
    for (uint32_t ms = 0; ms < max_ms; ++ms) {
      if (done()) return ms;
      run_ms(1);
    }
    return max_ms;
  }

  tmcl::SerialResponse send(const tmcl::Frame& frame, tmcl::ChannelId channel = 0) {
    return tmcl::serve_serial_frame(engine, frame, channel);
  }
  // Sends an instruction to address 1 and returns the decoded reply.
  tmcl::Reply command(uint8_t cmd, uint8_t type, uint8_t motor_bank, int32_t value) {
    const auto response = send(tmcl::encode_request(1, tmcl::Instruction{cmd, type, motor_bank, value}));
    const auto& b = response.bytes;
    const uint32_t v = (uint32_t{b[4]} << 24) | (uint32_t{b[5]} << 16) | (uint32_t{b[6]} << 8) | b[7];
    return tmcl::Reply{b[2], b[3], static_cast<int32_t>(v)};
  }
  uint8_t sap(uint8_t number, int32_t value) { return command(5, number, 0, value).status; }
  int32_t gap(uint8_t number) { return command(6, number, 0, 0).value; }
  uint8_t sgp(uint8_t number, uint8_t bank, int32_t value) { return command(9, number, bank, value).status; }
  int32_t ggp(uint8_t number, uint8_t bank = 0) { return command(10, number, bank, 0).value; }
};

}  // namespace motwin::testing
