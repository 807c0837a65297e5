// Named input and output signals of a simulated board: what `motwin serve --set NAME=VALUE`
// and scenario files address. Each simulated board lists its signals as data (SignalInfo), so
// that parsing, range checks and error messages are the same for every module.
#pragma once

#include <cstddef>
#include <cstdint>
#include <optional>
#include <span>
#include <string>
#include <string_view>
#include <vector>

#include "types/result.h"

namespace motwin::sim {

struct SignalInfo {
  std::string_view name;         // upper case, e.g. "GPI0", "VSUPPLY"
  double min;                    // accepted range, inclusive
  double max;
  bool whole_numbers_only;       // levels and raw ADC counts
  std::string_view description;  // for help text, e.g. "supply voltage in volts"
  std::string_view unit = {};    // of an analog quantity ("V", "N m", "rev"); empty for levels and counts
};

// An output that changed, stamped with the simulated time of the change.
struct OutputChange {
  std::string_view signal;  // e.g. "GPO0"
  int32_t level;
  uint64_t sim_time_us;
};

// The output changes a board recorded since the host last took them. Older changes are dropped
// (and counted) beyond kMaxPending, so that a program toggling an output every tick cannot grow
// memory unbounded.
class OutputChangeLog {
 public:
  static constexpr size_t kMaxPending = 4096;

  OutputChangeLog() { changes_.reserve(64); }

  // Simulated time stamped on the changes recorded from now on; the virtual module sets it per tick.
  void set_sim_time_us(uint64_t sim_time_us) { sim_time_us_ = sim_time_us; }
  void record(std::string_view signal, int32_t level);
  // Appends the recorded changes, oldest first, and forgets them.
  void take(std::vector<OutputChange>& out);
  size_t dropped() const { return dropped_; }

 private:
  uint64_t sim_time_us_ = 0;
  std::vector<OutputChange> changes_;
  size_t dropped_ = 0;
};

class SignalBoard {
 public:
  virtual ~SignalBoard() = default;

  virtual std::span<const SignalInfo> input_signals() const = 0;
  // `name` must be one of input_signals() and `value` must pass check_signal_value().
  virtual void set_input(std::string_view name, double value) = 0;
  // Inputs and outputs by name (outputs as 0/1); nullopt for an unknown name.
  virtual std::optional<double> read_signal(std::string_view name) const = 0;
  // Appends the output changes recorded since the last call, oldest first.
  virtual void take_output_changes(std::vector<OutputChange>& out) = 0;
};

// A SignalBoard that records its output changes in an OutputChangeLog.
class LoggingSignalBoard : public SignalBoard {
 public:
  static constexpr size_t kMaxPendingOutputChanges = OutputChangeLog::kMaxPending;

  // Simulated time used to stamp output changes; the virtual module sets it per tick.
  void set_sim_time_us(uint64_t sim_time_us) { output_changes_.set_sim_time_us(sim_time_us); }
  size_t dropped_output_changes() const { return output_changes_.dropped(); }
  void take_output_changes(std::vector<OutputChange>& out) override { output_changes_.take(out); }

 protected:
  OutputChangeLog output_changes_;
};

// Signal names are matched without regard to case ("gpi0" is GPI0).
bool same_signal_name(std::string_view a, std::string_view b);

// Case-insensitive lookup; returns nullptr for an unknown name.
const SignalInfo* find_signal(std::span<const SignalInfo> signals, std::string_view name);

// Success when `value` is acceptable for `signal`, otherwise what was expected, for example
// "GPI0 takes 0 or 1" or "VSUPPLY takes 0 to 100 (supply voltage in volts)".
Result<void> check_signal_value(const SignalInfo& signal, double value);

// `first` followed by `second`: a board's table made of its I/O's signals and the motor side's.
std::vector<SignalInfo> concat_signals(std::span<const SignalInfo> first, std::span<const SignalInfo> second);

// "GPI0, GPI1, ..., REF_H": for "unknown signal" messages.
std::string signal_names(std::span<const SignalInfo> signals);

// A finite decimal number ("1", "-0.5", "26.5", "1e3"); nullopt for anything else.
std::optional<double> parse_number(std::string_view text);

struct SignalAssignment {
  const SignalInfo* signal = nullptr;
  double value = 0;
};

// Parses "NAME=VALUE" (as given to --set): the assignment, or what is wrong with it.
Result<SignalAssignment> parse_signal_assignment(std::span<const SignalInfo> signals, std::string_view text);

}  // namespace motwin::sim
