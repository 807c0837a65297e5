#include "host/pacing.h"

#include <algorithm>
#include <cmath>
#include <cstdio>

#include "sim/signals.h"

namespace motwin::host {

Result<Pacing> Pacing::parse(std::string_view text) {
  if (text == "realtime") return realtime();
  if (text == "fast") return fast();
  const std::optional<double> factor = sim::parse_number(text);
  // Below 1e-3 a single 50 µs tick would take more than 50 ms of wall time; above 1e4 a paced
  // run is "fast" in all but name.
  if (!factor || *factor < 1e-3 || *factor > 1e4) {
    return Error{"--speed takes realtime, fast or a factor from 0.001 to 10000, got \"" + std::string(text) + "\""};
  }
  return Pacing::factor(*factor);
}

std::string Pacing::describe() const {
  if (mode == Mode::kFast) return "fast";
  if (speed_factor == 1.0) return "realtime";
  char buffer[32];
  std::snprintf(buffer, sizeof(buffer), "x%g", speed_factor);
  return buffer;
}

Pacer::Pacer(Pacing pacing, uint32_t tick_us)
    : pacing_(pacing),
      tick_us_(tick_us == 0 ? 1 : tick_us),
      batch_ticks_(std::max<uint64_t>(1, static_cast<uint64_t>(static_cast<double>(kBatchWallUs) * pacing.speed_factor) / tick_us_)),
      chunk_ticks_(std::max<uint64_t>(1, kChunkSimUs / tick_us_)),
      max_backlog_sim_us_(std::max<uint64_t>(static_cast<uint64_t>(static_cast<double>(kMaxBacklogWallUs) * pacing.speed_factor),
                                             batch_ticks_ * tick_us_)) {}

void Pacer::start(uint64_t wall_us, uint64_t sim_us) {
  anchor_wall_us_ = wall_us;
  anchor_sim_us_ = sim_us;
}

uint64_t Pacer::target_sim_us(uint64_t wall_us) const {
  if (wall_us <= anchor_wall_us_) return anchor_sim_us_;
  return anchor_sim_us_ + static_cast<uint64_t>(static_cast<double>(wall_us - anchor_wall_us_) * pacing_.speed_factor);
}

uint64_t Pacer::ticks_due(uint64_t wall_us, uint64_t sim_us) {
  if (pacing_.mode == Pacing::Mode::kFast) return chunk_ticks_;
  uint64_t target_us = target_sim_us(wall_us);
  if (target_us <= sim_us) return 0;
  if (target_us - sim_us > max_backlog_sim_us_) {
    // Too far behind: keep only the allowed backlog and let the rest of wall time go.
    dropped_backlog_sim_us_ += target_us - sim_us - max_backlog_sim_us_;
    target_us = sim_us + max_backlog_sim_us_;
    start(wall_us, target_us);
  }
  const uint64_t due = (target_us - sim_us) / tick_us_;
  return due >= batch_ticks_ ? due : 0;
}

uint64_t Pacer::wait_us(uint64_t wall_us, uint64_t sim_us) const {
  if (pacing_.mode == Pacing::Mode::kFast) return 0;
  const uint64_t needed_sim_us = sim_us + batch_ticks_ * tick_us_;
  if (needed_sim_us <= anchor_sim_us_) return 0;
  // +1: the float product in target_sim_us() must have reached needed_sim_us when we wake.
  const double wall_needed = static_cast<double>(anchor_wall_us_) +
                             std::ceil(static_cast<double>(needed_sim_us - anchor_sim_us_) / pacing_.speed_factor) + 1.0;
  const auto due_wall_us = static_cast<uint64_t>(wall_needed);
  return due_wall_us > wall_us ? due_wall_us - wall_us : 0;
}

}  // namespace motwin::host
