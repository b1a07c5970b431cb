// Per-return time and ring of KITTI Velodyne frames: on synthetic sweeps laid out like the KITTI
// files, and on the real sequence (skipped when ../shared/data is absent).
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <random>

#include "sensor_driver/kitti/kitti_scan.h"
#include "sensor_driver/kitti/kitti_sequence.h"
#include "tests/support/test_env.h"

namespace vtrack::kitti {
namespace {

constexpr std::int32_t kSweep = 100000;

// Clockwise rotation starting behind the car: behind 0, left 1/4, ahead 1/2, right 3/4 sweep.
TEST(KittiScanTest, ReturnTimeFollowsClockwiseSweepFromBehind) {
  EXPECT_NEAR(ReturnTimeUs(-10.0f, 1e-4f, kSweep), 0, 2);        // just left of straight behind
  EXPECT_NEAR(ReturnTimeUs(0.0f, 10.0f, kSweep), 25000, 1);      // left
  EXPECT_NEAR(ReturnTimeUs(10.0f, 0.0f, kSweep), 50000, 1);      // ahead
  EXPECT_NEAR(ReturnTimeUs(0.0f, -10.0f, kSweep), 75000, 1);     // right
  EXPECT_NEAR(ReturnTimeUs(-10.0f, -1e-4f, kSweep), kSweep - 1, 2);  // just right of behind
  // 30 deg left of ahead: (180 - 30) / 360 of the sweep.
  EXPECT_NEAR(ReturnTimeUs(std::cos(0.5236f), std::sin(0.5236f), kSweep), 41667, 2);
  EXPECT_EQ(ReturnTimeUs(NAN, 1.0f, kSweep), 0);
  // Always in [0, sweep).
  std::mt19937 rng(3);
  std::uniform_real_distribution<float> u(-50.0f, 50.0f);
  for (int k = 0; k < 1000; ++k) {
    const auto dt = ReturnTimeUs(u(rng), u(rng), kSweep);
    EXPECT_GE(dt, 0);
    EXPECT_LT(dt, kSweep);
  }
}

// A synthetic sweep laid out like a KITTI file: lasers from the highest to the lowest, each from
// just left of forward round (increasing azimuth) to just right of it, with azimuth jitter.
VelodyneFrame KittiLikeSweep(int lasers, int per_laser, unsigned seed) {
  std::mt19937 rng(seed);
  std::normal_distribution<double> jitter(0.0, 0.002);  // [rad]
  VelodyneFrame f;
  for (int l = 0; l < lasers; ++l) {
    const double elevation = 0.035 - 0.4 * l / lasers;  // [rad] highest first
    for (int k = 0; k < per_laser; ++k) {
      double az = 0.01 + (2 * M_PI - 0.02) * k / (per_laser - 1) + jitter(rng);
      if (k > per_laser / 3 && k < per_laser / 3 + 40) continue;  // a gap (no return, e.g. sky)
      const double r = 15.0;
      f.x.push_back(static_cast<float>(r * std::cos(elevation) * std::cos(az)));
      f.y.push_back(static_cast<float>(r * std::cos(elevation) * std::sin(az)));
      f.z.push_back(static_cast<float>(r * std::sin(elevation)));
      f.reflectance.push_back(0.3f);
    }
  }
  return f;
}

TEST(KittiScanTest, RingsFromFileOrderLowestIsZero) {
  const VelodyneFrame f = KittiLikeSweep(64, 1800, 11);
  int found = 0;
  const auto rings = AssignRings(f, 64, &found);
  EXPECT_EQ(found, 64);
  ASSERT_EQ(rings.size(), f.size());
  // Truth: the file position's laser, highest first; ring = 63 - laser.
  std::size_t i = 0;
  int wrong = 0;
  const int per = static_cast<int>(f.size() / 64);
  for (int l = 0; l < 64; ++l) {
    for (int k = 0; k < per; ++k, ++i) wrong += rings[i] != 63 - l;
  }
  EXPECT_EQ(wrong, 0);
  // Elevation grows with ring.
  EXPECT_LT(f.z[i - 1], f.z[0]);
  EXPECT_EQ(rings.front(), 63);
  EXPECT_EQ(rings.back(), 0);
}

TEST(KittiScanTest, WrongLaserCountGivesUnknownRings) {
  const VelodyneFrame f = KittiLikeSweep(63, 900, 12);
  int found = 0;
  const auto rings = AssignRings(f, 64, &found);
  EXPECT_EQ(found, 63);
  EXPECT_TRUE(std::all_of(rings.begin(), rings.end(), [](std::int16_t r) { return r == -1; }));
}

TEST(KittiScanTest, MakeScanFillsTheMessage) {
  VelodyneFrame f = KittiLikeSweep(64, 200, 13);
  f.x[5] = NAN;
  VelodyneParams p;
  ASSERT_EQ(p.Validate(), "");
  const auto s = MakeScan(f, 1'000'000, 42, p);
  EXPECT_EQ(s.utime, 1'000'000);
  EXPECT_EQ(s.seq, 42);
  EXPECT_EQ(s.sensor_id, "velodyne");
  EXPECT_EQ(s.npoints, static_cast<std::int32_t>(f.size()));
  EXPECT_EQ(s.x.size(), f.size());
  EXPECT_EQ(s.ring.size(), f.size());
  EXPECT_EQ(s.dt_us.size(), f.size());
  EXPECT_EQ(s.num_rings, 64);
  EXPECT_EQ(s.sweep_duration_us, kSweep);
  EXPECT_DOUBLE_EQ(s.sensor_orientation[0], 1.0);
  EXPECT_EQ(s.dt_us[5], 0);  // non-finite point
  EXPECT_EQ(s.intensity[7], 0.3f);
  VelodyneParams bad;
  bad.num_rings = 0;
  EXPECT_NE(bad.Validate().find("num_rings"), std::string::npos);
  bad = VelodyneParams{};
  bad.sweep_duration_us = -5;
  EXPECT_NE(bad.Validate().find("-5"), std::string::npos);
}

// The real HDL-64E frames split into 64 lasers whose elevation grows with the ring index, and the
// returns straight ahead are timed at half a sweep. Frame 42 has a stray return after its last
// laser; frame 153 is cut short after 53 lasers, so its rings are unknown.
TEST(KittiScanTest, RealFramesHave64OrderedRings) {
  const std::string dir = vtrack::testing::KittiDir();
  if (dir.empty()) GTEST_SKIP() << "KITTI data not found (../shared/data/kitti_tracking_0000): skipped";
  SequenceOptions o;
  o.dir = dir;
  o.cache_dir = vtrack::testing::BinDir() + "/../kitti_cache";
  const Sequence seq(o);
  for (int frame : {0, 42, 77}) {
    const auto scan = seq.Scan(frame);
    ASSERT_GT(scan.npoints, 90000);
    std::vector<std::vector<double>> elev(64);
    for (int i = 0; i < scan.npoints; ++i) {
      ASSERT_GE(scan.ring[i], 0) << "frame " << frame << " did not split into 64 lasers";
      const double r = std::hypot(scan.x[i], scan.y[i]);
      if (r > 2.5) elev[static_cast<std::size_t>(scan.ring[i])].push_back(std::atan2(scan.z[i], r));
    }
    double prev = -1.0;
    for (int r = 0; r < 64; ++r) {
      auto& e = elev[static_cast<std::size_t>(r)];
      ASSERT_FALSE(e.empty()) << "ring " << r;
      std::nth_element(e.begin(), e.begin() + e.size() / 2, e.end());
      const double med = e[e.size() / 2];
      EXPECT_GT(med, prev) << "frame " << frame << " ring " << r;
      prev = med;
    }
    // HDL-64E: lasers from about -24.8 deg to +2 deg.
    EXPECT_LT(prev, 0.06);
    for (int i = 0; i < scan.npoints; ++i) {
      if (std::abs(std::atan2(scan.y[i], scan.x[i])) < 0.01) {
        EXPECT_NEAR(scan.dt_us[i], 50000, 200);
      }
    }
  }
  int found = 0;
  const auto rings = AssignRings(seq.ReadFrame(153), 64, &found);
  EXPECT_EQ(found, 53);
  EXPECT_TRUE(std::all_of(rings.begin(), rings.end(), [](std::int16_t r) { return r == -1; }));
}

}  // namespace
}  // namespace vtrack::kitti
