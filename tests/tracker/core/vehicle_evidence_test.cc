// The vehicle-evidence arithmetic (tracker/core/vehicle_evidence.h) against sums and order
// statistics computed here from seeded returns of known heights.
#include "tracker/core/vehicle_evidence.h"

#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <cstdint>
#include <limits>
#include <random>
#include <string>
#include <vector>

#include "base/angle.h"
#include "tracker/core/preprocess.h"
#include "tracker/core/range_profile.h"
#include "tracker/core/scan.h"
#include "tracker/core/ekf.h"
#include "tracker/core/track.h"
#include "tracker/core/track_manager.h"
#include "tracker/core/tracker.h"

namespace vtrack {
namespace {

TEST(VehicleEvidence, LogitIsTheSumOfItsTermsAndAccumulationIsDiscountedAndClamped) {
  EvidenceParams p;
  p.model_3d = p.model_2d = EvidenceModel::kLogistic;
  p.prior = 0.2;
  p.scan_weight = 0.25;
  p.accumulation = EvidenceAccumulation::kSum;
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
  EXPECT_NEAR(PriorLogOdds(p, true), l0, 1e-12);
  // n scans of logit 1: L = l0 + n a (1 - l0) until the clamp at +3.
  double L = PriorLogOdds(p, true);
  for (int n = 1; n <= 20; ++n) {
    L = AccumulateLogOdds(p, true, L, 1.0);
    EXPECT_NEAR(L, std::min(3.0, l0 + n * 0.25 * (1.0 - l0)), 1e-12) << n;
  }
  // ... and from the clamp, scans of logit -5 bring it down as fast as the clamp allows.
  L = AccumulateLogOdds(p, true, L, -5.0);
  EXPECT_NEAR(L, 3.0 + 0.25 * (-5.0 - l0), 1e-12);
  // Averaging: L moves a quarter of the way to each scan's logit: after n scans of logit 1 from
  // l0, L = 1 + (l0 - 1) 0.75^n.
  p.accumulation = EvidenceAccumulation::kAverage;
  L = PriorLogOdds(p, true);
  for (int n = 1; n <= 20; ++n) {
    L = AccumulateLogOdds(p, true, L, 1.0);
    EXPECT_NEAR(L, 1.0 + (l0 - 1.0) * std::pow(0.75, n), 1e-12) << n;
  }
  EXPECT_NEAR(VehicleProbability(0.0), 0.5, 1e-15);
  EXPECT_NEAR(VehicleProbability(std::log(3.0)), 0.75, 1e-12);
}

// A dimension not estimated yet is missing: its terms add nothing (as at the training mean),
// and its indicator is 1. A 0 in its place would read as a 0 m wide object.
TEST(VehicleEvidence, AnUnestimatedDimensionIsMissingNotZero) {
  EvidenceParams p;
  p.model_3d = p.model_2d = EvidenceModel::kLogistic;
  p.terms_3d.clear();
  p.bias_2d = -1.0;
  p.terms_2d = {{EvidenceFeature::kWidth, 1, 1.5, 0.5, 2.0},
                {EvidenceFeature::kWidth, 2, 1.5, 0.5, -3.0},
                {EvidenceFeature::kLength, 1, 4.0, 2.0, 1.0},
                {EvidenceFeature::kWidthUnseen, 1, 0.25, 0.5, -0.5}};
  Track t;
  t.hyps.resize(1);
  t.selected = 0;
  t.hyps[0].length_est = 5.0;  // one face seen: a length, no width
  ReturnEvidence r;
  r.num_points = 12;
  r.range = 20.0;
  EvidenceFeatures f = FeaturesOf(r, t, 0.0);
  EXPECT_TRUE(std::isnan(f[static_cast<std::size_t>(EvidenceFeature::kWidth)]));
  EXPECT_EQ(f[static_cast<std::size_t>(EvidenceFeature::kWidthUnseen)], 1.0);
  EXPECT_EQ(f[static_cast<std::size_t>(EvidenceFeature::kLengthUnseen)], 0.0);
  EXPECT_EQ(f[static_cast<std::size_t>(EvidenceFeature::kLength)], 5.0);
  // bias + length z = 0.5 + indicator z = 1.5; both width terms absent.
  EXPECT_NEAR(ScanLogit(p, false, f), -1.0 + 0.5 - 0.75, 1e-12);

  EXPECT_TRUE(UsesFeature(p, false, EvidenceFeature::kWidth));
  EXPECT_FALSE(UsesFeature(p, false, EvidenceFeature::kHiddenEnds));
  EXPECT_FALSE(UsesFeature(p, true, EvidenceFeature::kWidth));  // the 3-D model's own terms

  t.hyps[0].width_est = 2.0;  // the second face seen: z = 1, 2 * 1 - 3 * 1
  f = FeaturesOf(r, t, 0.0);
  EXPECT_EQ(f[static_cast<std::size_t>(EvidenceFeature::kWidthUnseen)], 0.0);
  EXPECT_NEAR(ScanLogit(p, false, f), -1.0 + 2.0 - 3.0 + 0.5 + (-0.5) * (-0.5), 1e-12);
}

// inlier_share: the share of the fitted returns that the fit counted as inliers; missing when the
// scan gave no fit (a small object's centroid, a failed fit).
TEST(VehicleEvidence, InlierShareIsTheFitsInliersOverItsReturnsAndMissingWithoutAFit) {
  Track t;
  t.hyps.resize(1);
  t.selected = 0;
  TrackHypothesis& h = t.hyps[0];
  h.fit.point_edge.assign(40, FitResult::kOutlier);
  h.fit.num_inliers = 30;
  ReturnEvidence r;
  r.num_points = 40;
  const auto k = static_cast<std::size_t>(EvidenceFeature::kInlierShare);
  EXPECT_TRUE(std::isnan(FeaturesOf(r, t, 0.0)[k]));  // has_fit false: this scan gave no fit
  h.has_fit = true;
  EXPECT_DOUBLE_EQ(FeaturesOf(r, t, 0.0)[k], 0.75);
  h.fit.point_edge.clear();
  EXPECT_TRUE(std::isnan(FeaturesOf(r, t, 0.0)[k]));
}

// The decision has hysteresis: a track becomes a vehicle at vehicle_probability and stays one
// down to keep_probability; below that it is other until it reaches vehicle_probability again.
TEST(VehicleEvidence, AVehicleStaysOneDownToTheKeepProbability) {
  EvidenceParams p;
  p.vehicle_probability = 0.5;
  p.keep_probability = 0.3;
  auto L = [](double prob) { return std::log(prob / (1.0 - prob)); };
  EXPECT_FALSE(VehicleByEvidence(p, false, L(0.45)));
  EXPECT_TRUE(VehicleByEvidence(p, false, L(0.5)));
  EXPECT_TRUE(VehicleByEvidence(p, true, L(0.45)));
  EXPECT_TRUE(VehicleByEvidence(p, true, L(0.3000001)));
  EXPECT_FALSE(VehicleByEvidence(p, true, L(0.2999999)));
  // Through a track's life: 0.6 (becomes one), 0.35 (stays), 0.25 (leaves), 0.45 (not yet).
  bool v = false;
  std::vector<bool> seen;
  for (const double prob : {0.2, 0.6, 0.35, 0.25, 0.45, 0.55}) {
    v = VehicleByEvidence(p, v, L(prob));
    seen.push_back(v);
  }
  EXPECT_EQ(seen, (std::vector<bool>{false, true, true, false, false, true}));
  // keep_probability above vehicle_probability would be no hysteresis but a gap: refused.
  p.keep_probability = 0.6;
  std::string error;
  EXPECT_FALSE(p.Validate(&error));
  EXPECT_NE(error.find("keep_probability"), std::string::npos) << error;
}

// A boosted ensemble: the logit is the bias plus the leaf each tree sends the scan to, a missing
// feature going left; a list whose children do not follow their parent in the same tree is refused.
TEST(VehicleEvidence, TreesSumTheLeavesTheScanReachesAndSendMissingFeaturesLeft) {
  EvidenceParams p;
  p.model_2d = EvidenceModel::kTrees;
  p.bias_2d = 0.5;
  using F = EvidenceFeature;
  p.trees_2d = {
      {0, F::kWidth, 1.0, 1, 2, 0.0},    // 0: width <= 1 m?
      {0, F::kLogPoints, 0.0, -1, -1, 0.3},
      {0, F::kLength, 3.0, 3, 4, 0.0},   // 2: length <= 3 m?
      {0, F::kLogPoints, 0.0, -1, -1, -0.2},
      {0, F::kLogPoints, 0.0, -1, -1, 1.1},
      {1, F::kLogPoints, 0.0, -1, -1, 0.05},  // a tree that is one leaf
  };
  std::string error;
  ASSERT_TRUE(p.Validate(&error)) << error;
  EvidenceFeatures f{};
  auto set = [&f](F k, double v) { f[static_cast<std::size_t>(k)] = v; };
  set(F::kWidth, 2.0);
  set(F::kLength, 4.0);
  EXPECT_NEAR(ScanLogit(p, false, f), 0.5 + 1.1 + 0.05, 1e-12);
  set(F::kLength, 3.0);  // at the threshold: left
  EXPECT_NEAR(ScanLogit(p, false, f), 0.5 - 0.2 + 0.05, 1e-12);
  set(F::kWidth, std::numeric_limits<double>::quiet_NaN());  // missing: left
  EXPECT_NEAR(ScanLogit(p, false, f), 0.5 + 0.3 + 0.05, 1e-12);
  EXPECT_TRUE(UsesFeature(p, false, F::kLength));
  EXPECT_FALSE(UsesFeature(p, false, F::kSpeed));
  EXPECT_FALSE(UsesFeature(p, false, F::kLogPoints)) << "leaves compare nothing";

  EvidenceParams bad = p;
  bad.trees_2d[2].left = 1;  // before its parent
  EXPECT_FALSE(bad.Validate(&error));
  EXPECT_NE(error.find("trees_2d[2]"), std::string::npos) << error;
  bad = p;
  bad.trees_2d[2].right = 5;  // a node of the next tree
  EXPECT_FALSE(bad.Validate(&error));
  bad = p;
  bad.trees_2d[0].right = -1;  // half a split
  EXPECT_FALSE(bad.Validate(&error));
  bad = p;
  bad.trees_2d[5].tree = 0;  // tree numbers must not go down ...
  bad.trees_2d[4].tree = 1;
  EXPECT_FALSE(bad.Validate(&error));
}

// The trees' roots found once (EvidenceRoots, as the track manager scores) against a walk over
// every node written here: the first node of each tree, and for the shipped models (50 trees
// each) the very logit of that walk, over seeded feature vectors of every scale with missing
// features among them.
TEST(VehicleEvidence, TreeRootsFoundOnceGiveTheLogitOfAWalkOverEveryNode) {
  using F = EvidenceFeature;
  const std::vector<EvidenceNode> three_trees = {
      {0, F::kWidth, 1.0, 1, 2, 0.0}, {0, F::kLogPoints, 0.0, -1, -1, 0.3},
      {0, F::kLogPoints, 0.0, -1, -1, -0.2}, {1, F::kLogPoints, 0.0, -1, -1, 0.05},
      {2, F::kLength, 3.0, 5, 6, 0.0}, {2, F::kLogPoints, 0.0, -1, -1, 1.0},
      {2, F::kLogPoints, 0.0, -1, -1, 2.0}};
  EXPECT_EQ(TreeRoots(three_trees), (std::vector<std::int32_t>{0, 3, 4}));
  EXPECT_TRUE(TreeRoots({}).empty());

  const EvidenceParams p;  // the shipped models
  ASSERT_EQ(p.model_3d, EvidenceModel::kTrees);
  ASSERT_EQ(p.model_2d, EvidenceModel::kTrees);
  const EvidenceRoots roots(p);
  EXPECT_EQ(roots.three_d.size(), 50u);
  EXPECT_EQ(roots.two_d.size(), 50u);
  // The reference: every node visited in order, a tree's walk started at each change of tree.
  const auto walk_every_node = [](const std::vector<EvidenceNode>& nodes, double bias,
                                  const EvidenceFeatures& f) {
    double l = 0.0;
    for (std::size_t k = 0; k < nodes.size(); ++k) {
      if (k > 0 && nodes[k].tree == nodes[k - 1].tree) continue;
      std::size_t i = k;
      while (nodes[i].left >= 0) {
        const double v = f[static_cast<std::size_t>(nodes[i].feature)];
        i = static_cast<std::size_t>(v > nodes[i].threshold ? nodes[i].right : nodes[i].left);
      }
      l += nodes[i].value;
    }
    return bias + l;
  };
  std::mt19937 rng(1203u);
  std::uniform_real_distribution<double> value(-1.0, 12.0);
  std::bernoulli_distribution missing(0.1);
  for (int k = 0; k < 2000; ++k) {
    EvidenceFeatures f{};
    for (double& v : f) v = missing(rng) ? std::numeric_limits<double>::quiet_NaN() : value(rng);
    EXPECT_EQ(ScanLogit(p, true, f, roots), walk_every_node(p.trees_3d, p.bias_3d, f)) << "vector " << k;
    EXPECT_EQ(ScanLogit(p, false, f, roots), walk_every_node(p.trees_2d, p.bias_2d, f)) << "vector " << k;
    EXPECT_EQ(ScanLogit(p, true, f), ScanLogit(p, true, f, roots));
  }
}

TEST(VehicleEvidence, ReturnsGiveTheirHeightProfileColumnTopRangeAndSegmentExtent) {
  std::mt19937 rng(7);
  std::uniform_real_distribution<float> height(0.3f, 1.6f), xy(-1.0f, 1.0f);
  WorldPoints pts;
  std::vector<float> heights;
  for (int i = 0; i < 101; ++i) {
    const float h = height(rng);
    pts.push_back(20.0 + xy(rng), 5.0 + xy(rng), h, i, static_cast<std::int16_t>(i % 8));  // 13 on ring 3
    // Column tops: 26 of 101 under a crown 14 m high (clipped to 10 m), the rest their own top.
    pts.column_top.push_back(i % 4 == 0 ? 14.0f : 1.7f);
  }
  std::vector<std::int32_t> idx(101);
  for (int i = 0; i < 101; ++i) idx[static_cast<std::size_t>(i)] = i;
  // Two segments: returns 0-49 in one 3 m long, the rest in one 7.5 m long.
  std::vector<std::int32_t> segment_of(101, 0);
  for (int i = 50; i < 101; ++i) segment_of[static_cast<std::size_t>(i)] = 1;
  const std::vector<float> extent = {3.0f, 7.5f};
  std::vector<float> scratch;
  const ReturnEvidence r =
      MeasureReturns(pts, idx, segment_of, extent, Eigen::Vector2d(2.0, 5.0), true, 3, nullptr, &scratch);

  std::vector<float> sorted(pts.height.begin(), pts.height.end());
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
  EXPECT_FLOAT_EQ(r.column_top, 1.7f);  // the median: 75 of 101 at 1.7 m
  for (int i = 0; i < 60; ++i) pts.column_top[static_cast<std::size_t>(i)] = 14.0f;
  const ReturnEvidence under =
      MeasureReturns(pts, idx, segment_of, extent, Eigen::Vector2d(2.0, 5.0), true, 3, nullptr, &scratch);
  EXPECT_FLOAT_EQ(under.column_top, 10.0f);  // 60 of 101 at 14 m: the median, clipped
  EXPECT_NEAR(r.range, std::hypot(cx - 2.0, cy - 5.0), 1e-9);
  EXPECT_FLOAT_EQ(r.segment_extent, 7.5f);
  EXPECT_EQ(r.top_beam, 13);

  // Single-plane: no heights.
  const ReturnEvidence flat =
      MeasureReturns(pts, idx, segment_of, extent, Eigen::Vector2d(2.0, 5.0), false, 3, nullptr, &scratch);
  EXPECT_EQ(flat.height_max, 0.0);
  EXPECT_EQ(flat.height_median, 0.0);
}

// The ends of a track's returns, against a single-plane profile built here: a face 20 m ahead
// seen alone has both ends free; a nearer return just beyond one end hides that end; the same
// face inside a longer one at the same range (a wall seen in part) has neither end free.
// Roughness against its distribution: returns on a straight face with independent normal
// noise sigma across it, on two rings, given in shuffled order. The middle of three equally
// spaced returns lies off the chord of the outer two by b - (a + c) / 2 ~ N(0, 1.5 sigma^2),
// whose absolute value has the median 0.6745 sqrt(1.5) sigma. Returns farther apart than
// kRoughnessMaxChord (the face's far piece) make no triplet with the near ones.
TEST(VehicleEvidence, RoughnessIsTheMedianDistanceOffTheChordAlongARing) {
  constexpr double kSigma = 0.03;  // [m]
  std::mt19937 rng(11);
  std::normal_distribution<double> noise(0.0, kSigma);
  WorldPoints pts;
  // A face along y at x = 15, seen from the origin; returns every 0.1 m on rings 2 and 5.
  for (const std::int16_t ring : {2, 5}) {
    for (int k = 0; k < 1200; ++k) {
      pts.push_back(15.0 + noise(rng), -60.0 + 0.1 * k, 1.0f, 0, ring);
    }
  }
  std::vector<std::int32_t> idx(pts.size());
  for (std::size_t i = 0; i < idx.size(); ++i) idx[i] = static_cast<std::int32_t>(i);
  std::shuffle(idx.begin(), idx.end(), rng);
  double cx = 0.0, cy = 0.0;
  for (const std::int32_t i : idx) {
    cx += pts.x[static_cast<std::size_t>(i)] / static_cast<double>(idx.size());
    cy += pts.y[static_cast<std::size_t>(i)] / static_cast<double>(idx.size());
  }
  std::vector<RingReturn> order;
  std::vector<float> distances;
  const Eigen::Vector2d sensor(0.0, 0.0), centroid(cx, cy);
  const double expected = 0.6745 * std::sqrt(1.5) * kSigma;
  // 2398 triplets: the sample median's standard error is ~3 % of it.
  EXPECT_NEAR(SurfaceRoughness(pts, idx, centroid, sensor, true, &order, &distances), expected,
              0.1 * expected);

  // Every fourth return only: 0.4 m apart, still one surface (chords of 0.8 m).
  std::vector<std::int32_t> sparse;
  for (std::size_t i = 0; i < pts.size(); i += 4) sparse.push_back(static_cast<std::int32_t>(i));
  EXPECT_NEAR(SurfaceRoughness(pts, sparse, centroid, sensor, true, &order, &distances), expected,
              0.2 * expected);
  // Every sixth: 0.6 m apart, chords of 1.2 m: no triplet, no roughness.
  std::vector<std::int32_t> gaps;
  for (std::size_t i = 0; i < pts.size(); i += 6) gaps.push_back(static_cast<std::int32_t>(i));
  EXPECT_TRUE(std::isnan(SurfaceRoughness(pts, gaps, centroid, sensor, true, &order, &distances)));
  // Four returns in a row (two triplets) are too few.
  const std::vector<std::int32_t> four = {600, 601, 602, 603};
  EXPECT_TRUE(std::isnan(SurfaceRoughness(pts, four, centroid, sensor, true, &order, &distances)));
  // Ring 2 alone, its ring unknown (-1): left out of a 3-D cloud (its neighbours in bearing
  // could be another ring's); a single-plane scan's one ring whatever its ring field says.
  WorldPoints unknown = pts;
  std::vector<std::int32_t> ring2;
  for (std::size_t i = 0; i < pts.size(); ++i) {
    if (pts.ring[i] == 2) {
      unknown.ring[i] = -1;
      ring2.push_back(static_cast<std::int32_t>(i));
    }
  }
  EXPECT_TRUE(std::isnan(SurfaceRoughness(unknown, ring2, centroid, sensor, true, &order, &distances)));
  EXPECT_NEAR(SurfaceRoughness(unknown, ring2, centroid, sensor, false, &order, &distances), expected,
              0.15 * expected);
  // Both rings unknown in a 3-D cloud would interleave two rings: NaN, not a mixture.
  for (auto& r : unknown.ring) r = -1;
  EXPECT_TRUE(std::isnan(SurfaceRoughness(unknown, idx, centroid, sensor, true, &order, &distances)));
  // MeasureReturns measures it only when asked.
  std::vector<std::int32_t> segment_of(pts.size(), -1);
  std::vector<float> scratch;
  EXPECT_TRUE(std::isnan(MeasureReturns(pts, idx, segment_of, {}, sensor, true, 0, nullptr, &scratch)
                             .roughness));
  const ReturnEvidence with =
      MeasureReturns(pts, idx, segment_of, {}, sensor, true, 0, nullptr, &scratch, &order);
  EXPECT_NEAR(with.roughness, expected, 0.1 * expected);
  // Measuring it leaves the other features as they are without it.
  pts.height.assign(pts.size(), 0.0f);
  for (std::size_t i = 0; i < pts.size(); ++i) pts.height[i] = 0.5f + 0.001f * static_cast<float>(i % 1000);
  const ReturnEvidence a = MeasureReturns(pts, idx, segment_of, {}, sensor, true, 0, nullptr, &scratch);
  const ReturnEvidence b =
      MeasureReturns(pts, idx, segment_of, {}, sensor, true, 0, nullptr, &scratch, &order);
  EXPECT_FLOAT_EQ(a.height_min, 0.5f);
  EXPECT_FLOAT_EQ(a.height_max, 1.499f);
  EXPECT_EQ(b.height_min, a.height_min);
  EXPECT_EQ(b.height_max, a.height_max);
  EXPECT_EQ(b.height_median, a.height_median);
  EXPECT_EQ(b.column_top, a.column_top);
  EXPECT_EQ(b.num_points, a.num_points);
  EXPECT_EQ(b.range, a.range);
}

TEST(VehicleEvidence, HiddenEndsCountsTheEndsThatAreNotFree) {
  const Eigen::Vector2d sensor(0.0, 0.0);
  const double step_deg = 0.5;  // the bearing step of the returns
  // Returns at 20 m, bearings k * step for k in [k0, k1]; the track holds those of [-4, 4].
  auto face = [&](int k0, int k1, double range, WorldPoints* pts) {
    for (int k = k0; k <= k1; ++k) {
      const double a = DegToRad(k * step_deg);
      pts->push_back(range * std::cos(a), range * std::sin(a), 1.0f, static_cast<std::int32_t>(pts->size()), 0);
    }
  };
  auto hidden = [&](const WorldPoints& pts) {
    std::vector<std::int32_t> idx;
    Eigen::Vector2d c = Eigen::Vector2d::Zero();
    for (std::size_t i = 0; i < pts.size(); ++i) {
      if (std::abs(std::hypot(pts.x[i], pts.y[i]) - 20.0) < 1e-6 &&
          std::abs(std::atan2(pts.y[i], pts.x[i])) <= DegToRad(4.01 * step_deg)) {
        idx.push_back(static_cast<std::int32_t>(i));
        c += Eigen::Vector2d(pts.x[i], pts.y[i]);
      }
    }
    EXPECT_EQ(idx.size(), 9u);
    RangeProfile profile;
    profile.Build(sensor, pts.x, pts.y, 1.5 * step_deg);
    return HiddenEnds(pts, idx, c / static_cast<double>(idx.size()), sensor, profile);
  };
  WorldPoints alone;
  face(-4, 4, 20.0, &alone);
  face(-60, -20, 45.0, &alone);  // background well beyond: farther, not hiding
  face(20, 60, 45.0, &alone);
  EXPECT_EQ(hidden(alone), 0);
  WorldPoints occluded = alone;
  face(5, 9, 12.0, &occluded);  // a nearer object just beyond the end at +4 steps
  EXPECT_EQ(hidden(occluded), 1);
  WorldPoints wall;
  face(-4, 4, 20.0, &wall);
  face(-12, -5, 20.0, &wall);  // the face goes on at the same range on both sides
  face(5, 12, 20.0, &wall);
  EXPECT_EQ(hidden(wall), 2);
  // The bearing step of a scan, from its returns in order.
  std::vector<float> x, y;
  for (int k = -100; k <= 100; ++k) {
    x.push_back(static_cast<float>(30.0 * std::cos(DegToRad(k * step_deg))));
    y.push_back(static_cast<float>(30.0 * std::sin(DegToRad(k * step_deg))));
  }
  EXPECT_NEAR(MedianBearingStepDeg(x, y), step_deg, 1e-4);
}

TEST(VehicleEvidence, TopRingIsTheHighestBeamWhicheverWayRingsAreNumbered) {
  // Eight beams from +2 deg down by 3 deg, numbered upwards (ring 7 = +2 deg) or downwards.
  for (const bool upwards : {true, false}) {
    LadarScan scan;
    scan.num_rings = 8;
    for (int k = 0; k < 8; ++k) {
      const double elevation = (2.0 - 3.0 * k) * M_PI / 180.0;
      for (int a = 0; a < 360; ++a) {
        const double range = 5.0 + (a % 37), az = a * M_PI / 180.0;
        scan.x.push_back(static_cast<float>(range * std::cos(elevation) * std::cos(az)));
        scan.y.push_back(static_cast<float>(range * std::cos(elevation) * std::sin(az)));
        scan.z.push_back(static_cast<float>(range * std::sin(elevation)));
        scan.ring.push_back(static_cast<std::int16_t>(upwards ? 7 - k : k));
      }
    }
    EXPECT_EQ(TopRing(scan), upwards ? 7 : 0);
  }
  LadarScan flat;
  flat.num_rings = 1;
  flat.x = {1.0f};
  flat.y = {2.0f};
  flat.z = {0.0f};
  flat.ring = {0};
  EXPECT_EQ(TopRing(flat), -1);
}

// Six returns 0.5 m across at (10, 5) at t = 1 s: a new track of them is a small object.
PointSet SmallObjectReturns() {
  PointSet pts;
  pts.origin = Eigen::Vector2d(10.0, 5.0);
  for (int i = 0; i < 6; ++i) {
    pts.x.push_back(0.1f * static_cast<float>(i));
    pts.y.push_back(0.05f * static_cast<float>(i % 2));
  }
  pts.extent = std::hypot(0.5, 0.05);
  pts.mean_utime = 1'000'000;
  return pts;
}

// Through the track manager: scans whose evidence drops to p = 0.4 keep a vehicle reported as a
// vehicle (keep_probability 0.3); at p = 0.2 it becomes other, and p = 0.4 does not bring it back.
TEST(VehicleEvidence, TheManagerReportsAVehicleWhileItsEvidenceStaysAboveKeep) {
  TrackerParams p;
  p.evidence.classifier_3d = VehicleClassifier::kEvidence;
  p.evidence.model_3d = EvidenceModel::kLogistic;
  p.evidence.terms_3d.clear();
  p.evidence.accumulation = EvidenceAccumulation::kAverage;
  p.evidence.scan_weight = 1.0;  // L is the last scan's logit: each step sets the probability
  p.evidence.vehicle_probability = 0.5;
  p.evidence.keep_probability = 0.3;
  const Ekf ekf(p.ism, p.vasm, p.ekf, p.cv);
  TrackManager manager(p.manager, ekf, p.fit, p.shape);
  const PointSet pts = SmallObjectReturns();
  manager.SetEvidence(p.evidence);
  ASSERT_TRUE(manager.Create(pts, Eigen::Vector2d::Zero(), 1));
  ReturnEvidence r;
  r.three_d = true;
  r.num_points = 6;
  r.range = 11.0;
  std::vector<ObjectClass> seen;
  for (const double prob : {0.6, 0.4, 0.35, 0.2, 0.4, 0.7}) {
    p.evidence.bias_3d = std::log(prob / (1.0 - prob));  // every scan's logit
    manager.SetEvidence(p.evidence);
    manager.ObserveEvidence(0, r);
    std::vector<TrackReport> out;
    manager.Report(1'000'000, &out);
    ASSERT_EQ(out.size(), 1u);
    EXPECT_NEAR(out[0].vehicle_probability, prob, 1e-9);
    seen.push_back(out[0].object_class);
  }
  const ObjectClass V = ObjectClass::kVehicle, O = ObjectClass::kOther;
  EXPECT_EQ(seen, (std::vector<ObjectClass>{V, V, V, O, O, V}));
}

// Through the track manager, trees given by SetEvidence (not the defaults' 50) score the scan:
// the logit it returns is the bias plus the leaves of the given trees, again after a second
// SetEvidence with trees of another layout (a root kept from the first would fall elsewhere).
TEST(VehicleEvidence, TheManagerScoresWithTheTreesItIsGiven) {
  TrackerParams p;
  using F = EvidenceFeature;
  p.evidence.model_3d = EvidenceModel::kTrees;
  p.evidence.bias_3d = 0.25;
  p.evidence.trees_3d = {{0, F::kLogPoints, 0.0, -1, -1, 0.5}, {1, F::kLogPoints, 0.0, -1, -1, 0.125}};
  const Ekf ekf(p.ism, p.vasm, p.ekf, p.cv);
  TrackManager manager(p.manager, ekf, p.fit, p.shape);
  manager.SetEvidence(p.evidence);
  ASSERT_TRUE(manager.Create(SmallObjectReturns(), Eigen::Vector2d::Zero(), 1));
  ReturnEvidence r;
  r.three_d = true;
  r.num_points = 6;  // log 6 = 1.79
  r.range = 11.0;
  EXPECT_EQ(manager.ObserveEvidence(0, r), 0.25 + 0.5 + 0.125);
  // One tree of three nodes (log_points <= 1: left), then a single leaf.
  p.evidence.trees_3d = {{0, F::kLogPoints, 1.0, 1, 2, 0.0}, {0, F::kLogPoints, 0.0, -1, -1, -4.0},
                         {0, F::kLogPoints, 0.0, -1, -1, 2.0}, {1, F::kLogPoints, 0.0, -1, -1, 1.0}};
  std::string error;
  ASSERT_TRUE(p.evidence.Validate(&error)) << error;
  manager.SetEvidence(p.evidence);
  EXPECT_EQ(manager.ObserveEvidence(0, r), 0.25 + 2.0 + 1.0);
}

// Each model's logits are posteriors at its own prior: a track starts at the prior of the model
// that first measures it (prior for 3-D scans, prior_2d for single-plane ones), and with
// accumulation sum each scan's ratio is taken against that model's prior.
TEST(VehicleEvidence, ATrackStartsAtThePriorOfTheModelThatFirstMeasuresIt) {
  TrackerParams p;
  p.evidence.model_3d = p.evidence.model_2d = EvidenceModel::kLogistic;
  p.evidence.terms_3d.clear();
  p.evidence.terms_2d.clear();
  p.evidence.prior = 0.2;
  p.evidence.prior_2d = 0.6;
  p.evidence.bias_3d = 1.0;
  p.evidence.bias_2d = -0.5;
  p.evidence.accumulation = EvidenceAccumulation::kSum;
  p.evidence.scan_weight = 0.5;
  const double l3 = std::log(0.2 / 0.8), l2 = std::log(0.6 / 0.4);
  EXPECT_NEAR(PriorLogOdds(p.evidence, true), l3, 1e-12);
  EXPECT_NEAR(PriorLogOdds(p.evidence, false), l2, 1e-12);
  for (const bool three_d : {true, false}) {
    const Ekf ekf(p.ism, p.vasm, p.ekf, p.cv);
    TrackManager manager(p.manager, ekf, p.fit, p.shape);
    manager.SetEvidence(p.evidence);
    const PointSet pts = SmallObjectReturns();
    ASSERT_TRUE(manager.Create(pts, Eigen::Vector2d::Zero(), 1));
    ReturnEvidence r;
    r.three_d = three_d;
    r.num_points = 6;
    r.range = 11.0;
    const double start = three_d ? l3 : l2, bias = three_d ? 1.0 : -0.5;
    double expected = start;
    for (int k = 0; k < 3; ++k) {  // sum: L += a (l - logit(prior of this model))
      manager.ObserveEvidence(0, r);
      expected += 0.5 * (bias - start);
      EXPECT_NEAR(manager.tracks()[0].vehicle_log_odds, expected, 1e-12) << three_d << ' ' << k;
    }
  }
}

}  // namespace
}  // namespace vtrack

