// The evaluator on a synthetic run whose errors are set by construction (synthetic_run.h): every
// expected value below is worked out from that construction, not taken from the code.
#include <gtest/gtest.h>

#include <cmath>
#include <limits>
#include <map>
#include <numbers>
#include <sstream>

#include "lcmtypes/util/log_reader.h"
#include "log_tools/eval/evaluator.h"
#include "log_tools/eval/report.h"
#include "lcmtypes/util/decode.h"
#include "vtrack/object_list_t.hpp"
#include "vtrack/track_list_t.hpp"
#include "vtrack/ladar_scan_t.hpp"
#include "vtrack/pose_t.hpp"
#include "tests/log_tools/synthetic_run.h"
#include "tests/support/test_env.h"

namespace vtrack::eval {
namespace {

using vtrack::testing::kScans;

constexpr double kPi = std::numbers::pi;

// A camera looking along the sensor's x axis, f = 500 px, principal point (cx, cy): rect (x
// right, y down, z forward) from sensor (x forward, y left, z up).
CameraRegion AxisPermutationCamera(double cx, double cy, int width) {
  CameraRegion cam;
  Eigen::Matrix3d r;
  r << 0, -1, 0, 0, 0, -1, 1, 0, 0;
  cam.rect_from_sensor = Eigen::Affine3d::Identity();
  cam.rect_from_sensor.linear() = r;
  cam.P << 500, 0, cx, 0, 0, 500, cy, 0, 0, 0, 1, 0;
  cam.width = width;
  return cam;
}

class EvaluatorTest : public ::testing::Test {
 protected:
  void SetUp() override {
    dir_ = vtrack::testing::ScratchDir("evaluator");
    run_ = dir_ + "/run.lcm";
    tracks_ = dir_ + "/tracks.lcm";
    vtrack::testing::WriteSyntheticRun(run_);
    vtrack::testing::WriteSyntheticTracks(tracks_, "mht");
  }
  std::string dir_, run_, tracks_;
};

TEST_F(EvaluatorTest, MetricsOfTheSyntheticRun) {
  const EvalParams params;
  const LogData data = LoadLogs({run_, tracks_}, params);
  const EvalSummary s = Evaluate(data, params);
  EXPECT_EQ(s.mode, "mht");
  EXPECT_EQ(s.scans, kScans);
  EXPECT_EQ(s.scans_without_tracks, 1);   // the ground truth at -1 s
  EXPECT_EQ(s.tracks_without_truth, 1);   // the track list at +100 s
  // Scored: cars A and B (the pedestrian and the car outside the labelled region are not).
  EXPECT_EQ(s.clear.gt_objects, 2);
  EXPECT_EQ(s.clear.gt_detections, 2 * kScans);
  // Tracks 1 and 2 match; 7 is a false positive in every scan; 3 (other), 4 and 5 (on ignored
  // truth) and 6 (tentative) are not scored.
  EXPECT_EQ(s.clear.true_positives, 2 * kScans);
  EXPECT_EQ(s.clear.false_positives, kScans);
  EXPECT_EQ(s.clear.false_negatives, 0);
  EXPECT_EQ(s.clear.id_switches, 0);
  EXPECT_EQ(s.ignored_track_detections, 2 * kScans);
  EXPECT_EQ(s.scored_tracks, 3);
  EXPECT_NEAR(s.clear.mota, 1.0 - static_cast<double>(kScans) / (2 * kScans), 1e-12);
  EXPECT_NEAR(s.clear.motp_m, (0.3 + 0.0) / 2.0, 1e-9);
  // RMSE over the 2 * kScans matches: track 1 has errors (0.3 m, 2 deg, 0.5 m/s, 0.01 rad/s),
  // track 2 none (its 180 deg flip is not a heading error, but is counted as a flip).
  EXPECT_NEAR(s.position_rmse_m, std::sqrt(0.09 / 2.0), 1e-9);
  EXPECT_NEAR(s.heading_rmse_deg, std::sqrt(4.0 / 2.0), 1e-6);
  EXPECT_NEAR(s.heading_flip_fraction, 0.5, 1e-12);
  EXPECT_NEAR(s.speed_rmse_mps, std::sqrt(0.25 / 2.0), 1e-9);
  EXPECT_NEAR(s.yaw_rate_rmse_dps, 0.01 * 180.0 / kPi / std::sqrt(2.0), 1e-9);
  // L: only track 1 (VASM) on the moving car A, 0.1 m off.
  EXPECT_EQ(s.rear_axle_samples, kScans);
  EXPECT_NEAR(s.rear_axle_rmse_m, 0.1, 1e-9);
  // Prediction: 1 m off at every horizon, only where ground truth exists k seconds later
  // (scans 0 .. kScans-1 at 10 Hz: kScans - 10 k of them); track 2 predicts nothing.
  ASSERT_EQ(s.prediction_error_m.size(), 3u);
  for (int k = 1; k <= 3; ++k) {
    EXPECT_EQ(s.prediction_samples[k - 1], kScans - 10 * k) << k << " s";
    EXPECT_NEAR(s.prediction_error_m[k - 1], 1.0, 1e-6) << k << " s";
  }
  // NEES: track 1 e = (0.3, 0, 2 deg) with P = diag(0.09, 0.01, (2 deg)^2) -> 2; track 2: 0.
  EXPECT_EQ(s.nees_samples, 2 * kScans);
  EXPECT_NEAR(s.nees_mean, 1.0, 1e-6);
  EXPECT_NEAR(s.nees_within_95, 1.0, 1e-12);
  // HOTA with a 2 m gate: track 1's S = 1 - 0.3/2 = 0.85 matches for the 17 thresholds up to 0.85
  // (DetA = 2/3 with the false positive, AssA = 1); for 0.90 and 0.95 only B matches:
  // TP = kScans, FN = kScans, FP = 2 kScans -> DetA = 1/4.
  const double expected_hota = (17.0 * std::sqrt(2.0 / 3.0) + 2.0 * std::sqrt(0.25)) / 19.0;
  EXPECT_NEAR(s.hota.hota, expected_hota, 1e-9);
  // Per-track rows.
  ASSERT_EQ(s.per_track.size(), 3u);
  EXPECT_EQ(s.per_track[0].track_id, 1);
  EXPECT_EQ(s.per_track[0].truth_id, 1);
  EXPECT_EQ(s.per_track[0].matched, kScans);
  EXPECT_NEAR(s.per_track[0].position_rmse_m, 0.3, 1e-9);
  EXPECT_EQ(s.per_track[2].track_id, 7);
  EXPECT_EQ(s.per_track[2].matched, 0);
  EXPECT_EQ(s.per_track[2].truth_id, -1);
}

TEST_F(EvaluatorTest, RangeAndFieldOfViewRegion) {
  // Ego at the origin heading +x. Within 15 m and +-60 deg: B at (10, -5) (27 deg) is in; A starts
  // at (1.4, 0) and leaves the 15 m disc at some point of its circle; the false positive track 7 at
  // (-20, 10) is outside the region, so it is dropped instead of counted.
  EvalParams params;
  params.region_range_m = 15.0;
  params.region_fov_deg = 120.0;
  const LogData data = LoadLogs({run_, tracks_}, params);
  const EvalSummary s = Evaluate(data, params);
  EXPECT_EQ(s.clear.false_positives, 0);
  EXPECT_EQ(s.outside_region_track_detections, kScans);
  // Count A's scans inside the region independently.
  int a_inside = 0;
  for (int k = 0; k < kScans; ++k) {
    const auto a = vtrack::testing::CarA(k * 0.1);
    if (a.centre.norm() <= 15.0 && std::abs(std::atan2(a.centre.y(), a.centre.x())) <= kPi / 3) ++a_inside;
  }
  ASSERT_GT(a_inside, 0);
  ASSERT_LT(a_inside, kScans);
  EXPECT_EQ(s.clear.gt_detections, kScans + a_inside);
  EXPECT_EQ(s.clear.false_negatives, 0);
}

TEST_F(EvaluatorTest, CameraRegion) {
  // A camera looking along the sensor's x axis with a +-45 deg horizontal view (f = cx = 500 px,
  // width 1000): rect (x right, y down, z forward) from sensor (x forward, y left, z up).
  const CameraRegion cam = AxisPermutationCamera(500.0, 200.0, 1000);
  EXPECT_TRUE(cam.Contains({10.0, 0.0, -1.0}));
  EXPECT_TRUE(cam.Contains({10.0, 9.9, -1.0}));    // 44.7 deg to the left
  EXPECT_FALSE(cam.Contains({10.0, 10.1, -1.0}));  // 45.3 deg
  EXPECT_FALSE(cam.Contains({10.0, -10.1, -1.0}));
  EXPECT_FALSE(cam.Contains({-10.0, 0.0, -1.0}));  // behind
  EvalParams params;
  params.region_camera = cam;
  const LogData data = LoadLogs({run_, tracks_}, params);
  const EvalSummary s = Evaluate(data, params);
  int a_inside = 0;
  for (int k = 0; k < kScans; ++k) {
    const auto a = vtrack::testing::CarA(k * 0.1);
    if (a.centre.x() > 0 && std::abs(a.centre.y()) < a.centre.x()) ++a_inside;
  }
  EXPECT_EQ(s.clear.gt_detections, kScans + a_inside);  // B at 27 deg is always inside
  EXPECT_EQ(s.outside_region_track_detections, kScans);  // track 7 is behind the camera
}

// KITTI's DontCare rule: an unmatched track whose image box lies in a DontCare region by more
// than half of its own area is not a false positive; a matched track is kept whatever regions
// cover it. Camera: P = [500 0 600 0; 0 500 180 0; 0 0 1 0], rect from sensor the axis
// permutation; ego and sensor at the origin (world = sensor). Track 99, a false vehicle at
// (20, 0), theta 0, 4.5 x 1.8 m, no box z: bottom 1.73 m below the sensor, 1.6 m tall. Its
// corners x in [17.75, 22.25], y in +-0.9, z in [-1.73, -0.13] project to
// u = 600 - 500 y / x in [600 - 25.352, 600 + 25.352] and v = 180 - 500 z / x in
// [180 + 500 * 0.13 / 22.25, 180 + 500 * 1.73 / 17.75] = [182.921, 228.732].
TEST_F(EvaluatorTest, KittiDontCareRegionsDropUnmatchedTracksMostlyInside) {
  const CameraRegion cam = AxisPermutationCamera(600.0, 180.0, 1200);
  EvalParams params;
  params.region_camera = cam;
  LogData data = LoadLogs({run_, tracks_}, params);
  for (auto& [utime, list] : data.tracks.at("mht")) {
    vtrack::track_t fp = list.tracks.front();
    fp.id = 99;
    fp.status = vtrack::track_t::STATUS_CONFIRMED;
    fp.object_class = vtrack::track_t::CLASS_VEHICLE;
    fp.x = 20.0;
    fp.y = 0.0;
    fp.theta = 0.0;
    fp.speed = fp.yaw_rate = 0.0;
    fp.velocity_heading = 0.0;
    fp.length = 4.5;
    fp.width = 1.8;
    fp.z = fp.height = std::numeric_limits<double>::quiet_NaN();
    list.tracks.push_back(fp);
    list.num_tracks = static_cast<std::int32_t>(list.tracks.size());
  }
  const EvalSummary base = Evaluate(data, params);
  const double u0 = 600.0 - 500.0 * 0.9 / 17.75, u1 = 600.0 + 500.0 * 0.9 / 17.75;
  std::vector<TrackLabel> labels;
  // The region in the given frames (KITTI frame = the list's scan_seq, k for scan k here), by
  // default every scan's.
  const auto with_region = [&](ImageBox region, std::vector<int> frames = {}) {
    if (frames.empty()) {
      for (int k = 0; k < vtrack::testing::kScans; ++k) frames.push_back(k);
    }
    EvalParams p = params;
    DontCareRegions dc;
    dc.camera.rect_from_sensor = cam.rect_from_sensor;
    dc.camera.P = cam.P;
    dc.camera.image_width = 1200;
    dc.camera.image_height = 360;
    for (const int k : frames) dc.boxes[k].push_back(region);
    p.dont_care = dc;
    EXPECT_EQ(p.Validate(), "");
    labels.clear();
    return Evaluate(data, p, &labels);
  };
  // The labelled set of --track-labels: track 99 is not a vehicle (0) outside the regions and
  // ignored (-1) inside one, in every scored scan.
  const auto labels_of_99 = [&] {
    std::map<int, int> count;
    for (const TrackLabel& l : labels) {
      if (l.track_id == 99) ++count[l.label];
    }
    return count;
  };
  // Wholly inside: dropped in every scan.
  const EvalSummary whole = with_region({560.0, 170.0, 640.0, 240.0});
  EXPECT_EQ(whole.dont_care_track_detections, vtrack::testing::kScans);
  EXPECT_EQ(whole.clear.false_positives, base.clear.false_positives - vtrack::testing::kScans);
  EXPECT_EQ(whole.clear.true_positives, base.clear.true_positives);
  EXPECT_EQ(labels_of_99(), (std::map<int, int>{{-1, vtrack::testing::kScans}}));
  // 40 % of its width inside: still a false positive; 60 %: dropped.
  const EvalSummary part40 = with_region({500.0, 0.0, u0 + 0.4 * (u1 - u0), 359.0});
  EXPECT_EQ(part40.dont_care_track_detections, 0);
  EXPECT_EQ(part40.clear.false_positives, base.clear.false_positives);
  EXPECT_EQ(labels_of_99(), (std::map<int, int>{{0, vtrack::testing::kScans}}));
  const EvalSummary part60 = with_region({500.0, 0.0, u0 + 0.6 * (u1 - u0), 359.0});
  EXPECT_EQ(part60.dont_care_track_detections, vtrack::testing::kScans);
  // Exactly half inside: still a false positive (the rule is "more than half").
  EXPECT_EQ(with_region({500.0, 0.0, 0.5 * (u0 + u1), 359.0}).dont_care_track_detections, 0);
  // Regions of frames 5 and 17 only: dropped in those two scans.
  const EvalSummary two = with_region({560.0, 170.0, 640.0, 240.0}, {5, 17});
  EXPECT_EQ(two.dont_care_track_detections, 2);
  EXPECT_EQ(two.clear.false_positives, base.clear.false_positives - 2);
  EXPECT_EQ(two.problems.count("kitti_dontcare_regions_in_no_scored_frame"), 0u);
  // Regions of frames the log does not hold (another sequence's labels): said in the problems.
  const EvalSummary none = with_region({560.0, 170.0, 640.0, 240.0}, {5000});
  EXPECT_EQ(none.dont_care_track_detections, 0);
  EXPECT_EQ(none.problems.count("kitti_dontcare_regions_in_no_scored_frame"), 1u);
  // Below it in the image (v > 228.732): no overlap.
  EXPECT_EQ(with_region({560.0, 230.0, 640.0, 300.0}).dont_care_track_detections, 0);
  // The whole image: every unmatched track in view is dropped, no matched one.
  const EvalSummary all = with_region({0.0, 0.0, 1199.0, 359.0});
  EXPECT_EQ(all.clear.true_positives, base.clear.true_positives);
  EXPECT_EQ(all.clear.false_positives, 0);
  EXPECT_GE(all.dont_care_track_detections, vtrack::testing::kScans);
  // The camera is placed where the ego was at the truth's time (truth_time_offset_s after the
  // scan), as the track is advanced to it. Ego poses: at the origin at each scan, 3 m to the
  // left (+y) half a scan later; the truth is 50 ms after the scan. Seen from (0, 3) track 99's
  // corners (y in +-0.9) project to u = 600 + 500 (3 - y) / x: u in [600 + 500 * 2.1 / 22.25,
  // 600 + 500 * 3.9 / 17.75] = [647.19, 709.86].
  {
    LogData shifted = data;
    shifted.poses.Clear();
    for (int k = -1; k <= vtrack::testing::kScans; ++k) {
      const std::int64_t t = vtrack::testing::kUtime0 + k * vtrack::testing::kScanPeriodUs;
      Eigen::Isometry3d left = Eigen::Isometry3d::Identity();
      left.translation() = Eigen::Vector3d(0.0, 3.0, 0.0);
      shifted.poses.Add(t, Eigen::Isometry3d::Identity());
      shifted.poses.Add(t + vtrack::testing::kScanPeriodUs / 2, left);
    }
    EvalParams p = params;
    p.truth_time_offset_s = 0.05;
    DontCareRegions dc;
    dc.camera.rect_from_sensor = cam.rect_from_sensor;
    dc.camera.P = cam.P;
    dc.camera.image_width = 1200;
    dc.camera.image_height = 360;
    const double s0 = 600.0 + 500.0 * 2.1 / 22.25, s1 = 600.0 + 500.0 * 3.9 / 17.75;
    for (int k = 0; k < vtrack::testing::kScans; ++k) dc.boxes[k].push_back({s0 - 1.0, 170.0, s1 + 1.0, 240.0});
    p.dont_care = dc;
    EXPECT_EQ(Evaluate(shifted, p).dont_care_track_detections, vtrack::testing::kScans);
    // The region where the box would be from the pose at the scan's time: no longer over it.
    for (auto& [k, regions] : p.dont_care->boxes) regions = {{u0 - 1.0, 170.0, u1 + 1.0, 240.0}};
    EXPECT_EQ(Evaluate(shifted, p).dont_care_track_detections, 0);
  }
  // Without the camera region it cannot be placed: refused.
  EvalParams bad;
  bad.dont_care = DontCareRegions{};
  EXPECT_NE(bad.Validate().find("dont_care needs region_camera"), std::string::npos);
}

TEST_F(EvaluatorTest, ModesAndDuplicates) {
  const std::string other = dir_ + "/tracks_ism.lcm";
  vtrack::testing::WriteSyntheticTracks(other, "ism", 0.6);
  EvalParams params;
  const LogData data = LoadLogs({run_, tracks_, other}, params);
  try {
    Evaluate(data, params);
    FAIL() << "several modes accepted without a choice";
  } catch (const std::runtime_error& e) {
    EXPECT_NE(std::string(e.what()).find("--mode"), std::string::npos) << e.what();
  }
  params.mode = "ism";
  EXPECT_NEAR(Evaluate(data, params).clear.motp_m, 0.6 / 2.0, 1e-9);
  params.mode = "vasm";
  EXPECT_THROW(Evaluate(data, params), std::runtime_error);

  // The same log twice: identical copies are skipped (and counted).
  EvalParams p2;
  const LogData twice = LoadLogs({run_, tracks_, tracks_}, p2);
  EXPECT_EQ(Evaluate(twice, p2).clear.true_positives, 2 * kScans);
  EXPECT_EQ(twice.problems.at("duplicate_identical_tracks"), kScans + 1);
  // A different track list of the same mode and utime is an error that names the file.
  const std::string changed = dir_ + "/tracks_changed.lcm";
  vtrack::testing::WriteSyntheticTracks(changed, "mht", 0.4);
  try {
    LoadLogs({run_, tracks_, changed}, p2);
    FAIL() << "conflicting track lists accepted";
  } catch (const std::runtime_error& e) {
    EXPECT_NE(std::string(e.what()).find("tracks_changed.lcm"), std::string::npos) << e.what();
  }
}

// Input the evaluator cannot score: tracks with a NaN position or heading, ground truth with a
// NaN position and an object listed twice under one id. Each is refused, counted under its
// problem, printed in the report, and the scores are those of the clean input.
TEST_F(EvaluatorTest, NonFiniteAndDuplicateInputIsRefusedCountedAndPrinted) {
  const std::string run = dir_ + "/run_bad.lcm", tracks = dir_ + "/tracks_bad.lcm";
  const double nan = std::numeric_limits<double>::quiet_NaN();
  int truth_nan = 0, track_nan = 0;
  {
    lcm_util::LogReader in(run_);
    lcm_util::LogWriter out(run);
    while (const lcm::LogEvent* ev = in.Next()) {
      vtrack::object_list_t m;
      if (ev->channel != "GROUND_TRUTH" || m.decode(ev->data, 0, ev->datalen) < 0 || m.objects.empty()) {
        out.Write(ev->timestamp, ev->channel, ev->data, static_cast<std::size_t>(ev->datalen));
        continue;
      }
      m.objects.push_back(m.objects.front());  // the same object again, same id
      vtrack::object_t bad = m.objects.front();
      bad.id = 9000;
      bad.x = nan;
      m.objects.push_back(bad);
      ++truth_nan;
      m.num_objects = static_cast<std::int32_t>(m.objects.size());
      out.WriteMessage(ev->timestamp, ev->channel, m);
    }
  }
  {
    lcm_util::LogWriter out(tracks);
    for (vtrack::track_list_t l : vtrack::testing::SyntheticTracks("mht")) {
      for (const vtrack::track_t& t : std::vector<vtrack::track_t>(l.tracks)) {
        if (t.status != vtrack::track_t::STATUS_CONFIRMED ||
            t.object_class != vtrack::track_t::CLASS_VEHICLE) {
          continue;
        }
        vtrack::track_t a = t, b = t;
        a.id = t.id + 1000;
        a.y = nan;
        b.id = t.id + 2000;
        b.theta = nan;
        l.tracks.push_back(a);
        l.tracks.push_back(b);
        track_nan += 2;
        break;
      }
      l.num_tracks = static_cast<std::int32_t>(l.tracks.size());
      out.WriteMessage(l.utime, "TRACKS", l);
    }
  }
  ASSERT_GT(track_nan, 0);
  const EvalParams params;
  const EvalSummary clean = Evaluate(LoadLogs({run_, tracks_}, params), params);
  const EvalSummary s = Evaluate(LoadLogs({run, tracks}, params), params);
  // Frames are scored where truth and tracks meet: kScans of them (the truth at -1 s has no
  // tracks, the tracks at +100 s no truth), one bad truth object of each kind and two bad tracks
  // in each.
  ASSERT_EQ(truth_nan, kScans + 1);
  ASSERT_EQ(track_nan, 2 * (kScans + 1));
  EXPECT_EQ(s.problems.at("truth_not_finite"), kScans);
  EXPECT_EQ(s.problems.at("truth_duplicate_id"), kScans);
  EXPECT_EQ(s.problems.at("track_not_finite"), 2 * kScans);
  EXPECT_EQ(s.clear.true_positives, clean.clear.true_positives);
  EXPECT_EQ(s.clear.false_positives, clean.clear.false_positives);
  EXPECT_EQ(s.clear.false_negatives, clean.clear.false_negatives);
  EXPECT_DOUBLE_EQ(s.position_rmse_m, clean.position_rmse_m);
  EXPECT_DOUBLE_EQ(s.heading_rmse_deg, clean.heading_rmse_deg);
  const std::string text = SummaryText(s);
  for (const char* k : {"truth_not_finite", "truth_duplicate_id", "track_not_finite"}) {
    EXPECT_NE(text.find(std::string("input problem: ") + k), std::string::npos) << k << "\n" << text;
    EXPECT_NE(SummaryJson(s).find(k), std::string::npos) << k;
  }
}

TEST_F(EvaluatorTest, TruthTimeOffset) {
  // Ground truth stamped u but describing u + 50 ms (as KITTI logs): car A's truth is its state
  // 50 ms later; track 1 reports A's exact state at u (centre, speed, velocity heading, yaw rate)
  // and predicts A's exact future centre. Scored without the offset, track 1 is 50 ms behind
  // (about kSpeed * 0.05 = 0.25 m); with the offset (half the 100 ms sweep of the log's scan) it
  // is advanced to u + 50 ms and the errors nearly vanish (what remains is the straight-line
  // advance against the arc, v^2 dt^2 / (2 R) = 1.6 mm).
  const std::string run = dir_ + "/run_offset.lcm", tracks = dir_ + "/tracks_offset.lcm";
  {
    lcm_util::LogWriter w(run);
    vtrack::ladar_scan_t scan{};
    scan.utime = vtrack::testing::kUtime0;
    scan.sensor_orientation[0] = 1.0;
    scan.sweep_duration_us = 100'000;
    w.WriteMessage(scan.utime, "LADAR_SCAN", scan);
    for (auto list : vtrack::testing::SyntheticTruth()) {
      const double t = static_cast<double>(list.utime - vtrack::testing::kUtime0) * 1e-6 + 0.05;
      const auto a = vtrack::testing::CarA(t);
      list.objects[0].x = a.centre.x();
      list.objects[0].y = a.centre.y();
      list.objects[0].yaw = a.yaw;
      w.WriteMessage(list.utime, "GROUND_TRUTH", list);
    }
  }
  {
    lcm_util::LogWriter w(tracks);
    for (auto list : vtrack::testing::SyntheticTracks("mht")) {
      const double t = static_cast<double>(list.utime - vtrack::testing::kUtime0) * 1e-6;
      const auto a = vtrack::testing::CarA(t);
      auto& t1 = list.tracks[0];
      t1.x = a.centre.x();
      t1.y = a.centre.y();
      t1.theta = a.yaw;
      t1.speed = a.velocity.norm();
      t1.velocity_heading = std::atan2(a.velocity.y(), a.velocity.x());
      t1.yaw_rate = a.yaw_rate;
      for (std::size_t k = 0; k < t1.pred_x.size(); ++k) t1.pred_x[k] -= 1.0;  // exact future
      w.WriteMessage(list.utime, "TRACKS", list);
    }
  }
  EvalParams params;
  const LogData data = LoadLogs({run, tracks}, params);
  const EvalSummary plain = Evaluate(data, params);
  params.truth_time_offset_s = std::numeric_limits<double>::quiet_NaN();  // half the sweep
  const EvalSummary shifted = Evaluate(data, params);
  EXPECT_NEAR(shifted.truth_time_offset_s, 0.05, 1e-12);
  const double lag = vtrack::testing::CarA(0).velocity.norm() * 0.05;
  // Track 2 (on the parked car) is exact either way: RMSE over the two = lag / sqrt 2.
  EXPECT_NEAR(plain.position_rmse_m, lag / std::sqrt(2.0), 0.01);
  EXPECT_LT(shifted.position_rmse_m, 0.003);
  EXPECT_GT(plain.prediction_error_m[0], 0.2);
  EXPECT_LT(shifted.prediction_error_m[0], 0.01);
}

// vtrack-eval --track-labels: every track of every scored frame, any status and class, labelled
// against the nearest truth object of any class. Ego at the origin heading +x; truth in both
// frames: car 10 in the labelled region at (10, 0), wall 11 at (0, 10), car 12 outside the
// labelled region at (-10, 0), DontCare 13 (CLASS_UNKNOWN) at (0, -10).
class TrackLabelsTest : public ::testing::Test {
 protected:
  static constexpr std::int64_t kT0 = 1'700'000'000'000'000;
  static constexpr std::int64_t kDt = 100'000;
  struct Expect {
    std::int64_t track_id;
    double x, y;
    int label;
    std::int64_t truth_id;
    int truth_class;
    double distance_m;
  };
  void SetUp() override {
    dir_ = vtrack::testing::ScratchDir("track_labels");
    run_ = dir_ + "/run.lcm";
    tracks_ = dir_ + "/tracks.lcm";
    poses_ = dir_ + "/poses.lcm";
    lcm_util::LogWriter run(run_);
    // Truth at frames 0 and 1, and at frame 3 (no track list there).
    for (const int k : {0, 1, 3}) {
      vtrack::object_list_t gt{};
      gt.utime = kT0 + k * kDt;
      auto add = [&](std::int64_t id, std::int8_t cls, double x, double y, bool labelled) {
        vtrack::object_t o{};
        o.id = id;
        o.object_class = cls;
        o.x = x;
        o.y = y;
        o.length = 4.0;
        o.width = 1.8;
        o.height = 1.5;
        o.rear_axle_offset = std::numeric_limits<double>::quiet_NaN();
        o.in_labelled_region = labelled;
        o.num_points = -1;
        gt.objects.push_back(o);
      };
      add(10, vtrack::object_t::CLASS_CAR, 10.0, 0.0, true);
      add(11, vtrack::object_t::CLASS_WALL, 0.0, 10.0, true);
      add(12, vtrack::object_t::CLASS_CAR, -10.0, 0.0, false);
      add(13, vtrack::object_t::CLASS_UNKNOWN, 0.0, -10.0, true);
      gt.num_objects = static_cast<std::int32_t>(gt.objects.size());
      run.WriteMessage(gt.utime, "GROUND_TRUTH", gt);
    }
    lcm_util::LogWriter poses(poses_);
    for (int k = 0; k <= 3; ++k) {
      vtrack::pose_t p{};
      p.utime = kT0 + k * kDt;
      p.orientation[0] = 1.0;
      poses.WriteMessage(p.utime, "EGO_POSE", p);
    }
    // Track lists at frames 0, 1 and 2 (no truth at frame 2).
    lcm_util::LogWriter tracks(tracks_);
    for (const int k : {0, 1, 2}) {
      vtrack::track_list_t l{};
      l.utime = kT0 + k * kDt;
      l.mode = "mht";
      auto add = [&](std::int64_t id, std::int8_t status, std::int8_t cls, double x, double y) {
        vtrack::track_t t{};
        t.id = id;
        t.status = status;
        t.object_class = cls;
        t.x = x;
        t.y = y;
        t.length = 4.0;
        t.width = 1.8;
        t.rear_axle_offset = std::numeric_limits<double>::quiet_NaN();
        for (int i = 0; i < 9; i += 4) t.cov[i] = 0.01;
        l.tracks.push_back(t);
      };
      const auto confirmed = vtrack::track_t::STATUS_CONFIRMED;
      const auto vehicle = vtrack::track_t::CLASS_VEHICLE;
      for (const Expect& e : Expected()) {
        const bool tentative_other = e.track_id == 5;
        add(e.track_id, tentative_other ? vtrack::track_t::STATUS_TENTATIVE
                        : e.track_id == 6 ? vtrack::track_t::STATUS_COASTING : confirmed,
            tentative_other ? vtrack::track_t::CLASS_OTHER : vehicle, e.x, e.y);
      }
      add(7, confirmed, vehicle, std::numeric_limits<double>::quiet_NaN(), 0.0);  // refused
      l.num_tracks = static_cast<std::int32_t>(l.tracks.size());
      tracks.WriteMessage(l.utime, "TRACKS", l);
    }
  }
  // The tracks and what each must get, worked out by hand (gate 2 m).
  static std::vector<Expect> Expected() {
    const auto car = vtrack::object_t::CLASS_CAR;
    return {
        {1, 10.3, 0.4, 1, 10, car, 0.5},                     // on the labelled car
        {2, 0.6, 10.8, 0, 11, vtrack::object_t::CLASS_WALL, 1.0},  // on the wall
        {3, 25.0, 30.0, 0, -1, -1, std::sqrt(25.0 * 25.0 + 20.0 * 20.0)},  // nearest: wall
        {4, -10.0, 1.2, -1, 12, car, 1.2},                   // on the unlabelled car
        {5, 9.7, -0.4, 1, 10, car, 0.5},                     // tentative, class other
        {6, 0.9, -10.0, -1, 13, vtrack::object_t::CLASS_UNKNOWN, 0.9},  // coasting, DontCare
    };
  }
  // Checks rows against Expected() for frames 0 and 1, with label overridden by labels (if given).
  static void CheckRows(const std::vector<TrackLabel>& rows, bool with_range,
                        const std::map<std::int64_t, int>& label_override = {}) {
    const auto expected = Expected();
    ASSERT_EQ(rows.size(), 2 * expected.size());
    for (std::size_t r = 0; r < rows.size(); ++r) {
      const Expect& e = expected[r % expected.size()];
      const TrackLabel& row = rows[r];
      SCOPED_TRACE("row " + std::to_string(r) + ", track " + std::to_string(e.track_id));
      EXPECT_EQ(row.utime, kT0 + static_cast<std::int64_t>(r / expected.size()) * kDt);
      EXPECT_EQ(row.track_id, e.track_id);
      const auto o = label_override.find(e.track_id);
      EXPECT_EQ(row.label, o == label_override.end() ? e.label : o->second);
      EXPECT_EQ(row.truth_id, e.truth_id);
      EXPECT_EQ(row.truth_class, e.truth_class);
      EXPECT_NEAR(row.distance_m, e.distance_m, 1e-9);
      if (with_range) {
        EXPECT_NEAR(row.range_m, std::hypot(e.x, e.y), 1e-9);
      } else {
        EXPECT_TRUE(std::isnan(row.range_m));
      }
    }
  }
  std::string dir_, run_, tracks_, poses_;
};

TEST_F(TrackLabelsTest, EveryTrackOfEveryScoredFrameIsLabelled) {
  const EvalParams params;
  // Without a pose in the logs, the range is unknown.
  {
    std::vector<TrackLabel> rows;
    Evaluate(LoadLogs({run_, tracks_}, params), params, &rows);
    CheckRows(rows, false);
  }
  const LogData data = LoadLogs({run_, tracks_, poses_}, params);
  std::vector<TrackLabel> rows;
  const EvalSummary with = Evaluate(data, params, &rows);
  CheckRows(rows, true);
  // The scores are those without labels.
  const EvalSummary without = Evaluate(data, params);
  EXPECT_EQ(SummaryJson(with), SummaryJson(without));
  EXPECT_EQ(TrackCsv(with), TrackCsv(without));
  EXPECT_EQ(SummaryText(with), SummaryText(without));
  EXPECT_EQ(with.problems.count("track_not_finite"), 1u);
  EXPECT_EQ(with.problems.at("track_not_finite"), 2);  // the scoring's own count, not doubled
  // Scored: car 10 only; track 1 matches it, track 3 is a false positive, 2 (on the wall) and 4
  // (on the unlabelled car) pair with ignored truth and are dropped, 5 and 6 are not scored
  // (tentative other, coasting).
  EXPECT_EQ(with.clear.true_positives, 2);
  EXPECT_EQ(with.clear.false_positives, 2);
  EXPECT_EQ(with.ignored_track_detections, 4);

  // The file: the header, then one line per row with the values above (read back as numbers).
  std::istringstream in(TrackLabelCsv(rows));
  std::string line;
  ASSERT_TRUE(std::getline(in, line));
  EXPECT_EQ(line, "utime,track_id,label,range_m,truth_id,truth_class,distance_m");
  const auto expected = Expected();
  for (std::size_t r = 0; r < rows.size(); ++r) {
    ASSERT_TRUE(std::getline(in, line)) << r;
    std::vector<std::string> f;
    std::istringstream fields(line);
    for (std::string x; std::getline(fields, x, ',');) f.push_back(x);
    ASSERT_EQ(f.size(), 7u) << line;
    const Expect& e = expected[r % expected.size()];
    EXPECT_EQ(f[0], std::to_string(kT0 + static_cast<std::int64_t>(r / expected.size()) * kDt));
    EXPECT_EQ(f[1], std::to_string(e.track_id));
    EXPECT_EQ(f[2], std::to_string(e.label));
    EXPECT_NEAR(std::stod(f[3]), std::hypot(e.x, e.y), 1e-9) << line;
    EXPECT_EQ(f[4], std::to_string(e.truth_id));
    EXPECT_EQ(f[5], std::to_string(e.truth_class));
    EXPECT_NEAR(std::stod(f[6]), e.distance_m, 1e-9) << line;
  }
  EXPECT_FALSE(std::getline(in, line)) << "extra line: " << line;
  // Without a pose the range is written as nan.
  std::vector<TrackLabel> no_pose;
  Evaluate(LoadLogs({run_, tracks_}, params), params, &no_pose);
  std::istringstream in2(TrackLabelCsv(no_pose));
  std::getline(in2, line);
  std::getline(in2, line);
  EXPECT_EQ(line, std::to_string(kT0) + ",1,1,nan,10,1,0.5");
}

TEST_F(TrackLabelsTest, OutsideTheScoringRegionIsIgnored) {
  EvalParams params;
  params.region_range_m = 15.0;  // everything but track 3 at 39 m is inside
  const LogData data = LoadLogs({run_, tracks_, poses_}, params);
  std::vector<TrackLabel> rows;
  const EvalSummary with = Evaluate(data, params, &rows);
  CheckRows(rows, true, {{3, -1}});
  EXPECT_EQ(SummaryJson(with), SummaryJson(Evaluate(data, params)));
  // 9.9 m leaves car 10 (at 10 m) outside the region: track 5 at 9.71 m is inside, but the
  // nearest truth is an unscored vehicle, so it is ignored; every other track is outside.
  params.region_range_m = 9.9;
  Evaluate(data, params, &rows);
  CheckRows(rows, true, {{1, -1}, {2, -1}, {3, -1}, {4, -1}, {5, -1}, {6, -1}});
  ASSERT_EQ(rows.size(), 12u);
  EXPECT_EQ(rows[4].track_id, 5);
  EXPECT_LT(rows[4].range_m, 9.9);
}

}  // namespace
}  // namespace vtrack::eval
