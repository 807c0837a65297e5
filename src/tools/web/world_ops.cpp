#include "tools/web/world_ops.h"

#include <cmath>
#include <optional>
#include <string>
#include <vector>

namespace motwin::tools::web {

using Json = nlohmann::json;

namespace {

// Every axis has a load torque: "LOAD_TORQUE" (one axis) or "AXIS<n>_LOAD_TORQUE" names it, and
// its other signals share the prefix.
constexpr std::string_view kAxisMarker = "LOAD_TORQUE";

Json number_or_null(std::optional<double> value) {
  if (!value || !std::isfinite(*value)) return nullptr;
  return *value;
}

std::vector<std::string> axis_prefixes(std::span<const sim::SignalInfo> signals) {
  std::vector<std::string> prefixes;
  for (const sim::SignalInfo& signal : signals) {
    const std::string_view name = signal.name;
    if (name.size() < kAxisMarker.size()) continue;
    const size_t prefix_length = name.size() - kAxisMarker.size();
    if (sim::same_signal_name(name.substr(prefix_length), kAxisMarker)) {
      prefixes.emplace_back(name.substr(0, prefix_length));
    }
  }
  return prefixes;
}

// What the simulation has of each axis's shaft (null where it has none: the ideal TMCM-1636 motor
// is its ramp, without a rotor).
Json axes_json(const sim::SignalBoard& board) {
  Json axes = Json::array();
  for (const std::string& prefix : axis_prefixes(board.input_signals())) {
    axes.push_back({{"prefix", prefix},
                    {"position_rev", number_or_null(board.read_signal(prefix + "POSITION_REV"))},
                    {"speed_rpm", number_or_null(board.read_signal(prefix + "SPEED_RPM"))},
                    {"torque_nm", number_or_null(board.read_signal(prefix + "TORQUE_NM"))}});
  }
  return axes;
}

Result<Json> read_world(const Json& request, size_t module, const ConsoleWorld& world, uint64_t sim_time_us) {
  const auto values_only = request.find("values_only");
  if (values_only != request.end() && !values_only->is_boolean()) {
    return Error{"\"values_only\": expected true or false"};
  }
  const sim::SignalBoard& board = *world.board;
  Json reply = {{"ok", true}, {"module", module}, {"sim_time_us", sim_time_us}, {"settable", bool(world.set_input)}};
  if (values_only != request.end() && values_only->get<bool>()) {
    Json values = Json::object();
    for (const sim::SignalInfo& signal : board.input_signals()) {
      values[std::string(signal.name)] = number_or_null(board.read_signal(signal.name));
    }
    reply["values"] = std::move(values);
  } else {
    Json signals = Json::array();
    for (const sim::SignalInfo& signal : board.input_signals()) {
      signals.push_back({{"name", signal.name},
                         {"min", signal.min},
                         {"max", signal.max},
                         {"whole", signal.whole_numbers_only},
                         {"unit", signal.unit},
                         {"description", signal.description},
                         {"value", number_or_null(board.read_signal(signal.name))}});
    }
    reply["signals"] = std::move(signals);
  }
  reply["axes"] = axes_json(board);
  return reply;
}

Result<Json> set_world(const Json& request, size_t module, const ConsoleWorld& world, uint64_t sim_time_us) {
  if (!world.set_input) {
    return Error{"module " + std::to_string(module) +
                 ": its signals are not set from here (a node of a --node bus takes no --set or --scenario)"};
  }
  const auto signal = request.find("signal");
  if (signal == request.end() || !signal->is_string()) {
    return Error{"\"signal\": expected a signal name such as \"REF_L\""};
  }
  const auto value = request.find("value");
  if (value == request.end() || !value->is_number()) return Error{"\"value\": expected a number"};
  const std::string name = signal->get<std::string>();
  const double number = value->get<double>();
  if (const Result<void> set = world.set_input(name, number); !set) return Error{set.error()};
  const sim::SignalInfo* info = sim::find_signal(world.board->input_signals(), name);
  return Json{{"ok", true},
              {"module", module},
              {"signal", info != nullptr ? std::string(info->name) : name},
              {"value", number},
              {"sim_time_us", sim_time_us}};
}

}  // namespace

bool is_world_op(std::string_view op) { return op == "world" || op == "world_set"; }

Result<Json> world_op(std::string_view op, const Json& request, size_t module, const ConsoleWorld& world,
                      uint64_t sim_time_us) {
  if (world.board == nullptr) return Error{"module " + std::to_string(module) + " has no simulated world"};
  if (op == "world") return read_world(request, module, world, sim_time_us);
  return set_world(request, module, world, sim_time_us);
}

}  // namespace motwin::tools::web