namespace vtrack {
namespace {

// A small object (a few returns, measured by its centroid) that its evidence classes a vehicle is
// reported at a vehicle's size, never as a 0.5 m object.
TEST(VehicleEvidence, ASmallObjectClassedVehicleIsReportedAtAVehiclesSize) {
  TrackerParams p;
  p.evidence.classifier_3d = VehicleClassifier::kEvidence;
  p.evidence.bias_3d = 8.0;  // every scan says "vehicle"
  p.evidence.model_3d = EvidenceModel::kLogistic;
  p.evidence.terms_3d.clear();
  const Ekf ekf(p.ism, p.vasm, p.ekf, p.cv);
  TrackManager manager(p.manager, ekf, p.fit, p.shape);
  manager.SetEvidence(p.evidence);
  const PointSet pts = SmallObjectReturns();
  ASSERT_TRUE(manager.Create(pts, Eigen::Vector2d::Zero(), 1));
  ASSERT_TRUE(manager.tracks()[0].small_object);
  ReturnEvidence r;
  r.three_d = true;
  r.num_points = 6;
  r.range = 11.0;
  for (int k = 0; k < 5; ++k) manager.ObserveEvidence(0, r);
  std::vector<TrackReport> out;
  manager.Report(1'000'000, &out);
  ASSERT_EQ(out.size(), 1u);
  EXPECT_EQ(out[0].object_class, ObjectClass::kVehicle);
  EXPECT_GT(out[0].vehicle_probability, 0.99);
  EXPECT_GE(out[0].length, p.manager.default_length) << out[0].length << ' ' << out[0].width;
  EXPECT_GE(out[0].width, p.manager.default_width);
}

}  // namespace
}  // namespace vtrack
