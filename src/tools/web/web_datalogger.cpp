#include "tools/web/web_datalogger.h"
#include "tools/web/web_json.h"

#include <algorithm>
#include <limits>
#include <memory>
#include <utility>

#include "core/tmcl/ramdebug.h"
#include "core/tmcl/status.h"

namespace motwin::tools::web {

using Json = nlohmann::json;
namespace op = tmcl::ram_debug::op;
namespace info = tmcl::ram_debug::info;
namespace channel_type = tmcl::ram_debug::channel_type;

namespace {

// The most samples per channel a request may ask for; the module clamps the capture to its buffer.
constexpr int64_t kMaxSamplesPerChannel = 1 << 20;

const char* state_name(int32_t state) {
  switch (state) {
    case 0: return "idle";
    case 1: return "trigger";
    case 2: return "capture";
    case 3: return "complete";
    case 4: return "pretrigger";
    case 5: return "error";
    default: return "unknown";
  }
}

const char* step_name(uint8_t type) {
  switch (type) {
    case op::kInit: return "INIT";
    case op::kSetSampleCount: return "SET_SAMPLE_COUNT";
    case op::kSetPrescaler: return "SET_PRESCALER";
    case op::kSetChannel: return "SET_CHANNEL";
    case op::kSetTriggerChannel: return "SET_TRIGGER_CHANNEL";
    case op::kEnableTrigger: return "ENABLE_TRIGGER";
    case op::kGetState: return "GET_STATE";
    case op::kGetSample: return "GET_SAMPLE";
    case op::kGetInfo: return "GET_INFO";
    case op::kGetChannelType: return "GET_CHANNEL_TYPE";
    case op::kGetChannelAddress: return "GET_CHANNEL_ADDRESS";
    case op::kSetPretriggerCount: return "SET_PRETRIGGER_SAMPLE_COUNT";
    case op::kGetPretriggerCount: return "GET_PRETRIGGER_SAMPLE_COUNT";
    default: return "142";
  }
}

uint32_t select_word(const DataloggerChannel& channel) {
  return static_cast<uint32_t>(channel.motor_bank) << 24 | channel.number;
}

Json channel_json(uint8_t type, uint32_t select) {
  Json channel = {{"type", type}, {"select", select}};
  const auto number = static_cast<uint32_t>(select & 0xFFFF);
  const auto motor_bank = static_cast<uint32_t>(select >> 24);
  if (type == channel_type::kAxisParameter) {
    channel.update({{"kind", "axis"}, {"number", number}, {"axis", motor_bank}});
  } else if (type == channel_type::kGlobalParameter) {
    channel.update({{"kind", "global"}, {"number", number}, {"bank", motor_bank}});
  } else if (type == channel_type::kSystick) {
    channel["kind"] = "systick";
  }
  return channel;
}

// One op in flight: its instructions go out one after another (a read-out's GET_SAMPLEs a
// window at a time), each continuing with the module's answer; the first refusal ends it.
struct Run : std::enable_shared_from_this<Run> {
  DataloggerLink link;
  std::function<void(Json)> reply;
  bool finished = false;

  // Sends 142 `type`; `next` runs with the answer's value when the module accepted it.
  void ask(uint8_t type, uint8_t motor, int32_t value, std::function<void(int32_t)> next) {
    if (finished || !link.alive()) return;
    tmcl::Instruction instruction;
    instruction.command = tmcl::command::kRamDebug;
    instruction.type = type;
    instruction.motor_bank = motor;
    instruction.value = value;
    link.request(instruction, [self = shared_from_this(), type, next = std::move(next)](const DataloggerAnswer& answer) {
      if (self->finished || !self->link.alive()) return;
      if (!answer.replied || !tmcl::is_success(answer.status)) return self->fail(type, answer);
      next(answer.value);
    });
  }

  void fail(uint8_t type, const DataloggerAnswer& answer) {
    Json failure = {{"ok", false}, {"step", step_name(type)}};
    if (answer.replied) {
      failure["status"] = answer.status;
      failure["status_name"] = tmcl::status_name(answer.status);
    } else {
      failure["error"] = "the module sent no reply";
    }
    finish(std::move(failure));
  }

