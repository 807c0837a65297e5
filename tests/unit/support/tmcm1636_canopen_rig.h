// A TMCM-1636 with its CANopen firmware on a RAM NVM, a CAN controller that records what it sends,
// and the simulated board: the ideal motor, or a physical one (a preset, with its start-up
// settings in the image as `motwin serve --motor` writes them). SDO and NMT in raw frames
// (CanopenClient); time advances by control ticks of 50 µs.
#pragma once

#include <cstdint>
#include <functional>
#include <memory>
#include <optional>
#include <vector>

#include "board/ram_non_volatile_memory.h"
#include "canopen_rig.h"
#include "core/modules/tmcm1636/tmcm1636_canopen.h"
#include "host/modules/tmcm1636/tmcm1636_startup_image.h"
#include "sim/modules/tmcm1636/motor_description.h"
#include "sim/modules/tmcm1636/tmcm1636_sim_board.h"
#include "sim/modules/tmcm1636/tmcm1636_sim_io.h"

namespace motwin::testing {

struct Tmcm1636CanopenRig : CanopenClient<Tmcm1636CanopenRig> {
  using Module = modules::tmcm1636::Tmcm1636Canopen;
  static constexpr double kTickS = modules::tmcm1636::kControlTickUs * 1e-6;

  std::unique_ptr<board::RamNonVolatileMemory<Module::kNvmSize>> nvm =
      std::make_unique<board::RamNonVolatileMemory<Module::kNvmSize>>();
  RecordingCanController can;
  sim::Tmcm1636SimIo io;
  std::unique_ptr<sim::Tmcm1636SimBoard> board;
  std::unique_ptr<Module> device;

  // nullopt: the ideal motor.
  explicit Tmcm1636CanopenRig(const std::optional<sim::MotorDescription>& motor = std::nullopt) {
    Module::format_factory_image(nvm->mutable_data(), nvm->size());
    if (motor) {
      host::write_tmcm1636_canopen_startup_image(*motor, nvm->mutable_data(), nvm->size());
      board = std::make_unique<sim::Tmcm1636SimBoard>(io, *motor);
    } else {
      board = std::make_unique<sim::Tmcm1636SimBoard>(io);
    }
    power_cycle();
  }
  static sim::MotorDescription preset(const char* name) { return *sim::motor_preset(name); }

  // Power cycle with the same NVM and board.
  void power_cycle() {
    device = std::make_unique<Module>(*nvm, can, board->io());
    if (board::Tmcm1636PowerStage* stage = board->power_stage()) device->axis().attach_power_stage(stage);
    device->power_up();
  }

  // Control ticks; what the node sent meanwhile is appended to `sent`.
  std::vector<can::CanFrame> sent;
  void tick() {
    board->before_tick();
    device->tick();
    board->after_tick(kTickS);
    for (const can::CanFrame& f : can.take()) sent.push_back(f);
  }
  void run_ms(double ms) {
    const auto ticks = static_cast<uint64_t>(ms * modules::tmcm1636::kTicksPerMillisecond + 0.5);
    for (uint64_t i = 0; i < ticks; ++i) tick();
  }
  // Runs until `done` (checked every tick) or `max_ms`; the simulated milliseconds taken.
  double run_until(const std::function<bool()>& done, double max_ms) {
    const auto max_ticks = static_cast<uint64_t>(max_ms * modules::tmcm1636::kTicksPerMillisecond);
    for (uint64_t i = 0; i < max_ticks; ++i) {
      if (done()) return static_cast<double>(i) / modules::tmcm1636::kTicksPerMillisecond;
      tick();
    }
    return max_ms;
  }

  int32_t read_i32(uint16_t index, uint8_t sub = 0) { return static_cast<int32_t>(read_u32(index, sub)); }
  int16_t read_i16(uint16_t index, uint8_t sub = 0) { return static_cast<int16_t>(read_u32(index, sub)); }
  uint16_t statusword() { return static_cast<uint16_t>(read_u32(0x6041, 0)); }

  // NMT start, then the PDS walked to OPERATION ENABLED in `mode` (6060) by SDO.
  void enable(int8_t mode) {
    nmt(0x01, node());
    EXPECT_EQ(download(0x6060, 0, static_cast<uint8_t>(mode), 1), 0u);
    for (const uint16_t controlword : {0x06, 0x07, 0x0F}) EXPECT_EQ(download(0x6040, 0, controlword, 2), 0u);
    EXPECT_EQ(statusword() & 0x6F, 0x27) << "operation enabled";
  }
};

}  // namespace motwin::testing
