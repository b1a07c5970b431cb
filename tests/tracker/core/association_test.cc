// Association: the assignment solver against brute force, and scenes with known answers
// (swapped inputs, a merged segment split between two cars, a car cut in two by an occluder,
// a new object, and the preference for returns on the visible faces).
#include "tracker/core/association.h"

#include <gtest/gtest.h>

#include <algorithm>
#include <numeric>
#include <random>

#include "tracker/core/angle.h"

namespace vtrack {
namespace {

TEST(AssignmentTest, MatchesBruteForceOnRandomMatrices) {
  std::mt19937 rng(5);
  std::uniform_real_distribution<double> u(0.0, 10.0);
  for (int trial = 0; trial < 300; ++trial) {
    const int rows = 1 + static_cast<int>(rng() % 6);
    const int cols = rows + static_cast<int>(rng() % 3);
    std::vector<double> cost(static_cast<std::size_t>(rows * cols));
    for (auto& c : cost) c = u(rng);
    const std::vector<int> assign = SolveAssignment(cost, rows, cols);
    double got = 0.0;
    std::vector<int> used;
    for (int r = 0; r < rows; ++r) {
      ASSERT_GE(assign[static_cast<std::size_t>(r)], 0);
      used.push_back(assign[static_cast<std::size_t>(r)]);
      got += cost[static_cast<std::size_t>(r * cols + assign[static_cast<std::size_t>(r)])];
    }
    std::sort(used.begin(), used.end());
    EXPECT_EQ(std::unique(used.begin(), used.end()), used.end());
    // Brute force over all injective maps rows -> cols (permutations of the columns).
    std::vector<int> perm(static_cast<std::size_t>(cols));
    std::iota(perm.begin(), perm.end(), 0);
    double best = 1e300;
    do {
      double s = 0.0;
      for (int r = 0; r < rows; ++r) s += cost[static_cast<std::size_t>(r * cols + perm[static_cast<std::size_t>(r)])];
      best = std::min(best, s);
    } while (std::next_permutation(perm.begin(), perm.end()));
    EXPECT_NEAR(got, best, 1e-9);
  }
}

// Returns along the faces of a box visible from the sensor, every 0.1 m.
void AddBoxReturns(const OrientedBox& box, const Eigen::Vector2d& sensor, WorldPoints* pts) {
  const std::uint8_t vis = VisibleFaces(box, sensor, DegToRad(5.0));
  for (int f = 0; f < 4; ++f) {
    if (!(vis & (1u << f))) continue;
    Eigen::Vector2d a, b;
    box.FaceEndpoints(static_cast<Face>(f), &a, &b);
    const int n = static_cast<int>((b - a).norm() / 0.1);
    for (int i = 0; i <= n; ++i) {
      const Eigen::Vector2d p = a + (b - a) * (static_cast<double>(i) / n);
      pts->push_back(p.x(), p.y(), 1.0f, static_cast<std::int32_t>(pts->size()), 0);
    }
  }
}

// One segment per [first, last) index range of pts.
Segments SegmentsOf(const WorldPoints& pts, const std::vector<std::pair<int, int>>& ranges) {
  Segments s;
  for (auto [a, b] : ranges) {
    Segment seg;
    seg.begin = static_cast<std::int32_t>(s.point.size());
    seg.min = Eigen::Vector2d::Constant(1e300);
    seg.max = -seg.min;
    for (int i = a; i < b; ++i) {
      s.point.push_back(i);
      const Eigen::Vector2d p(pts.x[static_cast<std::size_t>(i)], pts.y[static_cast<std::size_t>(i)]);
      seg.min = seg.min.cwiseMin(p);
      seg.max = seg.max.cwiseMax(p);
    }
    seg.end = static_cast<std::int32_t>(s.point.size());
    s.segments.push_back(seg);
  }
  return s;
}

PredictedObject Pred(double x, double y, double theta, bool established = true) {
  PredictedObject p;
  p.box.center = {x, y};
  p.box.theta = theta;
  p.box.length = 4.5;
  p.box.width = 1.8;
  p.position_std = 0.2;
  p.established = established;
  return p;
}

TEST(AssociatorTest, AssignsEachCarToItsTrackWhateverTheOrder) {
  const Eigen::Vector2d sensor(0, 0);
  WorldPoints pts;
  OrientedBox a{{10.0, 3.0}, 0.0, 4.5, 1.8}, b{{10.0, -3.0}, 0.0, 4.5, 1.8};
  AddBoxReturns(a, sensor, &pts);
  const int na = static_cast<int>(pts.size());
  AddBoxReturns(b, sensor, &pts);
  const int nb = static_cast<int>(pts.size());
  const Segments segs = SegmentsOf(pts, {{0, na}, {na, nb}});
  Associator assoc(AssociationParams{});
  AssociationResult res;
  // Tracks predicted 0.4 m off the truth, given in the opposite order.
  assoc.Run({Pred(10.4, -2.8, 0.05), Pred(9.7, 3.3, -0.05)}, pts, segs, sensor, &res);
  ASSERT_EQ(res.track_points.size(), 2u);
  EXPECT_EQ(static_cast<int>(res.track_points[0].size()), nb - na);
  EXPECT_EQ(res.track_points[0].front(), na);
  EXPECT_EQ(static_cast<int>(res.track_points[1].size()), na);
  EXPECT_EQ(res.track_points[1].front(), 0);
  EXPECT_TRUE(res.new_objects.empty());
}

TEST(AssociatorTest, MergedSegmentIsSplitBetweenTwoEstablishedTracks) {
  const Eigen::Vector2d sensor(0, -10);
  WorldPoints pts;
  // Two cars parked nose to tail 0.6 m apart: one segment.
  OrientedBox a{{5.0, 0.0}, 0.0, 4.5, 1.8}, b{{10.1, 0.0}, 0.0, 4.5, 1.8};
  AddBoxReturns(a, sensor, &pts);
  const int na = static_cast<int>(pts.size());
  AddBoxReturns(b, sensor, &pts);
  const Segments segs = SegmentsOf(pts, {{0, static_cast<int>(pts.size())}});
  Associator assoc(AssociationParams{});
  AssociationResult res;
  assoc.Run({Pred(5.0, 0.0, 0.0), Pred(10.1, 0.0, 0.0)}, pts, segs, sensor, &res);
  EXPECT_EQ(res.num_split, 1);
  ASSERT_EQ(static_cast<int>(res.track_points[0].size()), na);
  for (auto i : res.track_points[0]) EXPECT_LT(i, na);
  for (auto i : res.track_points[1]) EXPECT_GE(i, na);
  // A tentative second track does not split: the segment goes to one track, the other misses.
  assoc.Run({Pred(5.0, 0.0, 0.0), Pred(10.1, 0.0, 0.0, false)}, pts, segs, sensor, &res);
  EXPECT_EQ(res.num_split, 0);
  EXPECT_EQ(res.track_points[0].size() + res.track_points[1].size(), pts.size());
}

TEST(AssociatorTest, CarCutByOccluderIsMergedAndFarSegmentIsNew) {
  const Eigen::Vector2d sensor(0, -10);
  WorldPoints pts;
  OrientedBox a{{5.0, 0.0}, 0.0, 4.5, 1.8};
  AddBoxReturns(a, sensor, &pts);
  const int na = static_cast<int>(pts.size());
  // Cut the returns in two pieces (a pole in front), and a far object at (30, 20).
  OrientedBox far{{30.0, 20.0}, 0.3, 4.0, 1.7};
  AddBoxReturns(far, sensor, &pts);
  const Segments segs =
      SegmentsOf(pts, {{0, na / 2 - 2}, {na / 2 + 2, na}, {na, static_cast<int>(pts.size())}});
  Associator assoc(AssociationParams{});
  AssociationResult res;
  assoc.Run({Pred(5.2, 0.1, 0.02)}, pts, segs, sensor, &res);
  EXPECT_EQ(res.num_merged, 1);
  EXPECT_EQ(static_cast<int>(res.track_points[0].size()), na - 4);
  ASSERT_EQ(res.new_objects.size(), 1u);
  EXPECT_EQ(res.new_objects[0].size(), pts.size() - static_cast<std::size_t>(na));
}

TEST(AssociatorTest, PrefersReturnsOnTheVisibleFaces) {
  // Sensor behind-left of the predicted car: rear and left faces visible. Two candidate
  // segments inside the gate: one along the rear face, one along the far (front) face.
  const Eigen::Vector2d sensor(-10, 5);
  const PredictedObject t = Pred(0.0, 0.0, 0.0);
  WorldPoints pts;
  for (int i = 0; i <= 18; ++i) pts.push_back(-2.25, -0.9 + 0.1 * i, 1.0f, 0, 0);  // rear face
  for (int i = 0; i <= 18; ++i) pts.push_back(2.25, -0.9 + 0.1 * i, 1.0f, 0, 0);   // front face
  const Segments segs = SegmentsOf(pts, {{19, 38}, {0, 19}});
  AssociationParams params;
  params.merge_fraction = 1.1 - 0.1;  // keep merging possible; the assignment decides first
  Associator assoc(params);
  AssociationResult res;
  assoc.Run({t}, pts, segs, sensor, &res);
  ASSERT_FALSE(res.track_points[0].empty());
  // The assigned part is the rear face (indices 0..18); the front part is merged afterwards
  // (it lies fully inside the gate), so check the assignment's cost is the rear face's: ~0.
  EXPECT_LT(res.track_cost[0], 0.05);
}

TEST(AssociatorTest, ValidateNamesTheKey) {
  AssociationParams p;
  std::string error;
  EXPECT_TRUE(p.Validate(&error));
  p.min_inside_fraction = 0.0;
  EXPECT_FALSE(p.Validate(&error));
  EXPECT_NE(error.find("min_inside_fraction = 0"), std::string::npos);
}

}  // namespace
}  // namespace vtrack
