// Motion at the ends of a static recording (processing/model_check/edge_motion.hpp): a burst
// at the start or the end is found and cut with a second's margin; isolated spikes anywhere,
// and a record without motion, are left whole.
#include <gtest/gtest.h>

#include <cmath>
#include <vector>

#include "processing/base/portable_random.hpp"
#include "processing/model_check/edge_motion.hpp"

using namespace gyrod::processing;

namespace {

constexpr double kEdgeRate = 100.0;

std::vector<std::vector<double>> edgeNoise(std::size_t n, std::uint64_t seed) {
  NormalGenerator g(seed);
  std::vector<std::vector<double>> axes(3, std::vector<double>(n));
  for (auto& a : axes)
    for (double& v : a) v = 0.1 * g.next();
  return axes;
}

// A decaying ring of 8 Hz, as a board put down rings, from `at` for `len` samples.
void addRing(std::vector<double>& x, std::size_t at, std::size_t len, double amplitude) {
  for (std::size_t i = 0; i < len && at + i < x.size(); ++i)
    x[at + i] += amplitude * std::exp(-static_cast<double>(i) / 20.0) *
                 std::sin(2.0 * 3.141592653589793 * 8.0 * static_cast<double>(i) / kEdgeRate);
}

}  // namespace

TEST(EdgeMotion, ABurstAtTheStartIsCutWithASecondsMargin) {
  auto axes = edgeNoise(7000, 3);
  addRing(axes[0], 75, 40, 4.0);
  const EdgeMotion m = findMotionAtEdges(axes, kEdgeRate);
  ASSERT_TRUE(m.cut(7000));
  // The last sample beyond 6 sd of the ring lies within its 40 samples: the cut ends 1 s later.
  EXPECT_GT(m.keep_first, 75u + 100u);
  EXPECT_LE(m.keep_first, 75u + 40u + 101u);
  EXPECT_EQ(m.keep_end, 7000u);
  EXPECT_GE(m.moving_at_start, 3u);
  EXPECT_GT(m.largest_z_at_start, 20.0);
}

TEST(EdgeMotion, ABurstAtTheEndIsCut) {
  auto axes = edgeNoise(7000, 4);
  addRing(axes[2], 6900, 60, -3.0);
  const EdgeMotion m = findMotionAtEdges(axes, kEdgeRate);
  EXPECT_EQ(m.keep_first, 0u);
  EXPECT_LT(m.keep_end, 6900u);
  EXPECT_GE(m.keep_end, 6900u - 101u);
  EXPECT_GE(m.moving_at_end, 3u);
}

TEST(EdgeMotion, SpikesAndQuietRecordsAreLeftWhole) {
  auto axes = edgeNoise(7000, 5);
  EXPECT_FALSE(findMotionAtEdges(axes, kEdgeRate).cut(7000));
  // Isolated outliers of 20 sd, two of them in the first tenth, more than half a second apart.
  for (std::size_t i : {30u, 400u, 3000u, 6950u}) axes[1][i] += 2.0;
  EXPECT_FALSE(findMotionAtEdges(axes, kEdgeRate).cut(7000));
  // A burst in the middle is not an edge: the record is left whole.
  addRing(axes[0], 3500, 40, 4.0);
  EXPECT_FALSE(findMotionAtEdges(axes, kEdgeRate).cut(7000));
}

TEST(EdgeMotion, ARecordThatMovesThroughoutIsNotCut) {
  auto axes = edgeNoise(2000, 6);
  for (std::size_t at = 0; at < 2000; at += 30) addRing(axes[0], at, 30, 4.0);
  EXPECT_FALSE(findMotionAtEdges(axes, kEdgeRate).cut(2000));
}
