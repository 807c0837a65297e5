// The TMCL datalogger (command 142, core/tmcl/ramdebug.h, docs/datalogger.md): the engine on
// scripted channels (timing, triggers, pretrigger, ring buffer, clamping, every error status),
// then on the TMCM-1636 through TMCL frames as PyTrinamic's DataLogger sends them (both of its
// orders), command 157, and a capture of the phase current on the running servo.
#include <gtest/gtest.h>

#include <algorithm>
#include <array>
#include <cmath>
#include <cstdint>
#include <optional>
#include <vector>

#include "core/tmcl/ramdebug.h"
#include "support/tmcm142_rig.h"
#include "support/tmcm1636_rig.h"
#include "support/tmcm1636_servo_rig.h"

namespace motwin::testing {
namespace {

using tmcl::RamDebug;
using tmcl::RamDebugProbe;
using tmcl::Status;
namespace op = tmcl::ram_debug::op;

constexpr uint8_t kRamDebugCommand = 142;
constexpr uint8_t kOk = 100;
constexpr uint8_t kMaxExceeded = 9;
constexpr int32_t kIdle = 0, kTrigger = 1, kCapture = 2, kComplete = 3, kPretrigger = 4;
constexpr uint8_t kAxisParameter = 1, kRegister = 2, kSystick = 4, kAnalogInput = 6, kGlobalParameter = 8;

// --- The engine on scripted channels ------------------------------------------------------------

// Channel `select` reads values[select]; a test sets them before each control tick.
class ScriptedChannels final : public tmcl::RamDebugChannels {
 public:
  std::array<int32_t, 8> values{};

  Status resolve_ram_debug_channel(uint8_t type, uint32_t select, RamDebugProbe& probe) override {
    if (type != kAxisParameter && type != kGlobalParameter) return Status::kMaxExceeded;
    if (select >= values.size()) return Status::kWrongType;
    probe.index = static_cast<uint8_t>(select);
    return Status::kOk;
  }
  int32_t read_ram_debug_channel(const RamDebugProbe& probe) override { return values[probe.index]; }
};

// A datalogger as the TMCM-1636's (4 channels, 2000 Hz, 10 control ticks per base tick) on a
// small buffer, so that the ring wraps within a test.
struct Logger {
  static constexpr uint32_t kTicksPerBase = 10;
  ScriptedChannels channels;
  std::array<uint32_t, 64> buffer{};
  RamDebug logger{channels, tmcl::RamDebugConfig{4, 2000, kTicksPerBase}, buffer};
  uint64_t control_ticks = 0;  // since construction; tick n is the n-th call, 1-based

