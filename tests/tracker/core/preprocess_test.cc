// Preprocessing: ego-motion compensation against an analytic ego trajectory, bad returns
// counted, ground removal on a synthetic scene with known object points.
#include "tracker/core/preprocess.h"

#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <limits>
#include <random>
#include <string>

#include "base/angle.h"
#include "base/pose.h"

namespace vtrack {
namespace {

constexpr std::int64_t kT0 = 1'700'000'000'000'000;

// Ego on a circle: speed v [m/s], yaw rate w [rad/s], starting at the origin heading +x.
Eigen::Isometry3d EgoAt(double t, double v, double w) {
  Eigen::Isometry3d p = Eigen::Isometry3d::Identity();
  const double yaw = w * t;
  p.linear() = Eigen::AngleAxisd(yaw, Eigen::Vector3d::UnitZ()).toRotationMatrix();
  p.translation() = Eigen::Vector3d(v * std::sin(yaw) / w, v * (1.0 - std::cos(yaw)) / w, 0.0);
  return p;
}

PoseHistory MakePoses(double v, double w, double duration_s) {
  PoseHistory h(10'000'000);
  for (std::int64_t t = -50'000; t <= static_cast<std::int64_t>(duration_s * 1e6); t += 10'000) {
    h.Add(kT0 + t, EgoAt(t * 1e-6, v, w));
  }
  return h;
}

TEST(PreprocessTest, EveryReturnIsPlacedWithThePoseAtItsOwnTime) {
  const double v = 15.0, w = 1.0;
  const PoseHistory poses = MakePoses(v, w, 0.3);
  LadarScan scan;
  scan.utime = kT0 + 50'000;
  scan.sweep_duration_us = 100'000;
  scan.num_rings = 1;
  scan.body_from_sensor.translation() = Eigen::Vector3d(1.2, 0.3, 0.8);
  scan.body_from_sensor.linear() = QuaternionFromRpy(0.0, 0.05, 0.3).toRotationMatrix();
  std::mt19937 rng(7);
  std::uniform_real_distribution<double> ang(-kPi, kPi), rr(2.0, 70.0), dtd(0.0, 100'000.0);
  for (int i = 0; i < 3000; ++i) {
    const double a = ang(rng), r = rr(rng);
    scan.x.push_back(static_cast<float>(r * std::cos(a)));
    scan.y.push_back(static_cast<float>(r * std::sin(a)));
    scan.z.push_back(0.0f);
    scan.intensity.push_back(0.5f);
    scan.dt_us.push_back(static_cast<std::int32_t>(dtd(rng)));
    scan.ring.push_back(0);
  }
  PreprocessParams params;
  Preprocessor pre(params);
  WorldPoints out;
  const PreprocessResult res = pre.Run(scan, poses, 0, &out);
  ASSERT_EQ(res.status, CompensationStatus::kOk);
  ASSERT_EQ(out.size(), scan.size());
  double max_err_history = 0.0, max_err_truth = 0.0;
  for (std::size_t k = 0; k < out.size(); ++k) {
    const auto i = static_cast<std::size_t>(out.index[k]);
    const Eigen::Vector3d p(scan.x[i], scan.y[i], scan.z[i]);
    const std::int64_t t = scan.utime + scan.dt_us[i];
    // Reference 1: the pose history's own interpolation at the return's time.
    const Eigen::Vector3d ref = *poses.At(t, 0) * scan.body_from_sensor * p;
    // Reference 2: the true (analytic) ego pose at that time.
    const Eigen::Vector3d truth = EgoAt((t - kT0) * 1e-6, v, w) * scan.body_from_sensor * p;
    max_err_history = std::max(max_err_history, std::hypot(out.x[k] - ref.x(), out.y[k] - ref.y()));
    max_err_truth = std::max(max_err_truth, std::hypot(out.x[k] - truth.x(), out.y[k] - truth.y()));
  }
  // Knot interpolation error bound (preprocess.h): (w * knot)^2 / 8 * range ~ 1e-5 m.
  EXPECT_LT(max_err_history, 1e-4);
  // Pose samples every 10 ms on a 15 m radius: chord error R (1 - cos(w dt / 2)) ~ 2e-4 m.
  EXPECT_LT(max_err_truth, 1e-3);
  // Without compensation (pose at scan start) the error would be metres: the test can fail.
  const Eigen::Vector3d p_last(scan.x[0], scan.y[0], scan.z[0]);
  const Eigen::Vector3d uncompensated = *poses.At(scan.utime, 0) * scan.body_from_sensor * p_last;
  const Eigen::Vector3d exact =
      EgoAt((scan.utime + scan.dt_us[0] - kT0) * 1e-6, v, w) * scan.body_from_sensor * p_last;
  if (scan.dt_us[0] > 20000) {
    EXPECT_GT((uncompensated - exact).head<2>().norm(), 0.2);
  }
}

TEST(PreprocessTest, BadReturnsAreDroppedAndCounted) {
  const PoseHistory poses = MakePoses(0.0 + 1e-9, 1e-3, 0.3);
  LadarScan scan;
  scan.utime = kT0;
  scan.sweep_duration_us = 1000;
  const float nan = std::numeric_limits<float>::quiet_NaN();
  const float inf = std::numeric_limits<float>::infinity();
  scan.x = {5.0f, nan, 5.0f, inf, 0.1f, 200.0f, 5.0f, 6.0f};
  scan.y = {0.0f, 0.0f, nan, 0.0f, 0.0f, 0.0f, 1.0f, 1.0f};
  scan.z = {0.0f, 0.0f, 0.0f, 0.0f, 0.0f, 0.0f, 0.0f, -inf};
  scan.dt_us = {0, 0, 0, 0, 0, 0, 5000, 0};  // index 6: after the sweep
  scan.intensity.assign(8, 0.0f);
  scan.ring.assign(8, 0);
  Preprocessor pre(PreprocessParams{});
  WorldPoints out;
  const auto res = pre.Run(scan, poses, 0, &out);
  EXPECT_EQ(res.stats.input, 8);
  EXPECT_EQ(res.stats.nonfinite, 4);
  EXPECT_EQ(res.stats.out_of_range, 2);
  EXPECT_EQ(res.stats.bad_time, 1);
  EXPECT_EQ(res.stats.kept, 1);
  ASSERT_EQ(out.size(), 1u);
  EXPECT_EQ(out.index[0], 0);
}

// A refused return is counted once, by the first reason that holds in the order not finite,
// beyond the sensor's range, bad ring, outside the tracker's range limits, bad time; a scan
// without rings or without times is not refused for them.
TEST(PreprocessTest, EachRefusedReturnIsCountedOnceByItsFirstReason) {
  const PoseHistory poses = MakePoses(1e-9, 1e-3, 0.3);
  const float nan = std::numeric_limits<float>::quiet_NaN();
  const float inf = std::numeric_limits<float>::infinity();
  struct Return {
    float x, y, z;
    std::int16_t ring;
    std::int32_t dt;
  };
  // num_rings 4, sweep 1000 us, the sensor's max_range 100 m (far: beyond 101 m), the tracker's
  // range limits [1, 80] m. Reasons: with every array / without rings / without times.
  const std::vector<Return> returns = {
      {5, 0, 0, 0, 0},       //  0 kept
      {nan, 0, 0, 9, -5},    //  1 not finite (also a bad ring and time)
      {500, 0, 0, 9, -5},    //  2 far (also a bad ring, out of range, a bad time)
      {5, 0, 0, 9, -5},      //  3 bad ring / bad time / bad ring
      {5, 0, 0, -1, 0},      //  4 kept: ring unknown
      {0.1f, 0, 0, 0, -5},   //  5 out of range (also a bad time)
      {90, 0, 0, -2, 0},     //  6 bad ring / out of range / bad ring
      {5, 0, 0, 4, 0},       //  7 bad ring (ring == num_rings) / kept / bad ring
      {5, 0, 0, 3, -1},      //  8 bad time / bad time / kept
      {5, 0, 0, 3, 1000},    //  9 kept: at the sweep's end
      {5, 0, 0, 3, 1001},    // 10 bad time / bad time / kept
      {5, inf, 0, 0, 0},     // 11 not finite
      {5, 0, nan, 0, 0},     // 12 not finite
      {-inf, 0, 0, 0, 0},    // 13 not finite
  };
  auto run = [&](std::int16_t num_rings, bool rings, bool times, WorldPoints* out) {
    LadarScan scan;
    scan.utime = kT0;
    scan.sweep_duration_us = 1000;
    scan.num_rings = num_rings;
    scan.max_range = 100.0f;
    for (const Return& r : returns) {
      scan.x.push_back(r.x);
      scan.y.push_back(r.y);
      scan.z.push_back(r.z);
      scan.intensity.push_back(0.0f);
      if (rings) scan.ring.push_back(r.ring);
      if (times) scan.dt_us.push_back(r.dt);
    }
    PreprocessParams params;
    params.ground_min_rings = 5;  // no ground removal: every kept return stays
    Preprocessor pre(params);
    return pre.Run(scan, poses, 0, out).stats;
  };
  auto indices = [](const WorldPoints& out) {
    return std::vector<std::int32_t>(out.index.begin(), out.index.end());
  };
  WorldPoints out;
  PreprocessStats st = run(4, true, true, &out);
  EXPECT_EQ(st.input, 14);
  EXPECT_EQ(st.nonfinite, 4);
  EXPECT_EQ(st.far, 1);
  EXPECT_EQ(st.bad_ring, 3);
  EXPECT_EQ(st.out_of_range, 1);
  EXPECT_EQ(st.bad_time, 2);
  EXPECT_EQ(st.kept, 3);
  EXPECT_EQ(indices(out), (std::vector<std::int32_t>{0, 4, 9}));
  EXPECT_EQ(out.ring[1], -1);

  st = run(4, false, true, &out);  // no rings: none refused for its ring
  EXPECT_EQ(st.nonfinite, 4);
  EXPECT_EQ(st.far, 1);
  EXPECT_EQ(st.bad_ring, 0);
  EXPECT_EQ(st.out_of_range, 2);
  EXPECT_EQ(st.bad_time, 3);
  EXPECT_EQ(indices(out), (std::vector<std::int32_t>{0, 4, 7, 9}));

  st = run(4, true, false, &out);  // no times: every return at the sweep's start
  EXPECT_EQ(st.nonfinite, 4);
  EXPECT_EQ(st.far, 1);
  EXPECT_EQ(st.bad_ring, 3);
  EXPECT_EQ(st.out_of_range, 1);
  EXPECT_EQ(st.bad_time, 0);
  EXPECT_EQ(indices(out), (std::vector<std::int32_t>{0, 4, 8, 9, 10}));

  st = run(-1, true, true, &out);  // no ring can be valid, not even -1 (unknown)
  EXPECT_EQ(st.nonfinite, 4);
  EXPECT_EQ(st.far, 1);
  EXPECT_EQ(st.bad_ring, 9);
  EXPECT_EQ(st.kept, 0);
}

// The largest distance [m per m of range] of the returns in `out` (plane, and height) from the
// same knot interpolation in double, computed here from the pose history.
std::pair<double, double> WorstAgainstDouble(const LadarScan& scan, const PoseHistory& poses,
                                             const PreprocessParams& params,
                                             const WorldPoints& out) {
  const std::int64_t step = params.knot_us;
  const std::int64_t sweep = scan.sweep_duration_us;
  auto world_from_sensor = [&](std::int64_t dt) {
    return (*poses.At(scan.utime + dt, 0) * scan.body_from_sensor).matrix();
  };
  double worst = 0.0, worst_height = 0.0;
  for (std::size_t k = 0; k < out.size(); ++k) {
    const auto i = static_cast<std::size_t>(out.index[k]);
    const Eigen::Vector4d p(scan.x[i], scan.y[i], scan.z[i], 1.0);
    const std::int64_t dt = scan.dt_us[i];
    const std::int64_t t0 = std::min<std::int64_t>(dt / step, (sweep - 1) / step) * step;
    const std::int64_t t1 = std::min<std::int64_t>(t0 + step, sweep);
    const double f = static_cast<double>(dt - t0) / static_cast<double>(t1 - t0);
    const Eigen::Matrix4d m0 = world_from_sensor(t0);
    const Eigen::Vector4d ref = (m0 + f * (world_from_sensor(t1) - m0)) * p;
    const double range = p.head<3>().norm();
    worst = std::max(worst, std::hypot(out.x[k] - ref.x(), out.y[k] - ref.y()) / range);
    const double height = (scan.body_from_sensor * p.head<3>()).z();
    worst_height = std::max(worst_height, std::abs(out.height[k] - height) / range);
  }
  return {worst, worst_height};
}

// The ego 3 km from the world origin (a world-scale translation in single precision would miss
// that by 1e-4 m and more) turning at 1 rad/s.
PoseHistory FarTurningPoses() {
  const double v = 15.0, w = 1.0;
  PoseHistory poses(10'000'000);
  const Eigen::Translation3d far_away(3000.0, -2500.0, 40.0);
  for (std::int64_t t = -50'000; t <= 300'000; t += 10'000) {
    poses.Add(kT0 + t, far_away * EgoAt(t * 1e-6, v, w));
  }
  return poses;
}

// A sweep of `count` returns out to 120 m in every direction, timed by dt_of(i).
template <class DtOf>
LadarScan RandomSweep(std::int32_t sweep, int count, std::uint32_t seed, DtOf dt_of) {
  LadarScan scan;
  scan.utime = kT0 + 50'000;
  scan.sweep_duration_us = sweep;
  scan.num_rings = 1;
  scan.body_from_sensor.translation() = Eigen::Vector3d(1.2, 0.3, 1.8);
  scan.body_from_sensor.linear() = QuaternionFromRpy(0.02, 0.05, 0.3).toRotationMatrix();
  std::mt19937 rng(seed);
  std::uniform_real_distribution<double> ang(-kPi, kPi), elev(-0.4, 0.2), rr(1.5, 120.0);
  for (int i = 0; i < count; ++i) {
    const double a = ang(rng), e = elev(rng), r = rr(rng);
    scan.x.push_back(static_cast<float>(r * std::cos(e) * std::cos(a)));
    scan.y.push_back(static_cast<float>(r * std::cos(e) * std::sin(a)));
    scan.z.push_back(static_cast<float>(r * std::sin(e)));
    scan.intensity.push_back(0.0f);
    scan.dt_us.push_back(dt_of(i, rng));
    scan.ring.push_back(0);
  }
  return scan;
}

// The single-precision compensation against the same knot interpolation in double: every return
// within kCompensationTolerance of its range. Two sweeps: one whose last knot interval is
// shorter than knot_us, one that knot_us divides (a return at its very end lies on the last
// knot).
TEST(PreprocessTest, SinglePrecisionCompensationStaysWithinItsToleranceOfDouble) {
  const PoseHistory poses = FarTurningPoses();
  for (const std::int32_t sweep : {99'500, 100'000}) {
    std::uniform_int_distribution<std::int32_t> dtd(0, sweep);
    // Every tenth return exactly on a knot (the end of one interval, the start of the next),
    // every hundredth at the sweep's end; the others at random times, in no order.
    const LadarScan scan = RandomSweep(sweep, 20000, 11, [&](int i, std::mt19937& rng) {
      const std::int32_t dt = dtd(rng);
      return i % 100 == 0 ? sweep : i % 10 == 0 ? dt / 1000 * 1000 : dt;
    });
    PreprocessParams params;
    params.max_range = 130.0;
    Preprocessor pre(params);
    WorldPoints out;
    ASSERT_EQ(pre.Run(scan, poses, 0, &out).status, CompensationStatus::kOk);
    ASSERT_EQ(out.size(), scan.size());
    const auto [worst, worst_height] = WorstAgainstDouble(scan, poses, params, out);
    std::printf("sweep %d us: largest distance from the double-precision interpolation: %.2e m "
                "per m of range (plane), %.2e (height)\n", sweep, worst, worst_height);
    EXPECT_LE(worst, kCompensationTolerance) << "sweep " << sweep;
    EXPECT_LE(worst_height, kCompensationTolerance) << "sweep " << sweep;
  }
}

// Returns in time order, as a sensor gives them, are placed a run of one knot interval at a time:
// runs that end at a knot, at a refused return (every 37th nearer than min_range, every 53rd
// timed after the sweep) and at the sweep's end must each take their own interval's pose.
TEST(PreprocessTest, ReturnsInTimeOrderArePlacedByTheirOwnKnotInterval) {
  const PoseHistory poses = FarTurningPoses();
  const std::int32_t sweep = 99'500;
  LadarScan scan = RandomSweep(sweep, 20000, 12, [&](int i, std::mt19937&) {
    return static_cast<std::int32_t>(static_cast<std::int64_t>(i) * sweep / 19999);
  });
  std::int64_t near = 0, late = 0;
  for (std::size_t i = 0; i < scan.size(); ++i) {
    if (i % 37 == 5) {
      scan.x[i] = 0.1f, scan.y[i] = 0.0f, scan.z[i] = 0.0f;
      ++near;
    } else if (i % 53 == 7) {
      scan.dt_us[i] = sweep + 1;
      ++late;
    }
  }
  PreprocessParams params;
  params.max_range = 130.0;
  Preprocessor pre(params);
  WorldPoints out;
  const PreprocessResult res = pre.Run(scan, poses, 0, &out);
  ASSERT_EQ(res.status, CompensationStatus::kOk);
  EXPECT_EQ(res.stats.out_of_range, near);
  EXPECT_EQ(res.stats.bad_time, late);
  ASSERT_EQ(static_cast<std::int64_t>(out.size()), static_cast<std::int64_t>(scan.size()) - near - late);
  // In order, each kept return once.
  for (std::size_t k = 1; k < out.size(); ++k) ASSERT_LT(out.index[k - 1], out.index[k]);
  const auto [worst, worst_height] = WorstAgainstDouble(scan, poses, params, out);
  EXPECT_LE(worst, kCompensationTolerance);
  EXPECT_LE(worst_height, kCompensationTolerance);
}

TEST(PreprocessTest, AnyNumberOfThreadsPlacesAndKeepsTheSameReturns) {
  // A 64-ring sweep of 100,000 returns (enough for three threads to share), a turning ego, a
  // sloped ground with boxes on it, and every kind of refused return sprinkled through: one
  // thread's result, written return by return, is what any number of threads must give.
  const PoseHistory poses = MakePoses(12.0, 0.6, 0.3);
  LadarScan scan;
  scan.utime = kT0 + 50'000;
  scan.sweep_duration_us = 100'000;
  scan.num_rings = 64;
  scan.max_range = 120.0f;
  scan.body_from_sensor.translation() = Eigen::Vector3d(0.3, 0.0, 1.7);
  std::mt19937 rng(11);
  std::uniform_real_distribution<double> ang(-kPi, kPi), range(1.5, 90.0), unit(0.0, 1.0);
  std::uniform_int_distribution<int> ring(0, 63), dt(0, 100'000);
  for (int i = 0; i < 100'000; ++i) {
    const double a = ang(rng), r = range(rng);
    const double bx = r * std::cos(a), by = r * std::sin(a);
    // Road sloping 2 % along x, and a box 0.3-2 m high in one return of five.
    const double height = 0.02 * bx + (unit(rng) < 0.2 ? 0.3 + 1.7 * unit(rng) : 0.0);
    float x = static_cast<float>(bx), y = static_cast<float>(by);
    std::int16_t rg = static_cast<std::int16_t>(ring(rng));
    std::int32_t t = dt(rng);
    const double bad = unit(rng);
    if (bad < 0.002) x = std::numeric_limits<float>::quiet_NaN();
    else if (bad < 0.004) y = 1e30f;  // far
    else if (bad < 0.006) rg = 70;    // bad ring
    else if (bad < 0.008) t = -3;     // bad time
    scan.x.push_back(x);
    scan.y.push_back(y);
    scan.z.push_back(static_cast<float>(height - 1.7));
    scan.intensity.push_back(0.0f);
    scan.ring.push_back(rg);
    scan.dt_us.push_back(t);
  }
  auto run = [&](int threads, PreprocessResult* res) {
    WorkerPool pool(threads);
    Preprocessor pre(PreprocessParams{});
    pre.SetPool(&pool);
    WorldPoints out;
    *res = pre.Run(scan, poses, 0, &out);
    // A second sweep through the same preprocessor: its buffers from the first must not show.
    *res = pre.Run(scan, poses, 0, &out);
    return out;
  };
  PreprocessResult one_res;
  const WorldPoints one = run(1, &one_res);
  ASSERT_EQ(one_res.status, CompensationStatus::kOk);
  // The scene exercises every path: refusals of each reason, ground removed, returns kept.
  EXPECT_GT(one_res.stats.nonfinite, 100);
  EXPECT_GT(one_res.stats.far, 100);
  EXPECT_GT(one_res.stats.bad_ring, 100);
  EXPECT_GT(one_res.stats.bad_time, 100);
  EXPECT_GT(one_res.stats.ground, 50'000);
  EXPECT_GT(one.size(), 10'000u);
  for (const int threads : {2, 3}) {
    SCOPED_TRACE("threads " + std::to_string(threads));
    PreprocessResult res;
    const WorldPoints many = run(threads, &res);
    EXPECT_EQ(res.stats.input, one_res.stats.input);
    EXPECT_EQ(res.stats.nonfinite, one_res.stats.nonfinite);
    EXPECT_EQ(res.stats.far, one_res.stats.far);
    EXPECT_EQ(res.stats.bad_ring, one_res.stats.bad_ring);
    EXPECT_EQ(res.stats.bad_time, one_res.stats.bad_time);
    EXPECT_EQ(res.stats.out_of_range, one_res.stats.out_of_range);
    EXPECT_EQ(res.stats.ground, one_res.stats.ground);
    EXPECT_EQ(res.stats.kept, one_res.stats.kept);
    // Bit for bit, element by element.
    EXPECT_EQ(many.x, one.x);
    EXPECT_EQ(many.y, one.y);
    EXPECT_EQ(many.height, one.height);
    EXPECT_EQ(many.index, one.index);
    EXPECT_EQ(many.ring, one.ring);
    EXPECT_EQ(many.column_top, one.column_top);
  }
}

TEST(PreprocessTest, NoPoseOrExtrapolationIsReported) {
  PoseHistory poses(10'000'000);
  LadarScan scan;
  scan.utime = kT0;
  scan.sweep_duration_us = 100'000;
  scan.x = {5.0f};
  scan.y = {0.0f};
  scan.z = {0.0f};
  scan.dt_us = {0};
  Preprocessor pre(PreprocessParams{});
  WorldPoints out;
  EXPECT_EQ(pre.Run(scan, poses, 50'000, &out).status, CompensationStatus::kNoPose);
  poses.Add(kT0 - 10'000, Eigen::Isometry3d::Identity());
  poses.Add(kT0 + 60'000, Eigen::Isometry3d::Identity());
  // Sweep end is 40 ms past the newest pose.
  EXPECT_EQ(pre.Run(scan, poses, 20'000, &out).status, CompensationStatus::kNoPose);
  EXPECT_EQ(pre.Run(scan, poses, 50'000, &out).status, CompensationStatus::kExtrapolated);
  EXPECT_EQ(out.size(), 1u);
  poses.Add(kT0 + 110'000, Eigen::Isometry3d::Identity());
  EXPECT_EQ(pre.Run(scan, poses, 0, &out).status, CompensationStatus::kOk);
}

// A Velodyne-like scene: road plane 1.7 m below the sensor (tilted 2 deg), a box 4 x 2 x 1.5 m.
TEST(PreprocessTest, GridGroundRemovalKeepsObjectsAndDropsRoad) {
  PoseHistory poses(10'000'000);
  poses.Add(kT0 - 10'000, Eigen::Isometry3d::Identity());
  poses.Add(kT0 + 200'000, Eigen::Isometry3d::Identity());
  LadarScan scan;
  scan.utime = kT0;
  scan.sweep_duration_us = 100'000;
  scan.num_rings = 32;
  scan.body_from_sensor.translation() = Eigen::Vector3d(0, 0, 1.7);  // body origin on the road
  std::mt19937 rng(3);
  std::uniform_real_distribution<double> u(-40.0, 40.0), noise(-0.02, 0.02);
  const double slope = std::tan(DegToRad(2.0));
  int num_object = 0;
  std::vector<bool> is_object;
  auto add = [&](double bx, double by, double bz, bool object) {
    scan.x.push_back(static_cast<float>(bx));
    scan.y.push_back(static_cast<float>(by));
    scan.z.push_back(static_cast<float>(bz - 1.7));
    scan.dt_us.push_back(0);
    scan.ring.push_back(0);
    scan.intensity.push_back(0.0f);
    is_object.push_back(object);
    num_object += object;
  };
  for (int i = 0; i < 20000; ++i) {
    const double x = u(rng), y = u(rng);
    if (std::abs(x - 15.0) < 2.2 && std::abs(y - 5.0) < 1.2) continue;  // under the box
    add(x, y, slope * x + noise(rng), false);
  }
  std::uniform_real_distribution<double> bx(13.0, 17.0), by(4.0, 6.0), bz(0.4, 1.9);
  for (int i = 0; i < 500; ++i) {
    // Box standing on the sloped road (road height 15 * slope at x = 15).
    add(bx(rng), by(rng), slope * 15.0 + bz(rng), true);
  }
  PreprocessParams params;
  Preprocessor pre(params);
  WorldPoints out;
  const auto res = pre.Run(scan, poses, 0, &out);
  ASSERT_NE(res.status, CompensationStatus::kNoPose);
  int kept_object = 0, kept_ground = 0;
  for (std::size_t k = 0; k < out.size(); ++k) {
    (is_object[static_cast<std::size_t>(out.index[k])] ? kept_object : kept_ground)++;
  }
  // Object returns lie 0.4 m or more above the road: all kept. Road returns: essentially none.
  EXPECT_EQ(kept_object, num_object);
  EXPECT_LT(kept_ground, 20);
  EXPECT_EQ(res.stats.ground + res.stats.kept, res.stats.input - res.stats.out_of_range);
  // The grid ground gives every kept return its column's top (a vehicle-evidence feature).
  EXPECT_EQ(out.column_top.size(), out.size());

  // The fixed band at the wrong height keeps much of the sloped road far away: grid is needed.
  // Into the same arrays: the band gives no column tops, and none are left from the grid's run
  // (the evidence reads them wherever there is one per return).
  params.ground = PreprocessParams::Ground::kBand;
  Preprocessor band(params);
  band.Run(scan, poses, 0, &out);
  int band_ground = 0;
  for (std::size_t k = 0; k < out.size(); ++k) band_ground += !is_object[static_cast<std::size_t>(out.index[k])];
  EXPECT_GT(band_ground, 1000);
  EXPECT_TRUE(out.column_top.empty()) << out.column_top.size() << " column tops left";
}

// A flat road seen everywhere except in the shadow of a nearer car (x 22-60 m, y -1.75 to 5.25),
// and in that shadow only the upper edge of a far car, 1.4 m above the road, seen by one ring:
// every cell around it holds only that edge.
struct ShadowScene {
  LadarScan scan;
  std::vector<bool> is_car;  // per return
  int num_car = 0;
};

ShadowScene RoofLineInAShadow() {
  ShadowScene s;
  s.scan.utime = kT0;
  s.scan.sweep_duration_us = 100'000;
  s.scan.num_rings = 64;
  s.scan.body_from_sensor.translation() = Eigen::Vector3d(0, 0, 1.7);
  auto add = [&](double bx, double by, double bz, bool car) {
    s.scan.x.push_back(static_cast<float>(bx));
    s.scan.y.push_back(static_cast<float>(by));
    s.scan.z.push_back(static_cast<float>(bz - 1.7));
    s.scan.dt_us.push_back(0);
    s.scan.ring.push_back(0);
    s.scan.intensity.push_back(0.0f);
    s.is_car.push_back(car);
    s.num_car += car;
  };
  std::mt19937 rng(5);
  std::uniform_real_distribution<double> u(-60.0, 60.0), noise(-0.02, 0.02);
  for (int i = 0; i < 40000; ++i) {
    const double x = u(rng), y = u(rng);
    if (x > 22.0 && y > -1.75 && y < 5.25) continue;  // the shadow
    add(x, y, noise(rng), false);
  }
  for (double y = 0.85; y <= 2.65 + 1e-9; y += 0.1) add(31.75, y, 1.4, true);
  for (double x = 31.85; x <= 36.25 + 1e-9; x += 0.1) add(x, 0.85, 1.4, true);
  return s;
}

TEST(PreprocessTest, GroundUnderAFarCarsRoofLineIsBoundedByTheRoadAroundIt) {
  PoseHistory poses(10'000'000);
  poses.Add(kT0 - 10'000, Eigen::Isometry3d::Identity());
  poses.Add(kT0 + 200'000, Eigen::Isometry3d::Identity());
  const ShadowScene scene = RoofLineInAShadow();
  auto kept = [&](const PreprocessParams& params, int* road) {
    Preprocessor pre(params);
    WorldPoints out;
    pre.Run(scene.scan, poses, 0, &out);
    int car = 0;
    *road = 0;
    for (std::size_t k = 0; k < out.size(); ++k) {
      (scene.is_car[static_cast<std::size_t>(out.index[k])] ? car : *road)++;
    }
    return car;
  };
  int road = 0;
  // The road 2.6 m or more beside the edge bounds the ground under it: 0.6 m (the tolerance),
  // not the edge's own 1.4 m. Every return of the edge is kept, none of the road.
  EXPECT_EQ(kept(PreprocessParams{}, &road), scene.num_car);
  EXPECT_EQ(road, 0);
  // With no bound from the road around (any grade allowed), the lowest return near the edge
  // is the edge itself, and it is removed as ground.
  PreprocessParams unbounded;
  unbounded.ground_max_grade = 10.0;
  EXPECT_EQ(kept(unbounded, &road), 0);
}

TEST(PreprocessTest, LowOutliersDoNotLowerTheGroundBeyondTheirNeighbours) {
  PoseHistory poses(10'000'000);
  poses.Add(kT0 - 10'000, Eigen::Isometry3d::Identity());
  poses.Add(kT0 + 200'000, Eigen::Isometry3d::Identity());
  ShadowScene s = RoofLineInAShadow();
  // Returns 1.5 m under the road, as reflections in puddles give: one on the open road at
  // (-20.5, 10.5), one in the shadow 1.85 m beside the far car's roof line (34.5, 4.5).
  for (const auto& [x, y] : {std::pair{-20.5f, 10.5f}, std::pair{34.5f, 4.5f}}) {
    s.scan.x.push_back(x);
    s.scan.y.push_back(y);
    s.scan.z.push_back(-1.5f - 1.7f);
    s.scan.dt_us.push_back(0);
    s.scan.ring.push_back(0);
    s.scan.intensity.push_back(0.0f);
    s.is_car.push_back(false);
  }
  Preprocessor pre(PreprocessParams{});
  WorldPoints out;
  pre.Run(s.scan, poses, 0, &out);
  // The roof line's ground stays at the tolerance (0.6 m), not at the outlier's bound
  // (-1.5 + 0.1 x 1.85 m): its returns stand 0.8 m above it.
  int car = 0;
  for (std::size_t k = 0; k < out.size(); ++k) {
    if (!s.is_car[static_cast<std::size_t>(out.index[k])]) continue;
    ++car;
    EXPECT_NEAR(out.height[k], 0.8, 0.02);
  }
  EXPECT_EQ(car, s.num_car);
  // The grid's 3x3 neighbourhood of an outlier's cell may keep road returns (as before); the
  // bound of the cells farther away comes into play only where the ground would lie more than
  // the tolerance above the scan's level, so no road return farther away is kept.
  int far_road = 0;
  for (std::size_t k = 0; k < out.size(); ++k) {
    if (s.is_car[static_cast<std::size_t>(out.index[k])]) continue;
    const bool near_outlier =
        std::max(std::abs(out.x[k] + 20.5), std::abs(out.y[k] - 10.5)) <= 2.0 ||
        std::max(std::abs(out.x[k] - 34.5), std::abs(out.y[k] - 4.5)) <= 2.0;
    far_road += !near_outlier;
  }
  EXPECT_EQ(far_road, 0);
}

TEST(PreprocessTest, ValidateNamesTheKeyAndValue) {
  PreprocessParams p;
  std::string error;
  EXPECT_TRUE(p.Validate(&error));
  p.max_range = -3.0;
  EXPECT_FALSE(p.Validate(&error));
  EXPECT_NE(error.find("max_range"), std::string::npos);
  EXPECT_NE(error.find("-3"), std::string::npos);
  p = PreprocessParams{};
  p.knot_us = 0;
  EXPECT_FALSE(p.Validate(&error));
  EXPECT_NE(error.find("knot_us"), std::string::npos);
}

}  // namespace
}  // namespace vtrack
