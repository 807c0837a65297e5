#include "host/host_runtime.h"

#include <algorithm>

#include "host/tmcl_can_node.h"

namespace motwin::host {

HostRuntime::HostRuntime(VirtualModule& module, Pacing pacing)
    : module_(module), pacer_(pacing, module.tick_period_us()) {
  if (module.has_tmcl()) service_.emplace(module.engine(), loop_);
  if (TmclCanNode* can = module.tmcl_can_node(); can != nullptr && service_) {
    can->use_event_channel(service_->open_event_channel(*can));
  }
}

HostRuntime::~HostRuntime() {
  if (TmclCanNode* can = module_.tmcl_can_node(); can != nullptr && service_) {
    service_->close_event_channel(can->channel());
    can->use_event_channel(TmclCanNode::kStandaloneChannel);
  }
}

void HostRuntime::set_scenario(std::vector<sim::ScenarioEvent> events) {
  scenario_.emplace(std::move(events), module_.signals());
}

Result<void> HostRuntime::set_input_now(std::string_view signal, double value) {
  Result<sim::ScenarioEvent> event =
      sim::make_scenario_event(module_.signals().input_signals(), signal, value, sim_time_us());
  if (!event) return Error{event.error()};
  if (!scenario_) scenario_.emplace(std::vector<sim::ScenarioEvent>{}, module_.signals());
  scenario_->insert(std::move(*event));
  scenario_->apply_due(sim_time_us());
  return {};
}

void HostRuntime::start() {
  if (scenario_) scenario_->apply_due(sim_time_us());
  pacer_.start(monotonic_now_us(), sim_time_us());
}

void HostRuntime::advance_ticks(uint64_t ticks) {
  const uint64_t tick_us = module_.tick_period_us();
  while (ticks > 0) {
    uint64_t batch = ticks;
    if (scenario_) {
      scenario_->apply_due(sim_time_us());
      if (const std::optional<uint64_t> next_us = scenario_->next_event_time_us()) {
        // Stop at the first tick that starts at or after the event.
        const uint64_t ticks_to_event = (*next_us - sim_time_us() + tick_us - 1) / tick_us;
        batch = std::min(batch, std::max<uint64_t>(ticks_to_event, 1));
      }
    }
    module_.run_ticks(batch);
    ticks -= batch;
  }
  // Events due exactly now apply before any host request at this sim time.
  if (scenario_) scenario_->apply_due(sim_time_us());
  if (service_) service_->deliver_events();
  report_output_changes();
}

void HostRuntime::step(uint64_t max_wait_us) {
  const uint64_t due = pacer_.ticks_due(monotonic_now_us(), sim_time_us());
  const uint64_t chunk = std::min(due, pacer_.chunk_ticks());
  if (chunk > 0) advance_ticks(chunk);
  // wait_us() is 0 while a whole batch is already due (catching up, or fast mode).
  const uint64_t now_us = monotonic_now_us();
  // Requests left after a round of serving (a flood) are served after the next poll, which must
  // not sleep.
  const bool requests_waiting = service_ && service_->total_queued_requests() > 0 && !service_->reply_held();
  const uint64_t wait_us =
      now_us < busy_poll_until_us_ || requests_waiting ? 0 : pacer_.wait_us(now_us, sim_time_us());
  const uint64_t input_events_before = loop_.input_event_count();
  loop_.poll_once(std::min(wait_us, max_wait_us));
  if (service_) service_->serve_queued();
  report_output_changes();
  // Input on any descriptor (a TMCL request, a CAN frame from a socketcand or SLCAN client, a
  // connection) means a host is talking; a served TMCL request of a host (also one queued
  // earlier) too, but not the web console's reads of subscribed values (ChannelTraffic).
  bool host_talked = loop_.input_event_count() != input_events_before;
  if (service_ && service_->served_host_request_count() != served_requests_seen_) {
    served_requests_seen_ = service_->served_host_request_count();
    host_talked = true;
  }
  if (host_talked) busy_poll_until_us_ = monotonic_now_us() + kBusyPollAfterRequestUs;
}

void HostRuntime::run() {
  while (!loop_.stop_requested()) step();
}

void HostRuntime::report_output_changes() {
  output_scratch_.clear();
  module_.signals().take_output_changes(output_scratch_);
  if (!output_listener_) return;
  for (const sim::OutputChange& change : output_scratch_) output_listener_(change);
}

}  // namespace motwin::host
