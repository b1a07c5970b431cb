// The outline of a 3-D cloud (tracker.cc): a return stands on a vertical face only if another
// return of its bearing bin lies near its range at a different height. Where no return of a
// segment has such support, one ring sees it: the roof line of a car seen over a nearer one
// spans ranges and is measured; a ring grazing a roof or bonnet, all at one range, is not.
// The truth is the hand-built scene: where the car is, and that the arc is no object.
#include <gtest/gtest.h>

#include <cmath>
#include <vector>

#include "base/angle.h"
#include "tracker/core/outline.h"
#include "tracker/core/tracker.h"

namespace vtrack {
namespace {

constexpr std::int64_t kT0 = 1'700'000'000'000'000;
constexpr double kSensorHeight = 1.7;  // [m] above the body origin, on the road

struct Return {
  double x, y, z;  // [m] body frame
};

// The upper edge of a 4.5 x 1.8 m car centred at (34, 1.75), heading 0, as one ring sees it
// from the origin over a nearer car that hides the rest: its rear face (x = 31.75) and the side
// facing the sensor (y = 0.85), 1.4 m above the road, returns about 0.1 m apart.
std::vector<Return> RoofLine() {
  std::vector<Return> r;
  for (double y = 0.85; y <= 2.65 + 1e-9; y += 0.1) r.push_back({31.75, y, 1.4});
  for (double x = 31.85; x <= 36.25 + 1e-9; x += 0.1) r.push_back({x, 0.85, 1.4});
  return r;
}

// A ring grazing the roof of a car beside the ego: an arc 8 m from the sensor, 1.5 m high,
// over bearings -55 to -25 deg (its middle at (6.13, -5.14)).
std::vector<Return> GrazedRoof() {
  std::vector<Return> r;
  for (double a = -55.0; a <= -25.0 + 1e-9; a += 0.2) {
    r.push_back({8.0 * std::cos(DegToRad(a)), 8.0 * std::sin(DegToRad(a)), 1.5});
  }
  return r;
}

// 2 s of a still ego at the origin seeing `returns` on ring 57 of a 64-ring scanner every
// 0.1 s; the reports of the last scan.
std::vector<TrackReport> RunStill(const std::vector<Return>& returns, const TrackerParams& params) {
  Tracker tracker(params);
  std::vector<ScanOutput> out;
  std::int64_t seq = 0;
  for (int tick = 0; tick <= 200; ++tick) {
    const std::int64_t t = kT0 + tick * 10'000;
    tracker.AddPose(EgoPose{t, Eigen::Isometry3d::Identity()}, &out);
    if (tick < 10 || tick % 10 != 0) continue;
    LadarScan s;
    s.utime = t - 100'000;
    s.seq = seq++;
    s.sweep_duration_us = 100'000;
    s.max_range = 120.0f;
    s.num_rings = 64;
    s.body_from_sensor.translation() = Eigen::Vector3d(0.0, 0.0, kSensorHeight);
    for (const Return& p : returns) {
      s.x.push_back(static_cast<float>(p.x));
      s.y.push_back(static_cast<float>(p.y));
      s.z.push_back(static_cast<float>(p.z - kSensorHeight));
      s.intensity.push_back(0.0f);
      s.dt_us.push_back(0);
      s.ring.push_back(57);
    }
    tracker.AddScan(std::move(s), &out);
  }
  tracker.Flush(&out);
  if (out.empty()) return {};
  return out.back().tracks;
}

TrackerParams NoGroundRemoval() {
  TrackerParams p;
  // The scene has no road returns; the heights are the body frame's.
  p.preprocess.ground = PreprocessParams::Ground::kNone;
  return p;
}

// The nearest confirmed track to (x, y), or nullptr if none lies within max_d.
const TrackReport* Near(const std::vector<TrackReport>& tracks, double x, double y, double max_d) {
  const TrackReport* best = nullptr;
  for (const TrackReport& r : tracks) {
    const double d = std::hypot(r.x - x, r.y - y);
    if (r.status != TrackStatus::kTentative && d < max_d) {
      max_d = d;
      best = &r;
    }
  }
  return best;
}

TEST(OutlineTest, RoofLineSeenByOneRingOverANearerCarIsTracked) {
  const auto tracks = RunStill(RoofLine(), NoGroundRemoval());
  const TrackReport* car = Near(tracks, 34.0, 1.75, 1.0);
  ASSERT_NE(car, nullptr) << "no confirmed track within 1 m of the car's centre";
  EXPECT_NEAR(std::abs(AngleDiff(2.0 * car->theta, 0.0)) / 2.0, 0.0, DegToRad(5.0));

  // Without the one-ring rule (any range span too small) no return of the car is measured.
  TrackerParams strict = NoGroundRemoval();
  strict.outline.arc_span = 1e6;
  EXPECT_EQ(Near(RunStill(RoofLine(), strict), 34.0, 1.75, 5.0), nullptr);
}

TEST(OutlineTest, RingGrazingARoofAtOneRangeMakesNoTrack) {
  const auto tracks = RunStill(GrazedRoof(), NoGroundRemoval());
  EXPECT_EQ(Near(tracks, 6.13, -5.14, 10.0), nullptr);
  // The same arc with the rule off for every span (0 m) is measured: the range span is what
  // tells the two apart.
  TrackerParams loose = NoGroundRemoval();
  loose.outline.arc_span = 0.0;
  EXPECT_NE(Near(RunStill(GrazedRoof(), loose), 6.13, -5.14, 10.0), nullptr);
}

// A face at the range where the key that orders a bin by range runs out: range^2 in cm^2 is
// held below 2^32, 655.36 m (max_range allows 1000 m). Two rings 0.5 m apart in height see it,
// the upper one listed first at 655.45 m (beyond: taken as 655.36 m, not carried into the bin's
// part of the key), the lower one at 655.30 m. Every bearing bin is on a vertical face, so the
// outline holds one return per bin, the nearer ring's, none lost or invented.
TEST(OutlineTest, FaceBeyond655mKeepsOneReturnPerBin) {
  OutlineParams params;
  OutlineExtractor extractor(params);
  WorldPoints pts;
  LadarScan scan;
  scan.num_rings = 64;
  const int columns = 40;
  for (int ring = 0; ring < 2; ++ring) {
    for (int c = 0; c < columns; ++c) {
      const double bearing = DegToRad(0.2 * c + 0.1);  // one column per 0.2 deg bin
      const double range = ring == 0 ? 655.45 : 655.30;
      pts.push_back(range * std::cos(bearing), range * std::sin(bearing), ring == 0 ? 1.0f : 0.5f,
                    static_cast<std::int32_t>(pts.size()), static_cast<std::int16_t>(10 + ring));
      scan.x.push_back(0.0f);
      scan.dt_us.push_back(0);
    }
  }
  std::vector<std::int32_t> idx(pts.size());
  for (std::size_t i = 0; i < idx.size(); ++i) idx[i] = static_cast<std::int32_t>(i);
  PointSet out;
  extractor.Extract(pts, idx, scan, Eigen::Vector2d::Zero(), &out);
  ASSERT_EQ(out.size(), static_cast<std::size_t>(columns));
  for (std::size_t k = 0; k < out.size(); ++k) {
    const double x = out.x[k] + out.origin.x(), y = out.y[k] + out.origin.y();
    EXPECT_TRUE(std::isfinite(x) && std::isfinite(y));
    EXPECT_NEAR(std::hypot(x, y), 655.30, 0.01) << "entry " << k;  // the lower ring's return
  }
}

}  // namespace
}  // namespace vtrack
