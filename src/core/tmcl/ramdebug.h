// The TMCL datalogger, command 142 ("RAMDebug"), as PyTrinamic's DataLogger and the TMCL-IDE
// speak it (docs/datalogger.md): a host chooses up to max_channels parameters, a sample count,
// a prescaler and a trigger; the firmware records them at its sampling base rate into a RAM ring
// buffer; the host polls the state and downloads the samples one 32-bit word per request.
//
// One file for the service (CANopenNode style). The module keeps what is its own behind
// RamDebugChannels: how a channel's select word becomes something it can read (resolved once,
// at SET_CHANNEL) and the read itself, called at each sample. The module calls control_tick()
// once per control tick; every control_ticks_per_base_tick-th tick is a base-rate tick.
//
// Freestanding: the buffer is the module's (a span given at construction), nothing allocates.
#pragma once

#include <array>
#include <cstddef>
#include <cstdint>
#include <span>

#include "core/tmcl/status.h"

namespace motwin::tmcl {

namespace ram_debug {

// Sub-commands: the type byte of command 142.
namespace op {
inline constexpr uint8_t kInit = 0;
inline constexpr uint8_t kSetSampleCount = 1;
inline constexpr uint8_t kSetSamplingSource = 2;
inline constexpr uint8_t kSetPrescaler = 3;
inline constexpr uint8_t kSetChannel = 4;
inline constexpr uint8_t kSetTriggerChannel = 5;
inline constexpr uint8_t kSetShiftMask = 6;
inline constexpr uint8_t kEnableTrigger = 7;
inline constexpr uint8_t kGetState = 8;
inline constexpr uint8_t kGetSample = 9;
inline constexpr uint8_t kGetInfo = 10;
inline constexpr uint8_t kGetChannelType = 11;
inline constexpr uint8_t kGetChannelAddress = 12;
inline constexpr uint8_t kSetPretriggerCount = 13;
inline constexpr uint8_t kGetPretriggerCount = 14;
inline constexpr uint8_t kBulkDownload = 22;  // the eval boards' USB bulk read: not on a 9-byte link
}  // namespace op

// GET_STATE values.
enum class State : uint8_t { kIdle = 0, kTrigger = 1, kCapture = 2, kComplete = 3, kPretrigger = 4 };

// Channel types: the motor byte of SET_CHANNEL and SET_TRIGGER_CHANNEL.
namespace channel_type {
inline constexpr uint8_t kDisabled = 0;
inline constexpr uint8_t kAxisParameter = 1;    // select: axis << 24 | AP number
inline constexpr uint8_t kSystick = 4;          // select ignored: the millisecond tick timer
inline constexpr uint8_t kGlobalParameter = 8;  // select: bank << 24 | GP number
}  // namespace channel_type

// ENABLE_TRIGGER's motor byte.
enum class TriggerType : uint8_t {
  kUnconditional = 0,
  kRisingSigned = 1,
  kFallingSigned = 2,
  kBothSigned = 3,
  kRisingUnsigned = 4,
  kFallingUnsigned = 5,
  kBothUnsigned = 6,
};
inline constexpr uint8_t kTriggerTypeCount = 7;

// GET_INFO ids.
namespace info {
inline constexpr uint32_t kMaxChannels = 0;
inline constexpr uint32_t kBufferWords = 1;
inline constexpr uint32_t kBaseRateHz = 2;
inline constexpr uint32_t kCapturedWords = 3;
inline constexpr uint32_t kMaxSamplesPerSecond = 4;  // not answered (status 9)
}  // namespace info

// The eval firmware's limit of parallel channels; a module may offer fewer.
inline constexpr size_t kMaxChannelSlots = 8;

}  // namespace ram_debug

// A channel as the module resolved it at SET_CHANNEL: opaque here, read back by the module.
struct RamDebugProbe {
  const void* source = nullptr;  // e.g. the module's parameter row
  uint8_t kind = 0;              // the module's own tag
  uint8_t index = 0;             // e.g. axis or bank
};

// The module side of the datalogger.
class RamDebugChannels {
 public:
  // Per command: a channel type and select word to a probe. Errors are the module's statuses
  // (docs/datalogger.md "Errors").
  virtual Status resolve_ram_debug_channel(uint8_t type, uint32_t select, RamDebugProbe& probe) = 0;
  // Per sample: the probe's value now, as GAP/GGP would answer it.
  virtual int32_t read_ram_debug_channel(const RamDebugProbe& probe) = 0;

