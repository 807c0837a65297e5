// The TMCM-3216 stepper axis (core/modules/tmcm3216/tmcm3216_stepper.h) on a bare power stage:
// currents along standby delay and power-down ramp, switches, encoder, brake timing, resolution,
// StallGuard wiring, driver flags, and its object rows (tmcm3216_manufacturer_objects.h).
#include <gtest/gtest.h>

#include <array>
#include <cstdint>
#include <cstdlib>

#include "board/stepper_drive.h"
#include "core/canopen/object_dictionary.h"
#include "core/modules/tmcm3216/tmcm3216_io.h"
#include "core/modules/tmcm3216/tmcm3216_manufacturer_objects.h"
#include "core/modules/tmcm3216/tmcm3216_stepper.h"

namespace motwin::modules::tmcm3216 {
namespace {

constexpr uint32_t kTickUs = 50;
constexpr uint32_t kTicksPerMs = 1000 / kTickUs;

struct Axis {
  Tmcm3216Stepper stepper;
  board::StepperPowerStage stage;
  StepperDemand demand;

  void tick() { stepper.tick(stage, demand, kTickUs); }
  void run_ms(uint32_t ms) {
    for (uint32_t i = 0; i < ms * kTicksPerMs; ++i) tick();
  }
  void run_ticks(uint32_t n) {
    for (uint32_t i = 0; i < n; ++i) tick();
  }
  void enable() {
    demand.power_enabled = true;
    demand.brake_released_request = true;
    demand.switch_on_disabled = false;
  }
  void disable() {
    demand.power_enabled = false;
    demand.brake_released_request = false;
    demand.switch_on_disabled = true;
  }
  // One tick of motion by `usteps` at `velocity_pps`.
  void move(int32_t usteps, int32_t velocity_pps = 1000) {
    demand.position_usteps += usteps;
    demand.velocity_pps = velocity_pps;
    tick();
    demand.velocity_pps = 0;
  }
  int32_t amplitude_ma() const {
    // At the electrical angles the tests use (multiples of a full step) one coil carries it all.
    return std::abs(stage.drive.coil_a_ma) + std::abs(stage.drive.coil_b_ma);
  }
};

TEST(Tmcm3216Stepper, RunCurrentIsTheScaleOfTheCurrentRange) {
  Axis axis;
  axis.enable();
  axis.tick();
  // 2003 = 128: CS 16, (16 + 1) / 32 of 3000 mA peak (20A3 = 3).
  EXPECT_TRUE(axis.stage.drive.enabled);
  EXPECT_EQ(axis.stepper.current_scale(), 16);
  EXPECT_EQ(axis.stepper.current_ma(), 1594);
  EXPECT_EQ(axis.stage.drive.coil_a_ma, 1594);
  EXPECT_EQ(axis.stage.drive.coil_b_ma, 0);
  // 20A3 = 1 (2 A peak) and 20A2 = 128 (half): 2000 x 128/256 x 17/32.
  axis.stepper.objects.current_range = 1;
  axis.stepper.objects.global_current_scaler = 128;
  axis.move(0);
  EXPECT_EQ(axis.stepper.current_ma(), 531);
}

TEST(Tmcm3216Stepper, StandbyCurrentAfterTheDelayAlongThePowerDownRamp) {
  Axis axis;
  axis.stepper.objects.standby_delay_10ms = 10;  // 100 ms
  axis.stepper.objects.power_down_ramp = 1;      // one CS step per 2^18 clocks = 21.845 ms
  axis.enable();
  axis.move(256 * 4);  // four full steps: the field is back at electrical angle 0
  // Still the run current just before the delay ends.
  axis.run_ticks(100 * kTicksPerMs - 2);
  EXPECT_EQ(axis.stepper.current_scale(), 16);
  EXPECT_FALSE(axis.stepper.standby());
  axis.tick();  // 100 ms of standstill: the ramp starts at the run scale
  EXPECT_EQ(axis.stepper.current_scale(), 16);
  // 3.5 steps into the ramp: CS 13, 3000 x 14 / 32.
  axis.run_ticks(static_cast<uint32_t>(3.5 * 21845.33 / kTickUs));
  EXPECT_EQ(axis.stepper.current_scale(), 13);
  EXPECT_EQ(axis.amplitude_ma(), 1313);
  // 15 steps in all (327.7 ms): the standby scale 1 (2004 = 8), 3000 x 2 / 32.
  axis.run_ms(252);
  EXPECT_EQ(axis.stepper.current_scale(), 1);
  EXPECT_EQ(axis.amplitude_ma(), 188);
  EXPECT_TRUE(axis.stepper.standby());
  // Motion brings the run current back at once.
  axis.move(1);
  EXPECT_EQ(axis.stepper.current_scale(), 16);
  EXPECT_FALSE(axis.stepper.standby());
}

TEST(Tmcm3216Stepper, RampZeroDropsToStandbyAtOnceAfterTheDefaultTwoSeconds) {
  Axis axis;
  axis.stepper.objects.power_down_ramp = 0;
  axis.enable();
  axis.move(1024);
  axis.run_ms(1999);
  EXPECT_EQ(axis.stepper.current_ma(), 1594);
  axis.run_ms(1);
  EXPECT_EQ(axis.stepper.current_ma(), 188);
}

TEST(Tmcm3216Stepper, FieldFollowsTheDemandsMotionNotItsValue) {
  Axis axis;
  axis.enable();
  axis.tick();
  axis.move(3);
  EXPECT_EQ(axis.stage.drive.electrical_angle, 3u << 22);  // 2^30 / 256 per microstep
  // Assigning a position (homing) does not move the field.
  axis.stepper.set_actual_position(1000000);
  axis.demand.position_usteps = 1000000;
  axis.tick();
  EXPECT_EQ(axis.stage.drive.electrical_angle, 3u << 22);
  axis.move(-4);
  EXPECT_EQ(axis.stage.drive.electrical_angle, static_cast<uint32_t>(-(1 << 22)));
}

TEST(Tmcm3216Stepper, NewResolutionAppliesWhileThePowerStageIsOff) {
  Axis axis;
  axis.enable();
  axis.tick();
  axis.stepper.objects.microstep_code = 4;  // 16 microsteps
  axis.move(1);
  EXPECT_EQ(axis.stepper.active_microstep_code(), 8);
  EXPECT_EQ(axis.stage.drive.electrical_angle, 1u << 22);
  axis.disable();
  axis.tick();
  axis.tick();
  EXPECT_FALSE(axis.stage.drive.enabled);
  EXPECT_EQ(axis.stepper.active_microstep_code(), 4);
  // The field stays where the old resolution left it, off the new grid: snapping it to the nearest
  // 1/16 step would pull the rotor there at the next switch-on (fuzz finding, fuzz/README.md).
  EXPECT_EQ(axis.stage.drive.electrical_angle, 1u << 22);
  axis.enable();
  axis.tick();
  EXPECT_EQ(axis.stage.drive.electrical_angle, 1u << 22);
  axis.move(1);  // one 1/16 step from there
  EXPECT_EQ(axis.stage.drive.electrical_angle, (1u << 22) + (1u << 26));
}

TEST(Tmcm3216Stepper, NewResolutionNearTheEndOfTheElectricalCircleKeepsTheField) {
  // The fuzz finding: 1/256 steps down to just below a full circle, then full steps (2000 = 0)
  // taken at switch-off; the driver's angle must not wrap to the nearest full step (0).
  Axis axis;
  axis.enable();
  axis.tick();
  axis.move(-63);  // 63/256 of a full step below a whole electrical circle: 0xF0400000
  const uint32_t angle = axis.stage.drive.electrical_angle;
  EXPECT_EQ(angle, 0xF0400000u);
  axis.stepper.objects.microstep_code = 0;
  axis.disable();
  for (int i = 0; i < 4; ++i) {
    axis.tick();
    EXPECT_EQ(axis.stage.drive.electrical_angle, angle);
  }
  EXPECT_EQ(axis.stepper.active_microstep_code(), 0);
  axis.enable();
  axis.move(1);  // one full step on from the kept field
  EXPECT_EQ(axis.stage.drive.electrical_angle, angle + (1u << 30));
}

TEST(Tmcm3216Stepper, SwitchesAfterInvertAndDisable) {
  Axis axis;
  axis.stage.feedback.switches = 0b101;  // right and home high, left low
  axis.tick();
  SwitchState s = axis.stepper.switches();
  EXPECT_TRUE(s.right);
  EXPECT_FALSE(s.left);
  EXPECT_TRUE(s.home);
  EXPECT_EQ(s.raw, 0b101);
  axis.stepper.objects.switch_config = switch_bits::kLeftInverted | switch_bits::kRightDisabled | switch_bits::kHomeInverted;
  axis.tick();
  s = axis.stepper.switches();
  EXPECT_FALSE(s.right);  // disabled
  EXPECT_TRUE(s.left);    // low level, inverted
  EXPECT_FALSE(s.home);   // high level, inverted
  axis.stepper.objects.switch_config = switch_bits::kRightInverted | switch_bits::kHomeDisabled;
  axis.stage.feedback.switches = 0b110;
  axis.tick();
  s = axis.stepper.switches();
  EXPECT_TRUE(s.right);
  EXPECT_TRUE(s.left);
  EXPECT_FALSE(s.home);
}

TEST(Tmcm3216Stepper, EncoderScaleAndDirection) {
  Axis axis;
  axis.stepper.objects.encoder_increments = 4000;  // 608F: 4000 counts per revolution
  axis.stage.feedback.encoder_count = 777;       // where the counter happens to start
  axis.tick();
  EXPECT_EQ(axis.stepper.encoder_position(), 0);
  axis.stage.feedback.encoder_count = 777 + 1000;
  axis.tick();
  EXPECT_EQ(axis.stepper.encoder_count(), 1000);
  EXPECT_EQ(axis.stepper.encoder_position(), 12800);  // 51200 µsteps per 4000 counts
  axis.stepper.objects.encoder_reversed = 1;
  axis.stage.feedback.encoder_count = 777;  // back by 1000 counts: forward, reversed
  axis.tick();
  EXPECT_EQ(axis.stepper.encoder_position(), 25600);
  // The counter wraps at 32 bits without a jump.
  axis.stepper.objects.encoder_reversed = 0;
  axis.stage.feedback.encoder_count = INT32_MAX;
  axis.tick();
  axis.stage.feedback.encoder_count = INT32_MIN;
  axis.tick();
  EXPECT_EQ(axis.stepper.encoder_count(), static_cast<int32_t>(2000u + (uint32_t{INT32_MAX} - 777u) + 1u));
}

TEST(Tmcm3216Stepper, IndexLatchesTheMotorPositionWhereTheRotorWasSensed) {
  Axis axis;
  axis.enable();
  axis.demand.position_usteps = 500;
  axis.tick();
  axis.move(10);  // the field is at 510 now; the sensors see it there next tick
  axis.stage.feedback.encoder_index_events = 1;
  axis.move(10);
  EXPECT_EQ(axis.stepper.index_events(), 1u);
  EXPECT_TRUE(axis.stepper.index_available());
  EXPECT_EQ(axis.stepper.index_position(), 510);
  // 200B sub 1 goes to the interface (the sim decides what an N pulse of the wrong polarity does).
  axis.stepper.objects.encoder_index_inverted = 1;
  axis.tick();
  EXPECT_TRUE(axis.stage.drive.encoder_index_active_low);
}

TEST(Tmcm3216Stepper, BrakeAndEnableDelays) {
  Axis axis;
  axis.stepper.objects.enable_drive_delay_ms = 20;   // 200A
  axis.stepper.objects.brake_release_delay_ms = 30;  // 2002 sub 2
  axis.stepper.objects.brake_apply_delay_ms = 40;    // 2002 sub 1
  axis.stepper.objects.brake_apply_current = 10;     // 200C
  axis.stepper.objects.brake_release_current = 200;
  EXPECT_TRUE(axis.stepper.brake_control());
  axis.tick();
  EXPECT_EQ(axis.stepper.brake_duty(), 10);
  axis.enable();
  axis.tick();
  EXPECT_TRUE(axis.stage.drive.enabled);
  EXPECT_FALSE(axis.stepper.brake_released());
  axis.run_ticks(20 * kTicksPerMs - 1);
  EXPECT_FALSE(axis.stepper.brake_released());
  EXPECT_EQ(axis.stepper.brake_duty(), 10);
  axis.tick();  // 20 ms after the power stage came on
  EXPECT_TRUE(axis.stepper.brake_released());
  EXPECT_EQ(axis.stepper.brake_duty(), 200);
  EXPECT_FALSE(axis.stepper.ready());
  axis.run_ticks(30 * kTicksPerMs - 1);
  EXPECT_FALSE(axis.stepper.ready());
  axis.tick();  // 30 ms after the brake opened
  EXPECT_TRUE(axis.stepper.ready());
  // Switching off: the brake closes at once, the power stage holds the motor 40 ms longer.
  axis.disable();
  axis.tick();
  EXPECT_FALSE(axis.stepper.ready());
  EXPECT_FALSE(axis.stepper.brake_released());
  EXPECT_EQ(axis.stepper.brake_duty(), 10);
  axis.run_ticks(40 * kTicksPerMs - 1);
  EXPECT_TRUE(axis.stage.drive.enabled);
  axis.tick();
  EXPECT_FALSE(axis.stage.drive.enabled);
  EXPECT_FALSE(axis.stepper.power_stage_on());
}

TEST(Tmcm3216Stepper, WithoutDelaysTheAxisIsReadyInTheFirstTick) {
  Axis axis;
  EXPECT_FALSE(axis.stepper.brake_control());
  axis.enable();
  axis.tick();
  EXPECT_TRUE(axis.stepper.ready());
  EXPECT_EQ(axis.stepper.brake_duty(), 0);
  // Switched on but not operation enabled: power, brake closed, not ready.
  axis.demand.brake_released_request = false;
  axis.tick();
  EXPECT_TRUE(axis.stage.drive.enabled);
  EXPECT_FALSE(axis.stepper.ready());
}

TEST(Tmcm3216Stepper, PositionInitializationFromTheEncoderAtSwitchOn) {
  Axis axis;
  axis.stepper.objects.encoder_increments = 4000;
  axis.stepper.objects.encoder_used = true;  // 606A = 0
  axis.tick();
  axis.stage.feedback.encoder_count = 400;  // moved by hand while off: 1/10 revolution
  axis.tick();
  int32_t position = 0;
  EXPECT_FALSE(axis.stepper.take_position_initialization(position));
  axis.enable();
  axis.tick();
  ASSERT_TRUE(axis.stepper.take_position_initialization(position));
  EXPECT_EQ(position, 5120);
  EXPECT_FALSE(axis.stepper.take_position_initialization(position));
  axis.disable();
  axis.tick();
  axis.stepper.objects.encoder_initialize_position = 0;
  axis.enable();
  axis.tick();
  EXPECT_FALSE(axis.stepper.take_position_initialization(position));
  // Without the encoder in use (606A = -1) 200B sub 3 has nothing to do.
  axis.disable();
  axis.tick();
  axis.stepper.objects.encoder_initialize_position = 1;
  axis.stepper.objects.encoder_used = false;
  axis.enable();
  axis.tick();
  EXPECT_FALSE(axis.stepper.take_position_initialization(position));
}

TEST(Tmcm3216Stepper, StallOnAZeroLoadValueAboveTheStopVelocity) {
  Axis axis;
  axis.stepper.objects.stop_on_stall_velocity = 5000;  // 20A4, pps
  axis.enable();
  axis.stage.feedback.stallguard2_result = 300;
  axis.tick();
  EXPECT_EQ(axis.stepper.load_value(), 300);
  // Zero below the stop velocity: no stall.
  axis.stage.feedback.stallguard2_result = 0;
  axis.stage.feedback.stallguard_measurements = 1;
  axis.move(1, 4000);
  EXPECT_FALSE(axis.stepper.stall_detected());
  // Zero above it: a stall, latched until cleared.
  axis.stage.feedback.stallguard_measurements = 2;
  axis.move(1, 6000);
  EXPECT_TRUE(axis.stepper.stall_detected());
  EXPECT_TRUE(axis.stepper.stall_enters_fault());
  axis.stage.feedback.stallguard2_result = 500;
  axis.stage.feedback.stallguard_measurements = 3;
  axis.move(1, 6000);
  EXPECT_TRUE(axis.stepper.stall_detected());
  axis.stepper.clear_stall();
  axis.tick();
  EXPECT_FALSE(axis.stepper.stall_detected());
  EXPECT_EQ(axis.stepper.load_value(), 500);
}

TEST(Tmcm3216Stepper, StealthChopBelowThePwmThreshold) {
  Axis axis;
  axis.stepper.objects.pwm_threshold_velocity = 10000;
  axis.stepper.objects.pwm_gradient = 10;
  axis.stepper.objects.pwm_amplitude = 100;
  axis.enable();
  axis.move(1, 51200);  // 1 rev/s at 256 µsteps: 51200 / 12e6 x 256 x 10 = 10.9 on top
  EXPECT_FALSE(axis.stepper.stealthchop_active());
  EXPECT_EQ(axis.stepper.pwm_scale(), 0);
  axis.move(1, 5120);
  EXPECT_TRUE(axis.stepper.stealthchop_active());
  EXPECT_TRUE(axis.stage.drive.stealth_chop);
  EXPECT_EQ(axis.stepper.pwm_scale(), 101);  // 100 + 10 x 256 x 5120 / 12e6 = 101.09
  EXPECT_EQ(axis.stepper.measured_velocity(), 5120);  // 2122 in pps (208C = 181)
  axis.stepper.objects.velocity_in_chip_units = true;  // 208C = 0: 5120 / (12 MHz / 2^24)
  axis.move(1, 5120);
  EXPECT_EQ(axis.stepper.measured_velocity(), 7158);
}

TEST(Tmcm3216Stepper, DriverErrorFlags) {
  Axis axis;
  axis.stage.feedback.driver_status = board::kDriverOpenLoadA | board::kDriverOvercurrentB;
  axis.tick();
  EXPECT_EQ(axis.stepper.driver_error_flags(), 0x06);
  axis.stepper.objects.short_protection_disabled = 1;  // 20A1: short flags not reported
  axis.stage.feedback.supply_millivolt = 7000;
  axis.tick();
  EXPECT_EQ(axis.stepper.driver_error_flags(), board::kDriverOpenLoadA | board::kDriverUndervoltage);
}

TEST(Tmcm3216Stepper, ChopperOffTimeZeroLetsTheMotorFreewheel) {
  Axis axis;
  axis.enable();
  axis.tick();
  EXPECT_TRUE(axis.stage.drive.enabled);
  axis.stepper.objects.chopper_off_time = 0;
  axis.tick();
  EXPECT_FALSE(axis.stage.drive.enabled);
  EXPECT_TRUE(axis.stepper.power_stage_on());
}

// --- The object rows --------------------------------------------------------------------------------

struct FakeModule {
  std::array<Tmcm3216Stepper, 3> steppers;
  Tmcm3216GeneralIo io;
  Tmcm3216Stepper& stepper(uint8_t axis) { return steppers[axis]; }
  Tmcm3216GeneralIo& general_io() { return io; }
};

using Row = canopen::EntryRow<FakeModule>;
struct Table {
  std::array<Row, 96> rows{};
  size_t count = 0;
  constexpr void add(const Row& r) { rows[count++] = r; }
};
constexpr Table build_table() {
  Table t;
  add_stepper_rows<FakeModule>(t);
  add_io_rows<FakeModule>(t);
  add_digital_inputs_row<FakeModule>(t);
  return t;
}
constexpr Table kTable = build_table();

struct Rows {
  FakeModule module;
  canopen::TableDictionary<FakeModule> dictionary{module, {kTable.rows.data(), kTable.count}, 3};

