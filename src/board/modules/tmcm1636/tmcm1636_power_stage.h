// Board seam of the TMCM-1636 for the motor: what the power stage and the motor sensors give
// the firmware once per 50 µs control tick, and what the firmware gives back. Plain data, as the
// ADC result registers, timer counters and PWM compare registers of a real board are: the
// firmware reads and writes memory and calls nothing, so the per-tick path has no virtual call
// and no plant knowledge (docs/tmcm-1636-servo.md, "Board seam").
//
// The simulated board (sim::Tmcm1636Plant) fills `feedback` before each tick and applies
// `drive` after it; a real board would fill the same fields from its peripherals.
#pragma once

#include <cstdint>

namespace motwin::board {

// Sampled at the start of each control tick (the centre of the PWM period, where the ADC of a
// real board is triggered).
struct Tmcm1636Feedback {
  // Phase current amplifiers of phases A (U) and B (V), 16-bit ADC counts; mid-scale is zero
  // current on an ideal board (AP 0, 1 show them raw).
  uint16_t adc_phase_a = 32767;
  uint16_t adc_phase_b = 32767;
  // ADC_VM, 12 bits, the same channel as GIO 2, bank 1 (core/modules/tmcm1636/tmcm1636_hardware.h).
  uint16_t adc_supply = 0;
  // ADC_TEMP, 16 bits, the driver temperature sensor (GIO 3, bank 1).
  uint16_t adc_temperature = 0;
  // Digital hall inputs as electrical levels: bit 0 H1, bit 1 H2, bit 2 H3.
  uint8_t hall = 0;
  // Reference switch inputs as electrical levels: bit 0 right, bit 1 left, bit 2 home.
  uint8_t reference_switches = 0;
  // ABN encoder: the quadrature counter (free running, wraps at 32 bits), the number of N pulses
  // seen so far (wraps) and the counter value latched by the last N pulse.
  int32_t abn_count = 0;
  uint32_t abn_index_events = 0;
  int32_t abn_index_count = 0;
  // SPI absolute encoder angle, left-aligned to 16 bits (one revolution = 65536), and whether
  // the last transfer was answered.
  uint16_t absolute_angle = 0;
  bool absolute_valid = false;
};

// Applied from the next PWM period on (a one-tick delay, as on the real board).
struct Tmcm1636Drive {
  // Gate driver enable: false leaves all six switches open.
  bool bridge_enabled = false;
  // High-side on-time of each half bridge (U, V, W) as a fraction of the PWM period, 0..1.
  // A DC motor is connected between U and V.
  float duty[3] = {0.5f, 0.5f, 0.5f};
  // Brake output connector, PWM duty in percent (0 = coil off).
  uint8_t brake_duty_percent = 0;
  // Brake chopper transistor: on connects the brake resistor across the supply bus.
  bool brake_chopper_on = false;
  // PWM frequency of the bridge (AP 110): switching losses of the driver.
  uint32_t pwm_frequency_hz = 25000;
};

struct Tmcm1636PowerStage {
  Tmcm1636Feedback feedback;
  Tmcm1636Drive drive;
};

}  // namespace motwin::board