 protected:
  ~RamDebugChannels() = default;
};

// The figures of a module's datalogger (GET_INFO 0..2) and its timing.
struct RamDebugConfig {
  uint32_t max_channels;                 // <= ram_debug::kMaxChannelSlots
  uint32_t base_rate_hz;                 // samples per second before the prescaler
  uint32_t control_ticks_per_base_tick;  // control tick rate / base_rate_hz
};

class RamDebug {
 public:
  // `buffer` (the sample ring, 32-bit words) stays the module's.
  RamDebug(RamDebugChannels& channels, const RamDebugConfig& config, std::span<uint32_t> buffer)
      : channels_(channels), config_(config), buffer_(buffer) {
    init();
  }
  RamDebug(const RamDebug&) = delete;
  RamDebug& operator=(const RamDebug&) = delete;

  // Command 142: `type` the sub-command, `motor` its byte operand, `value` in (the request's
  // value) and out (the reply's; set commands leave it, so the reply echoes the request).
  Status execute(uint8_t type, uint8_t motor, int32_t& value);

  // Once per control tick, after the regulators: a base-rate tick samples. Idle costs one test.
  void control_tick() {
    if (!running_) return;
    if (--ticks_to_base_tick_ != 0) return;
    ticks_to_base_tick_ = config_.control_ticks_per_base_tick;
    base_tick();
  }

  // Power-up: as after INIT.
  void init();

  ram_debug::State state() const { return state_; }
  uint32_t buffer_words() const { return static_cast<uint32_t>(buffer_.size()); }

 private:
  struct Channel {
    uint8_t type = ram_debug::channel_type::kDisabled;
    uint32_t select = 0;
    RamDebugProbe probe;
  };

  Status set_channel(uint8_t type, uint32_t select);
  Status set_trigger_channel(uint8_t type, uint32_t select);
  Status enable_trigger(uint8_t type, uint32_t threshold);
  Status get_sample(uint32_t index, int32_t& value) const;
  Status get_info(uint32_t id, int32_t& value) const;
  // The trigger channel through mask and shift, compared with the threshold.
  bool trigger_above(bool signed_compare);
  void base_tick();
  void write_row();
  void complete();

  RamDebugChannels& channels_;
  const RamDebugConfig config_;
  std::span<uint32_t> buffer_;

  // Configuration (INIT resets it).
  std::array<Channel, ram_debug::kMaxChannelSlots> channels_config_{};
  uint32_t channel_count_ = 0;
  uint32_t sample_words_ = 0;      // the capture's length, words over all channels
  uint32_t pretrigger_words_ = 0;  // of them, recorded before the trigger
  uint32_t divider_ = 1;           // base ticks per sample row (prescaler + 1)
  Channel trigger_channel_{};
  uint32_t trigger_mask_ = 0xFFFFFFFF;
  uint8_t trigger_shift_ = 0;
  ram_debug::TriggerType trigger_type_ = ram_debug::TriggerType::kUnconditional;
  uint32_t trigger_threshold_ = 0;

  // The capture.
  ram_debug::State state_ = ram_debug::State::kIdle;
  bool running_ = false;  // PRETRIGGER, TRIGGER or CAPTURE
  uint32_t ticks_to_base_tick_ = 1;
  uint32_t prescaler_phase_ = 0;  // base ticks since the last row, mod divider_
  bool was_above_ = false;
  uint32_t write_index_ = 0;    // next word of the ring
  uint32_t words_filled_ = 0;   // words written since ENABLE_TRIGGER, up to the buffer size
  uint32_t start_index_ = 0;    // the capture's first word
  uint32_t words_captured_ = 0; // words of the capture written so far, pretrigger included
};

}  // namespace motwin::tmcl
