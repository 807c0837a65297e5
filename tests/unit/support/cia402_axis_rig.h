// One CiA-402 axis (core/cia402/axis_drive.h, with the TMCM-3216's part: tmcm3216_drive.h) without hardware, stepped in 50 µs ticks: what the
// axis drive and axis object tests drive. The encoder input follows the position demand, `lag`
// µsteps behind (a motor behind its field).
#pragma once

#include <cmath>
#include <cstdint>

#include "core/modules/tmcm3216/tmcm3216_drive.h"

namespace motwin::testing {

struct Cia402AxisRig {
  static constexpr uint32_t kTickUs = 50;

  modules::tmcm3216::Tmcm3216Drive drive;
  cia402::AxisInputs inputs;
  // The encoder reads the demand minus this lag.
  int32_t encoder_lag = 0;
  // false: the encoder follows only while 606A = 0 selects it, so that a test with 606A = -1 can
  // set the input by hand; true: it follows whatever 606A says.
  bool encoder_always_follows = false;

  Cia402AxisRig() { drive.reset(0); }
  void enable(int8_t mode) {
    drive.objects.mode = mode;
    drive.write_controlword(0x06);
    drive.write_controlword(0x07);
    drive.write_controlword(0x0F);
    run_ms(1);
  }
  void run_ticks(int n) {
    for (int i = 0; i < n; ++i) {
      if (encoder_always_follows || drive.objects.sensor_selection == 0) {
        inputs.encoder_position_usteps = drive.position_demand() - encoder_lag;
      }
      drive.step(inputs, kTickUs);
    }
  }
  void run_ms(double ms) { run_ticks(static_cast<int>(std::lround(ms * 1000 / kTickUs))); }
  // Runs until `done` or the time runs out; returns the elapsed time in s (or -1).
  template <class F>
  double run_until(F done, double max_s) {
    const int max_ticks = static_cast<int>(max_s * 1e6 / kTickUs);
    for (int i = 0; i < max_ticks; ++i) {
      run_ticks(1);
      if (done()) return (i + 1) * kTickUs * 1e-6;
    }
    return -1;
  }
};

}  // namespace motwin::testing