  canopen::SdoAbort write(uint16_t index, uint8_t sub, int64_t value) {
    canopen::ObjectRef ref;
    if (const canopen::SdoAbort abort = dictionary.find(index, sub, ref); abort != canopen::SdoAbort::kNone) return abort;
    uint8_t data[4];
    canopen::encode_value(ref.info->type, value, data);
    return dictionary.write(ref, data, canopen::type_size(ref.info->type));
  }
  int64_t read(uint16_t index, uint8_t sub = 0) {
    canopen::ObjectRef ref;
    EXPECT_EQ(dictionary.find(index, sub, ref), canopen::SdoAbort::kNone) << std::hex << index;
    return dictionary.value(ref);
  }
};

TEST(Tmcm3216StepperObjects, DefaultsAndAxisStride) {
  Rows rows;
  EXPECT_EQ(rows.read(0x2000), 8);
  EXPECT_EQ(rows.read(0x2003), 128);
  EXPECT_EQ(rows.read(0x2004), 8);
  EXPECT_EQ(rows.read(0x2089), 200);
  EXPECT_EQ(rows.read(0x20B9), 7);
  EXPECT_EQ(rows.read(0x200B, 3), 1);
  EXPECT_EQ(rows.read(0x2107), 8);
  EXPECT_EQ(rows.write(0x2403, 0, 200), canopen::SdoAbort::kNone);  // 2003 of motor 2
  EXPECT_EQ(rows.module.steppers[2].objects.run_current, 200);
  EXPECT_EQ(rows.module.steppers[0].objects.run_current, 128);
  EXPECT_EQ(rows.write(0x2000, 0, 9), canopen::SdoAbort::kValueTooHigh);
  EXPECT_EQ(rows.write(0x209E, 0, -64), canopen::SdoAbort::kValueTooLow);
  EXPECT_EQ(rows.write(0x209E, 0, -63), canopen::SdoAbort::kNone);
  EXPECT_EQ(rows.module.steppers[0].objects.stallguard2_threshold, -63);
  EXPECT_EQ(rows.write(0x2097, 0, 1), canopen::SdoAbort::kInvalidValue);  // 0 or 2..15
  EXPECT_EQ(rows.write(0x20A2, 0, 31), canopen::SdoAbort::kInvalidValue);  // "do not use"
  EXPECT_EQ(rows.write(0x2101, 0, 1), canopen::SdoAbort::kReadOnly);
}

TEST(Tmcm3216StepperObjects, SwitchEncoderAndBrakeObjectsOnlyInSwitchOnDisabled) {
  Rows rows;
  EXPECT_EQ(rows.write(0x2005, 0, 3), canopen::SdoAbort::kNone);
  StepperDemand demand;
  demand.switch_on_disabled = false;
  board::StepperPowerStage stage;
  rows.module.steppers[0].tick(stage, demand, kTickUs);
  EXPECT_EQ(rows.write(0x2005, 0, 0), canopen::SdoAbort::kDeviceState);
  EXPECT_EQ(rows.write(0x200B, 2, 1), canopen::SdoAbort::kDeviceState);
  EXPECT_EQ(rows.write(0x200C, 1, 50), canopen::SdoAbort::kDeviceState);
  EXPECT_EQ(rows.write(0x2205, 0, 1), canopen::SdoAbort::kNone);  // motor 1 is still disabled
  EXPECT_EQ(rows.module.steppers[0].objects.switch_config, 3u);
  EXPECT_EQ(rows.write(0x2003, 0, 10), canopen::SdoAbort::kNone);  // currents any time
}

TEST(Tmcm3216StepperObjects, IoObjects) {
  Rows rows;
  // 2703: sub 1 reads back as written; it switches only the outputs the mask (sub 2) allows.
  EXPECT_EQ(rows.write(0x2703, 1, 0x000F0000), canopen::SdoAbort::kNone);
  EXPECT_EQ(rows.read(0x2703, 1), 0x000F0000);
  EXPECT_EQ(rows.module.io.output_levels(), 0u);
  EXPECT_EQ(rows.write(0x2703, 2, 0x00050000), canopen::SdoAbort::kNone);
  EXPECT_EQ(rows.write(0x2703, 1, 0x000F0000), canopen::SdoAbort::kNone);
  EXPECT_EQ(rows.read(0x2703, 1), 0x000F0000);
  EXPECT_EQ(rows.module.io.output_levels(), 0x00050000u);
  // Switching OUT0 off through a mask of OUT0 alone keeps OUT2 on.
  EXPECT_EQ(rows.write(0x2703, 2, 0x00010000), canopen::SdoAbort::kNone);
  EXPECT_EQ(rows.write(0x2703, 1, 0), canopen::SdoAbort::kNone);
  EXPECT_EQ(rows.read(0x2703, 1), 0);
  EXPECT_EQ(rows.module.io.output_levels(), 0x00040000u);
  EXPECT_EQ(rows.write(0x2703, 2, 0x00050000), canopen::SdoAbort::kNone);
  EXPECT_EQ(rows.write(0x2703, 1, 0x000F0000), canopen::SdoAbort::kNone);
  // Bits that name no output (the module has OUT0..OUT3 at bits 16..19) are refused, the
  // object unchanged: the canopen_sdo fuzz finding wrote "save" (0x65766173) here.
  EXPECT_EQ(rows.write(0x2703, 1, 0x65766173), canopen::SdoAbort::kInvalidValue);
  EXPECT_EQ(rows.write(0x2703, 1, 0x00100000), canopen::SdoAbort::kInvalidValue);
  EXPECT_EQ(rows.write(0x2703, 1, 0x00000001), canopen::SdoAbort::kInvalidValue);
  EXPECT_EQ(rows.read(0x2703, 1), 0x000F0000);
  // 2711: bits 0..3 and 8..11 only.
  EXPECT_EQ(rows.write(0x2711, 0, 0x0010), canopen::SdoAbort::kInvalidValue);
  EXPECT_EQ(rows.write(0x2711, 0, 0x0105), canopen::SdoAbort::kNone);
  board::Tmcm3216Io io;
  const bool brake_control[3] = {false, false, false};
  const uint8_t brake_duty[3] = {0, 0, 0};
  rows.module.io.drive(io, brake_control, brake_duty);
  EXPECT_TRUE(io.output_mode[0]);
  EXPECT_TRUE(io.push_pull[0]);
  EXPECT_TRUE(io.output_levels[0]);
  EXPECT_FALSE(io.output_mode[1]);
  EXPECT_TRUE(io.output_mode[2]);
  EXPECT_FALSE(io.push_pull[2]);
  // 2702, 270E and 60FD from the sampled pins and the switches.
  io.dio_levels = {true, false, false, true};
  io.analog_inputs = {1234, 4095};
  rows.module.io.sample(io);
  EXPECT_EQ(rows.read(0x2702), 0x00090000);
  EXPECT_EQ(rows.read(0x270E, 1), 1234);
  EXPECT_EQ(rows.read(0x270E, 2), 4095);
  board::StepperPowerStage stage;
  stage.feedback.switches = 0b110;  // left and home (motor 1)
  rows.module.steppers[1].tick(stage, StepperDemand{}, kTickUs);
  EXPECT_EQ(rows.read(0x68FD), 0x00090005);
  EXPECT_EQ(rows.read(0x60FD), 0x00090000);
}

}  // namespace
}  // namespace motwin::modules::tmcm3216
