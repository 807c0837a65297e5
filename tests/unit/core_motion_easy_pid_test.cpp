// motion::EasyPid (the TMC457 easyPID of the TMCM-142, docs/tmcm-142.md) with hand-computed
// numbers: each part's scaling and sign, and each clip: pid_e to +-2^23, the error sum to
// +-Iclip * 2^16, the D difference to +-127 and its sampling divider, the result to +-dv_clip.
#include <cstdint>
#include <vector>

#include <gtest/gtest.h>

#include "core/motion/easy_pid.h"

namespace motwin::testing {
namespace {

using motion::EasyPid;
using motion::EasyPidConfig;
using motion::EasyPidState;

constexpr int32_t kNoClip = INT32_MAX;

EasyPidConfig config(int32_t p, int32_t i, int32_t d, int32_t i_clip, int32_t velocity_clip) {
  return EasyPidConfig{p, i, d, i_clip, 0, velocity_clip};
}

// Corrections for a sequence of errors, 25 integrator samples per tick, D every `d_ticks`.
std::vector<int32_t> run(const EasyPidConfig& c, const std::vector<int64_t>& errors, uint32_t d_ticks = 1) {
  EasyPidState state;
  std::vector<int32_t> out;
  for (int64_t e : errors) out.push_back(EasyPid::step(c, state, e, 25, d_ticks));
  return out;
}

TEST(EasyPid, p_part_is_minus_error_times_p_over_256_truncated) {
  EXPECT_EQ(run(config(384, 0, 0, 0, kNoClip), {1000}), std::vector<int32_t>{-1500});
  EXPECT_EQ(run(config(384, 0, 0, 0, kNoClip), {-1000}), std::vector<int32_t>{1500});
  EXPECT_EQ(run(config(100, 0, 0, 0, kNoClip), {3, -3}), (std::vector<int32_t>{-1, 1}));  // 300 / 256 towards 0
  EXPECT_EQ(run(config(0, 0, 0, 0, kNoClip), {123456}), std::vector<int32_t>{0});
}

TEST(EasyPid, error_is_clipped_to_2_pow_23) {
  EasyPidState state;
  const auto c = config(256, 0, 0, 0, kNoClip);
  EXPECT_EQ(EasyPid::step(c, state, (int64_t{1} << 24) + 5, 25, 1), -8388608);
  EXPECT_EQ(state.error, 8388608);
  EXPECT_EQ(EasyPid::step(c, state, -(int64_t{1} << 40), 25, 1), 8388608);
  EXPECT_EQ(state.error, -8388608);
  EXPECT_EQ(EasyPid::step(c, state, 8388607, 25, 1), -8388607) << "just inside";
}

// I = 65536: the I part is minus the sum. The sum gains error x 25 per tick and stops at
// +-Iclip x 65536 (no wind-up beyond it: an opposite error unwinds it at once).
TEST(EasyPid, error_sum_is_clipped_to_i_clip_times_65536) {
  const auto c = config(0, 65536, 0, 1, kNoClip);
  EXPECT_EQ(run(c, {1000, 1000, 1000, 1000, -1000}),
            (std::vector<int32_t>{-25000, -50000, -65536, -65536, -40536}));
  EXPECT_EQ(run(c, {-3000, -3000}), (std::vector<int32_t>{65536, 65536}));
  EXPECT_EQ(run(config(0, 65536, 0, 0, kNoClip), {1000, 1000}), (std::vector<int32_t>{0, 0})) << "Iclip 0: no sum";
  // I = 256: sum x 256 / 65536, truncated: 25000 / 256 = 97.66 -> 97.
  EXPECT_EQ(run(config(0, 256, 0, 100, kNoClip), {1000, 1000}), (std::vector<int32_t>{-97, -195}));
  EasyPidState state;
  EasyPid::step(config(0, 1, 0, 32640, kNoClip), state, 2000, 25, 1);
  EXPECT_EQ(state.error_sum, 50000);
}

// D x (pid_e at the last D sample - pid_e now), the difference clipped to +-127.
TEST(EasyPid, d_part_uses_the_difference_clipped_to_127) {
  const auto c = config(0, 0, 10, 0, kNoClip);
  EXPECT_EQ(run(c, {0, 50, 50, 20}), (std::vector<int32_t>{0, -500, 0, 300}));
  EXPECT_EQ(run(c, {0, 1000, 0, -5000}), (std::vector<int32_t>{0, -1270, 1270, 1270}));
}

// Sampled every d_ticks ticks (the first sample on the d_ticks-th call) and held in between.
TEST(EasyPid, d_part_is_sampled_at_the_divider_and_held) {
  const auto c = config(0, 0, 1, 0, kNoClip);
  EXPECT_EQ(run(c, {0, 0, 0, 100, 100, 100, 100, 100}, 4), (std::vector<int32_t>{0, 0, 0, -100, -100, -100, -100, 0}));
  EXPECT_EQ(run(c, {0, 100, 100}, 0), (std::vector<int32_t>{0, -100, 0})) << "0 ticks: every tick";
}

TEST(EasyPid, result_is_clipped_to_the_velocity_clip) {
  const auto c = config(256 * 1000, 0, 0, 0, 2500);
  EXPECT_EQ(run(c, {10, -10, 2}), (std::vector<int32_t>{-2500, 2500, -2000}));
  EXPECT_EQ(run(config(256, 0, 0, 0, 0), {100}), std::vector<int32_t>{0}) << "dv_clip 0: no correction";
}

// P 512, I 65536, Iclip 100, D 2, error 0 then 40: P -80, sum 1000 -> I -1000, D 2 x (0 - 40) = -80.
TEST(EasyPid, parts_add_up) {
  EasyPidState state;
  const auto c = config(512, 65536, 2, 100, kNoClip);
  EXPECT_EQ(EasyPid::step(c, state, 0, 25, 1), 0);
  EXPECT_EQ(EasyPid::step(c, state, 40, 25, 1), -1160);
  EXPECT_EQ(state.error, 40);
  EXPECT_EQ(state.error_sum, 1000);
  EXPECT_EQ(state.d_part, -80);
  EXPECT_EQ(state.correction, -1160);
}

}  // namespace
}  // namespace motwin::testing
