// Board seam: the module's CAN controller. The core transmits through it; received frames come
// the other way, from the board (an interrupt on hardware, the virtual bus on the host) into the
// module profile's receive() function, which only queues them: the services handle them in their
// next process() call. status() is the controller's fault confinement (ISO 11898-1), which the
// CANopen firmware polls for its EMCY 8120 / 8140 (manual table 365).
#pragma once

#include <cstdint>

#include "types/can_frame.h"

namespace motwin::board {

// Fault confinement state of the controller (ISO 11898-1): error-active below 128 in both error
// counters, error-passive from 128 (it still transmits), bus-off when the transmit error counter
// passes 255 (it neither transmits nor receives until it recovers).
enum class CanErrorState : uint8_t { kErrorActive, kErrorPassive, kBusOff };

struct CanControllerStatus {
  CanErrorState error_state = CanErrorState::kErrorActive;
  bool warning = false;              // an error counter has reached the warning limit (96)
  uint32_t bus_off_recoveries = 0;   // times the controller came back from bus-off (counts up)
};

class CanController {
 public:
  // Queues a frame for transmission. false: the transmit queue is full and the frame is lost
  // (the caller may report it, as the firmware does with EMCY 8110).
  virtual bool transmit(const can::CanFrame& frame) = 0;
  // The controller's error state now. The default is a controller that never sees a bus error
  // (test doubles, links whose transport has no fault confinement).
  virtual CanControllerStatus status() const { return {}; }

 protected:
  ~CanController() = default;
};

}  // namespace motwin::board
