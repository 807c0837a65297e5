// The host runtime of one virtual module: a poll() loop that interleaves simulation tick
// batches (paced by Pacer) with the transports, the TMCL request service, scenario events and
// output-change reporting. Single-threaded; transports are attached by the caller (see
// src/cli/serve_command.cpp) and must be destroyed before the runtime.
#pragma once

#include <cstdint>
#include <functional>
#include <optional>
#include <string_view>
#include <vector>

#include "host/event_loop.h"
#include "host/pacing.h"
#include "host/tmcl_host_service.h"
#include "host/virtual_module.h"
#include "sim/scenario.h"

namespace motwin::host {

class HostRuntime {
 public:
  // After input from a host (a TMCL request over TCP or a pty, a CAN frame from a socketcand or
  // SLCAN client, ...) the loop polls without sleeping this long: a host in a request/reply
  // exchange sends its next frame within microseconds, and waking a sleeping process on another
  // CPU can cost more than the whole exchange (docs/host-runtime.md, docs/benchmarks.md). An idle
  // server still sleeps.
  static constexpr uint64_t kBusyPollAfterRequestUs = 200;

  using OutputListener = std::function<void(const sim::OutputChange& change)>;

  HostRuntime(VirtualModule& module, Pacing pacing);
  HostRuntime(const HostRuntime&) = delete;
  HostRuntime& operator=(const HostRuntime&) = delete;
  ~HostRuntime();

  VirtualModule& module() { return module_; }
  EventLoop& loop() { return loop_; }
  // Only for a module that has_tmcl(); the TMCM-3216 (CANopen only) has no TMCL service.
  TmclHostService& service() { return *service_; }
  bool has_tmcl_service() const { return service_.has_value(); }
  const Pacer& pacer() const { return pacer_; }

  // Events are applied to module().signals() at their sim times.
  void set_scenario(std::vector<sim::ScenarioEvent> events);
  const sim::ScenarioPlayer* scenario() const { return scenario_ ? &*scenario_ : nullptr; }
  // Sets an input signal now, as a scenario event at the present simulated time: checked by
  // sim::make_scenario_event() (an error names an unknown signal or the accepted range, and
  // changes nothing), then applied by the scenario player before the next tick. The web
  // console's World view sets signals through it.
  Result<void> set_input_now(std::string_view signal, double value);
  // Called for every output change, in order, after the tick batch or request that caused it.
  void set_output_listener(OutputListener listener) { output_listener_ = std::move(listener); }

  // Anchors pacing at the current wall time and applies the scenario events due at start.
  void start();
  // One loop iteration: the due ticks (at most one chunk of Pacer::kChunkSimUs), then waiting
  // for I/O until the next batch is due (but at most `max_wait_us`), then the callbacks, then
  // queued TMCL requests.
  void step(uint64_t max_wait_us = EventLoop::kWaitForever);
  // step() until loop().request_stop().
  void run();

  // Runs exactly `ticks` ticks now, whatever the pacing; scenario events land on their exact
  // tick however the ticks are batched (determinism). Then sends due command 138 replies and
  // reports output changes.
  void advance_ticks(uint64_t ticks);
  uint64_t sim_time_us() const { return module_.sim_time_us(); }
  // Wall time (monotonic_now_us()) until which step() polls without sleeping; 0 before any input.
  uint64_t busy_poll_until_us() const { return busy_poll_until_us_; }

 private:
  void report_output_changes();

  VirtualModule& module_;
  Pacer pacer_;
  EventLoop loop_;
  std::optional<TmclHostService> service_;
  std::optional<sim::ScenarioPlayer> scenario_;
  OutputListener output_listener_;
  std::vector<sim::OutputChange> output_scratch_;
  uint64_t served_requests_seen_ = 0;
  uint64_t busy_poll_until_us_ = 0;
};

}  // namespace motwin::host
