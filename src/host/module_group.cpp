#include "host/module_group.h"

#include <charconv>
#include <cstdlib>
#include <numeric>
#include <set>

#include "core/tmcl/can_link.h"
#include "host/tmcl_can_node.h"

namespace motwin::host {
namespace {

std::optional<long> parse_number(std::string_view text) {
  long value = 0;
  const auto result = std::from_chars(text.data(), text.data() + text.size(), value);
  if (text.empty() || result.ec != std::errc{} || result.ptr != text.data() + text.size()) return std::nullopt;
  return value;
}

bool valid_name(std::string_view name) {
  if (name.empty() || name == "." || name == "..") return false;
  for (const char c : name) {
    const bool ok = (c >= 'a' && c <= 'z') || (c >= 'A' && c <= 'Z') || (c >= '0' && c <= '9') || c == '-' || c == '_' || c == '.';
    if (!ok) return false;
  }
  return true;
}

// One KEY=VALUE item of a node spec, applied to `spec`.
Result<void> apply_node_key(std::string_view item, NodeSpec& spec) {
  const size_t equals = item.find('=');
  const std::string_view key = item.substr(0, equals);
  const std::string_view value = equals == std::string_view::npos ? std::string_view{} : item.substr(equals + 1);
  if (equals == std::string_view::npos || value.empty()) {
    return Error{"expected KEY=VALUE, got \"" + std::string(item) + "\""};
  }
  const std::optional<long> number = parse_number(value);
  if (key == "name") {
    if (!valid_name(value)) {
      return Error{"name \"" + std::string(value) + "\": letters, digits, '-', '_' and '.' only"};
    }
    spec.name = std::string(value);
  } else if (key == "node-id") {
    if (!number || *number < 1 || *number > 127) {
      return Error{"node-id must be 1..127, got \"" + std::string(value) + "\""};
    }
    spec.node_id = static_cast<uint8_t>(*number);
  } else if (key == "serial") {
    if (!number || *number < 1 || *number > 0xFFFFFFFFL) {
      return Error{"serial must be 1..4294967295, got \"" + std::string(value) + "\""};
    }
    spec.serial_number = static_cast<uint32_t>(*number);
  } else if (key == "motor") {
    spec.motor = std::string(value);
  } else if (key == "firmware") {
    spec.firmware = std::string(value);
  } else if (key == "receive-id" || key == "send-id") {
    if (!number || *number < 0 || *number > 255) {
      return Error{std::string(key) + " must be 0..255 (GP 70/71), got \"" + std::string(value) + "\""};
    }
    (key == "receive-id" ? spec.receive_id : spec.send_id) = static_cast<int32_t>(*number);
  } else if (key == "boot-delay-ms" || key == "comm-boot-delay-ms") {
    if (!number || *number < 0 || *number > kMaxBootDelayMs) {
      return Error{std::string(key) + " must be 0.." + std::to_string(kMaxBootDelayMs) + " (ms), got \"" +
                   std::string(value) + "\""};
    }
    (key == "boot-delay-ms" ? spec.boot_delay_ms : spec.communication_boot_delay_ms) = static_cast<uint32_t>(*number);
  } else {
    return Error{"unknown key \"" + std::string(key) +
                 "\" (name, node-id, serial, motor, firmware, receive-id, send-id, boot-delay-ms, comm-boot-delay-ms)"};
  }
  return {};
}

// One member of a group: its module, which must have a CAN interface, with the CAN IDs of its spec.
Result<std::unique_ptr<VirtualModule>> make_member(const NodeSpec& spec,
                                                   const std::optional<std::filesystem::path>& state_dir,
                                                   const LogSink& log) {
  const Result<ModuleDescriptor> descriptor = node_module(spec);
  if (!descriptor) return Error{descriptor.error()};
  if ((spec.boot_delay_ms || spec.communication_boot_delay_ms) && descriptor->canopen == nullptr) {
    return Error{"boot-delay-ms/comm-boot-delay-ms are for CANopen modules"};
  }
  ModuleOptions options;
  if (state_dir) options.state_dir = *state_dir / spec.name;
  options.node_id = spec.node_id;
  options.serial_number = spec.serial_number;
  options.motor = spec.motor;
  options.firmware = spec.firmware;
  options.boot_delay_ms = spec.boot_delay_ms;
  options.communication_boot_delay_ms = spec.communication_boot_delay_ms;
  options.log = log;
  MakeModuleResult made = descriptor->make(options);
  if (!made) return made;
  VirtualModule& module = **made;
  if (module.can_node() == nullptr) return Error{spec.module + " has no CAN interface"};
  if (spec.receive_id >= 0 || spec.send_id >= 0) {
    if (!module.has_tmcl()) return Error{"receive-id/send-id are for TMCL modules (use node-id)"};
    // As a user would set them once with SGP: GP 70/71 are stored automatically.
    const auto set = [&module](uint8_t number, int32_t value) {
      return module.engine().execute(tmcl::Instruction{tmcl::command::kSgp, number, 0, value}, tmcl::Origin::kHost).status;
    };
    if ((spec.receive_id >= 0 && set(tmcl::can_parameter::kReceiveId, spec.receive_id) != tmcl::Status::kOk) ||
        (spec.send_id >= 0 && set(tmcl::can_parameter::kSendId, spec.send_id) != tmcl::Status::kOk)) {
      return Error{"cannot set the CAN IDs"};
    }
  }
  return made;
}

}  // namespace

Result<NodeSpec> parse_node_spec(std::string_view text, size_t position) {
  NodeSpec spec;
  const size_t colon = text.find(':');
  spec.module = std::string(text.substr(0, colon));
  if (find_module(spec.module) == nullptr) {
    return Error{"unknown module \"" + spec.module + "\" (available: " + module_names() + ")"};
  }
  spec.name = spec.module + "-" + std::to_string(position);
  std::string_view rest = colon == std::string_view::npos ? std::string_view{} : text.substr(colon + 1);
  while (!rest.empty()) {
    const size_t comma = rest.find(',');
    const std::string_view item = rest.substr(0, comma);
    rest = comma == std::string_view::npos ? std::string_view{} : rest.substr(comma + 1);
    if (const Result<void> applied = apply_node_key(item, spec); !applied) return Error{applied.error()};
  }
  if (const Result<ModuleDescriptor> descriptor = node_module(spec); !descriptor) return Error{descriptor.error()};
  return spec;
}

Result<ModuleDescriptor> node_module(const NodeSpec& spec) { return find_module_with_firmware(spec.module, spec.firmware); }

Result<std::unique_ptr<ModuleGroup>> ModuleGroup::make(const std::vector<NodeSpec>& specs,
                                                       const std::optional<std::filesystem::path>& state_dir,
                                                       LogSink log) {
  if (specs.empty()) return Error{"no nodes"};
  std::set<std::string> names;
  for (const NodeSpec& spec : specs) {
    if (!names.insert(spec.name).second) return Error{"two nodes named \"" + spec.name + "\" (give one a name=...)"};
  }
  std::unique_ptr<ModuleGroup> group(new ModuleGroup());
  uint32_t period = 0;
  for (const NodeSpec& spec : specs) {
    Result<std::unique_ptr<VirtualModule>> member = make_member(spec, state_dir, log);
    if (!member) return member.error_with_context(spec.name + ": ");
    period = std::gcd(period, (*member)->tick_period_us());
    group->members_.push_back(Member{spec.name, std::move(*member)});
  }
  group->tick_period_us_ = period == 0 ? 1 : period;
  return group;
}

tmcl::TmclEngine& ModuleGroup::engine() { std::abort(); }

void ModuleGroup::run_ticks(uint64_t count) {
  tick_count_ += count;
  const uint64_t now_us = tick_count_ * tick_period_us_;
  for (Member& member : members_) {
    VirtualModule& module = *member.module;
    const uint64_t target_ticks = now_us / module.tick_period_us();
    if (target_ticks > module.tick_count()) module.run_ticks(target_ticks - module.tick_count());
    // Nobody serves TMCL over TCP here: the CAN link collects its own command 138 replies.
    if (TmclCanNode* can = module.tmcl_can_node()) can->deliver_events();
    discarded_outputs_.clear();
    module.signals().take_output_changes(discarded_outputs_);
  }
}

std::string ModuleGroup::nvm_location() const {
  std::string text;
  for (const Member& member : members_) {
    if (!text.empty()) text += ", ";
    text += member.name + "=" + member.module->nvm_location();
  }
  return text;
}

}  // namespace motwin::host
