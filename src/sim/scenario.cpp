#include "sim/scenario.h"

#include <algorithm>
#include <cerrno>
#include <cmath>
#include <cstring>

#include <fcntl.h>
#include <unistd.h>

namespace motwin::sim {
namespace {

bool is_blank(char c) { return c == ' ' || c == '\t' || c == '\r'; }

// Splits a line (comment already removed) at runs of blanks.
std::vector<std::string_view> split_fields(std::string_view line) {
  std::vector<std::string_view> fields;
  size_t i = 0;
  while (i < line.size()) {
    while (i < line.size() && is_blank(line[i])) ++i;
    const size_t start = i;
    while (i < line.size() && !is_blank(line[i])) ++i;
    if (i > start) fields.push_back(line.substr(start, i - start));
  }
  return fields;
}

}  // namespace

Result<ScenarioEvent> make_scenario_event(std::span<const SignalInfo> signals, std::string_view signal_name, double value,
                                          uint64_t time_us, size_t line) {
  const SignalInfo* signal = find_signal(signals, signal_name);
  if (signal == nullptr) {
    return Error{"unknown signal \"" + std::string(signal_name) + "\" (expected one of " + signal_names(signals) + ")"};
  }
  if (const Result<void> acceptable = check_signal_value(*signal, value); !acceptable) return Error{acceptable.error()};
  return ScenarioEvent{time_us, std::string(signal->name), value, line};
}

Result<std::vector<ScenarioEvent>> parse_scenario(std::string_view text, std::string_view source_name,
                                                  std::span<const SignalInfo> signals) {
  std::vector<ScenarioEvent> events;
  size_t line_number = 0;
  size_t position = 0;
  auto fail = [&](const std::string& what) {
    return Error{std::string(source_name) + ":" + std::to_string(line_number) + ": " + what};
  };
  while (position < text.size()) {
    ++line_number;
    size_t end = text.find('\n', position);
    if (end == std::string_view::npos) end = text.size();
    std::string_view line = text.substr(position, end - position);
    position = end + 1;
    if (const size_t hash = line.find('#'); hash != std::string_view::npos) line = line.substr(0, hash);
    const std::vector<std::string_view> fields = split_fields(line);
    if (fields.empty()) continue;
    if (fields.size() != 3) {
      return fail("expected \"<time_s> <SIGNAL> <value>\", got " + std::to_string(fields.size()) +
                  (fields.size() == 1 ? " field" : " fields"));
    }
    const std::optional<double> time_s = parse_number(fields[0]);
    if (!time_s) return fail("expected a time in seconds, got \"" + std::string(fields[0]) + "\"");
    if (*time_s < 0) return fail("expected a time >= 0 s, got " + std::string(fields[0]));
    if (*time_s > kMaxScenarioTimeS) return fail("time " + std::string(fields[0]) + " s is too large");
    const SignalInfo* signal = find_signal(signals, fields[1]);
    const std::optional<double> value = parse_number(fields[2]);
    // An unknown signal, or a value out of its range, make_scenario_event() names.
    if (signal != nullptr && !value) {
      return fail("expected a number as the value of " + std::string(signal->name) + ", got \"" +
                  std::string(fields[2]) + "\"");
    }
    Result<ScenarioEvent> event = make_scenario_event(
        signals, fields[1], value.value_or(0), static_cast<uint64_t>(std::llround(*time_s * 1e6)), line_number);
    if (!event) return fail(event.error() + (signal != nullptr ? ", got " + std::string(fields[2]) : ""));
    events.push_back(std::move(*event));
  }
  std::stable_sort(events.begin(), events.end(),
                   [](const ScenarioEvent& a, const ScenarioEvent& b) { return a.time_us < b.time_us; });
  return events;
}

Result<std::vector<ScenarioEvent>> load_scenario_file(const std::string& path, std::span<const SignalInfo> signals) {
  const int fd = ::open(path.c_str(), O_RDONLY | O_CLOEXEC);
  if (fd < 0) return Error{"cannot read scenario file " + path + ": " + std::strerror(errno)};
  std::string contents;
  char buffer[4096];
  for (;;) {
    const ssize_t n = ::read(fd, buffer, sizeof(buffer));
    if (n < 0 && errno == EINTR) continue;
    if (n < 0) {
      Error error{"cannot read scenario file " + path + ": " + std::strerror(errno)};
      ::close(fd);
      return error;
    }
    if (n == 0) break;
    contents.append(buffer, static_cast<size_t>(n));
  }
  ::close(fd);
  return parse_scenario(contents, path, signals);
}

ScenarioPlayer::ScenarioPlayer(std::vector<ScenarioEvent> events, SignalBoard& board)
    : events_(std::move(events)), board_(board) {
  // Callers normally pass parse_scenario() output; keep the invariant even if they do not.
  std::stable_sort(events_.begin(), events_.end(),
                   [](const ScenarioEvent& a, const ScenarioEvent& b) { return a.time_us < b.time_us; });
}

void ScenarioPlayer::insert(ScenarioEvent event) {
  // Events set live (the web console) would otherwise pile up: the applied ones go.
  events_.erase(events_.begin(), events_.begin() + static_cast<std::ptrdiff_t>(next_));
  applied_before_ += next_;
  next_ = 0;
  const auto after = std::upper_bound(events_.begin() + static_cast<std::ptrdiff_t>(next_), events_.end(), event,
                                      [](const ScenarioEvent& a, const ScenarioEvent& b) { return a.time_us < b.time_us; });
  events_.insert(after, std::move(event));
}

size_t ScenarioPlayer::apply_due(uint64_t sim_time_us) {
  size_t applied = 0;
  while (next_ < events_.size() && events_[next_].time_us <= sim_time_us) {
    board_.set_input(events_[next_].signal, events_[next_].value);
    ++next_;
    ++applied;
  }
  return applied;
}

std::optional<uint64_t> ScenarioPlayer::next_event_time_us() const {
  if (next_ == events_.size()) return std::nullopt;
  return events_[next_].time_us;
}

}  // namespace motwin::sim
