// Segmentation: seeded synthetic scenes whose objects are known; every segment must hold the
// returns of exactly one object and every object must be one segment.
#include "tracker/core/segmentation.h"

#include <gtest/gtest.h>

#include <map>
#include <random>
#include <set>

#include "base/angle.h"
#include "tests/support/params_check.h"

namespace vtrack {
namespace {

// Checks that segments and objects correspond one to one (labels per WorldPoints index).
void ExpectOneSegmentPerObject(const Segments& segs, const std::vector<int>& label,
                               int num_objects) {
  ASSERT_EQ(static_cast<int>(segs.segments.size()), num_objects);
  std::set<int> seen;
  for (const Segment& s : segs.segments) {
    std::set<int> labels;
    for (int k = s.begin; k < s.end; ++k) labels.insert(label[static_cast<std::size_t>(segs.point[static_cast<std::size_t>(k)])]);
    ASSERT_EQ(labels.size(), 1u);
    EXPECT_TRUE(seen.insert(*labels.begin()).second) << "object split into two segments";
  }
}

TEST(SegmentationTest, ScanLineBreaksAtRangeJumpsAndWrapsAround) {
  // A 360 deg single-plane scan, 0.5 deg steps, of three arcs at different ranges; the first
  // arc straddles the start/end of the sweep (azimuth 0).
  WorldPoints pts;
  std::vector<int> label;
  struct Arc {
    double from_deg, to_deg, range;
  };
  const std::vector<Arc> arcs = {{-10, 10, 8.0}, {40, 60, 15.0}, {120, 125, 30.0}};
  for (int k = 0; k < 720; ++k) {
    double a = k * 0.5;
    const double a_signed = a > 180 ? a - 360 : a;
    for (std::size_t j = 0; j < arcs.size(); ++j) {
      if (a_signed >= arcs[j].from_deg && a_signed <= arcs[j].to_deg) {
        const double r = arcs[j].range;
        pts.push_back(r * std::cos(DegToRad(a)), r * std::sin(DegToRad(a)), 0.0f, k, 0);
        label.push_back(static_cast<int>(j));
      }
    }
  }
  SegmentationParams params;
  Segmenter seg(params);
  Segments out;
  seg.Run(pts, /*scan_line=*/true, Eigen::Vector2d::Zero(), &out);
  ExpectOneSegmentPerObject(out, label, 3);
}

TEST(SegmentationTest, ScanLineSplitsObjectsAtDifferentRanges) {
  // Two walls seen edge on: same bearing sector, ranges 10 m and 12 m: a range jump of 2 m.
  WorldPoints pts;
  std::vector<int> label;
  for (int k = 0; k < 40; ++k) {
    const double a = DegToRad(k * 0.25);
    const double r = k < 20 ? 10.0 : 12.0;
    pts.push_back(r * std::cos(a), r * std::sin(a), 0.0f, k, 0);
    label.push_back(k < 20 ? 0 : 1);
  }
  Segmenter seg(SegmentationParams{});
  Segments out;
  seg.Run(pts, true, Eigen::Vector2d::Zero(), &out);
  ExpectOneSegmentPerObject(out, label, 2);
}

TEST(SegmentationTest, GridComponentsMatchSeededClusters) {
  std::mt19937 rng(11);
  SegmentationParams params;
  Segmenter seg(params);
  Segments out;
  for (int trial = 0; trial < 5; ++trial) {
    // Dense clusters (100 returns/m^2) on a 6 m lattice, each 2 m wide: gaps of 4 m.
    WorldPoints pts;
    std::vector<int> label;
    const Eigen::Vector2d sensor(100.0 * trial, -50.0);
    std::uniform_real_distribution<double> u(-1.0, 1.0);
    int n_obj = 0;
    for (int gx = -5; gx <= 5; ++gx) {
      for (int gy = -5; gy <= 5; ++gy) {
        if ((gx * 7 + gy * 3 + trial) % 4 != 0) continue;
        for (int i = 0; i < 400; ++i) {
          pts.push_back(sensor.x() + gx * 6.0 + u(rng), sensor.y() + gy * 6.0 + u(rng), 1.0f, 0, 0);
          label.push_back(n_obj);
        }
        ++n_obj;
      }
    }
    // Shuffle the order: the grid must not depend on it.
    std::vector<std::size_t> perm(pts.size());
    std::iota(perm.begin(), perm.end(), 0);
    std::shuffle(perm.begin(), perm.end(), rng);
    WorldPoints shuffled;
    std::vector<int> shuffled_label;
    for (auto i : perm) {
      shuffled.push_back(pts.x[i], pts.y[i], 1.0f, 0, 0);
      shuffled_label.push_back(label[i]);
    }
    seg.Run(shuffled, false, sensor, &out);
    ExpectOneSegmentPerObject(out, shuffled_label, n_obj);
    std::size_t total = 0;
    for (const auto& s : out.segments) total += static_cast<std::size_t>(s.size());
    EXPECT_EQ(total, shuffled.size());
  }
}

TEST(SegmentationTest, SmallAndHugeSegmentsAreDropped) {
  WorldPoints pts;
  pts.push_back(10.0, 10.0, 1.0f, 0, 0);  // a lone return
  for (int i = 0; i < 200; ++i) pts.push_back(-20.0 + 0.2 * i, 5.0, 1.0f, 0, 0);  // 40 m wall
  for (int i = 0; i < 20; ++i) pts.push_back(5.0 + 0.2 * i, -8.0, 1.0f, 0, 0);    // 4 m object
  Segmenter seg(SegmentationParams{});
  Segments out;
  seg.Run(pts, false, Eigen::Vector2d::Zero(), &out);
  ASSERT_EQ(out.segments.size(), 1u);
  EXPECT_EQ(out.segments[0].size(), 20);
  EXPECT_NEAR(out.segments[0].centroid.x(), 5.0 + 0.1 * 19, 1e-9);
  EXPECT_EQ(out.dropped_small, 1);
  EXPECT_EQ(out.dropped_large, 1);
}

TEST(SegmentationTest, ValidateNamesTheKey) {
  SegmentationParams p;
  EXPECT_TRUE(testing::Accepted(p));
  p.connectivity = 6;
  EXPECT_TRUE(testing::RefusedSaying(p, {"connectivity = 6"}));
}

}  // namespace
}  // namespace vtrack
