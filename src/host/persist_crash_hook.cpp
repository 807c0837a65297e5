#include "host/persist_crash_hook.h"

#include <array>
#include <csignal>
#include <cstdlib>
#include <optional>

namespace motwin::host {
namespace {

struct NamedStep {
  std::string_view name;
  PersistStep step;
};

// In the order a write runs them.
constexpr std::array<NamedStep, 5> kNamedSteps = {{
    {"open-temporary", PersistStep::kOpenTemporary},
    {"write-temporary", PersistStep::kWriteTemporary},
    {"sync-temporary", PersistStep::kSyncTemporary},
    {"rename", PersistStep::kRename},
    {"sync-directory", PersistStep::kSyncDirectory},
}};

// Far more image writes than any test makes; keeps the count clear of overflow.
constexpr uint64_t kMaxPersistNumber = 1'000'000'000;

std::string expected_form() {
  std::string steps;
  for (const NamedStep& named : kNamedSteps) {
    if (!steps.empty()) steps += ", ";
    steps += named.name;
  }
  return "expected STEP or STEP:N with STEP one of " + steps + " and N the image write to crash in (1 to " +
         std::to_string(kMaxPersistNumber) + ")";
}

std::optional<uint64_t> parse_persist_number(std::string_view digits) {
  if (digits.empty() || digits.size() > 10) return std::nullopt;
  uint64_t number = 0;
  for (const char c : digits) {
    if (c < '0' || c > '9') return std::nullopt;
    number = number * 10 + static_cast<uint64_t>(c - '0');
  }
  if (number < 1 || number > kMaxPersistNumber) return std::nullopt;
  return number;
}

}  // namespace

std::string_view persist_step_name(PersistStep step) {
  for (const NamedStep& named : kNamedSteps) {
    if (named.step == step) return named.name;
  }
  return "?";
}

Result<PersistCrashPoint> parse_persist_crash_point(std::string_view text) {
  const size_t colon = text.find(':');
  const std::string_view step_text = text.substr(0, colon);
  std::optional<PersistStep> step;
  for (const NamedStep& named : kNamedSteps) {
    if (named.name == step_text) step = named.step;
  }
  std::optional<uint64_t> persist_number = uint64_t{1};
  if (colon != std::string_view::npos) persist_number = parse_persist_number(text.substr(colon + 1));
  if (!step || !persist_number) {
    return Error{std::string(kCrashAtPersistStepVariable) + "=\"" + std::string(text) + "\": " + expected_form()};
  }
  return PersistCrashPoint{*step, *persist_number};
}

Result<void> install_persist_crash_hook_from_environment() {
  const char* value = std::getenv(kCrashAtPersistStepVariable);
  if (value == nullptr || value[0] == '\0') return {};
  const Result<PersistCrashPoint> point = parse_persist_crash_point(value);
  if (!point) return Error{point.error()};
  EepromFile::set_process_persist_observer([point = *point, writes_started = uint64_t{0}](PersistStep step) mutable {
    if (step == PersistStep::kOpenTemporary) ++writes_started;
    // SIGKILL, not abort() or exit(): no handler, no flush, no destructor runs, as in a real crash.
    if (step == point.step && writes_started == point.persist_number) std::raise(SIGKILL);
  });
  return {};
}

}  // namespace motwin::host
