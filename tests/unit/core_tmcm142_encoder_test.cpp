// TMCM-142 on the physical NEMA23 model: the encoder position (AP 41, 42, 43), lost steps on a
// blocked rotor, the encoder deviation stop (AP 212, AP 207, EDV for JC and CLE) and the easyPID
// correcting a load-induced lag.
#include <cmath>
#include <initializer_list>

#include <gtest/gtest.h>

#include "core/modules/tmcm142/tmcm142_hardware.h"
#include "support/tmcm142_rig.h"

namespace motwin::testing {
namespace {

constexpr uint8_t kOk = 100;

// A 10240-line encoder (40960 counts per revolution): 5 microsteps per count at 1024.
void use_fine_encoder(Tmcm142Rig& rig) {
  auto config = rig.sensors.config();
  config.encoder.counts_per_revolution = 40960;
  rig.sensors.set_config(config);
  ASSERT_EQ(rig.sap(42, 5 * 65536), kOk);
}

void use_pps(Tmcm142Rig& rig, int32_t vmax, int32_t acceleration) {
  ASSERT_EQ(rig.sap(255, 1), kOk);
  ASSERT_EQ(rig.sap(4, vmax), kOk);
  ASSERT_EQ(rig.sap(5, acceleration), kOk);
  ASSERT_EQ(rig.sap(20, 65535), kOk);  // standby delay: keep the run current at rest
}

TEST(Tmcm142Encoder, encoder_position_follows_the_rotor_in_either_direction) {
  Tmcm142Rig rig(StepperMotor::kPhysical);
  use_pps(rig, 50000, 500000);
  ASSERT_EQ(rig.command(4, 0, 0, 20480).status, kOk);  // a tenth of a revolution
  rig.run_until([&] { return rig.gap(8) == 1; }, 3000);
  rig.run_ms(300);
  // Default constant 51.2 µsteps per count of the default 4000-count encoder.
  EXPECT_NEAR(rig.gap(41), 20480, 52);
  EXPECT_NEAR(rig.rotor_microsteps(), 20480.0, 80.0);
  ASSERT_EQ(rig.sap(41, 0), kOk);
  ASSERT_EQ(rig.sap(43, 1), kOk);  // encoder mode bit 0: count the other way
  ASSERT_EQ(rig.command(4, 0, 0, 40960).status, kOk);
  rig.run_until([&] { return rig.gap(8) == 1; }, 3000);
  rig.run_ms(300);
  EXPECT_NEAR(rig.gap(41), -20480, 104);
}

TEST(Tmcm142Encoder, blocked_rotor_loses_its_steps) {
  Tmcm142Rig rig(StepperMotor::kPhysical);
  use_pps(rig, 100000, 1000000);
  rig.plant.set_blocked(true);
  ASSERT_EQ(rig.command(4, 0, 0, 102400).status, kOk);
  rig.run_until([&] { return rig.gap(8) == 1; }, 5000);
  EXPECT_EQ(rig.gap(1), 102400);                    // the ramp arrived...
  EXPECT_NEAR(rig.rotor_microsteps(), 0.0, 1.0);    // ...the rotor did not move
  EXPECT_NEAR(rig.gap(41), 0, 52);
  EXPECT_EQ(rig.gap(207), 0);                       // no deviation check without AP 212
}

TEST(Tmcm142Encoder, deviation_stops_the_motor_and_flags_edv) {
  Tmcm142Rig rig(StepperMotor::kPhysical);
  use_fine_encoder(rig);
  use_pps(rig, 100000, 1000000);
  ASSERT_EQ(rig.sap(212, 2000), kOk);
  rig.plant.set_blocked(true);
  ASSERT_EQ(rig.command(4, 0, 0, 102400).status, kOk);
  rig.run_ms(500);
  EXPECT_EQ(rig.gap(3), 0);
  // Stopped within a tick of passing the allowed deviation.
  EXPECT_GT(rig.gap(1), 2000);
  EXPECT_LE(rig.gap(1), 2000 + 100000 * 50e-6 * 2 + 1);
  EXPECT_EQ(rig.gap(129) & 8, 8);  // deviation exceeded
  EXPECT_EQ(rig.gap(207), 2);      // stopped by the deviation...
  EXPECT_EQ(rig.gap(207), 0);      // ...cleared by reading
  EXPECT_NE(rig.module.runtime().error_flags & tmcl::kErrorDeviation, 0);
  ASSERT_EQ(rig.command(36, 3, 0, 0).status, kOk);  // CLE EDV
  EXPECT_EQ(rig.module.runtime().error_flags & tmcl::kErrorDeviation, 0);
  // Once actual and encoder positions agree again the axis moves.
  rig.plant.set_blocked(false);
  rig.run_ms(100);  // the freed rotor snaps to the field
  ASSERT_EQ(rig.sap(1, rig.gap(41)), kOk);
  const int32_t start = rig.gap(1);
  ASSERT_EQ(rig.command(4, 0, 0, start + 10240).status, kOk);
  rig.run_until([&] { return rig.gap(8) == 1; }, 3000);
  rig.run_ms(200);
  EXPECT_EQ(rig.gap(129) & 8, 0);
  EXPECT_NEAR(rig.gap(41), start + 10240, 60);
}

// AP 207 reports the deviation stop as an event: set when the deviation starts, cleared by the
// read, and not set again while the same deviation lasts (AP 129 bit 3 shows the condition).
// Only a new excursion, after AP 1 and AP 41 agreed again, sets it again.
TEST(Tmcm142Encoder, ap_207_is_set_once_per_deviation_and_stays_cleared_after_a_read) {
  Tmcm142Rig rig(StepperMotor::kPhysical);
  use_fine_encoder(rig);
  use_pps(rig, 100000, 1000000);
  ASSERT_EQ(rig.sap(212, 2000), kOk);
  rig.plant.set_blocked(true);
  ASSERT_EQ(rig.command(4, 0, 0, 102400).status, kOk);
  rig.run_ms(500);
  EXPECT_EQ(rig.gap(207), 2);
  for (int i = 0; i < 5; ++i) {
    rig.run_ms(100);  // ticks between the reads, the deviation lasting
    EXPECT_EQ(rig.gap(129) & 8, 8);
    EXPECT_EQ(rig.gap(207), 0) << "read " << i << " after the clearing read";
  }
  // A new move while the deviation lasts is stopped at once; no new event.
  const int32_t stopped_at = rig.gap(1);
  ASSERT_EQ(rig.command(4, 0, 0, 204800).status, kOk);
  rig.run_ms(100);
  EXPECT_EQ(rig.gap(1), stopped_at);
  EXPECT_EQ(rig.gap(207), 0);
  // Realigned, then blocked again: a second event.
  ASSERT_EQ(rig.command(3, 0, 0, 0).status, kOk);
  ASSERT_EQ(rig.sap(1, rig.gap(41)), kOk);
  rig.run_ms(10);
  EXPECT_EQ(rig.gap(129) & 8, 0);
  EXPECT_EQ(rig.gap(207), 0);
  ASSERT_EQ(rig.command(36, 3, 0, 0).status, kOk);  // CLE EDV
  ASSERT_EQ(rig.command(4, 1, 0, 10240).status, kOk);  // MVP REL
  rig.run_ms(500);
  EXPECT_EQ(rig.gap(129) & 8, 8);
  EXPECT_EQ(rig.gap(207), 2) << "the second excursion";
  EXPECT_EQ(rig.gap(207), 0);
  EXPECT_NE(rig.module.runtime().error_flags & tmcl::kErrorDeviation, 0) << "EDV raised again";
}

void download(Tmcm142Rig& rig, std::initializer_list<tmcl::Instruction> program) {
  ASSERT_EQ(rig.command(132, 0, 0, 0).status, kOk);
  for (const auto& in : program) ASSERT_EQ(rig.command(in.command, in.type, in.motor_bank, in.value).status, 101);
  ASSERT_EQ(rig.command(133, 0, 0, 0).status, kOk);
}

TEST(Tmcm142Encoder, a_program_reacts_to_edv_with_jc) {
  Tmcm142Rig rig(StepperMotor::kPhysical);
  use_fine_encoder(rig);
  use_pps(rig, 100000, 1000000);
  ASSERT_EQ(rig.sap(212, 2000), kOk);
  rig.plant.set_blocked(true);
  download(rig, {
      {4, 0, 0, 102400},  // 0: MVP ABS
      {21, 10, 0, 4},     // 1: JC EDV, 4
      {22, 0, 0, 1},      // 2: JA 1
      {28, 0, 0, 0},      // 3: STOP
      {9, 0, 2, 77},      // 4: SGP 0, 2, 77 (user variable 0)
      {36, 3, 0, 0},      // 5: CLE EDV
      {28, 0, 0, 0},      // 6: STOP
  });
  ASSERT_EQ(rig.command(129, 1, 0, 0).status, kOk);
  rig.run_ms(500);
  EXPECT_EQ(rig.ggp(128), 0);  // stopped
  EXPECT_EQ(rig.ggp(0, 2), 77);
  EXPECT_EQ(rig.module.runtime().error_flags & tmcl::kErrorDeviation, 0);
  EXPECT_EQ(rig.command(135, 4, 0, 0).value & 0xFFFF, 6);  // stopped at the second STOP
}

// Lag of the rotor behind a target under a constant load, open and closed loop.
double final_error_under_load(bool closed_loop) {
  Tmcm142Rig rig(StepperMotor::kPhysical);
  use_fine_encoder(rig);
  use_pps(rig, 50000, 500000);
  EXPECT_EQ(rig.sap(40, closed_loop ? 1 : 0), kOk);
  rig.plant.set_load_torque_nm(0.5);  // about half the holding torque at 2625 mA
  EXPECT_EQ(rig.command(4, 0, 0, 51200).status, kOk);
  rig.run_until([&] { return rig.gap(8) == 1; }, 3000);
  rig.run_ms(2000);
  return rig.rotor_microsteps() - 51200.0;
}

TEST(Tmcm142Encoder, easy_pid_corrects_a_load_induced_lag) {
  const double open_loop = final_error_under_load(false);
  const double closed_loop = final_error_under_load(true);
  // Open loop the load angle stays: about 0.36 full step behind.
  EXPECT_LT(open_loop, -200.0);
  EXPECT_GT(open_loop, -1024.0);
  // Closed loop the microsteps lead until the encoder agrees (5 µsteps per count).
  EXPECT_LT(std::fabs(closed_loop), 10.0);
}

}  // namespace
}  // namespace motwin::testing
