// The whole tracker core on seeded synthetic scenes with known truth: a parked car and an
// Ackermann car turning in front of a moving ego vehicle. Checks tracking accuracy, identity,
// the hypothesis counts of the multi-hypothesis manager, determinism, and every bad input of
// docs/design.md, section 9 with its counter.
#include "tracker/core/tracker.h"

#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <limits>
#include <map>
#include <memory>
#include <random>
#include <set>
#include <string>

#include "tests/support/affinity.h"
#include "tests/tracker/core/synthetic_scene.h"

namespace vtrack {
namespace {

using testing::AckermannPath;
using testing::SceneConfig;
using testing::SceneObject;
using testing::SyntheticScene;

std::vector<SceneObject> TwoCars() {
  return {
      {1, AckermannPath({16.0, 7.0}, 0.3, 0.0, 0.0, -1.4)},     // parked
      {2, AckermannPath({4.0, -8.0}, 0.0, 7.0, 0.2, -1.4)},     // turning left
  };
}

// Runs the scene for duration_s and returns the output of every processed scan. Poses at 100 Hz;
// a scan is handed over when its sweep ends (as a driver publishes it).
std::vector<ScanOutput> RunScene(Tracker* tracker, SyntheticScene* scene, double duration_s) {
  std::vector<ScanOutput> out;
  std::int64_t seq = 0;
  for (int tick = 0; tick <= static_cast<int>(duration_s * 100); ++tick) {
    const double t = tick * 0.01;
    tracker->AddPose(scene->PoseAt(t), &out);
    if (tick >= 10 && tick % 10 == 0) tracker->AddScan(scene->ScanAt(t - 0.1, seq++), &out);
  }
  tracker->Flush(&out);
  return out;
}

struct Match {
  std::map<int, std::set<std::int64_t>> ids;      // object -> track ids matched after 1 s
  std::map<int, double> sum_sq, count;            // position error
  std::map<int, double> heading_sq;               // heading error (mod 180 deg)
  std::map<int, int> missed;                      // scans with no confirmed track near
};

Match Evaluate(const std::vector<ScanOutput>& outs, const SyntheticScene& scene, double t0_s) {
  Match m;
  for (const ScanOutput& o : outs) {
    const double t = (o.utime - scene.Utime(0.0)) * 1e-6;
    if (t < t0_s) continue;
    for (const auto& obj : scene.objects()) {
      const OrientedBox truth = obj.box_at(t);
      const TrackReport* best = nullptr;
      double best_d = 2.0;
      for (const auto& r : o.tracks) {
        if (r.status == TrackStatus::kTentative) continue;
        const double d = std::hypot(r.x - truth.center.x(), r.y - truth.center.y());
        if (d < best_d) {
          best_d = d;
          best = &r;
        }
      }
      if (!best) {
        ++m.missed[obj.id];
        continue;
      }
      m.ids[obj.id].insert(best->id);
      m.sum_sq[obj.id] += best_d * best_d;
      m.count[obj.id] += 1;
      const double dh = std::abs(AngleDiff(2.0 * best->theta, 2.0 * truth.theta)) / 2.0;
      m.heading_sq[obj.id] += dh * dh;
    }
  }
  return m;
}

TEST(TrackerTest, TracksParkedAndTurningCarsWithoutIdentitySwitch) {
  for (TrackerMode mode :
       {TrackerMode::kMht, TrackerMode::kIsm, TrackerMode::kVasm, TrackerMode::kCv}) {
    SCOPED_TRACE(ToString(mode));
    SyntheticScene scene(SceneConfig{}, TwoCars(), 42);
    TrackerParams params;
    params.manager.mode = mode;
    Tracker tracker(params);
    const auto outs = RunScene(&tracker, &scene, 6.0);
    ASSERT_GE(outs.size(), 55u);
    const Match m = Evaluate(outs, scene, 1.0);
    for (int id : {1, 2}) {
      SCOPED_TRACE(id);
      EXPECT_EQ(m.missed.count(id) ? m.missed.at(id) : 0, 0);
      ASSERT_TRUE(m.ids.count(id));
      EXPECT_EQ(m.ids.at(id).size(), 1u) << "identity switch";
      const double rmse = std::sqrt(m.sum_sq.at(id) / m.count.at(id));
      const double hrmse = std::sqrt(m.heading_sq.at(id) / m.count.at(id));
      EXPECT_LT(rmse, 0.4);
      EXPECT_LT(RadToDeg(hrmse), 6.0);
    }
    EXPECT_EQ(tracker.scans_dropped(), 0);
    // Scans only: the score is n / (n + confirm_updates) for n updates, 0.5 at confirmation.
    for (const TrackReport& r : outs.back().tracks) {
      const double n = r.num_updates, c = params.manager.confirm_updates;
      EXPECT_NEAR(r.score, n / (n + c), 1e-12);
      EXPECT_TRUE(std::isnan(r.z) && std::isnan(r.height));  // no box measured it
      if (r.status == TrackStatus::kConfirmed) {
        EXPECT_GE(r.score, 0.5);
      }
    }
  }
}

// Fused input: the scans see both cars, a detector's boxes (the truth plus seeded noise, score 7)
// only the turning one, each frame half a sweep after its scan. The detected car keeps one track
// measured by both (its score is the boxes' score), and the car that only the scans see still
// gets its track (its score from the scans, below 1); no other confirmed track appears.
TEST(TrackerTest, FusedBoxesAndScansOfOneCarGiveOneTrackAndAScanOnlyCarStillGetsOne) {
  for (TrackerMode mode : {TrackerMode::kMht, TrackerMode::kCv}) {
    SCOPED_TRACE(ToString(mode));
    SyntheticScene scene(SceneConfig{}, TwoCars(), 44);
    TrackerParams params;
    params.manager.mode = mode;
    params.detections.mode = InputMode::kFused;
    params.detections.min_score = 0.0;
    params.detections.birth_score = 1.0;
    Tracker tracker(params);
    std::mt19937 rng(5);
    std::normal_distribution<double> pos(0.0, 0.1), head(0.0, DegToRad(2.0));
    std::vector<ScanOutput> outs;
    std::int64_t seq = 0;
    for (int tick = 0; tick <= 600; ++tick) {  // 6 s, poses at 100 Hz
      const double t = tick * 0.01;
      tracker.AddPose(scene.PoseAt(t), &outs);
      if (tick < 10 || tick % 10 != 0) continue;
      tracker.AddScan(scene.ScanAt(t - 0.1, seq), &outs);
      const double td = t - 0.05;  // the frame's time: half a sweep after the scan's start
      const OrientedBox b = scene.objects()[1].box_at(td);
      const Eigen::Vector3d c = scene.EgoAt(td).inverse() * Eigen::Vector3d(b.center.x(), b.center.y(), 0.0);
      DetectionList list;
      list.utime = scene.Utime(td);
      list.seq = seq++;
      Detection d;
      d.x = c.x() + pos(rng);
      d.y = c.y() + pos(rng);
      d.z = -1.7;
      d.yaw = WrapToPi(b.theta + head(rng));  // the ego does not turn
      d.length = b.length;
      d.width = b.width;
      d.height = 1.5;
      d.score = 7.0;
      list.boxes.push_back(d);
      tracker.AddDetections(std::move(list), &outs);
    }
    tracker.Flush(&outs);
    ASSERT_GE(outs.size(), 55u);
    const Match m = Evaluate(outs, scene, 1.0);
    for (int id : {1, 2}) {
      SCOPED_TRACE(id);
      EXPECT_EQ(m.missed.count(id) ? m.missed.at(id) : 0, 0);
      ASSERT_TRUE(m.ids.count(id));
      EXPECT_EQ(m.ids.at(id).size(), 1u) << "identity switch";
    }
    const std::int64_t parked_id = *m.ids.at(1).begin(), turning_id = *m.ids.at(2).begin();
    EXPECT_NE(parked_id, turning_id);
    int confirmed = 0, parked_updates = 0, turning_updates = 0;
    for (const TrackReport& r : outs.back().tracks) {
      if (r.status == TrackStatus::kTentative) continue;
      ++confirmed;
      if (r.id == turning_id) {
        EXPECT_NEAR(r.score, 7.0, 1e-9);
        turning_updates = r.num_updates;
      }
      if (r.id == parked_id) {
        EXPECT_GT(r.score, 0.5);
        EXPECT_LT(r.score, 1.0);
        parked_updates = r.num_updates;
      }
    }
    EXPECT_EQ(confirmed, 2);
    // Measured by its boxes and by the scans: about twice the updates of the scan-only car.
    EXPECT_GT(turning_updates, 3 * parked_updates / 2);
    EXPECT_EQ(tracker.rejects().count("bad_detections"), 0u);
  }
}

TEST(TrackerTest, MoversGainVasmHypothesesAndStationaryObjectsKeepOneIsm) {
  SyntheticScene scene(SceneConfig{}, TwoCars(), 43);
  Tracker tracker(TrackerParams{});
  const auto outs = RunScene(&tracker, &scene, 5.0);
  const ScanOutput& last = outs.back();
  const double t = (last.utime - scene.Utime(0.0)) * 1e-6;
  int checked = 0;
  for (const auto& r : last.tracks) {
    const OrientedBox parked = scene.objects()[0].box_at(t);
    const OrientedBox mover = scene.objects()[1].box_at(t);
    if (std::hypot(r.x - parked.center.x(), r.y - parked.center.y()) < 1.0) {
      EXPECT_FALSE(r.moving);
      EXPECT_EQ(r.num_hypotheses, 1);
      EXPECT_EQ(r.model, ModelKind::kIsm);
      EXPECT_EQ(r.object_class, ObjectClass::kVehicle);
      ++checked;
    }
    if (std::hypot(r.x - mover.center.x(), r.y - mover.center.y()) < 1.0) {
      EXPECT_TRUE(r.moving);
      EXPECT_GE(r.num_hypotheses, 2);
      EXPECT_LE(r.num_hypotheses, 4);
      EXPECT_NEAR(r.speed, 7.0, 1.0);
      // Velocity heading of the centre (Eq. 7) against the truth's finite difference.
      const OrientedBox ahead = scene.objects()[1].box_at(t + 1e-3);
      const Eigen::Vector2d v = (ahead.center - mover.center) / 1e-3;
      EXPECT_LT(std::abs(AngleDiff(r.velocity_heading, std::atan2(v.y(), v.x()))), DegToRad(8));
      // The predicted trajectory: 0..3 s by 0.1 s, std growing, near the truth at 1 s.
      ASSERT_EQ(r.prediction.size(), 31u);
      EXPECT_GT(r.prediction.back().pos_std, r.prediction.front().pos_std);
      const OrientedBox at1 = scene.objects()[1].box_at(t + 1.0);
      EXPECT_LT((r.prediction[10].pose.head<2>() - at1.center).norm(), 1.0);
      ++checked;
    }
  }
  EXPECT_EQ(checked, 2);
}

// The trajectory is for the planner, which acts on vehicles: by default only vehicle tracks carry
// one; manager.predict_all_tracks gives every track one, and changes nothing else.
TEST(TrackerTest, PredictsVehiclesOnlyUnlessAllTracksAreAsked) {
  auto run = [](bool all) {
    SyntheticScene scene(SceneConfig{}, TwoCars(), 44);
    TrackerParams params;
    params.manager.predict_all_tracks = all;
    Tracker tracker(params);
    return RunScene(&tracker, &scene, 4.0);
  };
  const auto vehicles_only = run(false), all = run(true);
  ASSERT_EQ(vehicles_only.size(), all.size());
  int vehicles = 0, others = 0;
  for (std::size_t s = 0; s < all.size(); ++s) {
    ASSERT_EQ(vehicles_only[s].tracks.size(), all[s].tracks.size());
    for (std::size_t k = 0; k < all[s].tracks.size(); ++k) {
      const TrackReport& a = all[s].tracks[k];
      const TrackReport& v = vehicles_only[s].tracks[k];
      EXPECT_EQ(a.id, v.id);
      EXPECT_EQ(a.x, v.x);
      EXPECT_EQ(a.theta, v.theta);
      ASSERT_EQ(a.prediction.size(), 31u);  // 0..3 s by 0.1 s
      if (a.object_class == ObjectClass::kVehicle) {
        ++vehicles;
        ASSERT_EQ(v.prediction.size(), a.prediction.size());
        EXPECT_EQ(v.prediction.back().pose, a.prediction.back().pose);
      } else {
        ++others;
        EXPECT_TRUE(v.prediction.empty());
      }
    }
  }
  // Both kinds occur: new tracks are not vehicles until their size is known.
  EXPECT_GT(vehicles, 0);
  EXPECT_GT(others, 0);
}

TEST(TrackerTest, SameInputGivesIdenticalOutput) {
  auto run = [] {
    SyntheticScene scene(SceneConfig{}, TwoCars(), 44);
    Tracker tracker(TrackerParams{}, /*debug=*/true);
    return RunScene(&tracker, &scene, 3.0);
  };
  const auto a = run(), b = run();
  ASSERT_EQ(a.size(), b.size());
  for (std::size_t i = 0; i < a.size(); ++i) {
    ASSERT_EQ(a[i].tracks.size(), b[i].tracks.size());
    for (std::size_t j = 0; j < a[i].tracks.size(); ++j) {
      EXPECT_EQ(a[i].tracks[j].id, b[i].tracks[j].id);
      EXPECT_EQ(a[i].tracks[j].x, b[i].tracks[j].x);  // bit for bit
      EXPECT_EQ(a[i].tracks[j].theta, b[i].tracks[j].theta);
    }
  }
}

// Section 4.8: new objects become tracks in their order (the larger first), and an object with
// merge_fraction of its returns on a rectangle created before it from the same scan is part of
// that object, not a new one. A single-plane scan of a car's corner 10 m ahead (two faces, 4.4 x
// 1.8 m, 40 returns) and, after it in the scan (a range jump: its own segment), a small cluster
// of 6 returns inside the car's rectangle: one track, and no second one started (no evidence row,
// no id spent), with any number of threads (the objects are measured on the pool, then kept in
// order).
TEST(TrackerTest, AnObjectOnARectangleCreatedFromTheSameScanStartsNoTrack) {
  for (const int threads : {1, 2}) {
    TrackerParams params;
    params.compute.threads = threads;
    Tracker tracker(params);
    tracker.SetRecordEvidence(true);
    constexpr std::int64_t kT = 1'700'000'000'000'000;
    std::vector<ScanOutput> out;
    for (std::int64_t t = kT - 50'000; t <= kT + 200'000; t += 10'000) tracker.AddPose({t, Eigen::Isometry3d::Identity()}, &out);
    LadarScan scan;
    scan.utime = kT;
    scan.sweep_duration_us = 100'000;
    scan.num_rings = 1;
    const auto add = [&](double x, double y) {
      scan.x.push_back(static_cast<float>(x));
      scan.y.push_back(static_cast<float>(y));
      scan.z.push_back(0.0f);
      scan.intensity.push_back(0.0f);
      scan.dt_us.push_back(static_cast<std::int32_t>(scan.x.size()));
      scan.ring.push_back(0);
    };
    // The corner at (10, -0.9): the rear face along y to (10, 0.9), the side along x to (14.4, -0.9).
    for (int i = 0; i < 20; ++i) add(10.0, 0.9 - 1.8 * i / 19.0);
    for (int i = 1; i <= 20; ++i) add(10.0 + 4.4 * i / 20.0, -0.9);
    // Inside the car's rectangle, 2 m behind its rear face.
    for (int i = 0; i < 6; ++i) add(12.0 + 0.05 * i, 0.2 + 0.04 * i);
    tracker.AddScan(std::move(scan), &out);
    tracker.Flush(&out);
    std::string rejects;
    for (const auto& [reason, n] : tracker.rejects()) rejects += reason + " " + std::to_string(n) + "; ";
    ASSERT_EQ(out.size(), 1u) << threads << " threads; refused: " << rejects;
    EXPECT_EQ(out[0].tracks.size(), 1u) << threads << " threads";
    EXPECT_EQ(out[0].evidence.size(), 1u) << threads << " threads: a track was started on the cluster";
  }
}

// ScanOutput::stages: each stage's time is the difference of the caller's clock between its end
// and the one before (a clock that advances by a stage's own number of seconds at each reading
// gives every stage that number, in the pipeline's order); without a clock nothing is measured,
// and the tracks are the same either way (the library's decisions read no clock).
TEST(TrackerTest, StageClockTimesEachStageAndChangesNoTrack) {
  double now = 0.0;
  int readings = 0;
  const auto run = [&](bool clock) {
    SyntheticScene scene(SceneConfig{}, TwoCars(), 44);
    Tracker tracker(TrackerParams{});
    // Reading k (from 0) advances the clock by k % 7 seconds: stage j of a scan (its j-th
    // reading after the first) then takes j seconds.
    if (clock) {
      tracker.SetStageClock([&] {
        now += static_cast<double>(readings++ % 7);
        return now;
      });
    }
    return RunScene(&tracker, &scene, 2.0);
  };
  const std::vector<ScanOutput> timed = run(true), plain = run(false);
  ASSERT_GT(timed.size(), 10u);
  EXPECT_EQ(readings, 7 * static_cast<int>(timed.size()));
  ASSERT_EQ(timed.size(), plain.size());
  for (std::size_t i = 0; i < timed.size(); ++i) {
    const ScanOutput::StageSeconds& s = timed[i].stages;
    EXPECT_EQ(s.preprocess, 1.0);
    EXPECT_EQ(s.segment, 2.0);
    EXPECT_EQ(s.associate, 3.0);
    EXPECT_EQ(s.update, 4.0);
    EXPECT_EQ(s.create, 5.0);
    EXPECT_EQ(s.life_cycle, 6.0);
    const ScanOutput::StageSeconds& z = plain[i].stages;
    EXPECT_EQ(z.preprocess + z.segment + z.associate + z.update + z.create + z.life_cycle, 0.0);
    ASSERT_EQ(timed[i].tracks.size(), plain[i].tracks.size());
    for (std::size_t j = 0; j < timed[i].tracks.size(); ++j) {
      EXPECT_EQ(timed[i].tracks[j].id, plain[i].tracks[j].id);
      EXPECT_EQ(timed[i].tracks[j].x, plain[i].tracks[j].x);
    }
  }
}

// Where threads run is the process's to decide (Tracker::AllowThreadPinning): a tracker built
// with the shipped parameters leaves its caller's thread where it was, unless the process
// allows pinning, as vtrack-tracker does live. The calling thread's CPUs as the kernel reports
// them, after scans that ran the pool's loops.
TEST(TrackerTest, PinsItsThreadsOnlyWhereTheProcessAllowsIt) {
  const pthread_t self = pthread_self();
  const std::vector<int> allowed = testing::AffinityOf(self);
  const int n = static_cast<int>(allowed.size());
  if (n < 2 || n > 64) GTEST_SKIP() << "the process may run on " << n << " CPUs";
  TrackerParams params;
  ASSERT_TRUE(params.compute.pin_threads);  // shipped on
  params.compute.threads = n;               // as many threads as CPUs: pinned where allowed
  // The permission for the trackers made in its scope (decided when a tracker is made).
  struct Allowed {
    explicit Allowed(bool allow) { Tracker::AllowThreadPinning(allow); }
    ~Allowed() { Tracker::AllowThreadPinning(false); }
  };
  auto run = [&params](bool allow_pinning) {
    std::unique_ptr<Tracker> tracker;
    {
      const Allowed scope(allow_pinning);
      tracker = std::make_unique<Tracker>(params);
    }
    SyntheticScene scene(SceneConfig{}, TwoCars(), 47);
    EXPECT_FALSE(RunScene(tracker.get(), &scene, 1.0).empty());
    return tracker;
  };
  {
    const auto tracker = run(false);
    EXPECT_EQ(testing::AffinityOf(self), allowed);
  }
  if (!testing::CanPinAThread(allowed[0])) GTEST_SKIP() << "this process may not pin a thread";
  {
    const auto tracker = run(true);
    EXPECT_EQ(testing::AffinityOf(self), std::vector<int>{allowed[0]});
  }
  EXPECT_EQ(testing::AffinityOf(self), allowed);  // set free with the tracker
}

TEST(TrackerTest, AnyNumberOfThreadsGivesTheSameOutput) {
  // compute.threads shares the scan's track updates among threads: the tracks, the debug output
  // and the evidence rows must be those of one thread, in the same order. Fourteen objects (a
  // row of parked cars on either side, two movers) give the threads tracks to share.
  std::vector<SceneObject> objects = TwoCars();
  for (int k = 0; k < 6; ++k) {
    objects.push_back({10 + k, AckermannPath({-10.0 + 7.0 * k, 14.0}, 0.0, 0.0, 0.0, -1.4)});
    objects.push_back({20 + k, AckermannPath({-8.0 + 7.0 * k, -16.0}, 0.05, 0.0, 0.0, -1.4)});
  }
  auto run = [&objects](int threads) {
    SyntheticScene scene(SceneConfig{}, objects, 45);
    TrackerParams params;
    params.compute.threads = threads;
    Tracker tracker(params, /*debug=*/true);
    tracker.SetRecordEvidence(true);
    return RunScene(&tracker, &scene, 3.0);
  };
  const std::vector<ScanOutput> one = run(1);
  std::size_t max_tracks = 0;
  for (const ScanOutput& o : one) max_tracks = std::max(max_tracks, o.tracks.size());
  ASSERT_GE(max_tracks, 10u) << "the scene should give the threads many tracks to share";
  for (const int threads : {2, 3}) {
    SCOPED_TRACE("threads " + std::to_string(threads));
    const std::vector<ScanOutput> many = run(threads);
    ASSERT_EQ(one.size(), many.size());
    for (std::size_t i = 0; i < one.size(); ++i) {
      const ScanOutput& a = one[i];
      const ScanOutput& b = many[i];
      ASSERT_EQ(a.tracks.size(), b.tracks.size()) << "scan " << i;
      for (std::size_t j = 0; j < a.tracks.size(); ++j) {
        const TrackReport& ta = a.tracks[j];
        const TrackReport& tb = b.tracks[j];
        EXPECT_EQ(ta.id, tb.id);  // bit for bit below
        EXPECT_EQ(ta.x, tb.x);
        EXPECT_EQ(ta.y, tb.y);
        EXPECT_EQ(ta.theta, tb.theta);
        EXPECT_EQ(ta.speed, tb.speed);
        EXPECT_EQ(ta.length, tb.length);
        EXPECT_EQ(ta.num_hypotheses, tb.num_hypotheses);
        EXPECT_EQ(ta.object_class, tb.object_class);
        EXPECT_EQ(ta.vehicle_probability, tb.vehicle_probability);
        EXPECT_EQ(ta.cov, tb.cov);
      }
      ASSERT_EQ(a.debug.size(), b.debug.size()) << "scan " << i;
      for (std::size_t j = 0; j < a.debug.size(); ++j) {
        EXPECT_EQ(a.debug[j].track_id, b.debug[j].track_id);
        EXPECT_EQ(a.debug[j].point_x, b.debug[j].point_x);
      }
      ASSERT_EQ(a.evidence.size(), b.evidence.size()) << "scan " << i;
      for (std::size_t j = 0; j < a.evidence.size(); ++j) {
        EXPECT_EQ(a.evidence[j].track_id, b.evidence[j].track_id);
        EXPECT_EQ(a.evidence[j].logit, b.evidence[j].logit);
        EXPECT_EQ(a.evidence[j].log_odds, b.evidence[j].log_odds);
      }
    }
  }
}

TEST(TrackerTest, ScanWaitsForThePoseStreamThenIsForcedWithExtrapolation) {
  SyntheticScene scene(SceneConfig{}, TwoCars(), 45);
  TrackerParams params;
  Tracker tracker(params);
  std::vector<ScanOutput> out;
  for (int tick = 0; tick <= 5; ++tick) tracker.AddPose(scene.PoseAt(tick * 0.01), &out);
  tracker.AddScan(scene.ScanAt(0.0, 0), &out);  // sweep to 0.1 s, poses only to 0.05 s
  EXPECT_TRUE(out.empty());
  EXPECT_EQ(tracker.queued_scans(), 1u);
  tracker.AddPose(scene.PoseAt(0.1), &out);      // pose reaches the sweep's end
  ASSERT_EQ(out.size(), 1u);
  EXPECT_EQ(tracker.rejects().count("pose_extrapolated"), 0u);
  // Poses stop at 0.1 s; the next scans are processed once messages are max_pose_wait later.
  tracker.AddScan(scene.ScanAt(0.1, 1), &out);
  tracker.AddScan(scene.ScanAt(0.2, 2), &out);
  EXPECT_EQ(out.size(), 1u);
  tracker.AddScan(scene.ScanAt(0.4, 3), &out);   // 0.4 >= 0.2 + max_pose_wait (0.2 s)
  EXPECT_EQ(out.size(), 2u);
  EXPECT_EQ(tracker.rejects().at("pose_extrapolated"), 1);
}

TEST(TrackerTest, SurvivesEveryBadInputAndCountsIt) {
  SyntheticScene scene(SceneConfig{}, TwoCars(), 46);
  TrackerParams params;
  params.preprocess.max_points = 5000;
  Tracker tracker(params);
  std::vector<ScanOutput> out;
  for (int tick = 0; tick <= 30; ++tick) tracker.AddPose(scene.PoseAt(tick * 0.01), &out);
  // NaN / Inf returns: dropped, counted per return; the scan is still processed.
  LadarScan s = scene.ScanAt(0.0, 0);
  s.x[0] = std::numeric_limits<float>::quiet_NaN();
  s.y[1] = std::numeric_limits<float>::infinity();
  s.dt_us[2] = -5;
  tracker.AddScan(std::move(s), &out);
  EXPECT_EQ(tracker.rejects().at("nan_point"), 2);
  EXPECT_EQ(tracker.rejects().at("bad_point_time"), 1);
  EXPECT_EQ(out.size(), 1u);
  // Repeated and out-of-order scans.
  tracker.AddScan(scene.ScanAt(0.0, 0), &out);
  EXPECT_EQ(tracker.rejects().at("scan_repeated"), 1);
  tracker.AddScan(scene.ScanAt(-0.05, 0), &out);
  EXPECT_EQ(tracker.rejects().at("scan_out_of_order"), 1);
  // Empty, huge, inconsistent scans.
  LadarScan empty = scene.ScanAt(0.1, 1);
  empty.x.clear(); empty.y.clear(); empty.z.clear(); empty.dt_us.clear(); empty.ring.clear();
  tracker.AddScan(std::move(empty), &out);
  EXPECT_EQ(tracker.rejects().at("empty_scan"), 1);
  LadarScan huge = scene.ScanAt(0.1, 1);
  huge.x.resize(6000, 1.0f); huge.y.resize(6000, 1.0f); huge.z.resize(6000, 0.0f);
  huge.dt_us.resize(6000, 0); huge.ring.resize(6000, 0);
  tracker.AddScan(std::move(huge), &out);
  EXPECT_EQ(tracker.rejects().at("huge_scan"), 1);
  LadarScan bad = scene.ScanAt(0.1, 1);
  bad.y.pop_back();
  tracker.AddScan(std::move(bad), &out);
  LadarScan bad_sweep = scene.ScanAt(0.1, 1);
  bad_sweep.sweep_duration_us = -1;
  tracker.AddScan(std::move(bad_sweep), &out);
  EXPECT_EQ(tracker.rejects().at("bad_scan"), 2);
  // Poses: repeated, out of order, not a rotation, NaN.
  tracker.AddPose(scene.PoseAt(0.30), &out);
  EXPECT_EQ(tracker.rejects().at("pose_repeated"), 1);
  tracker.AddPose(scene.PoseAt(0.25), &out);
  EXPECT_EQ(tracker.rejects().at("pose_out_of_order"), 1);
  EgoPose p = scene.PoseAt(0.31);
  p.world_from_body.linear() *= 2.0;
  tracker.AddPose(p, &out);
  p = scene.PoseAt(0.32);
  p.world_from_body.translation().x() = std::numeric_limits<double>::quiet_NaN();
  tracker.AddPose(p, &out);
  EXPECT_EQ(tracker.rejects().at("invalid_pose"), 2);
  // Stale pose: poses stop at 0.3 s; a scan at 1.0 s is forced later and the pose is too old.
  tracker.AddScan(scene.ScanAt(1.0, 5), &out);
  tracker.AddScan(scene.ScanAt(1.5, 6), &out);
  EXPECT_EQ(tracker.rejects().at("stale_pose"), 1);
  // A jump back in time (looped log) resets the tracker: tracks gone, ids not reused.
  std::int64_t max_id = 0;
  for (const auto& o : out) for (const auto& r : o.tracks) max_id = std::max(max_id, r.id);
  EXPECT_GT(max_id, 0);
  std::vector<ScanOutput> after;
  SyntheticScene again(SceneConfig{}, TwoCars(), 47);
  for (int tick = 0; tick <= 100; ++tick) {
    const double t = tick * 0.01;
    EgoPose q = again.PoseAt(t);
    q.utime -= 0;  // same times as the first pass: 1.5 s earlier than the newest message
    tracker.AddPose(q, &after);
    if (tick >= 10 && tick % 10 == 0) tracker.AddScan(again.ScanAt(t - 0.1, 100 + tick), &after);
  }
  EXPECT_EQ(tracker.resets(), 1);
  ASSERT_FALSE(after.empty());
  for (const auto& o : after) for (const auto& r : o.tracks) EXPECT_GT(r.id, max_id);
  // Every event has a reason and a message for the warning.
  for (const auto& e : tracker.TakeEvents()) {
    EXPECT_FALSE(e.reason.empty());
    EXPECT_FALSE(e.message.empty());
  }
  EXPECT_EQ(tracker.scans_received(),
            tracker.scans_processed() + tracker.scans_dropped() +
                static_cast<std::int64_t>(tracker.queued_scans()));
}

// One stray message stamped 1 h ahead, then one 5 s behind, amid a steady stream: neither resets
// the tracker (each is refused and counted), the tracks keep their ids. Two messages in a row
// 1 h ahead (a real clock step) reset it. A stamp near INT64_MIN is a jump back, said with a
// positive number of milliseconds (no overflow in the difference).
TEST(TrackerTest, OneMessageOutOfTimeDoesNotResetTwoInARowDo) {
  SyntheticScene scene(SceneConfig{}, TwoCars(), 5);
  Tracker tracker(TrackerParams{});
  std::vector<ScanOutput> out;
  std::int64_t seq = 0;
  auto run = [&](double from_s, double to_s) {
    for (int tick = static_cast<int>(from_s * 100); tick <= static_cast<int>(to_s * 100); ++tick) {
      const double t = tick * 0.01;
      tracker.AddPose(scene.PoseAt(t), &out);
      if (tick >= 10 && tick % 10 == 0) tracker.AddScan(scene.ScanAt(t - 0.1, seq++), &out);
    }
  };
  run(0.0, 2.0);
  auto confirmed_ids = [&] {
    std::set<std::int64_t> ids;
    for (const auto& r : out.back().tracks) {
      if (r.status == TrackStatus::kConfirmed) ids.insert(r.id);
    }
    return ids;
  };
  const std::set<std::int64_t> before = confirmed_ids();
  ASSERT_EQ(before.size(), 2u);
  EgoPose ahead = scene.PoseAt(2.005);
  ahead.utime += 3'600'000'000;  // 1 h ahead
  tracker.AddPose(ahead, &out);
  tracker.AddScan(scene.ScanAt(-3.0, seq++), &out);  // 5 s behind the newest message
  run(2.01, 3.0);
  EXPECT_EQ(tracker.resets(), 0);
  EXPECT_EQ(tracker.rejects().at("time_jump_unconfirmed"), 1);  // the pose
  EXPECT_EQ(tracker.rejects().at("scan_time_jump"), 1);         // the scan (a scan reason)
  EXPECT_EQ(confirmed_ids(), before);
  EXPECT_EQ(tracker.scans_received(),
            tracker.scans_processed() + tracker.scans_dropped() +
                static_cast<std::int64_t>(tracker.queued_scans()));
  // A stamp at INT64_MIN: refused, and the message says how far back in positive milliseconds.
  tracker.TakeEvents();
  EgoPose bottom = scene.PoseAt(3.005);
  bottom.utime = std::numeric_limits<std::int64_t>::min();
  tracker.AddPose(bottom, &out);
  bool said = false;
  for (const auto& e : tracker.TakeEvents()) {
    if (e.reason != "time_jump_unconfirmed") continue;
    said = true;
    EXPECT_EQ(e.message.find("by -"), std::string::npos) << e.message;
  }
  EXPECT_TRUE(said);
  EXPECT_EQ(tracker.resets(), 0);
  // Two poses in a row 1 h ahead: believed.
  for (double t : {3.01, 3.02}) {
    EgoPose p = scene.PoseAt(t);
    p.utime += 3'600'000'000;
    tracker.AddPose(p, &out);
  }
  EXPECT_EQ(tracker.resets(), 1);
}

TEST(TrackerTest, FirstTrackIdsOfLaterStartsLieAboveEveryEarlierId) {
  const std::int64_t t1 = 1'700'000'000'000'000;  // [us]
  // A tracker started 1 ms later starts 100000 ids higher: more than it could give in 1 ms.
  EXPECT_GE(FirstTrackIdAt(t1 + 1000) - FirstTrackIdAt(t1), 100'000);
  EXPECT_GE(FirstTrackIdAt(t1), 1);
  EXPECT_EQ(FirstTrackIdAt(-5), 1);
  // The tracker takes it: its first track carries that id.
  SyntheticScene scene(SceneConfig{}, TwoCars(), 5);
  Tracker tracker(TrackerParams{});
  tracker.SetFirstTrackId(FirstTrackIdAt(t1));
  EXPECT_THROW(tracker.SetFirstTrackId(0), std::invalid_argument);
  const std::vector<ScanOutput> outs = RunScene(&tracker, &scene, 1.0);
  std::int64_t min_id = std::numeric_limits<std::int64_t>::max();
  for (const auto& o : outs) for (const auto& r : o.tracks) min_id = std::min(min_id, r.id);
  EXPECT_EQ(min_id, FirstTrackIdAt(t1));
}

TEST(TrackerTest, InvalidParamsNameTheKey) {
  TrackerParams p;
  p.manager.max_hypotheses = 7;
  std::string error;
  EXPECT_FALSE(p.Validate(&error));
  EXPECT_NE(error.find("max_hypotheses"), std::string::npos) << error;
  EXPECT_THROW(Tracker{p}, std::invalid_argument);
  p = TrackerParams{};
  p.input.max_queued_scans = 0;
  EXPECT_FALSE(p.Validate(&error));
  EXPECT_NE(error.find("max_queued_scans"), std::string::npos) << error;
}

}  // namespace
}  // namespace vtrack

namespace vtrack {
namespace {

// Poses lost from a jittered 100 Hz stream (seeded): the counter infers exactly the poses left
// out, from the timing alone, and nothing from jitter; it follows a change of rate.
TEST(StreamGapCounterTest, CountsTheMessagesLeftOutOfAJitteredStream) {
  std::mt19937_64 rng(20240611);
  // [us] each stamp +-15 % of the period off its slot (intervals 70 to 130 % of the period)
  std::uniform_int_distribution<int> jitter(-1500, 1500);
  std::bernoulli_distribution lose(0.05);
  StreamGapCounter gaps;
  std::int64_t left_out = 0, counted = 0;
  const std::int64_t t0 = 1'700'000'000'000'000;
  for (int k = 0; k < 5000; ++k) {
    // Never in the first 20 (the period is not known yet); a burst of 25 at 3000.
    const bool lost = k >= 20 && (lose(rng) || (k >= 3000 && k < 3025));
    const std::int64_t t = t0 + k * 10'000 + jitter(rng);
    if (lost) {
      ++left_out;
      continue;
    }
    counted += gaps.Add(t);
  }
  EXPECT_GT(left_out, 200);
  EXPECT_EQ(counted, left_out);
  EXPECT_NEAR(static_cast<double>(gaps.period_us()), 10'000.0, 2'000.0);
  // The source slows to 50 Hz: once the median has followed, nothing more is counted.
  std::int64_t t = t0 + 5000 * 10'000;
  std::int64_t after = 0;
  for (int k = 0; k < 300; ++k) {
    t += 20'000;
    const std::int64_t n = gaps.Add(t);
    if (k >= static_cast<int>(StreamGapCounter::kWindow)) after += n;
  }
  EXPECT_EQ(after, 0);
  EXPECT_EQ(gaps.period_us(), 20'000);
}

}  // namespace
}  // namespace vtrack
