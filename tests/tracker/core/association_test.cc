// Association: the assignment solver against brute force, and scenes with known answers
// (swapped inputs, a merged segment split between two cars, a car cut in two by an occluder,
// a new object, and the preference for returns on the visible faces).
#include "tracker/core/association.h"
#include "tracker/core/grazing_pieces.h"

#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <iostream>
#include <numeric>
#include <random>
#include <set>
#include <string>
#include <vector>

#include "base/angle.h"
#include "tests/support/params_check.h"
#include "tracker/core/segmentation.h"

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
  // (it lies fully inside the gate), so check the assignment's cost is the rear face's: ~0 (it
  // holds as many of the gate's returns as the front part: no share of them counts against it).
  EXPECT_LT(res.track_cost[0], 0.05);
}

TEST(AssociatorTest, AFewReturnsOnAFaceDoNotWinTheTrackOverTheRestOfItsObject) {
  // The sensor behind-left of a parked car's track (rear and left faces visible), whose shape
  // is known only from a partial view (1 m x 0.5 m seen). In its gate: 4 returns exactly on the
  // rear face (a fragment), and the car's side, 60 returns 0.3 m outside the predicted left
  // face. By face distance alone the fragment wins (0 against 0.3 m); the side, stretching the
  // track beyond what it has seen, cannot merge then and is ignored on its rectangle: the car's
  // returns are lost. With the share of the gate's returns the fragment holds fewer than the
  // side, the side wins.
  const Eigen::Vector2d sensor(-10, 5);
  PredictedObject t = Pred(0.0, 0.0, 0.0);
  t.seen_length = 1.0;
  t.seen_width = 0.5;
  WorldPoints pts;
  for (int i = 0; i < 4; ++i) pts.push_back(-2.25, -0.2 + 0.1 * i, 1.0f, 0, 0);
  for (int i = 0; i < 60; ++i) pts.push_back(-2.0 + 3.9 * i / 59.0, 1.2, 1.0f, 0, 0);
  const Segments segs = SegmentsOf(pts, {{0, 4}, {4, 64}});
  AssociationParams params;
  Associator assoc(params);
  AssociationResult res;
  assoc.Run({t}, pts, segs, sensor, &res);
  // Assigned: the side, at its face distance alone (it holds the most of the gate's returns; the
  // fragment pays outside_penalty x 56 / 64 on top of its 0).
  EXPECT_NEAR(res.track_cost[0], 0.3, 1e-3);
  int side = 0;
  for (const std::int32_t i : res.track_points[0]) side += i >= 4;
  EXPECT_EQ(side, 60);
}

// First hit of the ray from `sensor` at bearing `b` on the faces of `boxes`: the box index, or
// -1; *hit is the point. Ray against each face segment (independent of the code under test).
int CastRay(const std::vector<OrientedBox>& boxes, const Eigen::Vector2d& sensor, double b,
            Eigen::Vector2d* hit) {
  const Eigen::Vector2d d(std::cos(b), std::sin(b));
  double best = 1e300;
  int which = -1;
  for (std::size_t k = 0; k < boxes.size(); ++k) {
    for (int f = 0; f < 4; ++f) {
      Eigen::Vector2d a, c;
      boxes[k].FaceEndpoints(static_cast<Face>(f), &a, &c);
      const Eigen::Vector2d e = c - a;
      const double den = d.x() * e.y() - d.y() * e.x();
      if (std::abs(den) < 1e-12) continue;
      const Eigen::Vector2d w = a - sensor;
      const double t = (w.x() * e.y() - w.y() * e.x()) / den;  // along the ray
      const double u = (w.x() * d.y() - w.y() * d.x()) / den;  // along the face
      if (t > 0.0 && u >= 0.0 && u <= 1.0 && t < best) {
        best = t;
        which = static_cast<int>(k);
      }
    }
  }
  *hit = sensor + best * d;
  return which;
}

