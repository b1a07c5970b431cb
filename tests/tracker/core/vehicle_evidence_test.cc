// The vehicle-evidence arithmetic (tracker/core/vehicle_evidence.h) against sums and order
// statistics computed here from seeded returns of known heights.
#include "tracker/core/vehicle_evidence.h"

#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <random>
#include <vector>

#include "tracker/core/preprocess.h"
#include "tracker/core/track.h"

namespace vtrack {
namespace {

TEST(VehicleEvidence, LogitIsTheSumOfItsTermsAndAccumulationIsDiscountedAndClamped) {
  EvidenceParams p;
  p.prior = 0.2;
  p.scan_weight = 0.25;
  p.max_log_odds = 3.0;
  p.bias_3d = 0.5;
  p.bias_2d = 0.0;
  p.terms_2d.clear();
  p.terms_3d = {{EvidenceFeature::kHeightMax, 2, 1.5, 0.5, -2.0},
                {EvidenceFeature::kLength, 1, 4.0, 2.0, 1.5}};
  EvidenceFeatures f{};
  f[static_cast<std::size_t>(EvidenceFeature::kHeightMax)] = 2.5;  // z = 2: -2 * 4 = -8
  f[static_cast<std::size_t>(EvidenceFeature::kLength)] = 5.0;     // z = 0.5: 1.5 * 0.5
  EXPECT_NEAR(ScanLogit(p, true, f), 0.5 - 8.0 + 0.75, 1e-12);
  EXPECT_NEAR(ScanLogit(p, false, f), 0.0, 1e-12);  // no single-plane terms: bias_2d only

  const double l0 = std::log(0.2 / 0.8);
  EXPECT_NEAR(PriorLogOdds(p), l0, 1e-12);
  // n scans of logit 1: L = l0 + n a (1 - l0) until the clamp at +3.
  double L = PriorLogOdds(p);
  for (int n = 1; n <= 20; ++n) {
    L = AccumulateLogOdds(p, L, 1.0);
    EXPECT_NEAR(L, std::min(3.0, l0 + n * 0.25 * (1.0 - l0)), 1e-12) << n;
  }
  // ... and from the clamp, scans of logit -5 bring it down as fast as the clamp allows.
  L = AccumulateLogOdds(p, L, -5.0);
  EXPECT_NEAR(L, 3.0 + 0.25 * (-5.0 - l0), 1e-12);
  EXPECT_NEAR(VehicleProbability(0.0), 0.5, 1e-15);
  EXPECT_NEAR(VehicleProbability(std::log(3.0)), 0.75, 1e-12);
}

TEST(VehicleEvidence, ReturnsGiveTheirHeightProfileOverhangRangeAndSegmentExtent) {
  std::mt19937 rng(7);
  std::uniform_real_distribution<float> height(0.3f, 1.6f), xy(-1.0f, 1.0f);
  WorldPoints pts;
  std::vector<float> heights;
  for (int i = 0; i < 101; ++i) {
    const float h = height(rng);
    pts.push_back(20.0 + xy(rng), 5.0 + xy(rng), h, i, 0);
    pts.overhang.push_back(i % 4 == 0 ? 4.5f : 0.0f);  // 26 of 101 under something tall
  }
  std::vector<std::int32_t> idx(101);
  for (int i = 0; i < 101; ++i) idx[static_cast<std::size_t>(i)] = i;
  // Two segments: returns 0-49 in one 3 m long, the rest in one 7.5 m long.
  std::vector<std::int32_t> segment_of(101, 0);
  for (int i = 50; i < 101; ++i) segment_of[static_cast<std::size_t>(i)] = 1;
  const std::vector<float> extent = {3.0f, 7.5f};
  std::vector<float> scratch;
  const ReturnEvidence r =
      MeasureReturns(pts, idx, segment_of, extent, Eigen::Vector2d(2.0, 5.0), true, &scratch);

  std::vector<float> sorted = pts.height;
  std::sort(sorted.begin(), sorted.end());
  double cx = 0, cy = 0;
  for (std::size_t i = 0; i < 101; ++i) {
    cx += pts.x[i] / 101.0;
    cy += pts.y[i] / 101.0;
  }
  EXPECT_EQ(r.num_points, 101);
  EXPECT_FLOAT_EQ(r.height_min, sorted.front());
  EXPECT_FLOAT_EQ(r.height_max, sorted.back());
  EXPECT_FLOAT_EQ(r.height_median, sorted[50]);
  EXPECT_NEAR(r.overhang, 26.0 / 101.0, 1e-12);
  EXPECT_NEAR(r.range, std::hypot(cx - 2.0, cy - 5.0), 1e-9);
  EXPECT_FLOAT_EQ(r.segment_extent, 7.5f);

  // Single-plane: no heights.
  const ReturnEvidence flat =
      MeasureReturns(pts, idx, segment_of, extent, Eigen::Vector2d(2.0, 5.0), false, &scratch);
  EXPECT_EQ(flat.height_max, 0.0);
  EXPECT_EQ(flat.height_median, 0.0);
}

}  // namespace
}  // namespace vtrack
