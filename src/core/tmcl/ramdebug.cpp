#include "core/tmcl/ramdebug.h"

namespace motwin::tmcl {

using ram_debug::State;
using ram_debug::TriggerType;
namespace op = ram_debug::op;
namespace channel_type = ram_debug::channel_type;

namespace {

bool is_signed_trigger(TriggerType type) {
  return type == TriggerType::kRisingSigned || type == TriggerType::kFallingSigned || type == TriggerType::kBothSigned;
}

bool edge_fires(TriggerType type, bool was_above, bool above) {
  switch (type) {
    case TriggerType::kRisingSigned:
    case TriggerType::kRisingUnsigned:
      return !was_above && above;
    case TriggerType::kFallingSigned:
    case TriggerType::kFallingUnsigned:
      return was_above && !above;
    case TriggerType::kBothSigned:
    case TriggerType::kBothUnsigned:
      return was_above != above;
    case TriggerType::kUnconditional:
      break;
  }
  return true;
}

}  // namespace

void RamDebug::init() {
  channels_config_ = {};
  channel_count_ = 0;
  sample_words_ = buffer_words();
  pretrigger_words_ = 0;
  divider_ = 1;
  trigger_channel_ = {};
  trigger_mask_ = 0xFFFFFFFF;
  trigger_shift_ = 0;
  trigger_type_ = TriggerType::kUnconditional;
  trigger_threshold_ = 0;
  state_ = State::kIdle;
  running_ = false;
  write_index_ = 0;
  words_filled_ = 0;
  start_index_ = 0;
  words_captured_ = 0;
}

// Configuration is accepted while IDLE only (after INIT, before ENABLE_TRIGGER): any other
// state answers status 9, as the eval firmware's channel commands do (docs/datalogger.md).
Status RamDebug::execute(uint8_t type, uint8_t motor, int32_t& value) {
  const auto operand = static_cast<uint32_t>(value);
  const bool idle = state_ == State::kIdle;
  switch (type) {
    case op::kInit:
      init();
      return Status::kOk;
    case op::kSetSampleCount:
      if (!idle) return Status::kMaxExceeded;
      sample_words_ = operand < buffer_words() ? operand : buffer_words();
      return Status::kOk;
    case op::kSetSamplingSource:
      // One source: the base-rate tick.
      return operand == 0 ? Status::kOk : Status::kInvalidValue;
    case op::kSetPrescaler:
      if (!idle) return Status::kMaxExceeded;
      // The host sends the divider minus one.
      divider_ = operand == UINT32_MAX ? UINT32_MAX : operand + 1;
      return Status::kOk;
    case op::kSetChannel:
      return set_channel(motor, operand);
    case op::kSetTriggerChannel:
      return set_trigger_channel(motor, operand);
    case op::kSetShiftMask:
      if (!idle) return Status::kMaxExceeded;
      if (motor > 31) return Status::kInvalidValue;
      trigger_shift_ = motor;
      trigger_mask_ = operand;
      return Status::kOk;
    case op::kEnableTrigger:
      return enable_trigger(motor, operand);
    case op::kGetState:
      value = static_cast<int32_t>(state_);
      return Status::kOk;
    case op::kGetSample:
      return get_sample(operand, value);
    case op::kGetInfo:
      return get_info(operand, value);
    case op::kGetChannelType:
    case op::kGetChannelAddress: {
      const Channel* channel = nullptr;
      if (motor == 0xFF) {
        channel = &trigger_channel_;
      } else if (motor < config_.max_channels) {
        channel = &channels_config_[motor];
      } else {
        return Status::kMaxExceeded;
      }
      value = type == op::kGetChannelType ? channel->type : static_cast<int32_t>(channel->select);
      return Status::kOk;
    }
    case op::kSetPretriggerCount:
      if (!idle) return Status::kMaxExceeded;
      pretrigger_words_ = operand < sample_words_ ? operand : sample_words_;
      return Status::kOk;
    case op::kGetPretriggerCount:
      value = static_cast<int32_t>(pretrigger_words_);
      return Status::kOk;
    case op::kBulkDownload:
      return Status::kNotAvailable;
    default:
      return Status::kWrongType;
  }
}

Status RamDebug::set_channel(uint8_t type, uint32_t select) {
  if (state_ != State::kIdle) return Status::kMaxExceeded;
  if (type == channel_type::kDisabled) return Status::kOk;  // takes no slot
  if (channel_count_ >= config_.max_channels) return Status::kMaxExceeded;
  Channel channel{type, select, {}};
  const Status status = channels_.resolve_ram_debug_channel(type, select, channel.probe);
  if (status != Status::kOk) return status;
  channels_config_[channel_count_++] = channel;
  return Status::kOk;
}

Status RamDebug::set_trigger_channel(uint8_t type, uint32_t select) {
  if (state_ != State::kIdle) return Status::kMaxExceeded;
  Channel channel{type, select, {}};
  if (type != channel_type::kDisabled) {
    const Status status = channels_.resolve_ram_debug_channel(type, select, channel.probe);
    if (status != Status::kOk) return status;
  }
  trigger_channel_ = channel;
  return Status::kOk;
}

Status RamDebug::enable_trigger(uint8_t type, uint32_t threshold) {
  if (state_ != State::kIdle || type >= ram_debug::kTriggerTypeCount || channel_count_ == 0) return Status::kMaxExceeded;
  const auto trigger = static_cast<TriggerType>(type);
  if (trigger != TriggerType::kUnconditional && trigger_channel_.type == channel_type::kDisabled) {
    return Status::kMaxExceeded;
  }
  trigger_type_ = trigger;
  trigger_threshold_ = threshold;
  // Whole rows before the trigger, so that the download starts with the first channel.
  if (pretrigger_words_ > sample_words_) pretrigger_words_ = sample_words_;
  pretrigger_words_ -= pretrigger_words_ % channel_count_;
  if (trigger != TriggerType::kUnconditional) was_above_ = trigger_above(is_signed_trigger(trigger));
  write_index_ = 0;
  words_filled_ = 0;
  start_index_ = 0;
  words_captured_ = 0;
  prescaler_phase_ = 0;
  ticks_to_base_tick_ = 1;  // the first base tick is the next control tick
  state_ = State::kPretrigger;
  running_ = true;
  return Status::kOk;
}

Status RamDebug::get_sample(uint32_t index, int32_t& value) const {
  if (state_ != State::kCapture && state_ != State::kComplete) return Status::kMaxExceeded;
  if (index >= sample_words_ || index >= words_captured_) return Status::kMaxExceeded;
  value = static_cast<int32_t>(buffer_[(start_index_ + index) % buffer_words()]);
  return Status::kOk;
}

Status RamDebug::get_info(uint32_t id, int32_t& value) const {
  switch (id) {
    case ram_debug::info::kMaxChannels:
      value = static_cast<int32_t>(config_.max_channels);
      return Status::kOk;
    case ram_debug::info::kBufferWords:
      value = static_cast<int32_t>(buffer_words());
      return Status::kOk;
    case ram_debug::info::kBaseRateHz:
      value = static_cast<int32_t>(config_.base_rate_hz);
      return Status::kOk;
    case ram_debug::info::kCapturedWords:
      value = static_cast<int32_t>(words_captured_);
      return Status::kOk;
    default:  // 4, the host link's samples per second, included: no figure (docs/datalogger.md)
      return Status::kMaxExceeded;
  }
}

// The eval firmware's rule: the field is (value & mask) >> shift; a signed compare extends its
// sign from the top bit of mask >> shift. "Above" is strictly greater than the threshold.
bool RamDebug::trigger_above(bool signed_compare) {
  const auto raw = static_cast<uint32_t>(channels_.read_ram_debug_channel(trigger_channel_.probe));
  const uint32_t width = trigger_mask_ >> trigger_shift_;
  uint32_t field = (raw & trigger_mask_) >> trigger_shift_;
  if (!signed_compare) return field > trigger_threshold_;
  uint32_t top = width;
  while ((top & (top - 1)) != 0) top &= top - 1;  // the highest set bit
  if ((field & top) != 0) field |= ~width;
  return static_cast<int32_t>(field) > static_cast<int32_t>(trigger_threshold_);
}

void RamDebug::base_tick() {
  if (state_ == State::kPretrigger && words_filled_ >= pretrigger_words_) state_ = State::kTrigger;
  if (state_ != State::kCapture) {
    // The edge detector follows the signal while the pretrigger part fills, so that only an edge
    // after that counts (as an oscilloscope's holdoff).
    bool fires = state_ == State::kTrigger;
    if (trigger_type_ != TriggerType::kUnconditional) {
      const bool above = trigger_above(is_signed_trigger(trigger_type_));
      fires = fires && edge_fires(trigger_type_, was_above_, above);
      was_above_ = above;
    }
    if (fires) {
      state_ = State::kCapture;
      start_index_ = (write_index_ + buffer_words() - pretrigger_words_) % buffer_words();
      words_captured_ = pretrigger_words_;
      if (words_captured_ >= sample_words_) {
        complete();
        return;
      }
    }
  }
  const bool row_due = prescaler_phase_ == 0;
  if (++prescaler_phase_ >= divider_) prescaler_phase_ = 0;
  if (row_due) write_row();
}

void RamDebug::write_row() {
  for (uint32_t i = 0; i < channel_count_; ++i) {
    buffer_[write_index_] = static_cast<uint32_t>(channels_.read_ram_debug_channel(channels_config_[i].probe));
    if (++write_index_ == buffer_words()) write_index_ = 0;
    if (words_filled_ < buffer_words()) ++words_filled_;
    if (state_ == State::kCapture && ++words_captured_ >= sample_words_) {
      complete();
      return;
    }
  }
}

void RamDebug::complete() {
  state_ = State::kComplete;
  running_ = false;
}

}  // namespace motwin::tmcl
