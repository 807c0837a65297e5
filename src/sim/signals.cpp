#include "sim/signals.h"

#include <charconv>
#include <cmath>

namespace motwin::sim {
namespace {

std::string format_bound(double value) {
  // Bounds in the tables are short decimals; print them without trailing zeros.
  char buffer[32];
  const auto result = std::to_chars(buffer, buffer + sizeof(buffer), value);
  return std::string(buffer, result.ptr);
}

}  // namespace

bool same_signal_name(std::string_view a, std::string_view b) {
  if (a.size() != b.size()) return false;
  for (size_t i = 0; i < a.size(); ++i) {
    auto lower = [](char c) { return (c >= 'A' && c <= 'Z') ? static_cast<char>(c - 'A' + 'a') : c; };
    if (lower(a[i]) != lower(b[i])) return false;
  }
  return true;
}

const SignalInfo* find_signal(std::span<const SignalInfo> signals, std::string_view name) {
  for (const SignalInfo& signal : signals) {
    if (same_signal_name(signal.name, name)) return &signal;
  }
  return nullptr;
}

Result<void> check_signal_value(const SignalInfo& signal, double value) {
  const bool whole = std::floor(value) == value;
  if (std::isfinite(value) && value >= signal.min && value <= signal.max && (whole || !signal.whole_numbers_only)) {
    return {};
  }
  std::string expected = std::string(signal.name) + " takes ";
  if (signal.whole_numbers_only && signal.min == 0 && signal.max == 1) {
    expected += "0 or 1";
  } else {
    expected += signal.whole_numbers_only ? "a whole number from " : "";
    expected += format_bound(signal.min) + " to " + format_bound(signal.max);
  }
  expected += " (" + std::string(signal.description) + ")";
  return Error{expected};
}

void OutputChangeLog::record(std::string_view signal, int32_t level) {
  if (changes_.size() >= kMaxPending) {
    changes_.erase(changes_.begin());
    ++dropped_;
  }
  changes_.push_back(OutputChange{signal, level, sim_time_us_});
}

void OutputChangeLog::take(std::vector<OutputChange>& out) {
  out.insert(out.end(), changes_.begin(), changes_.end());
  changes_.clear();
}

std::vector<SignalInfo> concat_signals(std::span<const SignalInfo> first, std::span<const SignalInfo> second) {
  std::vector<SignalInfo> all(first.begin(), first.end());
  all.insert(all.end(), second.begin(), second.end());
  return all;
}

std::string signal_names(std::span<const SignalInfo> signals) {
  std::string names;
  for (const SignalInfo& signal : signals) {
    if (!names.empty()) names += ", ";
    names += signal.name;
  }
  return names;
}

std::optional<double> parse_number(std::string_view text) {
  if (text.empty()) return std::nullopt;
  // from_chars rejects a leading '+'; accept it since people write "+1.5".
  if (text.front() == '+') text.remove_prefix(1);
  double value = 0;
  const auto result = std::from_chars(text.data(), text.data() + text.size(), value);
  if (result.ec != std::errc{} || result.ptr != text.data() + text.size() || !std::isfinite(value)) {
    return std::nullopt;
  }
  return value;
}

Result<SignalAssignment> parse_signal_assignment(std::span<const SignalInfo> signals, std::string_view text) {
  const size_t equals = text.find('=');
  if (equals == std::string_view::npos) return Error{"expected SIGNAL=VALUE, got \"" + std::string(text) + "\""};
  const std::string_view name = text.substr(0, equals);
  const std::string_view value_text = text.substr(equals + 1);
  const SignalInfo* signal = find_signal(signals, name);
  if (signal == nullptr) {
    return Error{"unknown signal \"" + std::string(name) + "\" (known: " + signal_names(signals) + ")"};
  }
  const std::optional<double> value = parse_number(value_text);
  if (!value) {
    return Error{"value of " + std::string(signal->name) + " is not a number: \"" + std::string(value_text) + "\""};
  }
  if (const Result<void> acceptable = check_signal_value(*signal, *value); !acceptable) {
    return Error{acceptable.error() + ", got " + std::string(value_text)};
  }
  return SignalAssignment{signal, *value};
}

}  // namespace motwin::sim
