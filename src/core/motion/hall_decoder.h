// Digital hall sensors: three sensors 120° apart give six 60° sectors per electrical turn
// (TMCM-1636 AP 18, 90..93). The decoder turns the three levels into an electrical angle: the
// sector centre, or with interpolation the angle extrapolated from the last edge at the speed
// measured between the last two edges. Edges are exact angles, which the ABN encoder
// initialisation "use hall" relies on.
#pragma once

#include <cstdint>

namespace motwin::motion {

struct HallConfig {
  bool inverted_polarity = false;   // AP 90: all three levels inverted
  bool reversed_direction = false;  // AP 91: the sector sequence runs backwards
  bool interpolation = false;       // AP 92
  int32_t offset = 0;               // AP 93: added to the electrical angle, 65536 per turn
};

// Hall state (H1 bit 0, H2 bit 1, H3 bit 2) -> sector 0..5 of the standard sequence
// 5, 1, 3, 2, 6, 4 (sector s spans s*60°..(s+1)*60° of the hall angle); -1 for 0 and 7.
inline constexpr int8_t kHallSector[8] = {-1, 1, 3, 2, 5, 0, 4, -1};

class HallDecoder {
 public:
  // Longest sector (in ticks) that interpolation extrapolates from: slower means the centre.
  static constexpr uint32_t kMaxInterpolatedSectorTicks = 4000;

  // One control tick's levels.
  void update(uint8_t levels, const HallConfig& config);
  void reset() { *this = HallDecoder{}; }

  bool valid() const { return sector_ >= 0; }
  // Electrical angle after direction and offset (AP 18).
  uint16_t angle() const { return angle_; }
  // Hall sectors passed since reset, + in the electrical forward direction.
  int32_t steps() const { return steps_; }
  // An edge between two valid neighbouring sectors happened in the last update, at this exact
  // electrical angle (direction and offset applied).
  bool edge() const { return edge_; }
  uint16_t edge_angle() const { return edge_angle_; }

 private:
  uint16_t to_electrical(uint32_t hall_angle, const HallConfig& config) const;

  int8_t sector_ = -1;
  int8_t direction_ = 0;           // +1/-1 in the hall frame at the last edge, 0 unknown
  uint32_t ticks_since_edge_ = 0;
  uint32_t last_sector_ticks_ = 0;  // duration of the last complete sector, 0 unknown
  uint32_t last_edge_hall_angle_ = 0;
  int32_t steps_ = 0;
  uint16_t angle_ = 0;
  bool edge_ = false;
  uint16_t edge_angle_ = 0;
};

}  // namespace motwin::motion
