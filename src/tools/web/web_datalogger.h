// The web console's "datalogger" op (docs/web-console.md, "Protocol"; docs/datalogger.md): a
// capture of the module's datalogger (TMCL command 142, "RAMDebug") set up, watched and read out
// through the module's own TMCL service, as a host would do it, one instruction after another.
// The console adds nothing the module does not answer: each step is one 142 request, and the
// first status other than 100 ends the op with that status. What it saves is the round trips:
// reading out a capture is thousands of GET_SAMPLE requests, which the op sends server-side and
// answers with one reply.
//
// No sockets and no console internals here: web_console.cpp hands in a way to send an
// instruction (its TmclPort) and a way to reply.
#pragma once

#include <cstddef>
#include <cstdint>
#include <functional>
#include <optional>
#include <string>
#include <variant>
#include <vector>

#include <nlohmann/json.hpp>

#include "core/tmcl/instruction.h"

namespace motwin::tools::web {

// A module's answer to one instruction.
struct DataloggerAnswer {
  bool replied = false;
  uint8_t status = 0;
  int32_t value = 0;
};

// What the op needs of the console.
struct DataloggerLink {
  // Sends one instruction to the module; `done` runs with its answer (in request order).
  std::function<void(const tmcl::Instruction&, std::function<void(const DataloggerAnswer&)> done)> request;
  // False once the session that asked is gone: the op then sends nothing more.
  std::function<bool()> alive;
  std::function<uint64_t()> sim_time_us;
};

// One channel of a capture: an axis parameter (axis << 24 | number) or a global parameter
// (bank << 24 | number), as SET_CHANNEL takes it.
struct DataloggerChannel {
  bool axis = true;
  uint8_t number = 0;
  uint8_t motor_bank = 0;
};

enum class DataloggerAction { kInfo, kStart, kState, kRead, kStop };

// A request checked and turned into what the op sends.
struct DataloggerPlan {
  DataloggerAction action = DataloggerAction::kInfo;
  // kStart:
  std::vector<DataloggerChannel> channels;
  uint32_t samples_per_channel = 0;
  uint32_t prescaler = 0;  // divider − 1
  std::optional<size_t> trigger_channel;  // an index into `channels`
  uint8_t trigger_type = 0;               // ENABLE_TRIGGER's motor byte
  int32_t trigger_level = 0;
  uint32_t pretrigger_samples = 0;  // per channel
};

// At most this many GET_SAMPLE requests wait in the module's queue at once, so that the other
// requests of the console (a page's live values) take their turns during a read-out.
inline constexpr size_t kDataloggerReadWindow = 16;
// The most channels a request may name (the protocol's slot limit; the module may take fewer).
inline constexpr size_t kDataloggerMaxChannels = 8;

// The plan of {"op":"datalogger",...}, or why the request is malformed (nothing is sent then).
std::variant<DataloggerPlan, std::string> parse_datalogger_request(const nlohmann::json& request);

// Runs the plan; `reply` is called exactly once (unless the session went away), with the reply's
// fields but "id".
void run_datalogger(const DataloggerPlan& plan, DataloggerLink link, std::function<void(nlohmann::json)> reply);

}  // namespace motwin::tools::web