// A 3-D scanner (0.176 deg azimuth steps, 5 rings on each face) passing a parked row 2 m to
// its side: each car's side is seen at 3-6 deg, one column of returns per step, metres apart.
struct RowScene {
  WorldPoints pts;
  std::vector<int> car;  // per return: index of the car hit
  Segments segments;
};

RowScene ParkedRow(const Eigen::Vector2d& sensor) {
  std::vector<OrientedBox> cars;
  for (int k = 0; k < 4; ++k) cars.push_back({{2.85, 18.0 + 7.5 * k}, kPi / 2, 4.5, 1.8});
  RowScene s;
  const double step = DegToRad(360.0 / 2048.0);
  for (double b = DegToRad(60.0); b < DegToRad(89.0); b += step) {
    Eigen::Vector2d hit;
    const int k = CastRay(cars, sensor, b, &hit);
    if (k < 0) continue;
    for (int ring = 0; ring < 5; ++ring) {
      s.pts.push_back(hit.x(), hit.y(), 0.3f + 0.25f * static_cast<float>(ring),
                      static_cast<std::int32_t>(s.pts.size()), static_cast<std::int16_t>(ring));
      s.car.push_back(k);
    }
  }
  SegmentationParams sp;
  Segmenter(sp).Run(s.pts, /*scan_line=*/false, sensor, &s.segments);
  return s;
}

// Cars of each segment, and segments of each car.
void Tally(const RowScene& s, std::vector<std::set<int>>* cars_of_segment,
           std::vector<std::set<int>>* segments_of_car) {
  cars_of_segment->assign(s.segments.segments.size(), {});
  segments_of_car->assign(4, {});
  for (std::size_t g = 0; g < s.segments.segments.size(); ++g) {
    const Segment& seg = s.segments.segments[g];
    for (std::int32_t i = seg.begin; i < seg.end; ++i) {
      const int k = s.car[static_cast<std::size_t>(s.segments.point[static_cast<std::size_t>(i)])];
      (*cars_of_segment)[g].insert(k);
      (*segments_of_car)[static_cast<std::size_t>(k)].insert(static_cast<int>(g));
    }
  }
}

TEST(JoinGrazingPiecesTest, ColumnsOfEachParkedCarBecomeOneSegmentWithoutChainingCars) {
  const Eigen::Vector2d sensor(0, 0);
  RowScene s = ParkedRow(sensor);
  std::vector<std::set<int>> cars_of_segment, segments_of_car;
  Tally(s, &cars_of_segment, &segments_of_car);
  // Without joining, the cars 23-38 m away fall apart into columns.
  for (int k = 1; k < 3; ++k) EXPECT_GE(segments_of_car[static_cast<std::size_t>(k)].size(), 3u) << "car " << k;
  const std::size_t returns = s.segments.point.size();
  const int joins = JoinGrazingPieces(s.pts, sensor, GrazingJoinParams{}, &s.segments);
  EXPECT_GT(joins, 0);
  EXPECT_EQ(s.segments.point.size(), returns);  // no return lost or duplicated
  Tally(s, &cars_of_segment, &segments_of_car);
  for (std::size_t g = 0; g < cars_of_segment.size(); ++g) {
    EXPECT_EQ(cars_of_segment[g].size(), 1u) << "segment " << g << " holds returns of several cars";
    const Segment& seg = s.segments.segments[g];
    Eigen::Vector2d lo = Eigen::Vector2d::Constant(1e300), hi = -lo, sum = Eigen::Vector2d::Zero();
    for (std::int32_t i = seg.begin; i < seg.end; ++i) {
      const auto p = static_cast<std::size_t>(s.segments.point[static_cast<std::size_t>(i)]);
      const Eigen::Vector2d q(s.pts.x[p], s.pts.y[p]);
      lo = lo.cwiseMin(q);
      hi = hi.cwiseMax(q);
      sum += q;
    }
    EXPECT_NEAR((seg.min - lo).norm() + (seg.max - hi).norm(), 0.0, 1e-9);
    EXPECT_NEAR((seg.centroid - sum / seg.size()).norm(), 0.0, 1e-9);
  }
  // The nearest car's rear face and first metre of side are one dense segment (larger than a
  // piece: not joined; association absorbs columns on a track's rectangle), its columns another.
  EXPECT_EQ(segments_of_car[0].size(), 2u);
  for (int k = 1; k < 4; ++k) {
    EXPECT_EQ(segments_of_car[static_cast<std::size_t>(k)].size(), 1u) << "car " << k;
  }
}

