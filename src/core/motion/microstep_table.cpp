#include "core/motion/microstep_table.h"

namespace motwin::motion {

constexpr std::array<uint16_t, kMicrostepTableQuarter + 1> kQuarterSine = detail::make_quarter_sine();

}  // namespace motwin::motion
