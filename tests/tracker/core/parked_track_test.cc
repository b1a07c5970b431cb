// TrackManager: a parked track that is missed stays where it was last measured, with the gate of
// its rectangle only, and coasts longer than a moving one may (track_manager.h, life cycle).
// The truth is the scene itself: a car parked at a known place, measured, then hidden.
#include "tracker/core/track_manager.h"

#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <cstdint>
#include <string>
#include <vector>

#include "base/angle.h"
#include "tracker/core/ekf.h"
#include "tracker/core/range_profile.h"

namespace vtrack {
namespace {

// The corner of a car parked at (20, 5), heading 0, 4.5 x 1.8 m, seen from the origin: its rear
// face (x = 17.75) and its right side (y = 4.1), as returns relative to the origin (20, 5).
PointSet ParkedCorner(std::int64_t utime) {
  PointSet p;
  p.origin = Eigen::Vector2d(20.0, 5.0);
  for (double y = 4.1; y <= 5.9 + 1e-9; y += 0.05) {
    p.x.push_back(static_cast<float>(17.75 - 20.0));
    p.y.push_back(static_cast<float>(y - 5.0));
  }
  for (double x = 17.85; x <= 22.25 + 1e-9; x += 0.1) {
    p.x.push_back(static_cast<float>(x - 20.0));
    p.y.push_back(static_cast<float>(4.1 - 5.0));
  }
  p.mean_utime = utime;
  p.extent = std::hypot(4.5, 1.8);
  return p;
}

constexpr std::int64_t kStep = 100'000;  // [us] 10 Hz

TrackManagerParams ParamsIn(TrackerMode mode) {
  TrackManagerParams p;
  p.mode = mode;
  return p;
}

// A track manager with the default parameters (or those of a mode), the sensor at the origin,
// and the scans' clock.
struct Scans {
  Scans() = default;
  explicit Scans(TrackerMode mode) : params(ParamsIn(mode)) {}

  const Ekf ekf;
  const TrackManagerParams params{};
  TrackManager m{params, ekf, FitParams(), ShapeParams()};
  const Eigen::Vector2d sensor{0.0, 0.0};
  std::int64_t t = 1'000'000'000;  // [us] the current scan's time