TEST(JoinGrazingPiecesTest, PiecesSideBySideAcrossTheRayOrTooFarApartStaySeparate) {
  const Eigen::Vector2d sensor(0, 0);
  WorldPoints pts;
  // Two poles 1.5 m apart across the ray at 20 m, and two columns 4 m apart along it.
  for (const Eigen::Vector2d& c : {Eigen::Vector2d(20.0, -0.75), Eigen::Vector2d(20.0, 0.75),
                                  Eigen::Vector2d(0.5, 30.0), Eigen::Vector2d(0.6, 34.0)}) {
    for (int i = 0; i < 4; ++i) {
      pts.push_back(c.x() + 0.05 * (i % 2), c.y() + 0.05 * (i / 2), 1.0f, static_cast<std::int32_t>(pts.size()), 0);
    }
  }
  Segments segs = SegmentsOf(pts, {{0, 4}, {4, 8}, {8, 12}, {12, 16}});
  for (auto& g : segs.segments) g.centroid = 0.5 * (g.min + g.max);
  EXPECT_EQ(JoinGrazingPieces(pts, sensor, GrazingJoinParams{}, &segs), 0);
  EXPECT_EQ(segs.segments.size(), 4u);
  // Joining off: nothing changes even for the parked row.
  RowScene s = ParkedRow(sensor);
  const std::size_t n = s.segments.segments.size();
  GrazingJoinParams off;
  off.max_piece = 0.0;
  EXPECT_EQ(JoinGrazingPieces(s.pts, sensor, off, &s.segments), 0);
  EXPECT_EQ(s.segments.segments.size(), n);
}

// An 8 x 2.5 m truck coming head-on (centre (-1.75, 44), heading -90 deg) seen from the origin:
// its front face (y = 40) and, behind it, its side edge-on (x = -0.5) as columns of two returns
// along the ray. Its track has the default 4.5 m length. The columns within 12 m of the front
// are the truck's own side and join its track; a column beyond, and the front face of a car
// following it (across the ray), are new objects. Without a mover the columns are new objects.
TEST(AssociatorTest, SideOfALongMoverSeenEdgeOnJoinsIt) {
  const Eigen::Vector2d sensor(0, 0);
  WorldPoints pts;
  auto add = [&](double x, double y) {
    pts.push_back(x, y, 1.0f, static_cast<std::int32_t>(pts.size()), 0);
  };
  for (int i = 0; i <= 25; ++i) add(-3.0 + 0.1 * i, 40.0);  // front face: 26 returns
  const int front = static_cast<int>(pts.size());
  add(-0.5, 46.5);  // side columns behind the front
  add(-0.5, 46.8);
  add(-0.5, 48.5);
  add(-0.5, 48.9);
  const int columns = static_cast<int>(pts.size());
  add(-0.5, 53.0);  // 13 m behind the front
  add(-0.5, 53.4);
  const int far = static_cast<int>(pts.size());
  for (int i = 0; i <= 18; ++i) add(-2.6 + 0.1 * i, 50.0);  // a following car's front face
  const Segments segs = SegmentsOf(
      pts, {{0, front}, {front, front + 2}, {front + 2, columns}, {columns, far},
            {far, static_cast<int>(pts.size())}});
  PredictedObject truck = Pred(-1.75, 42.25, -kPi / 2);
  truck.box.width = 2.5;
  truck.rear_sign = -1;  // box x points along the motion (-y): the rear is at -x
  Associator assoc(AssociationParams{});
  AssociationResult res;
  assoc.Run({truck}, pts, segs, sensor, &res);
  EXPECT_EQ(static_cast<int>(res.track_points[0].size()), columns);
  EXPECT_EQ(res.num_merged, 2);
  ASSERT_EQ(res.new_objects.size(), 2u);
  EXPECT_EQ(res.new_objects[0].front(), columns);
  EXPECT_EQ(res.new_objects[1].front(), far);

  truck.rear_sign = 0;  // not a mover
  assoc.Run({truck}, pts, segs, sensor, &res);
  EXPECT_EQ(static_cast<int>(res.track_points[0].size()), front);
  EXPECT_EQ(res.new_objects.size(), 4u);
}