  void finish(Json message) {
    if (finished) return;
    finished = true;
    message["sim_time_us"] = link.sim_time_us();
    reply(std::move(message));
  }
};

void run_info(const std::shared_ptr<Run>& run) {
  run->ask(op::kGetInfo, 0, static_cast<int32_t>(info::kMaxChannels), [run](int32_t channels) {
    run->ask(op::kGetInfo, 0, static_cast<int32_t>(info::kBufferWords), [run, channels](int32_t words) {
      run->ask(op::kGetInfo, 0, static_cast<int32_t>(info::kBaseRateHz), [run, channels, words](int32_t rate_hz) {
        run->finish(Json{{"ok", true}, {"channels", channels}, {"buffer_words", words}, {"base_rate_hz", rate_hz}});
      });
    });
  });
}

void send_step(const std::shared_ptr<Run>& run, const std::shared_ptr<std::vector<tmcl::Instruction>>& steps,
               size_t index);

// The sequence PyTrinamic >= 0.2.23 sends (docs/datalogger.md): INIT, count, prescaler, channels,
// [trigger channel, pretrigger], enable.
void run_start(const std::shared_ptr<Run>& run, const DataloggerPlan& plan) {
  auto steps = std::make_shared<std::vector<tmcl::Instruction>>();
  const auto add = [&](uint8_t type, uint8_t motor, uint32_t value) {
    tmcl::Instruction instruction;
    instruction.type = type;
    instruction.motor_bank = motor;
    instruction.value = static_cast<int32_t>(value);
    steps->push_back(instruction);
  };
  const auto channel_count = static_cast<uint32_t>(plan.channels.size());
  add(op::kInit, 0, 0);
  add(op::kSetSampleCount, 0, plan.samples_per_channel * channel_count);
  add(op::kSetPrescaler, 0, plan.prescaler);
  for (const DataloggerChannel& channel : plan.channels) {
    add(op::kSetChannel, channel.axis ? channel_type::kAxisParameter : channel_type::kGlobalParameter,
        select_word(channel));
  }
  if (plan.trigger_channel) {
    const DataloggerChannel& channel = plan.channels[*plan.trigger_channel];
    add(op::kSetTriggerChannel, channel.axis ? channel_type::kAxisParameter : channel_type::kGlobalParameter,
        select_word(channel));
    add(op::kSetPretriggerCount, 0, plan.pretrigger_samples * channel_count);
  }
  add(op::kEnableTrigger, plan.trigger_type, static_cast<uint32_t>(plan.trigger_level));
  send_step(run, steps, 0);
}

void send_step(const std::shared_ptr<Run>& run, const std::shared_ptr<std::vector<tmcl::Instruction>>& steps,
               size_t index) {
  if (index == steps->size()) return run->finish(Json{{"ok", true}, {"instructions", steps->size()}});
  const tmcl::Instruction& step = (*steps)[index];
  run->ask(step.type, step.motor_bank, step.value, [run, steps, index](int32_t) { send_step(run, steps, index + 1); });
}

void run_state(const std::shared_ptr<Run>& run) {
  run->ask(op::kGetState, 0, 0, [run](int32_t state) {
    run->ask(op::kGetInfo, 0, static_cast<int32_t>(info::kCapturedWords), [run, state](int32_t words) {
      run->finish(Json{{"ok", true}, {"state", state_name(state)}, {"state_code", state}, {"captured_words", words}});
    });
  });
}

// The capture as the module describes it, then its samples.
struct ReadOut {
  int32_t max_channels = 0;
  int32_t base_rate_hz = 0;
  std::vector<std::pair<uint8_t, uint32_t>> channels;  // type, select word
  uint32_t words = 0;
  uint32_t pretrigger_words = 0;
  std::vector<int32_t> samples;
  uint32_t next_index = 0;  // the next GET_SAMPLE to send
  uint32_t received = 0;
};

void read_samples(const std::shared_ptr<Run>& run, const std::shared_ptr<ReadOut>& read);

void send_sample_request(const std::shared_ptr<Run>& run, const std::shared_ptr<ReadOut>& read) {
  const uint32_t index = read->next_index++;
  run->ask(op::kGetSample, 0, static_cast<int32_t>(index), [run, read, index](int32_t value) {
    read->samples[index] = value;
    ++read->received;
    if (read->next_index < read->words) send_sample_request(run, read);
    if (read->received == read->words) read_samples(run, read);
  });
}

void read_samples(const std::shared_ptr<Run>& run, const std::shared_ptr<ReadOut>& read) {
  if (read->received < read->words) {
    // The first window; each answer sends the next request.
    while (read->next_index < read->words && read->next_index < kDataloggerReadWindow) send_sample_request(run, read);
    return;
  }
  const size_t channel_count = read->channels.size();
  const size_t rows = channel_count == 0 ? 0 : read->words / channel_count;
  Json channels = Json::array();
  Json values = Json::array();
  for (size_t c = 0; c < channel_count; ++c) {
    channels.push_back(channel_json(read->channels[c].first, read->channels[c].second));
    Json column = Json::array();
    for (size_t row = 0; row < rows; ++row) column.push_back(read->samples[row * channel_count + c]);
    values.push_back(std::move(column));
  }
  run->finish(Json{{"ok", true},
                   {"base_rate_hz", read->base_rate_hz},
                   {"channels", std::move(channels)},
                   {"samples", rows},
                   {"pretrigger_samples", channel_count == 0 ? 0 : read->pretrigger_words / channel_count},
                   {"values", std::move(values)}});
}

void read_channel(const std::shared_ptr<Run>& run, const std::shared_ptr<ReadOut>& read, int32_t slot) {
  if (slot == read->max_channels) {
    return run->ask(op::kGetInfo, 0, static_cast<int32_t>(info::kCapturedWords), [run, read](int32_t words) {
      run->ask(op::kGetPretriggerCount, 0, 0, [run, read, words](int32_t pretrigger) {
        const size_t channel_count = std::max<size_t>(read->channels.size(), 1);
        // Whole rows only: a count the host gave that is not a multiple of the channels ends
        // in a part row, which no curve can use.
        read->words = static_cast<uint32_t>(static_cast<uint32_t>(words) / channel_count * channel_count);
        if (read->channels.empty()) read->words = 0;
        read->pretrigger_words = static_cast<uint32_t>(pretrigger);
        read->samples.assign(read->words, 0);
        read_samples(run, read);
      });
    });
  }
  const auto slot_byte = static_cast<uint8_t>(slot);
  run->ask(op::kGetChannelType, slot_byte, 0, [run, read, slot, slot_byte](int32_t type) {
    if (type == channel_type::kDisabled) return read_channel(run, read, read->max_channels);  // slots fill in order
    run->ask(op::kGetChannelAddress, slot_byte, 0, [run, read, slot, type](int32_t select) {
      read->channels.emplace_back(static_cast<uint8_t>(type), static_cast<uint32_t>(select));
      read_channel(run, read, slot + 1);
    });
  });
}

void run_read(const std::shared_ptr<Run>& run) {
  run->ask(op::kGetState, 0, 0, [run](int32_t state) {
    if (state != static_cast<int32_t>(tmcl::ram_debug::State::kComplete)) {
      return run->finish(Json{{"ok", false},
                              {"error", std::string("no complete capture (state ") + state_name(state) + ")"},
                              {"state", state_name(state)},
                              {"state_code", state}});
    }
    auto read = std::make_shared<ReadOut>();
    run->ask(op::kGetInfo, 0, static_cast<int32_t>(info::kMaxChannels), [run, read](int32_t max_channels) {
      read->max_channels = std::clamp<int32_t>(max_channels, 0, static_cast<int32_t>(kDataloggerMaxChannels));
      run->ask(op::kGetInfo, 0, static_cast<int32_t>(info::kBaseRateHz), [run, read](int32_t rate_hz) {
        read->base_rate_hz = rate_hz;
        read_channel(run, read, 0);
      });
    });
  });
}

}  // namespace

std::variant<DataloggerPlan, std::string> parse_datalogger_request(const Json& request) {
  DataloggerPlan plan;
  const auto action = request.find("action");
  const std::string name = action != request.end() && action->is_string() ? action->get<std::string>() : "";
  if (name == "info") {
    plan.action = DataloggerAction::kInfo;
  } else if (name == "state") {
    plan.action = DataloggerAction::kState;
  } else if (name == "read") {
    plan.action = DataloggerAction::kRead;
  } else if (name == "stop") {
    plan.action = DataloggerAction::kStop;
  } else if (name == "start") {
    plan.action = DataloggerAction::kStart;
  } else {
    return std::string("\"action\": expected info, start, state, read or stop");
  }
  if (plan.action != DataloggerAction::kStart) return plan;

  const auto channels = request.find("channels");
  if (channels == request.end() || !channels->is_array() || channels->empty() ||
      channels->size() > kDataloggerMaxChannels) {
    return std::string("\"channels\": expected 1 to 8 parameters, as {\"kind\":\"axis\",\"number\":N,\"axis\":A}");
  }
  for (const Json& given : *channels) {
    if (!given.is_object()) return std::string("\"channels\": each an object");
    DataloggerChannel channel;
    const auto kind = given.find("kind");
    const std::string kind_text = kind != given.end() && kind->is_string() ? kind->get<std::string>() : "axis";
    if (kind_text != "axis" && kind_text != "global") return std::string("\"kind\": expected \"axis\" or \"global\"");
    channel.axis = kind_text == "axis";
    const std::optional<int64_t> number = integer_field(given, "number");
    if (!number || *number < 0 || *number > 255) return std::string("\"number\": expected a parameter number 0..255");
    const char* motor_bank_name = channel.axis ? "axis" : "bank";
    const std::optional<int64_t> motor_bank = integer_field(given, motor_bank_name);
    if (given.contains(motor_bank_name) && (!motor_bank || *motor_bank < 0 || *motor_bank > 255)) {
      return std::string("\"") + motor_bank_name + "\": expected 0..255";
    }
    channel.number = static_cast<uint8_t>(*number);
    channel.motor_bank = static_cast<uint8_t>(motor_bank.value_or(0));
    plan.channels.push_back(channel);
  }
  const std::optional<int64_t> samples = integer_field(request, "samples");
  if (!samples || *samples < 1 || *samples > kMaxSamplesPerChannel) {
    return std::string("\"samples\": expected the samples per channel, 1..") + std::to_string(kMaxSamplesPerChannel);
  }
  plan.samples_per_channel = static_cast<uint32_t>(*samples);
  if (request.contains("prescaler")) {
    const std::optional<int64_t> prescaler = integer_field(request, "prescaler");
    if (!prescaler || *prescaler < 0 || *prescaler > std::numeric_limits<int32_t>::max()) {
      return std::string("\"prescaler\": expected the divider minus one, 0 or more");
    }
    plan.prescaler = static_cast<uint32_t>(*prescaler);
  }
  const auto trigger = request.find("trigger");
  if (trigger == request.end() || trigger->is_null()) return plan;
  if (!trigger->is_object()) return std::string("\"trigger\": expected an object or null");
  const std::optional<int64_t> channel = integer_field(*trigger, "channel");
  if (!channel || *channel < 0 || static_cast<size_t>(*channel) >= plan.channels.size()) {
    return std::string("\"trigger\".\"channel\": expected the index of one of \"channels\"");
  }
  plan.trigger_channel = static_cast<size_t>(*channel);
  const std::optional<int64_t> level = integer_field(*trigger, "level");
  if (!level || *level < std::numeric_limits<int32_t>::min() || *level > std::numeric_limits<uint32_t>::max()) {
    return std::string("\"trigger\".\"level\": expected a 32-bit integer");
  }
  plan.trigger_level = static_cast<int32_t>(static_cast<uint32_t>(*level));
  const auto edge = trigger->find("edge");
  const std::string edge_text = edge != trigger->end() && edge->is_string() ? edge->get<std::string>() : "rising";
  const auto is_signed = trigger->find("signed");
  if (is_signed != trigger->end() && !is_signed->is_boolean()) return std::string("\"trigger\".\"signed\": expected true or false");
  const bool signed_compare = is_signed == trigger->end() || is_signed->get<bool>();
  uint8_t type = 0;
  if (edge_text == "rising") {
    type = 1;
  } else if (edge_text == "falling") {
    type = 2;
  } else if (edge_text == "both") {
    type = 3;
  } else {
    return std::string("\"trigger\".\"edge\": expected rising, falling or both");
  }
  plan.trigger_type = signed_compare ? type : static_cast<uint8_t>(type + 3);  // 4..6: unsigned
  if (trigger->contains("pretrigger")) {
    const std::optional<int64_t> pretrigger = integer_field(*trigger, "pretrigger");
    if (!pretrigger || *pretrigger < 0 || *pretrigger > *samples) {
      return std::string("\"trigger\".\"pretrigger\": expected samples per channel, 0..\"samples\"");
    }
    plan.pretrigger_samples = static_cast<uint32_t>(*pretrigger);
  }
  return plan;
}

void run_datalogger(const DataloggerPlan& plan, DataloggerLink link, std::function<void(Json)> reply) {
  auto run = std::make_shared<Run>();
  run->link = std::move(link);
  run->reply = std::move(reply);
  switch (plan.action) {
    case DataloggerAction::kInfo: return run_info(run);
    case DataloggerAction::kStart: return run_start(run, plan);
    case DataloggerAction::kState: return run_state(run);
    case DataloggerAction::kRead: return run_read(run);
    case DataloggerAction::kStop:
      return run->ask(op::kInit, 0, 0, [run](int32_t) { run->finish(Json{{"ok", true}}); });
  }
}

}  // namespace motwin::tools::web