  // Scan 0, at t: a track is started from p. Returns whether it was.
  bool Create(const PointSet& p) {
    const bool created = m.Create(p, sensor, 1);
    m.EndScan(t);
    return created;
  }
  // Scan k, at t: track 0 is measured by p.
  void Update(int k, const PointSet& p) {
    m.Update(0, p, sensor, static_cast<std::uint64_t>(k), nullptr);
    m.EndScan(t);
  }
};

// Creates the parked car's track from its corner and updates it for 2 s with the same returns
// (confirmed, not a mover).
void SeeParkedCornerFor2s(Scans* s) {
  EXPECT_TRUE(s->Create(ParkedCorner(s->t)));
  for (int k = 1; k <= 20; ++k) {
    s->t += kStep;
    s->Update(k, ParkedCorner(s->t));
  }
}

TEST(ParkedTrackTest, MissedParkedTrackIsLookedForWhereItWasWithoutGateGrowthAndCoastsLonger) {
  Scans s;
  SeeParkedCornerFor2s(&s);
  TrackManager& m = s.m;
  const TrackManagerParams& params = s.params;
  std::int64_t& t = s.t;
  ASSERT_EQ(m.tracks().size(), 1u);
  ASSERT_NE(m.tracks()[0].status, TrackStatus::kTentative);
  ASSERT_FALSE(m.tracks()[0].mover);
  std::vector<PredictedObject> seen;
  m.Predict(t + kStep, &seen);
  ASSERT_EQ(seen.size(), 1u);
  EXPECT_GT(seen[0].position_std, 0.0);  // updated on the last scan: the usual grown gate
  // The rectangle covers the car: centre within 0.3 m of (20, 5) along the side seen whole.
  EXPECT_NEAR(seen[0].box.center.y(), 5.0, 0.3);

  // Hidden: missed on every scan from now on.
  const Eigen::Vector2d last_centre = seen[0].box.center;
  const std::int64_t last_update = t;
  std::vector<PredictedObject> hidden;
  for (int k = 1; k <= 20; ++k) {  // 2 s hidden: longer than coast_max_s (1.5 s)
    t += kStep;
    m.Predict(t, &hidden);
    ASSERT_EQ(hidden.size(), 1u) << "deleted after " << (t - last_update) * 1e-6 << " s";
    if (k >= 2) {  // missed on the previous scan: where it was, gate = rectangle + gate_margin
      EXPECT_EQ(hidden[0].position_std, 0.0);
      EXPECT_NEAR((hidden[0].box.center - last_centre).norm(), 0.0, 0.05);
    }
    m.Miss(0);
    m.EndScan(t);
  }
  EXPECT_GT(static_cast<double>(t - last_update) * 1e-6, params.coast_max_s);
  ASSERT_EQ(m.tracks().size(), 1u);  // a parked car behind stopped traffic is kept
  EXPECT_EQ(m.tracks()[0].status, TrackStatus::kCoasting);
  // ... but not beyond parked_coast_max_s (or the position std bound, whichever comes first).
  for (int k = 0; k < 20 && !m.tracks().empty(); ++k) {
    t += kStep;
    m.Miss(0);
    m.EndScan(t);
  }
  EXPECT_TRUE(m.tracks().empty());
  EXPECT_LE(static_cast<double>(t - last_update) * 1e-6, params.parked_coast_max_s + 0.15);
}

// Returns of the parked car at (20, 5) at the world points xy, relative to its centre, spanning
// extent [m].
PointSet CarReturns(std::int64_t utime, const std::vector<Eigen::Vector2d>& xy, double extent) {
  PointSet p;
  p.origin = Eigen::Vector2d(20.0, 5.0);
  for (const Eigen::Vector2d& q : xy) {
    p.x.push_back(static_cast<float>(q.x() - p.origin.x()));
    p.y.push_back(static_cast<float>(q.y() - p.origin.y()));
  }
  p.mean_utime = utime;
  p.extent = extent;
  return p;
}

// Three returns on the car's rear face: too few for a fit (FitParams::min_points), so they give
// the track no accepted update.
PointSet TooFewToFit(std::int64_t utime) {
  return CarReturns(utime, {{17.75, 4.6}, {17.75, 5.0}, {17.75, 5.4}}, 0.8);
}

// The status says whether a scan saw the object, not whether it moved its state: a confirmed
// track given returns that update none of its hypotheses stays confirmed (its object is there),
// while the scans without an accepted update still count towards its deletion, as a hidden
// one's do; a track given no returns coasts.
TEST(ParkedTrackTest, ReturnsWithoutAnAcceptedUpdateKeepItConfirmedButDoNotKeepItAlive) {
  Scans s;
  SeeParkedCornerFor2s(&s);
  TrackManager& m = s.m;
  ASSERT_EQ(m.tracks().size(), 1u);
  ASSERT_EQ(m.tracks()[0].status, TrackStatus::kConfirmed);
  const std::int64_t last_update = s.t;
  int scans = 0;
  for (int k = 21; k <= 60 && !m.tracks().empty(); ++k) {
    s.t += kStep;
    s.Update(k, TooFewToFit(s.t));
    if (m.tracks().empty()) break;
    ++scans;
    EXPECT_EQ(m.tracks()[0].consecutive_misses, scans) << "scan " << k << ": an update was accepted";
    EXPECT_EQ(m.tracks()[0].last_update_utime, last_update);
    EXPECT_EQ(m.tracks()[0].status, TrackStatus::kConfirmed) << "scan " << k;
  }
  EXPECT_TRUE(m.tracks().empty()) << "kept " << scans << " scans without an accepted update";
  const double kept_s = static_cast<double>(s.t - last_update) * 1e-6;
  EXPECT_GT(kept_s, s.params.coast_max_s);
  EXPECT_LE(kept_s, s.params.parked_coast_max_s + 0.15);

  // The same car given no returns: coasting from the first such scan.
  Scans hidden;
  SeeParkedCornerFor2s(&hidden);
  hidden.t += kStep;
  hidden.m.Miss(0);
  hidden.m.EndScan(hidden.t);
  ASSERT_EQ(hidden.m.tracks().size(), 1u);
  EXPECT_EQ(hidden.m.tracks()[0].status, TrackStatus::kCoasting);
}

// The west 0.9 m of the same car's side, the rest hidden (a car passing in front): where along
// the side that piece lies is not measured, so the same view scan after scan must not move the
// parked car's track along its side (its middle, 1.7 m west of the car's centre, pulled it: the
// track ended 1.9 m west without the rule).
PointSet HiddenButForTheSidesWestEnd(std::int64_t utime) {
  std::vector<Eigen::Vector2d> side;
  for (double x = 17.85; x <= 18.75 + 1e-9; x += 0.05) side.emplace_back(x, 4.1);
  return CarReturns(utime, side, 0.9);
}

TEST(ParkedTrackTest, PartialViewOfAParkedCarKeepsItsTrackInPlace) {
  Scans s;
  SeeParkedCornerFor2s(&s);
  ASSERT_EQ(s.m.tracks().size(), 1u);
  ASSERT_FALSE(s.m.tracks()[0].mover);
  for (int k = 21; k <= 50; ++k) {  // 3 s of the partial view
    s.t += kStep;
    s.Update(k, HiddenButForTheSidesWestEnd(s.t));
  }
  ASSERT_EQ(s.m.tracks().size(), 1u);
  const OrientedBox box = s.m.Box(0);
  EXPECT_NEAR(box.center.x(), 20.0, 0.3);
  EXPECT_NEAR(box.center.y(), 5.0, 0.3);
}

// A car parked at (28, -4.6), heading 0, 4.5 x 1.8 m, seen from the origin end-on: returns on its
// rear face (x = 25.75) over [y_lo, y_hi], and on its right side (y = -3.7) from the rear corner
// to x = side_to (none if side_to <= 25.75), relative to the origin (28, -4.6); the outline of a
// 3-D cloud, as vtrack-tracker fits it (the 2-D fit leaves out faces seen below 10 deg).
PointSet RearView(std::int64_t utime, double y_lo, double y_hi, double side_to) {
  PointSet p;
  p.origin = Eigen::Vector2d(28.0, -4.6);
  for (double y = y_lo; y <= y_hi + 1e-9; y += 0.1) {
    p.x.push_back(static_cast<float>(25.75 - 28.0));
    p.y.push_back(static_cast<float>(y + 4.6));
  }
  for (double x = 25.85; x <= side_to + 1e-9; x += 0.1) {
    p.x.push_back(static_cast<float>(x - 28.0));
    p.y.push_back(static_cast<float>(-3.7 + 4.6));
  }
  Eigen::Vector2d lo(25.75, y_lo), hi(std::max(25.75, side_to), y_hi);
  if (side_to > 25.75) hi.y() = -3.7;
  p.extent = (hi - lo).norm();
  p.mean_utime = utime;
  p.outline = true;  // a 3-D cloud's outline (the side, seen at 8 deg, is fitted)
  return p;
}

// Axis error [deg] of a heading against the truth's 0, modulo 180 deg.
double AxisErrorDeg(double theta) {
  return std::abs(RadToDeg(std::remainder(theta, kPi)));
}

// The one track is RearView's car as a rectangle: along its axis, centred within 0.3 m.
void ExpectTheRearViewsCarAsOneRectangle(const TrackManager& m) {
  ASSERT_EQ(m.tracks().size(), 1u);
  EXPECT_FALSE(m.tracks()[0].small_object);
  const OrientedBox box = m.Box(0);
  EXPECT_LT(AxisErrorDeg(box.theta), 5.0);
  EXPECT_NEAR(box.center.x(), 28.0, 0.3);
  EXPECT_NEAR(box.center.y(), -4.6, 0.3);
}

TEST(ParkedTrackTest, RearFaceSeenWholeBesideTheFirstMetreOfTheSideKeepsTheAxis) {
  // The rear face seen whole (1.8 m) is an end: the track starts along the car. Then the first
  // 1.2 m of its side shows too: the shape's "width" (1.8) now exceeds 1.3 x its "length" (1.2
  // seen), and turning the axis by 90 deg (a side 1.8 m long) put the centre 1.4 m off.
  Scans s;
  ASSERT_TRUE(s.Create(RearView(s.t, -5.5, -3.7, 0.0)));
  for (int k = 1; k <= 40; ++k) {
    s.t += kStep;
    s.Update(k, RearView(s.t, -5.5, -3.7, k <= 10 ? 0.0 : 26.95));
    ASSERT_EQ(s.m.tracks().size(), 1u);
    const OrientedBox box = s.m.Box(0);
    EXPECT_LT(AxisErrorDeg(box.theta), 5.0) << "scan " << k;
    EXPECT_LT((box.center - Eigen::Vector2d(28.0, -4.6)).norm(), 0.5) << "scan " << k;
  }
}

// The range profile of the returns p (relative to p.origin) and of the points extra (world
// frame), seen from the origin, binned as vtrack-tracker bins it (outline.bin_deg).
RangeProfile ProfileOf(const PointSet& p, const std::vector<Eigen::Vector2d>& extra) {
  std::vector<double> x, y;
  for (std::size_t i = 0; i < p.size(); ++i) {
    x.push_back(p.origin.x() + p.x[i]);
    y.push_back(p.origin.y() + p.y[i]);
  }
  for (const Eigen::Vector2d& e : extra) {
    x.push_back(e.x());
    y.push_back(e.y());
  }
  RangeProfile profile;
  profile.Build(Eigen::Vector2d::Zero(), x, y, 0.2);
  return profile;
}

TEST(ParkedTrackTest, ASideSeenShorterThanBeforeIsNotTakenForAnEndFace) {
  // The parked car at (20, 5) seen at its corner for 2 s (the rear face and the whole 4.4 m side:
  // a length estimate of about 4.5 m). Then the far part of the side goes missing (1.8 m of it
  // seen, nothing nearer beyond: the range profile cannot tell a missing part from free space),
  // and a post 10 m away hides the rear face's far end. The 1.8 m piece of the side is not a
  // whole end face: the axis stays along the car (without asking the shape estimate it turns
  // by 90 deg, its centre 1.4 m off).
  Scans s;
  ASSERT_TRUE(s.Create(ParkedCorner(s.t)));
  for (int k = 1; k <= 20; ++k) {
    s.t += kStep;
    const PointSet p = ParkedCorner(s.t);
    const RangeProfile profile = ProfileOf(p, {});
    s.m.Update(0, p, s.sensor, static_cast<std::uint64_t>(k), nullptr, &profile);
    s.m.EndScan(s.t);
  }
  ASSERT_EQ(s.m.tracks().size(), 1u);
  ASSERT_TRUE(s.m.tracks()[0].hyps[0].length_est.has_value());
  ASSERT_GT(*s.m.tracks()[0].hyps[0].length_est, 4.0);
  const double post_bearing = std::atan2(5.9, 17.75) + DegToRad(0.5);
  const std::vector<Eigen::Vector2d> post = {10.0 * Eigen::Vector2d(std::cos(post_bearing), std::sin(post_bearing))};
  for (int k = 21; k <= 40; ++k) {
    s.t += kStep;
    PointSet p = ParkedCorner(s.t);
    PointSet cut = p;
    cut.x.clear();
    cut.y.clear();
    for (std::size_t i = 0; i < p.size(); ++i) {
      if (p.origin.x() + p.x[i] > 19.65 + 1e-6) continue;  // the side's far part is missing
      cut.x.push_back(p.x[i]);
      cut.y.push_back(p.y[i]);
    }
    cut.extent = std::hypot(1.9, 1.8);
    const RangeProfile profile = ProfileOf(cut, post);
    s.m.Update(0, cut, s.sensor, static_cast<std::uint64_t>(k), nullptr, &profile);
    s.m.EndScan(s.t);
    ASSERT_EQ(s.m.tracks().size(), 1u);
    const OrientedBox box = s.m.Box(0);
    EXPECT_LT(AxisErrorDeg(box.theta), 5.0) << "scan " << k;
    EXPECT_LT((box.center - Eigen::Vector2d(20.0, 5.0)).norm(), 0.5) << "scan " << k;
  }
}

TEST(ParkedTrackTest, FarCarFirstSeenAsAFewReturnsBecomesARectangleOnceItsRearFaceIsSeenWhole) {
  // First 0.6 m of the rear face (a small object, measured by its centroid), then the whole
  // face (1.8 m): the track becomes a vehicle's rectangle, the face its end, the centre half a
  // default length behind it. (Before: it stayed a centroid at the face, 2.25 m from the centre,
  // until the segment spanned 2 m; and the face, judged against a small object's 1 m width,
  // was taken for a side.)
  Scans s;
  ASSERT_TRUE(s.Create(RearView(s.t, -4.9, -4.3, 0.0)));
  ASSERT_EQ(s.m.tracks().size(), 1u);
  ASSERT_TRUE(s.m.tracks()[0].small_object);
  for (int k = 1; k <= 20; ++k) {
    s.t += kStep;
    const bool whole = k > 5;
    s.Update(k, whole ? RearView(s.t, -5.5, -3.7, 0.0) : RearView(s.t, -4.9, -4.3, 0.0));
  }
  ExpectTheRearViewsCarAsOneRectangle(s.m);
}

TEST(ParkedTrackTest, GrownSmallObjectWhoseFitFailsStaysASmallObjectUntilOneFits) {
  // A small object's segment grows to the rectangle extent (1.8 m) but holds 4 returns, fewer than
  // a fit needs (FitParams::min_points 5): the conversion's fit fails, and the track stays a
  // small object measured by its centroid (neither lost nor left a rectangle without a fit).
  // Once the whole face is seen it becomes the rectangle. A single-plane scan's segments (not a
  // 3-D outline, whose fits need only TrackManagerParams::outline_min_points).
  const auto view = [](std::int64_t utime, double y_lo, double y_hi) {
    PointSet p = RearView(utime, y_lo, y_hi, 0.0);
    p.outline = false;
    return p;
  };
  ASSERT_EQ(FitParams().min_points, 5);  // the fit parameters of Scans
  Scans s;
  ASSERT_TRUE(s.Create(view(s.t, -4.9, -4.3)));
  ASSERT_TRUE(s.m.tracks()[0].small_object);
  const auto sparse = [&view](std::int64_t utime) {  // 4 returns over the whole rear face
    PointSet p = view(utime, -5.5, -3.7);
    PointSet q = p;
    q.x.clear();
    q.y.clear();
    for (std::size_t i = 0; i < p.size(); i += 6) {
      q.x.push_back(p.x[i]);
      q.y.push_back(p.y[i]);
    }
    return q;
  };
  ASSERT_EQ(sparse(s.t).size(), 4u);
  ASSERT_GE(sparse(s.t).extent, s.params.small_object_grown_extent);
  int k = 1;
  for (; k <= 10; ++k) {
    s.t += kStep;
    s.Update(k, sparse(s.t));
    ASSERT_EQ(s.m.tracks().size(), 1u) << "scan " << k;
    EXPECT_TRUE(s.m.tracks()[0].small_object) << "scan " << k;
    EXPECT_EQ(s.m.tracks()[0].hyps.size(), 1u) << "scan " << k;
  }
  // Measured by the centroid of the returns: on the rear face, near its middle.
  const OrientedBox small = s.m.Box(0);
  EXPECT_NEAR(small.center.x(), 25.75, 0.3);
  EXPECT_NEAR(small.center.y(), -4.6, 0.4);
  for (; k <= 25; ++k) {
    s.t += kStep;
    s.Update(k, view(s.t, -5.5, -3.7));
  }
  ExpectTheRearViewsCarAsOneRectangle(s.m);
}


// Returns of a vehicle parked beside the origin (20, 5), heading 0, relative to that origin: its
// rear face at x = rear_x from y = right_y to right_y + width (every 5 cm), and the first `side`
// metres of its right side at y = right_y (every 10 cm; none for side 0).
PointSet RearAndRightSide(std::int64_t utime, double rear_x, double right_y, double width,
                          double side) {
  PointSet p;
  p.origin = Eigen::Vector2d(20.0, 5.0);
  for (double y = right_y; y <= right_y + width + 1e-9; y += 0.05) {
    p.x.push_back(static_cast<float>(rear_x - 20.0));
    p.y.push_back(static_cast<float>(y - 5.0));
  }
  for (double x = rear_x + 0.1; x <= rear_x + side + 1e-9; x += 0.1) {
    p.x.push_back(static_cast<float>(x - 20.0));
    p.y.push_back(static_cast<float>(right_y - 5.0));
  }
  p.mean_utime = utime;
  p.extent = std::hypot(side, width);
  return p;
}

// A parked bus (12 x 2.5 m) passed by the ego: its rear face is seen whole and its side comes into
// view 0.4 m more on every scan, so the fitted rectangle grows and its centre moves along the
// side while every return stays where it was. The returns did not move: never a mover
// (ReturnsMovedWith, in the mover test).
TEST(ParkedTrackTest, AParkedBusWhoseSideComesIntoViewIsNoMover) {
  Scans s;
  auto bus = [&s](double side) { return RearAndRightSide(s.t, 14.0, 4.0, 2.5, side); };
  ASSERT_TRUE(s.Create(bus(4.0)));
  for (int k = 1; k <= 20; ++k) {
    s.t += kStep;
    s.Update(k, bus(std::min(12.0, 4.0 + 0.4 * k)));
    ASSERT_EQ(s.m.tracks().size(), 1u);
    EXPECT_FALSE(s.m.tracks()[0].mover) << "scan " << k;
  }
}

// A parked truck (10 x 2.5 m, centre (20, 5), heading 0) first seen by its rear face alone, then
// whole once what hid its side has gone. The rear face alone is taken for a side (it is longer
// than a car's default width), so the track's rectangle lies across the truck with its centre
// just behind the face; the first corner fit measures the true centre, 4 m away and turned by
// 90 deg, far beyond the gate. No return moved: the lone hypothesis restarts from the
// measurement after fail_misses rejected scans (TrackManager, "Restart of a lost still object")
// and lies on the truck from then on, instead of staying where the face alone had put it.
// In every mode: the restart keeps the hypothesis' model kind (ISM, VASM or CV).
class LostStillTest : public ::testing::TestWithParam<TrackerMode> {};

TEST_P(LostStillTest, AParkedTruckWhoseSideIsRevealedIsFollowedByItsTrack) {
  Scans s(GetParam());
  auto truck = [&s](bool side) { return RearAndRightSide(s.t, 15.0, 3.75, 2.5, side ? 10.0 : 0.0); };
  ASSERT_TRUE(s.Create(truck(false)));
  int k = 1;
  for (; k <= 20; ++k) {
    s.t += kStep;
    s.Update(k, truck(false));
  }
  ASSERT_EQ(s.m.tracks().size(), 1u);
  ASSERT_FALSE(s.m.tracks()[0].mover);
  ASSERT_EQ(s.m.tracks()[0].hyps.size(), 1u);
  // The premise: the face alone put the centre near the face, 4 m or more from the truck's.
  ASSERT_GT((s.m.Box(0).center - Eigen::Vector2d(20.0, 5.0)).norm(), 3.0);
  int most_misses = 0;  // the hypothesis' consecutive misses before the restart
  for (int j = 0; j < 15; ++j, ++k) {
    s.t += kStep;
    s.Update(k, truck(true));
    ASSERT_EQ(s.m.tracks().size(), 1u);
    EXPECT_FALSE(s.m.tracks()[0].mover) << "scan " << k;
    most_misses = std::max(most_misses, s.m.tracks()[0].hyps[0].consecutive_misses);
  }
  // The gate refused the corner fits (the premise of the restart), fail_misses - 1 counted before
  // the scan that restarted it.
  EXPECT_EQ(most_misses, s.params.fail_misses - 1);
  const OrientedBox box = s.m.Box(0);
  EXPECT_NEAR(box.center.x(), 20.0, 0.5);
  EXPECT_NEAR(box.center.y(), 5.0, 0.5);
  EXPECT_NEAR(std::abs(std::cos(box.theta)), 1.0, 0.05) << "theta " << box.theta;
  EXPECT_EQ(s.m.tracks()[0].hyps[0].consecutive_misses, 0);
  // The mode's single model (mht: the ISM a still object is tracked with).
  const ModelKind kind = GetParam() == TrackerMode::kVasm ? ModelKind::kVasm
                         : GetParam() == TrackerMode::kCv ? ModelKind::kCv
                                                          : ModelKind::kIsm;
  EXPECT_EQ(s.m.tracks()[0].hyps[0].filter.kind, kind);
}

// The same view, of an 18 m articulated truck driving away at 5 m/s: its side is revealed at
// scan 4, before six scans of evidence could make it a mover, and the gate refuses the corner
// fits (the centre 7 m from the prediction, beyond even the gate the young filter's velocity
// spread has grown; a 10 m truck's corner fit is accepted on the third scan). Its
// returns moved with the filter's velocity, so it is no lost still object: it is not restarted
// at rest (the filter keeps its velocity). Not in mode vasm: a VASM moves only along its heading,
// which the rear face alone put across the motion, so its filter never takes up the motion.
class MovingTruckTest : public ::testing::TestWithParam<TrackerMode> {};

TEST_P(MovingTruckTest, AMovingTruckWhoseSideIsRevealedIsNotRestartedAtRest) {
  Scans s(GetParam());
  constexpr double kSpeed = 5.0;  // [m/s] along x
  const std::int64_t t0 = s.t;
  auto truck = [&s, t0](bool side) {
    const double rear_x = 15.0 + kSpeed * static_cast<double>(s.t - t0) * 1e-6;
    return RearAndRightSide(s.t, rear_x, 3.75, 2.5, side ? 18.0 : 0.0);
  };
  ASSERT_TRUE(s.Create(truck(false)));
  int k = 1;
  for (; k <= 3; ++k) {
    s.t += kStep;
    s.Update(k, truck(false));
  }
  ASSERT_EQ(s.m.tracks().size(), 1u);
  ASSERT_EQ(s.m.tracks()[0].hyps.size(), 1u);
  // The premise: the filter has taken up the motion (the returns move with its velocity).
  const Ekf ekf;
  ASSERT_GT(ekf.Centre(s.m.tracks()[0].hyps[0].filter).speed, 3.0);
  for (int j = 0; j < s.params.fail_misses; ++j, ++k) {
    s.t += kStep;
    s.Update(k, truck(true));
    ASSERT_EQ(s.m.tracks().size(), 1u);
    ASSERT_FALSE(s.m.tracks()[0].mover) << "scan " << k;
  }
  const TrackHypothesis& h = s.m.tracks()[0].hyps[0];
  EXPECT_EQ(h.consecutive_misses, s.params.fail_misses);  // refused each time, not restarted
  EXPECT_GT(ekf.Centre(h.filter).speed, 3.0);
}

std::string ModeName(const ::testing::TestParamInfo<TrackerMode>& info) {
  return NameOf(info.param);
}

INSTANTIATE_TEST_SUITE_P(Modes, LostStillTest,
                         ::testing::Values(TrackerMode::kMht, TrackerMode::kIsm, TrackerMode::kVasm,
                                           TrackerMode::kCv),
                         ModeName);
INSTANTIATE_TEST_SUITE_P(Modes, MovingTruckTest,
                         ::testing::Values(TrackerMode::kMht, TrackerMode::kIsm, TrackerMode::kCv),
                         ModeName);

// The manager hands the scan's range profile to the fits of Create and Update: two parked cars'
// faces 40 m ahead, 4.5 m and 3.5 m long, 1 m apart, returns every 0.25 m (5 spacings bridge
// the gap), the rings above them seeing a wall 5 m behind the gap. With the profile each fit
// measures the larger car's face alone; without it, both faces and the gap. A profile marks a
// 3-D scan, whose fits' lengths enter the shape's histogram weighted by how well their ends were
// seen (DimensionSampleWeight against range_sigma); without one, each weighs 1.
TEST(ParkedTrackTest, ManagerGivesTheRangeProfileToItsFits) {
  PointSet p;
  p.origin = Eigen::Vector2d(40.0, 0.0);
  std::vector<double> wx, wy;
  std::vector<std::int16_t> ring;
  auto face = [&](double at, double y0, double y1, double step, int r0, int r1, bool fit) {
    for (double v = y0; v <= y1 + 1e-9; v += step) {
      if (fit) {
        p.x.push_back(static_cast<float>(at - p.origin.x()));
        p.y.push_back(static_cast<float>(v - p.origin.y()));
      }
      for (int r = r0; r <= r1; ++r) {
        wx.push_back(at);
        wy.push_back(v);
        ring.push_back(static_cast<std::int16_t>(r));
      }
    }
  };
  face(40.0, 0.5, 5.0, 0.25, 30, 35, true);
  face(40.0, -4.0, -0.5, 0.25, 30, 35, true);
  face(45.0, -6.0, 6.0, 0.02, 36, 40, false);
  p.extent = 9.0;
  RangeProfile profile;
  profile.Build(Eigen::Vector2d::Zero(), wx, wy, ring, 0.2);
  // Every pairing of the creation's scan and the update's (3-D or single-plane), so that neither
  // call can go by what the other was given.
  for (const RangeProfile* at_create : std::vector<const RangeProfile*>{nullptr, &profile}) {
    for (const RangeProfile* at_update : std::vector<const RangeProfile*>{nullptr, &profile}) {
      SCOPED_TRACE(std::string(at_create ? "profile" : "none") + " at creation, " +
                   (at_update ? "profile" : "none") + " at the update");
      Scans s;
      TrackMeasurer worker = s.m.NewMeasurer();  // as a worker thread's, made before any scan
      // The weight of a sample: 1 on a single-plane scan, else from the fit's uncertainty.
      auto weight_of = [&](const RangeProfile* given, const FitResult& f) {
        return given ? std::min(1.0, std::pow(s.params.range_sigma / f.observed_length_std_m, 2))
                     : 1.0;
      };
      p.mean_utime = s.t;
      ASSERT_TRUE(s.m.Create(p, s.sensor, 1, at_create));
      ASSERT_TRUE(s.m.tracks()[0].hyps[0].has_fit);
      EXPECT_NEAR(s.m.tracks()[0].hyps[0].fit.observed_length_m, at_create ? 4.5 : 9.0, 0.3);
      const double w0 = weight_of(at_create, s.m.tracks()[0].hyps[0].fit);
      const double t0 = static_cast<double>(s.t) * 1e-6;
      EXPECT_DOUBLE_EQ(s.m.tracks()[0].hyps[0].shape.length_histogram().TotalWeight(t0), w0);
      if (at_create) {
        EXPECT_LT(w0, 0.5);  // ends 0.25 m apart, known to about a spacing
      }
      s.m.EndScan(s.t);
      s.t += kStep;
      p.mean_utime = s.t;
      s.m.Update(0, p, s.sensor, 2, nullptr, at_update, &worker);
      ASSERT_TRUE(s.m.tracks()[0].hyps[0].has_fit);
      EXPECT_NEAR(s.m.tracks()[0].hyps[0].fit.observed_length_m, at_update ? 4.5 : 9.0, 0.3);
      const double w1 = weight_of(at_update, s.m.tracks()[0].hyps[0].fit);
      if (at_update) {
        EXPECT_LT(w1, 0.5);
      }
      const double t1 = static_cast<double>(s.t) * 1e-6;
      const double decay = std::exp2(-(t1 - t0) / ShapeParams().half_life);
      EXPECT_NEAR(s.m.tracks()[0].hyps[0].shape.length_histogram().TotalWeight(t1),
                  w0 * decay + w1, 1e-12);
    }
  }
}

// A corner fit gives a length and a width, each with its own uncertainty; on a 3-D scan each
// enters its own histogram with the weight of its own uncertainty (the width's face is sampled
// twice as densely as the side here, so the two differ and an exchange would show).
TEST(ParkedTrackTest, LengthAndWidthOfACornerAreEachWeighedByTheirOwnUncertainty) {
  Scans s;
  PointSet p = ParkedCorner(s.t);
  std::vector<double> wx, wy;
  for (std::size_t i = 0; i < p.size(); ++i) {
    wx.push_back(p.origin.x() + p.x[i]);
    wy.push_back(p.origin.y() + p.y[i]);
  }
  RangeProfile profile;
  profile.Build(s.sensor, wx, wy, 0.2);
  ASSERT_TRUE(s.m.Create(p, s.sensor, 1, &profile));
  const TrackHypothesis& h = s.m.tracks()[0].hyps[0];
  ASSERT_TRUE(h.has_fit);
  ASSERT_TRUE(std::isfinite(h.fit.observed_length_m) && std::isfinite(h.fit.observed_width_m));
  const double r = s.params.range_sigma;
  const double w_len = std::min(1.0, std::pow(r / h.fit.observed_length_std_m, 2));
  const double w_wid = std::min(1.0, std::pow(r / h.fit.observed_width_std_m, 2));
  ASSERT_GT(std::abs(w_len - w_wid), 0.01) << w_len << " " << w_wid;
  const double t = static_cast<double>(s.t) * 1e-6;
  EXPECT_DOUBLE_EQ(h.shape.length_histogram().TotalWeight(t), w_len);
  EXPECT_DOUBLE_EQ(h.shape.width_histogram().TotalWeight(t), w_wid);
}

}  // namespace
}  // namespace vtrack