// A wall of 200 returns, 0.2 m apart along y = 0 from x = 0, and one track whose gate spans
// 11.9 m of it: with exactly the share a candidate needs inside the gate (min_inside_fraction
// 0.3: 60 of 200) the wall is a candidate of the track, with one return fewer it is not (the
// early stop of the cost's loop and its count of the returns needed, at their limit).
TEST(AssociatorTest, ALongWallIsACandidateOfAGateHoldingExactlyTheShareItNeeds) {
  const Eigen::Vector2d sensor(6.0, -20.0);
  WorldPoints pts;
  for (int i = 0; i < 200; ++i) pts.push_back(0.2 * i, 0.0, 1.0f, i, 0);
  const Segments segs = SegmentsOf(pts, {{0, 200}});
  AssociationParams params;
  params.miss_cost = 1e3;  // a candidate is assigned, whatever its cost
  const auto assigned = [&](double centre_x) {
    PredictedObject t = Pred(centre_x, 0.0, 0.0, /*established=*/false);
    t.position_std = 0.0;               // gate margin: gate_margin alone, 0.8 m
    t.box.length = 2.0 * (5.95 - 0.8);  // the gate reaches 5.95 m either side of the centre
    Associator assoc(params);
    AssociationResult res;
    assoc.Run({t}, pts, segs, sensor, &res);
    return res.track_points.at(0).size();
  };
  EXPECT_EQ(assigned(5.9), 200u);  // x in [-0.05, 11.85]: returns 0..59, 60 of them
  EXPECT_EQ(assigned(5.8), 0u);    // x in [-0.15, 11.75]: returns 0..58, 59
  EXPECT_EQ(assigned(45.7), 0u);   // x in [39.75, 51.65], past the wall's end: 1 return
}