  Status send(uint8_t type, uint8_t motor = 0, int32_t value = 0) { return logger.execute(type, motor, value); }
  int32_t read(uint8_t type, uint8_t motor = 0, int32_t value = 0) {
    EXPECT_EQ(logger.execute(type, motor, value), Status::kOk) << "sub-command " << int{type};
    return value;
  }
  int32_t state() { return read(op::kGetState); }
  // One control tick; `before` sets the channel values the tick reads.
  template <class Before>
  void tick(Before&& before) {
    ++control_ticks;
    before(control_ticks);
    logger.control_tick();
  }
  void tick() {
    tick([](uint64_t) {});
  }
  std::vector<int32_t> samples(uint32_t count) {
    std::vector<int32_t> out;
    for (uint32_t i = 0; i < count; ++i) out.push_back(read(op::kGetSample, 0, static_cast<int32_t>(i)));
    return out;
  }
  // Ticks with channel 0 = the control tick's number until the state is `wanted`.
  void run_until_state(int32_t wanted, uint64_t max_ticks = 100000) {
    for (uint64_t i = 0; i < max_ticks && state() != wanted; ++i) {
      tick([this](uint64_t t) { channels.values[0] = static_cast<int32_t>(t); });
    }
  }
};

TEST(RamDebug, starts_idle_and_reports_its_figures) {
  Logger l;
  EXPECT_EQ(l.state(), kIdle);
  EXPECT_EQ(l.read(op::kGetInfo, 0, 0), 4);
  EXPECT_EQ(l.read(op::kGetInfo, 0, 1), 64);
  EXPECT_EQ(l.read(op::kGetInfo, 0, 2), 2000);
  EXPECT_EQ(l.read(op::kGetInfo, 0, 3), 0);
  EXPECT_EQ(l.send(op::kGetInfo, 0, 4), Status::kMaxExceeded);  // no figure for the host link
  EXPECT_EQ(l.send(op::kGetInfo, 0, 5), Status::kMaxExceeded);
  EXPECT_EQ(l.read(op::kGetPretriggerCount), 0);
}

// Unconditional, full base rate: the first base tick is the control tick after ENABLE, then every
// 10th; the capture completes with the last word.
TEST(RamDebug, samples_at_every_tenth_control_tick_from_the_one_after_enable) {
  Logger l;
  for (int i = 0; i < 7; ++i) l.tick();  // the grid follows ENABLE, not power-up
  ASSERT_EQ(l.send(op::kInit), Status::kOk);
  ASSERT_EQ(l.send(op::kSetSampleCount, 0, 5), Status::kOk);
  ASSERT_EQ(l.send(op::kSetPrescaler, 0, 0), Status::kOk);
  ASSERT_EQ(l.send(op::kSetChannel, kAxisParameter, 0), Status::kOk);
  ASSERT_EQ(l.send(op::kEnableTrigger, 0, 0), Status::kOk);
  EXPECT_EQ(l.state(), kPretrigger);
  const uint64_t enabled_at = l.control_ticks;
  std::vector<int32_t> states;
  for (int i = 0; i < 45; ++i) {
    l.tick([&](uint64_t t) { l.channels.values[0] = static_cast<int32_t>(t - enabled_at); });
    states.push_back(l.state());
  }
  EXPECT_EQ(states[0], kCapture);
  EXPECT_EQ(states[39], kCapture);  // control tick 40 after enable: 4 words
  EXPECT_EQ(states[40], kComplete);  // tick 41: the fifth
  EXPECT_EQ(l.samples(5), (std::vector<int32_t>{1, 11, 21, 31, 41}));
  EXPECT_EQ(l.read(op::kGetInfo, 0, 3), 5);
}

// Prescaler value 2 divides by 3: rows at base ticks 0, 3, 6 after ENABLE.
TEST(RamDebug, prescaler_divides_the_base_rate) {
  Logger l;
  l.send(op::kInit);
  l.send(op::kSetSampleCount, 0, 3);
  l.send(op::kSetPrescaler, 0, 2);
  l.send(op::kSetChannel, kAxisParameter, 0);
  l.send(op::kEnableTrigger, 0, 0);
  l.run_until_state(kComplete);
  EXPECT_EQ(l.samples(3), (std::vector<int32_t>{1, 31, 61}));
  EXPECT_EQ(l.control_ticks, 61u);
}

// Channels are interleaved in the order of SET_CHANNEL; the download de-interleaves them.
TEST(RamDebug, interleaves_channels_in_set_channel_order) {
  Logger l;
  l.send(op::kInit);
  l.send(op::kSetSampleCount, 0, 6);
  l.send(op::kSetChannel, kAxisParameter, 1);
  l.send(op::kSetChannel, kGlobalParameter, 0);
  l.send(op::kEnableTrigger, 0, 0);
  for (int i = 0; i < 30; ++i) {
    l.tick([&](uint64_t t) {
      l.channels.values[0] = static_cast<int32_t>(t);
      l.channels.values[1] = -static_cast<int32_t>(t);
    });
  }
  EXPECT_EQ(l.state(), kComplete);
  EXPECT_EQ(l.samples(6), (std::vector<int32_t>{-1, 1, -11, 11, -21, 21}));
  EXPECT_EQ(l.read(op::kGetChannelType, 0), kAxisParameter);
  EXPECT_EQ(l.read(op::kGetChannelAddress, 0), 1);
  EXPECT_EQ(l.read(op::kGetChannelType, 1), kGlobalParameter);
  EXPECT_EQ(l.read(op::kGetChannelType, 2), 0);
}

// A trigger on channel 2 fed one value per base tick; channel 0 records the base tick's index.
// Returns the base tick at which the capture started (its first word), or nullopt.
std::optional<int32_t> trigger_tick(uint8_t type, int32_t threshold, const std::vector<int32_t>& trigger_values,
                                    uint8_t shift = 0, uint32_t mask = 0xFFFFFFFF) {
  Logger l;
  l.send(op::kInit);
  l.send(op::kSetSampleCount, 0, 1);
  l.send(op::kSetChannel, kAxisParameter, 0);
  EXPECT_EQ(l.send(op::kSetTriggerChannel, kAxisParameter, 2), Status::kOk);
  EXPECT_EQ(l.send(op::kSetShiftMask, shift, static_cast<int32_t>(mask)), Status::kOk);
  l.channels.values[2] = trigger_values.front();  // what ENABLE sees
  EXPECT_EQ(l.send(op::kEnableTrigger, type, threshold), Status::kOk);
  for (size_t base = 0; base < trigger_values.size(); ++base) {
    for (uint32_t i = 0; i < Logger::kTicksPerBase; ++i) {
      l.tick([&](uint64_t) {
        l.channels.values[0] = static_cast<int32_t>(base);
        l.channels.values[2] = trigger_values[base];
      });
    }
    if (l.state() == kComplete) return l.read(op::kGetSample, 0, 0);
    EXPECT_EQ(l.state(), kTrigger) << "base tick " << base;
  }
  return std::nullopt;
}

constexpr uint8_t kRisingSigned = 1, kFallingSigned = 2, kBothSigned = 3;
constexpr uint8_t kRisingUnsigned = 4, kFallingUnsigned = 5, kBothUnsigned = 6;

TEST(RamDebug, edges_compare_strictly_above_the_threshold) {
  const std::vector<int32_t> up{-2, -1, 0, 1, 2, 1, 0, -1};
  EXPECT_EQ(trigger_tick(kRisingSigned, 0, up), 3);   // 0 -> 1: 1 > 0
  EXPECT_EQ(trigger_tick(kFallingSigned, 0, up), 6);  // 1 -> 0
  EXPECT_EQ(trigger_tick(kBothSigned, 0, up), 3);
  EXPECT_EQ(trigger_tick(kRisingSigned, 5, up), std::nullopt);
  EXPECT_EQ(trigger_tick(kFallingSigned, -2, up), std::nullopt);  // never at or below -2 after start
}

// -1 is 0xFFFFFFFF: below 0 signed, above everything unsigned.
TEST(RamDebug, signed_and_unsigned_compares_differ_on_negative_values) {
  const std::vector<int32_t> values{0, 0, -1, -1, 0};
  EXPECT_EQ(trigger_tick(kRisingSigned, 0, values), std::nullopt);
  EXPECT_EQ(trigger_tick(kRisingUnsigned, 0, values), 2);
  EXPECT_EQ(trigger_tick(kFallingUnsigned, 0, values), 4);
  EXPECT_EQ(trigger_tick(kBothUnsigned, 0, values), 2);
  EXPECT_EQ(trigger_tick(kFallingSigned, 0, values), std::nullopt);
  EXPECT_EQ(trigger_tick(kBothSigned, 0, values), std::nullopt);
  // A threshold of -1: signed, 0 is above it; unsigned, nothing is.
  EXPECT_EQ(trigger_tick(kFallingSigned, -1, {0, 0, -2, 0}), 2);
  EXPECT_EQ(trigger_tick(kRisingUnsigned, -1, {0, 0, -1, 0}), std::nullopt);
}

// Mask 0xFF00, shift 8: the field is bits 15..8; a signed compare extends bit 15.
TEST(RamDebug, mask_and_shift_select_a_field_whose_top_bit_is_its_sign) {
  // 0x8000 -> field 0x80 = -128 signed, 128 unsigned; 0x0100 -> field 1.
  const std::vector<int32_t> values{0x8000, 0x8000, 0x0100, 0x0100, 0x8000, 0x7FFF00FF};
  EXPECT_EQ(trigger_tick(kRisingSigned, 0, values, 8, 0xFF00), 2);
  EXPECT_EQ(trigger_tick(kRisingUnsigned, 100, values, 8, 0xFF00), 4);
  EXPECT_EQ(trigger_tick(kFallingSigned, -128, values, 8, 0xFF00), 4);
  EXPECT_EQ(trigger_tick(kBothUnsigned, 0x7F, values, 8, 0xFF00), 2);  // 128 > 127 to 1
  // Bits outside the mask do not count: 0x7FFF00FF has field 0.
  EXPECT_EQ(trigger_tick(kFallingUnsigned, 0x7F, {0x8000, 0x8000, 0x7FFF00FF}, 8, 0xFF00), 2);
}

// Pretrigger: four words before the trigger, the trigger tick's row at index 4.
TEST(RamDebug, pretrigger_keeps_the_words_before_the_trigger) {
  Logger l;
  l.send(op::kInit);
  l.send(op::kSetSampleCount, 0, 10);
  l.send(op::kSetChannel, kAxisParameter, 0);
  l.send(op::kSetTriggerChannel, kAxisParameter, 2);
  l.send(op::kSetPretriggerCount, 0, 4);
  l.send(op::kEnableTrigger, kRisingSigned, 0);
  std::vector<int32_t> states;
  for (int base = 0; base < 40; ++base) {
    for (uint32_t i = 0; i < Logger::kTicksPerBase; ++i) {
      l.tick([&](uint64_t) {
        l.channels.values[0] = base;
        l.channels.values[2] = base >= 20 ? 1 : 0;
      });
    }
    states.push_back(l.state());
  }
  EXPECT_EQ(states[2], kPretrigger);  // 3 of 4 words
  EXPECT_EQ(states[3], kPretrigger);  // the fourth written in this tick: armed at the next
  EXPECT_EQ(states[4], kTrigger);
  EXPECT_EQ(states[20], kCapture);
  EXPECT_EQ(states[25], kComplete);  // words 20..25 after the trigger: 4 + 6
  EXPECT_EQ(l.samples(10), (std::vector<int32_t>{16, 17, 18, 19, 20, 21, 22, 23, 24, 25}));
  EXPECT_EQ(l.send(op::kGetSample, 0, 10), Status::kMaxExceeded);
}

// An edge while the pretrigger part fills is not the trigger: only an edge after it is.
TEST(RamDebug, an_edge_before_the_pretrigger_part_is_full_does_not_trigger) {
  Logger l;
  l.send(op::kInit);
  l.send(op::kSetSampleCount, 0, 6);
  l.send(op::kSetChannel, kAxisParameter, 0);
  l.send(op::kSetTriggerChannel, kAxisParameter, 2);
  l.send(op::kSetPretriggerCount, 0, 3);
  l.send(op::kEnableTrigger, kRisingSigned, 0);
  for (int base = 0; base < 20; ++base) {
    for (uint32_t i = 0; i < Logger::kTicksPerBase; ++i) {
      l.tick([&](uint64_t) {
        l.channels.values[0] = base;
        l.channels.values[2] = (base == 1 || base >= 10) ? 1 : 0;  // a pulse during the fill
      });
    }
  }
  EXPECT_EQ(l.state(), kComplete);
  EXPECT_EQ(l.samples(6), (std::vector<int32_t>{7, 8, 9, 10, 11, 12}));
}

// The ring wraps while the logger waits; the capture reads across the wrap, rows stay aligned.
TEST(RamDebug, ring_buffer_wraps_while_armed) {
  Logger l;  // 64 words
  l.send(op::kInit);
  l.send(op::kSetSampleCount, 0, 20);
  l.send(op::kSetChannel, kAxisParameter, 0);
  l.send(op::kSetChannel, kAxisParameter, 1);
  l.send(op::kSetTriggerChannel, kAxisParameter, 2);
  l.send(op::kSetPretriggerCount, 0, 11);  // rounded down to whole rows: 10 words
  l.send(op::kEnableTrigger, kRisingSigned, 0);
  for (int base = 0; base < 120; ++base) {
    for (uint32_t i = 0; i < Logger::kTicksPerBase; ++i) {
      l.tick([&](uint64_t) {
        l.channels.values[0] = base;
        l.channels.values[1] = 1000 + base;
        l.channels.values[2] = base >= 101 ? 1 : 0;
      });
    }
  }
  EXPECT_EQ(l.state(), kComplete);
  EXPECT_EQ(l.read(op::kGetPretriggerCount), 10);
  std::vector<int32_t> expected;
  for (int base = 96; base < 106; ++base) {
    expected.push_back(base);
    expected.push_back(1000 + base);
  }
  EXPECT_EQ(l.samples(20), expected);
}

TEST(RamDebug, sample_and_pretrigger_counts_are_clamped) {
  Logger l;
  l.send(op::kInit);
  l.send(op::kSetSampleCount, 0, 1000);  // more than the 64 words
  l.send(op::kSetPretriggerCount, 0, 500);
  EXPECT_EQ(l.read(op::kGetPretriggerCount), 64);
  l.send(op::kSetSampleCount, 0, 8);
  l.send(op::kSetChannel, kAxisParameter, 0);
  l.send(op::kEnableTrigger, 0, 0);  // unconditional; the pretrigger is clamped to the 8 words
  EXPECT_EQ(l.read(op::kGetPretriggerCount), 8);
  l.run_until_state(kComplete, 1000);
  EXPECT_EQ(l.state(), kComplete);
  l.send(op::kInit);
  l.send(op::kSetSampleCount, 0, -1);  // 0xFFFFFFFF
  l.send(op::kSetChannel, kAxisParameter, 0);
  l.send(op::kEnableTrigger, 0, 0);
  l.run_until_state(kComplete, 10000);
  EXPECT_EQ(l.read(op::kGetInfo, 0, 3), 64);
  EXPECT_EQ(l.send(op::kGetSample, 0, 63), Status::kOk);
  EXPECT_EQ(l.send(op::kGetSample, 0, 64), Status::kMaxExceeded);
}

TEST(RamDebug, a_capture_of_no_words_completes_when_triggered) {
  Logger l;
  l.send(op::kInit);
  l.send(op::kSetSampleCount, 0, 0);
  l.send(op::kSetChannel, kAxisParameter, 0);
  l.send(op::kEnableTrigger, 0, 0);
  l.tick();
  EXPECT_EQ(l.state(), kComplete);
  EXPECT_EQ(l.send(op::kGetSample, 0, 0), Status::kMaxExceeded);
}

TEST(RamDebug, init_stops_a_capture_and_clears_the_configuration) {
  Logger l;
  l.send(op::kInit);
  l.send(op::kSetSampleCount, 0, 50);
  l.send(op::kSetPrescaler, 0, 9);
  l.send(op::kSetChannel, kAxisParameter, 0);
  l.send(op::kEnableTrigger, 0, 0);
  l.tick();
  EXPECT_EQ(l.state(), kCapture);
  EXPECT_EQ(l.send(op::kInit), Status::kOk);
  EXPECT_EQ(l.state(), kIdle);
  EXPECT_EQ(l.read(op::kGetChannelType, 0), 0);
  EXPECT_EQ(l.send(op::kEnableTrigger, 0, 0), Status::kMaxExceeded);  // no channel any more
}

TEST(RamDebug, every_error_status) {
  Logger l;
  l.send(op::kInit);
  // Unknown sub-commands: 3; the eval boards' bulk download: 6.
  EXPECT_EQ(l.send(15, 0, 1000), Status::kWrongType);
  EXPECT_EQ(l.send(16), Status::kWrongType);
  EXPECT_EQ(l.send(23), Status::kWrongType);
  EXPECT_EQ(l.send(255), Status::kWrongType);
  EXPECT_EQ(l.send(op::kBulkDownload), Status::kNotAvailable);
  // One sampling source; shifts up to 31.
  EXPECT_EQ(l.send(op::kSetSamplingSource, 0, 0), Status::kOk);
  EXPECT_EQ(l.send(op::kSetSamplingSource, 0, 1), Status::kInvalidValue);
  EXPECT_EQ(l.send(op::kSetShiftMask, 32, 0xFF), Status::kInvalidValue);
  // No samples while idle.
  EXPECT_EQ(l.send(op::kGetSample, 0, 0), Status::kMaxExceeded);
  // Channel slots: 4; type 0 takes none; an unsupported type or unknown channel: the module's status.
  EXPECT_EQ(l.send(op::kSetChannel, 0, 0), Status::kOk);
  EXPECT_EQ(l.send(op::kSetChannel, kRegister, 0), Status::kMaxExceeded);
  EXPECT_EQ(l.send(op::kSetChannel, kAxisParameter, 100), Status::kWrongType);
  EXPECT_EQ(l.send(op::kSetTriggerChannel, kAxisParameter, 100), Status::kWrongType);
  for (int32_t i = 0; i < 4; ++i) EXPECT_EQ(l.send(op::kSetChannel, kAxisParameter, i), Status::kOk);
  EXPECT_EQ(l.send(op::kSetChannel, kAxisParameter, 4), Status::kMaxExceeded);
  EXPECT_EQ(l.send(op::kGetChannelType, 4), Status::kMaxExceeded);
  EXPECT_EQ(l.send(op::kGetChannelAddress, 4), Status::kMaxExceeded);
  EXPECT_EQ(l.read(op::kGetChannelType, 0xFF), 0);
  // ENABLE: a trigger type beyond 6, or an edge without a trigger channel.
  EXPECT_EQ(l.send(op::kEnableTrigger, 7, 0), Status::kMaxExceeded);
  EXPECT_EQ(l.send(op::kEnableTrigger, kRisingSigned, 0), Status::kMaxExceeded);
  EXPECT_EQ(l.state(), kIdle);
  l.send(op::kSetSampleCount, 0, 8);
  ASSERT_EQ(l.send(op::kEnableTrigger, 0, 0), Status::kOk);
  // Configuration only while idle.
  EXPECT_EQ(l.send(op::kEnableTrigger, 0, 0), Status::kMaxExceeded);
  EXPECT_EQ(l.send(op::kSetSampleCount, 0, 4), Status::kMaxExceeded);
  EXPECT_EQ(l.send(op::kSetPrescaler, 0, 1), Status::kMaxExceeded);
  EXPECT_EQ(l.send(op::kSetPretriggerCount, 0, 1), Status::kMaxExceeded);
  EXPECT_EQ(l.send(op::kSetShiftMask, 0, 1), Status::kMaxExceeded);
  l.send(op::kInit);
  EXPECT_EQ(l.send(op::kSetChannel, kAxisParameter, 0), Status::kOk);
  l.send(op::kSetSampleCount, 0, 8);
  l.send(op::kSetPrescaler, 0, 1);
  l.send(op::kEnableTrigger, 0, 0);
  EXPECT_EQ(l.send(op::kSetChannel, kAxisParameter, 1), Status::kMaxExceeded);
  EXPECT_EQ(l.send(op::kSetTriggerChannel, kAxisParameter, 1), Status::kMaxExceeded);
  // While capturing: only words written so far.
  EXPECT_EQ(l.send(op::kGetSample, 0, 0), Status::kMaxExceeded);  // PRETRIGGER
  l.tick();
  EXPECT_EQ(l.state(), kCapture);
  EXPECT_EQ(l.send(op::kGetSample, 0, 0), Status::kOk);
  EXPECT_EQ(l.send(op::kGetSample, 0, 1), Status::kMaxExceeded);
  l.run_until_state(kComplete);
  EXPECT_EQ(l.send(op::kGetSample, 0, 7), Status::kOk);
  EXPECT_EQ(l.send(op::kGetSample, 0, 8), Status::kMaxExceeded);
  EXPECT_EQ(l.send(op::kGetSample, 0, -1), Status::kMaxExceeded);
}

// --- The TMCM-1636 through TMCL frames ----------------------------------------------------------

using modules::tmcm1636::Firmware;

// A host as PyTrinamic's DataLogger: 142 requests, the reply's status and value.
template <class Rig>
struct Host {
  Rig& rig;
  tmcl::Reply send(uint8_t type, uint8_t motor = 0, int32_t value = 0) {
    const tmcl::Reply reply = rig.command(kRamDebugCommand, type, motor, value);
    EXPECT_EQ(reply.command, kRamDebugCommand);
    return reply;
  }
  int32_t ok(uint8_t type, uint8_t motor = 0, int32_t value = 0) {
    const tmcl::Reply reply = send(type, motor, value);
    EXPECT_EQ(reply.status, kOk) << "142 type " << int{type} << " motor " << int{motor} << " value " << value;
    return reply.value;
  }
  // get_info(): ids 4, 2, 1, 0; 4 is not answered.
  void get_info() {
    EXPECT_EQ(send(op::kGetInfo, 0, 4).status, kMaxExceeded);
    EXPECT_EQ(ok(op::kGetInfo, 0, 2), 2000);
    EXPECT_EQ(ok(op::kGetInfo, 0, 1), 8192);
    EXPECT_EQ(ok(op::kGetInfo, 0, 0), 4);
  }
  std::vector<int32_t> download(int32_t count) {
    std::vector<int32_t> raw;
    for (int32_t i = 0; i < count; ++i) raw.push_back(ok(op::kGetSample, 0, i));
    return raw;
  }
};

// datalogger_minimal.py (PyTrinamic >= 0.2.23): 10 samples of AP 0, no trigger, full rate.
TEST(Tmcm1636RamDebug, minimal_example_sequence_on_both_generations) {
  for (const Firmware firmware : {Firmware::kV109, Firmware::kV113}) {
    Tmcm1636Rig rig(firmware);
    Host<Tmcm1636Rig> host{rig};
    host.get_info();
    host.ok(op::kInit);
    host.ok(op::kSetSampleCount, 0, 10);
    host.ok(op::kSetPrescaler, 0, 0);
    host.ok(op::kSetChannel, kAxisParameter, 0);
    EXPECT_EQ(host.ok(op::kEnableTrigger, 0, 0), 0);
    int polls = 0;
    while (host.ok(op::kGetState) != kComplete && polls < 1000) {
      rig.module.tick();
      ++polls;
    }
    EXPECT_EQ(polls, 91);  // 10 words, one every 10 control ticks from the first
    const std::vector<int32_t> samples = host.download(10);
    for (int32_t sample : samples) EXPECT_EQ(sample, rig.gap(0));  // the ideal motor's ADC at rest
  }
}

// PyTrinamic <= 0.2.22 sends the trigger channel before the channels and always a pretrigger
// count. A capture of AP 42 and 52 while ROR 1000 ramps at AP 44 = 2000 rpm/s, triggered when the
// velocity rises above 500 rpm, with 20 rows before: every word equals what GAP reads at the
// control tick it was taken, the velocity climbs 1 rpm per 0.5 ms row and the trigger row is the
// first above 500 rpm.
TEST(Tmcm1636RamDebug, old_host_order_with_a_trigger_captures_a_ramp_at_the_right_ticks) {
  Tmcm1636Rig rig;
  Host<Tmcm1636Rig> host{rig};
  constexpr int32_t kRows = 200, kPretriggerRows = 20;
  host.ok(op::kInit);
  host.ok(op::kSetSampleCount, 0, 2 * kRows);
  host.ok(op::kSetPrescaler, 0, 0);
  host.ok(op::kSetTriggerChannel, kAxisParameter, 42);
  host.ok(op::kSetChannel, kAxisParameter, 42);
  host.ok(op::kSetChannel, kAxisParameter, 52);
  host.ok(op::kSetPretriggerCount, 0, 2 * kPretriggerRows);
  host.ok(op::kEnableTrigger, kRisingSigned, 500);
  EXPECT_EQ(rig.command(1, 0, 0, 1000).status, kOk);  // ROR 1000
  // What GAP reads after every control tick, to compare with the capture.
  std::vector<std::pair<int32_t, int32_t>> polled;
  for (int i = 0; i < 20000 && host.ok(op::kGetState) != kComplete; ++i) {
    rig.module.tick();
    polled.emplace_back(rig.gap(42), rig.gap(52));
  }
  ASSERT_EQ(host.ok(op::kGetState), kComplete);
  const std::vector<int32_t> raw = host.download(2 * kRows);
  // Base ticks are the control ticks 1, 11, 21 ... after ENABLE (polled[0] is tick 1).
  size_t trigger_row_tick = 0;
  for (size_t t = 0; t < polled.size(); t += 10) {
    if (polled[t].first > 500) {
      trigger_row_tick = t;
      break;
    }
  }
  ASSERT_GT(trigger_row_tick, 0u);
  for (int32_t row = 0; row < kRows; ++row) {
    const size_t tick = trigger_row_tick + 10 * static_cast<size_t>(row - kPretriggerRows);
    ASSERT_LT(tick, polled.size());
    EXPECT_EQ(raw[2 * row], polled[tick].first) << "velocity of row " << row;
    EXPECT_EQ(raw[2 * row + 1], polled[tick].second) << "position of row " << row;
  }
  EXPECT_LE(raw[2 * (kPretriggerRows - 1)], 500);
  EXPECT_GT(raw[2 * kPretriggerRows], 500);
  // 2000 rpm/s at 2000 rows/s: 1 rpm per row.
  EXPECT_NEAR(raw[2 * (kRows - 1)] - raw[0], kRows - 1, 2);
  // Position advances by velocity [rpm] / 60 * 8192 counts * 0.5 ms per row.
  for (int32_t row = 1; row < kRows; ++row) {
    const double expected = raw[2 * row] / 60.0 * 8192 * 0.0005;
    EXPECT_NEAR(raw[2 * row + 1] - raw[2 * row - 1], expected, 2.0) << "row " << row;
  }
}

// datalogger_demo.py: AP 42 and 52, 1024 samples each, down-sampling 2 (prescaler 1).
TEST(Tmcm1636RamDebug, demo_example_sequence_takes_a_second_and_a_bit) {
  Tmcm1636Rig rig(Firmware::kV113);
  Host<Tmcm1636Rig> host{rig};
  host.get_info();
  host.get_info();
  host.ok(op::kInit);
  host.ok(op::kSetSampleCount, 0, 2048);
  host.ok(op::kSetPrescaler, 0, 1);
  host.ok(op::kSetChannel, kAxisParameter, 42);
  host.ok(op::kSetChannel, kAxisParameter, 52);
  host.ok(op::kEnableTrigger, 0, 0);
  uint64_t ticks = 0;
  while (host.ok(op::kGetState) != kComplete && ticks < 100000) {
    rig.module.tick();
    ++ticks;
  }
  EXPECT_EQ(ticks, 1 + 1023 * 20u);  // 1024 rows, one every 20 control ticks (1 ms)
  const std::vector<int32_t> raw = host.download(2048);
  EXPECT_EQ(raw[2046], 0);
  EXPECT_EQ(raw[2047], rig.gap(52));
  EXPECT_EQ(host.send(op::kGetSample, 0, 2048).status, kMaxExceeded);
}

TEST(Tmcm1636RamDebug, channels_resolve_through_the_parameter_tables) {
  Tmcm1636Rig rig;
  Host<Tmcm1636Rig> host{rig};
  host.ok(op::kInit);
  EXPECT_EQ(host.send(op::kSetChannel, kAxisParameter, 99).status, 3);          // no AP 99
  EXPECT_EQ(host.send(op::kSetChannel, kAxisParameter, 1 << 24).status, 4);     // motor 1
  EXPECT_EQ(host.send(op::kSetChannel, kGlobalParameter, 1).status, 3);        // no GP 1
  EXPECT_EQ(host.send(op::kSetChannel, kGlobalParameter, (1 << 24) | 1).status, 4);  // bank 1
  EXPECT_EQ(host.send(op::kSetChannel, kRegister, 0).status, kMaxExceeded);
  EXPECT_EQ(host.send(op::kSetChannel, kAnalogInput, 0).status, kMaxExceeded);
  EXPECT_EQ(host.send(op::kSetChannel, 3, 0).status, kMaxExceeded);
  EXPECT_EQ(host.send(op::kSetChannel, 9, 0).status, kMaxExceeded);
  ASSERT_EQ(rig.command(9, 7, 2, -77).status, kOk);  // SGP 7, bank 2: user variable 7
  host.ok(op::kSetChannel, kGlobalParameter, 66);               // GP 66, serial address
  host.ok(op::kSetChannel, kGlobalParameter, (2 << 24) | 7);    // user variable 7
  host.ok(op::kSetChannel, kSystick, 0);                        // the millisecond tick timer
  host.ok(op::kSetChannel, kAxisParameter, 0x00010000 | 220);   // legacy bit 16 ignored: AP 220
  host.ok(op::kSetSampleCount, 0, 8);
  host.ok(op::kEnableTrigger, 0, 0);
  rig.run_ms(1);
  EXPECT_EQ(host.ok(op::kGetState), kComplete);
  const int32_t supply = rig.gap(220);
  EXPECT_GT(supply, 0);
  EXPECT_EQ(host.download(8), (std::vector<int32_t>{1, -77, 0, supply, 1, -77, 0, supply}));
  EXPECT_EQ(host.ok(op::kGetChannelAddress, 1), (2 << 24) | 7);
}

TEST(Tmcm1636RamDebug, reset_and_power_up_return_to_idle) {
  Tmcm1636Rig rig;
  Host<Tmcm1636Rig> host{rig};
  host.ok(op::kInit);
  host.ok(op::kSetChannel, kAxisParameter, 42);
  host.ok(op::kEnableTrigger, 0, 0);
  rig.run_ms(1);
  EXPECT_EQ(host.ok(op::kGetState), kCapture);
  rig.command(255, 0, 0, 1234);
  rig.engine.complete_reset();
  EXPECT_EQ(host.ok(op::kGetState), kIdle);
  EXPECT_EQ(host.ok(op::kGetChannelType, 0), 0);
}

// A stored program stops at command 142 with "invalid instruction", as at any command >= 128.
TEST(Tmcm1636RamDebug, a_program_does_not_run_it) {
  Tmcm1636Rig rig;
  ASSERT_EQ(rig.command(132, 0, 0, 0).status, kOk);  // download mode
  EXPECT_EQ(rig.command(kRamDebugCommand, op::kInit, 0, 0).status, 101);
  EXPECT_EQ(rig.command(133, 0, 0, 0).status, kOk);
  EXPECT_EQ(rig.command(129, 1, 0, 0).status, kOk);  // run from 0
  rig.run_ms(2);
  const tmcl::Reply status = rig.command(135, 4, 0, 0);  // stop reason << 16 | address
  EXPECT_EQ(rig.command(135, 0, 0, 0).value >> 24, 0) << "stopped";
  EXPECT_EQ(status.value & 0xFFFF, 0);
  EXPECT_NE(status.value >> 16, 0);
}

TEST(Tmcm1636RamDebug, the_tmcm_142_has_no_datalogger) {
  Tmcm142Rig rig;
  EXPECT_EQ(rig.command(kRamDebugCommand, op::kGetState, 0, 0).status, 2);
  EXPECT_EQ(rig.command(157, 0, 0, 0).status, 2);
}

// --- Command 157 ----------------------------------------------------------------------------------

TEST(Tmcm1636GetInfo, answers_identity_entries_of_each_generation) {
  for (const auto& [firmware, version] : {std::pair{Firmware::kV109, 0x00010009}, std::pair{Firmware::kV113, 0x0001000D}}) {
    Tmcm1636Rig rig(firmware);
    const auto info = [&](uint8_t entry) { return rig.command(157, entry, 0, 0); };
    EXPECT_EQ(info(0).value, 1636);
    EXPECT_EQ(info(1).value, version);
    EXPECT_EQ(info(2).value, 0x02);  // TMCL, no bootloader
    EXPECT_EQ(info(3).value, 0);     // public release
    EXPECT_EQ(info(20).value, 8);    // AP numbers are 8 bits
    for (uint8_t entry : {0, 1, 2, 3, 20}) {
      EXPECT_EQ(info(entry).status, kOk);
      EXPECT_EQ(info(entry).command, 157);
    }
    for (uint8_t entry : {4, 10, 11, 21, 30, 200, 255}) EXPECT_EQ(info(entry).status, 3) << "entry " << int{entry};
  }
}

// --- The running servo ----------------------------------------------------------------------------

// AP 0 (raw ADC of phase A) at 2000 Hz while the default motor turns at 2000 rpm under load: every
// word is the value the 20 kHz loop had at its control tick, and the capture resolves the phase
// current's sine at the electrical frequency (pole pairs x 2000 / 60 Hz) with its amplitude, which
// a host polling GAP over a link at its own irregular pace cannot.
TEST(Tmcm1636RamDebug, captures_the_phase_current_of_the_running_servo) {
  Tmcm1636ServoRig rig(Tmcm1636ServoRig::preset("default-24v"));
  Host<Tmcm1636ServoRig> host{rig};
  rig.set("LOAD_TORQUE", 0.02);
  ASSERT_EQ(rig.ror(2000), kOk);
  rig.run_ms(1500);
  ASSERT_NEAR(rig.speed_rpm(), 2000, 40);
  constexpr int32_t kSamples = 400;  // 0.2 s
  host.ok(op::kInit);
  host.ok(op::kSetSampleCount, 0, kSamples);
  host.ok(op::kSetChannel, kAxisParameter, 0);
  host.ok(op::kEnableTrigger, 0, 0);
  std::vector<int32_t> polled;
  while (host.ok(op::kGetState) != kComplete) {
    rig.tick();
    polled.push_back(rig.gap(0));
  }
  const std::vector<int32_t> raw = host.download(kSamples);
  for (int32_t i = 0; i < kSamples; ++i) ASSERT_EQ(raw[i], polled[10 * static_cast<size_t>(i)]) << "sample " << i;
  const auto [low, high] = std::minmax_element(raw.begin(), raw.end());
  double mean = 0;
  for (int32_t v : raw) mean += v;
  mean /= kSamples;
  EXPECT_GT(*high - *low, 200) << "the phase current swings";
  int crossings = 0;
  for (int32_t i = 1; i < kSamples; ++i) crossings += ((raw[i - 1] - mean) < 0) != ((raw[i] - mean) < 0) ? 1 : 0;
  const double electrical_hz = rig.gap(10) * 2000.0 / 60.0;
  EXPECT_NEAR(crossings, 2 * electrical_hz * 0.2, 4) << "zero crossings at " << electrical_hz << " Hz";
}

}  // namespace
}  // namespace motwin::testing
