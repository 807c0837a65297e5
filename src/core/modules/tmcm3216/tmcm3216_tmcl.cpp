#include "core/modules/tmcm3216/tmcm3216_tmcl.h"

namespace motwin::modules::tmcm3216 {

void Tmcm3216Tmcl::tick_axis() {
  for (uint8_t motor = 0; motor < kAxisCount; ++motor) {
    Tmcm3216TmclAxis& a = axis(motor);
    a.tick(board_.axes[motor], kTickUs);
    // The brake output of the motor, as the CANopen firmware drives it (200C: AP-less here).
    board_.io.brake_control[motor] = a.stepper.brake_control();
    board_.io.brake_duty[motor] = a.stepper.brake_duty();
  }
}

}  // namespace motwin::modules::tmcm3216
