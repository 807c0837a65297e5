// Board seam: the module's CAN controller. The core transmits through it; received frames come
// the other way, from the board (an interrupt on hardware, the virtual bus on the host) into the
// module profile's receive() function, which only queues them: the services handle them in their
// next process() call.
#pragma once

#include "core/can/can_frame.h"

namespace motwin::board {

class CanController {
 public:
  // Queues a frame for transmission. false: the transmit queue is full and the frame is lost
  // (the caller may report it, as the firmware does with EMCY 8110).
  virtual bool transmit(const can::CanFrame& frame) = 0;

 protected:
  ~CanController() = default;
};

}  // namespace motwin::board
