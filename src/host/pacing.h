// How simulated time follows the wall clock (`motwin serve --speed`).
//
//  realtime  sim time follows the wall clock (factor 1)
//  FACTOR    sim time runs FACTOR times as fast as the wall clock (2, 0.5, ...)
//  fast      as fast as the CPU allows
//
// Paced modes run the due ticks in batches of about 1 ms of wall time and sleep in between, so
// an idle server does not spin. If the simulation falls behind (a slow machine, a debugger),
// at most kMaxBacklogWallUs of wall time is caught up; the rest is dropped, so sim time slips
// instead of racing to catch up. Ticks themselves are never skipped: the same inputs at the
// same sim times give the same trajectory in every mode.
#pragma once

#include <cstdint>
#include <string>
#include <string_view>

#include "types/result.h"

namespace motwin::host {

struct Pacing {
  enum class Mode : uint8_t { kPaced, kFast };
  Mode mode = Mode::kPaced;
  double speed_factor = 1.0;  // sim seconds per wall second (paced mode)

  static Pacing realtime() { return Pacing{}; }
  static Pacing fast() { return Pacing{Mode::kFast, 1.0}; }
  static Pacing factor(double speed_factor) { return Pacing{Mode::kPaced, speed_factor}; }

  // "realtime", "fast" or a positive factor ("2", "0.5").
  static Result<Pacing> parse(std::string_view text);
  std::string describe() const;  // "realtime", "fast", "x2"
};

class Pacer {
 public:
  static constexpr uint64_t kMaxBacklogWallUs = 100'000;
  static constexpr uint64_t kBatchWallUs = 1'000;  // paced: sleep between batches this long
  static constexpr uint64_t kChunkSimUs = 1'000;   // sockets are served between chunks of this

  Pacer(Pacing pacing, uint32_t tick_us);

  // Sim time `sim_us` corresponds to wall time `wall_us` from now on.
  void start(uint64_t wall_us, uint64_t sim_us);

  // Ticks the simulation should run now to keep up. Paced: 0 until a whole batch is due.
  // Fast: one chunk. May drop backlog (see dropped_backlog_sim_us()).
  uint64_t ticks_due(uint64_t wall_us, uint64_t sim_us);
  // Wall time to sleep until the next batch is due (0 in fast mode or when already due).
  uint64_t wait_us(uint64_t wall_us, uint64_t sim_us) const;

  // Sim time the wall clock has reached (paced mode).
  uint64_t target_sim_us(uint64_t wall_us) const;
  uint64_t batch_ticks() const { return batch_ticks_; }
  uint64_t chunk_ticks() const { return chunk_ticks_; }
  uint64_t dropped_backlog_sim_us() const { return dropped_backlog_sim_us_; }
  const Pacing& pacing() const { return pacing_; }

 private:
  Pacing pacing_;
  uint32_t tick_us_;
  uint64_t batch_ticks_;
  uint64_t chunk_ticks_;
  uint64_t max_backlog_sim_us_;
  uint64_t anchor_wall_us_ = 0;
  uint64_t anchor_sim_us_ = 0;
  uint64_t dropped_backlog_sim_us_ = 0;
};

}  // namespace motwin::host
