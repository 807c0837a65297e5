#include "core/modules/tmcm3216/tmcm3216_tmcl.h"

namespace motwin::modules::tmcm3216 {

void Tmcm3216Tmcl::tick_axis() {
  uint8_t inputs = 0;  // IN0..IN3: the DIO levels
  for (uint8_t n = 0; n < board::Tmcm3216Io::kDioCount; ++n) {
    if (board_.io.dio_levels[n]) inputs |= static_cast<uint8_t>(1u << n);
  }
  uint8_t driven = 0;
  uint8_t levels = 0;
  for (uint8_t motor = 0; motor < kAxisCount; ++motor) {
    Tmcm3216TmclAxis& a = axis(motor);
    a.tick(board_.axes[motor], kTickUs, inputs);
    // The brake output of the motor, as the CANopen firmware drives it (200C: AP-less here).
    board_.io.brake_control[motor] = a.stepper.brake_control();
    board_.io.brake_duty[motor] = a.stepper.brake_duty();
    driven |= a.driven_outputs();
    levels |= a.output_levels();
  }
  // AP 45 and 47 drive their outputs (an output two axes drive is high when either sets it);
  // the others stay as SIO left them.
  for (uint8_t port = 0; port < board::Tmcm3216Io::kDioCount; ++port) {
    if ((driven & (1u << port)) != 0) io_adapter_.set_digital_output(port, (levels & (1u << port)) != 0);
  }
  datalogger_.control_tick();
}

}  // namespace motwin::modules::tmcm3216
