// A TMCM-3216 module on its simulated board (sim/modules/tmcm3216/tmcm3216_sim_board.h) and a RAM NVM, with a CAN
// controller that records what the module transmits and reports the fault confinement a test
// sets: what the TMCM-3216 drive and module emergency tests drive through the dictionary.
#pragma once

#include <cstdint>
#include <memory>
#include <vector>

#include "board/can_controller.h"
#include "board/ram_non_volatile_memory.h"
#include "core/modules/tmcm3216/tmcm3216.h"
#include "sim/modules/tmcm3216/tmcm3216_sim_board.h"
#include "types/can_frame.h"

namespace motwin::testing {

// Not sdo_frames.h's RecordingCanController: this one also reports a status() the test sets.
class CanRecorderWithStatus final : public board::CanController {
 public:
  std::vector<can::CanFrame> frames;
  board::CanControllerStatus can_status;  // what the controller reports (fault confinement)
  bool transmit(const can::CanFrame& frame) override {
    frames.push_back(frame);
    return true;
  }
  board::CanControllerStatus status() const override { return can_status; }
};

struct Tmcm3216BoardRig {
  using Module = modules::tmcm3216::Tmcm3216;
  using Nvm = board::RamNonVolatileMemory<Module::kNvmSize>;
  static constexpr uint32_t kTickUs = modules::tmcm3216::kTickUs;

  std::unique_ptr<Nvm> nvm = std::make_unique<Nvm>();
  CanRecorderWithStatus can;
  sim::Tmcm3216SimBoard board;
  std::unique_ptr<Module> device;

  Tmcm3216BoardRig() { start(); }
  explicit Tmcm3216BoardRig(const sim::StepperMotorDescription& motor) : board(motor) { start(); }
  // A factory-formatted NVM and a module powered up on it.
  void start() {
    Module::format_factory_image(nvm->mutable_data(), nvm->size());
    device = std::make_unique<Module>(*nvm, can, board.board());
    device->power_up();
  }
  // Writes an object as an SDO download does; kNone when the dictionary takes it.
  canopen::SdoAbort write_object(uint16_t index, uint8_t sub, int64_t value) {
    canopen::ObjectRef ref;
    if (const canopen::SdoAbort abort = device->dictionary().find(index, sub, ref); abort != canopen::SdoAbort::kNone) {
      return abort;
    }
    uint8_t data[4] = {};
    canopen::encode_value(ref.info->type, value, data);
    return device->dictionary().write(ref, data, canopen::type_size(ref.info->type));
  }
  void nmt(uint8_t command) {
    can::CanFrame frame;
    frame.id = 0;
    frame.dlc = 2;
    frame.data[0] = command;
    frame.data[1] = 0;
    device->receive(frame);
  }
  void sync() {
    can::CanFrame frame;
    frame.id = 0x80;
    frame.dlc = 0;
    device->receive(frame);
  }
  void tick(uint64_t n = 1) {
    for (uint64_t i = 0; i < n; ++i) {
      board.before_tick();
      device->tick();
      board.after_tick(kTickUs * 1e-6);
    }
  }
  void run_ms(double ms) { tick(static_cast<uint64_t>(ms * 1000 / kTickUs)); }
  // The EMCY frames (node 1) sent since the last call; forgets everything else recorded.
  std::vector<can::CanFrame> emergencies() {
    std::vector<can::CanFrame> out;
    for (const can::CanFrame& f : can.frames) {
      if (f.id == 0x81) out.push_back(f);
    }
    can.frames.clear();
    return out;
  }
};

}  // namespace motwin::testing