TEST(AssociatorTest, AnyNumberOfThreadsGivesTheSameAssociation) {
  // A car park of 400 cars in 25 rows 4 m apart, either side of the sensor (neighbours' gates
  // overlap, so tracks compete for parts), tracked by 375 tracks predicted up to 0.6 m off
  // (25 cars are new, a few tracks tentative); some pairs of neighbours in one segment (split
  // between their tracks), some cars cut in two segments (one merged into the track that takes
  // the other): enough segments and tracks for the parts and the candidate pairs to be shared
  // among threads in several blocks. One thread's result is what any number of threads must
  // give, after a smaller scan through the same associator. (The order of the pairs is not seen here:
  // the assignment depends on it only at exact ties. The TRACKS digests of KITTI 0000, 238
  // tracks a scan, are the check of the whole with two threads.)
  const Eigen::Vector2d sensor(0, 0);
  std::mt19937 rng(17);
  std::uniform_real_distribution<double> off(-0.6, 0.6), yaw(-0.1, 0.1);
  WorldPoints pts;
  std::vector<std::pair<int, int>> ranges;
  std::vector<PredictedObject> tracks;
  for (int k = 0; k < 400; ++k) {
    const int row = k / 16;
    const double x = -50.0 + 6.5 * (k % 16);
    const double y = (row % 2 == 0 ? 1.0 : -1.0) * (5.0 + 4.0 * (row / 2));
    const OrientedBox car{{x, y}, yaw(rng), 4.5, 1.8};
    const int first = static_cast<int>(pts.size());
    AddBoxReturns(car, sensor, &pts);
    const int last = static_cast<int>(pts.size());
    if (k % 7 == 3 && k % 16 != 0) {
      ranges.back().second = last;  // one segment with the car before
    } else if (k % 9 == 4) {
      ranges.push_back({first, (first + last) / 2});  // cut in two
      ranges.push_back({(first + last) / 2, last});
    } else {
      ranges.push_back({first, last});
    }
    if (k % 16 != 5) {
      tracks.push_back(Pred(x + off(rng), y + off(rng), car.theta + yaw(rng), k % 11 != 0));
    }
  }
  const Segments segs = SegmentsOf(pts, ranges);
  auto run = [&](int threads) {
    WorkerPool pool(threads);
    Associator assoc(AssociationParams{});
    assoc.SetPool(&pool);
    AssociationResult res;
    if (threads > 1) {
      // A scan before, with a third of the segments and tracks (fewer blocks): what it leaves in
      // the associator's buffers must not show in the next.
      const std::size_t some_ranges = ranges.size() / 3;
      const std::vector<std::pair<int, int>> first_ranges(ranges.begin(), ranges.begin() + static_cast<std::ptrdiff_t>(some_ranges));
      const std::vector<PredictedObject> first_tracks(tracks.begin(), tracks.begin() + static_cast<std::ptrdiff_t>(tracks.size() / 3));
      assoc.Run(first_tracks, pts, SegmentsOf(pts, first_ranges), sensor, &res);
    }
    assoc.Run(tracks, pts, segs, sensor, &res);
    return res;
  };
  const AssociationResult one = run(1);
  ASSERT_EQ(one.track_points.size(), tracks.size());
  std::size_t assigned = 0;
  for (const auto& idx : one.track_points) assigned += idx.empty() ? 0 : 1;
  EXPECT_GT(assigned, 300u);
  EXPECT_GT(one.num_split, 0);
  EXPECT_GT(one.num_merged, 0);
  EXPECT_FALSE(one.new_objects.empty());
  std::cout << assigned << " of " << tracks.size() << " tracks assigned, " << one.num_split
            << " segments split, " << one.num_merged << " merged, " << one.new_objects.size()
            << " new objects\n";
  for (const int threads : {2, 3}) {
    SCOPED_TRACE("threads " + std::to_string(threads));
    const AssociationResult many = run(threads);
    EXPECT_EQ(many.track_points, one.track_points);
    ASSERT_EQ(many.track_cost.size(), one.track_cost.size());
    for (std::size_t j = 0; j < one.track_cost.size(); ++j) {
      // Bit for bit (NaN for a track left unassigned).
      EXPECT_TRUE(many.track_cost[j] == one.track_cost[j] ||
                  (std::isnan(many.track_cost[j]) && std::isnan(one.track_cost[j])))
          << "track " << j;
    }
    EXPECT_EQ(many.new_objects, one.new_objects);
    EXPECT_EQ(many.num_split, one.num_split);
    EXPECT_EQ(many.num_merged, one.num_merged);
    EXPECT_EQ(many.num_ignored, one.num_ignored);
  }
}

TEST(AssociatorTest, ValidateNamesTheKey) {
  AssociationParams p;
  EXPECT_TRUE(testing::Accepted(p));
  p.min_inside_fraction = 0.0;
  EXPECT_TRUE(testing::RefusedSaying(p, {"min_inside_fraction = 0"}));
  p = AssociationParams{};
  p.mover_column_deg = 90.0;
  EXPECT_TRUE(testing::RefusedSaying(p, {"association.mover_column_deg = 90"}));
  GrazingJoinParams g;
  g.max_gap = -1.0;
  EXPECT_TRUE(testing::RefusedSaying(g, {"grazing.max_gap = -1"}));
}

}  // namespace
}  // namespace vtrack
