#include "core/motion/hall_decoder.h"

namespace motwin::motion {
namespace {

constexpr uint32_t kTurn = 65536;
constexpr uint32_t sector_start(int s) { return static_cast<uint32_t>(s) * kTurn / 6; }
constexpr uint32_t sector_centre(int s) { return (2 * static_cast<uint32_t>(s) + 1) * kTurn / 12; }

}  // namespace

uint16_t HallDecoder::to_electrical(uint32_t hall_angle, const HallConfig& config) const {
  const uint32_t directed = config.reversed_direction ? kTurn - (hall_angle % kTurn) : hall_angle;
  return static_cast<uint16_t>(directed + static_cast<uint32_t>(config.offset));
}

void HallDecoder::update(uint8_t levels, const HallConfig& config) {
  const uint8_t state = static_cast<uint8_t>((config.inverted_polarity ? ~levels : levels) & 7);
  const int8_t sector = kHallSector[state];
  edge_ = false;
  if (ticks_since_edge_ < 0xFFFFFFFFu) ++ticks_since_edge_;
  if (sector < 0) {
    // 000 or 111: a broken wire or a missing supply. Keep the last angle, lose the timing.
    sector_ = -1;
    direction_ = 0;
    last_sector_ticks_ = 0;
    return;
  }
  if (sector_ >= 0 && sector != sector_) {
    const int step = (sector - sector_ + 6) % 6;
    if (step == 1 || step == 5) {
      const int8_t direction = step == 1 ? 1 : -1;
      // A full sector between two edges in the same direction is a speed measurement.
      last_sector_ticks_ = direction == direction_ ? ticks_since_edge_ : 0;
      direction_ = direction;
      ticks_since_edge_ = 0;
      last_edge_hall_angle_ = direction > 0 ? sector_start(sector) : sector_start((sector + 1) % 6);
      steps_ += config.reversed_direction ? -direction : direction;
      edge_ = true;
      edge_angle_ = to_electrical(last_edge_hall_angle_, config);
    } else {
      // Skipped a sector: too fast for the tick, or noise. Resynchronise.
      direction_ = 0;
      last_sector_ticks_ = 0;
    }
  }
  sector_ = sector;
  uint32_t hall_angle = sector_centre(sector);
  if (config.interpolation && direction_ != 0 && last_sector_ticks_ > 0 &&
      last_sector_ticks_ <= kMaxInterpolatedSectorTicks && ticks_since_edge_ <= 2 * last_sector_ticks_) {
    uint32_t advance = static_cast<uint32_t>(static_cast<float>(kTurn / 6) * static_cast<float>(ticks_since_edge_) /
                                             static_cast<float>(last_sector_ticks_));
    if (advance > kTurn / 6 - 1) advance = kTurn / 6 - 1;
    hall_angle = direction_ > 0 ? last_edge_hall_angle_ + advance : last_edge_hall_angle_ + kTurn - advance;
  }
  angle_ = to_electrical(hall_angle, config);
}

}  // namespace motwin::motion
