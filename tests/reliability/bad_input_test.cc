// Bad input into vtrack-tracker's node (docs/design.md, section 9), checked against a clean run of the
// same scenario rather than against expected counters alone: a message that the tracker must
// refuse as a whole (wrong type, too short, truncated, inflated length field, empty / huge /
// repeated / out-of-order scans, sweeps out of range, mountings and poses that are not
// rotations, NaN poses, repeated / out-of-order poses) must leave every TRACKS message exactly
// as in the clean run, and each must be counted under its reason. NaN/Inf returns must give the
// tracks of the same scans without those returns. Lost scans are counted from seq gaps; a scan
// with no pose at all is counted as pose_missing; a jump forward in time does not carry tracks
// across it.
//
// The scenario is paper_fig4_turn from the simulator library, fed in-process (memory only).
#include <gtest/gtest.h>

#include <cmath>
#include <cstring>
#include <functional>
#include <limits>
#include <map>
#include <string>
#include <vector>

#include "lcmtypes/util/decode.h"
#include "sensor_driver/driver/sim_cli.h"
#include "tests/support/encode.h"
#include "tracker/core/parameters.h"
#include "tracker/core/tracker.h"
#include "tracker/lcm_convert.h"
#include "tracker/tracker_node.h"
#include "vtrack/ladar_scan_t.hpp"
#include "vtrack/pose_t.hpp"
#include "vtrack/track_list_t.hpp"

namespace vtrack {
namespace {

using testing::Encode;

// What the node published: the tracks of every TRACKS message, encoded (latency left out).
struct Output {
  std::vector<std::int64_t> utimes;
  std::vector<std::vector<std::uint8_t>> tracks;
  int num_tracks = 0;
};

// Injects extra messages into the clean stream: called before scan i / pose k is fed.
struct Injector {
  std::function<void(int i, const ladar_scan_t& scan, TrackerNode& node)> before_scan;
  std::function<void(int k, const pose_t& pose, TrackerNode& node)> before_pose;
  std::function<void(int i, ladar_scan_t* scan)> edit_scan;  // npoints = -1: the scan is lost
  std::function<bool(int k)> lose_pose;                       // true: pose k is lost
};

class BadInputTest : public ::testing::Test {
 protected:
  static void SetUpTestSuite() {
    sim::SimCli cli;
    cli.scenario = "paper_fig4_turn";
    cli.duration = 6.0;
    sim_ = sim::MakeSimulator(cli).release();
  }
  static void TearDownTestSuite() {
    delete sim_;
    sim_ = nullptr;
  }

  // Feeds the scenario's messages in publication order through a TrackerNode.
  static Output Run(const Injector& inj, std::unique_ptr<TrackerNode>* keep = nullptr) {
    Output out;
    TrackerParams params;
    params.preprocess.max_points = 5000;
    auto node = std::make_unique<TrackerNode>(
        params, NodeOptions{}, [&](std::int64_t, const std::string& channel, const void* data, std::size_t size) {
          if (channel != "TRACKS") return;
          track_list_t m;
          ASSERT_EQ(lcm_util::Decode(data, size, &m), lcm_util::DecodeError::kNone);
          out.utimes.push_back(m.utime);
          std::vector<std::uint8_t> bytes;
          for (const track_t& t : m.tracks) {
            const auto b = Encode(t);
            bytes.insert(bytes.end(), b.begin(), b.end());
          }
          out.tracks.push_back(std::move(bytes));
          out.num_tracks += m.num_tracks;
        });
    const std::int64_t start = sim_->scenario().start_utime;
    int i = 0, k = 0;
    ladar_scan_t scan;
    object_list_t truth;
    pose_t pose;
    while (i < sim_->NumScans() || k < sim_->NumPoses()) {
      const bool pose_next = k < sim_->NumPoses() &&
                             (i >= sim_->NumScans() || sim_->PoseOffsetUs(k) <= sim_->ScanPublishOffsetUs(i));
      if (pose_next) {
        sim_->MakePose(k, start, &pose);
        if (inj.before_pose) inj.before_pose(k, pose, *node);
        if (!inj.lose_pose || !inj.lose_pose(k)) {
          const auto b = Encode(pose);
          node->Handle("EGO_POSE", b.data(), b.size());
        }
        ++k;
      } else {
        sim_->MakeScan(i, start, i, &scan, &truth);
        if (inj.before_scan) inj.before_scan(i, scan, *node);
        if (inj.edit_scan) inj.edit_scan(i, &scan);
        if (scan.npoints >= 0) {
          const auto b = Encode(scan);
          node->Handle("LADAR_SCAN", b.data(), b.size());
        }
        ++i;
      }
    }
    node->Flush();
    if (keep) *keep = std::move(node);
    return out;
  }

  static std::map<std::string, std::int64_t> Reasons(const TrackerNode& node) {
    std::map<std::string, std::int64_t> r;
    const tracker_status_t st = node.Status();
    for (int i = 0; i < st.num_reasons; ++i) r[st.reject_reason[i]] = st.reject_count[i];
    return r;
  }

  static void Send(TrackerNode& node, const std::string& channel, const std::vector<std::uint8_t>& b) {
    node.Handle(channel, b.data(), b.size());
  }

  static sim::Simulator* sim_;
};

sim::Simulator* BadInputTest::sim_ = nullptr;

TEST_F(BadInputTest, RefusedMessagesAreCountedAndLeaveEveryTrackUnchanged) {
  const Output clean = Run({});
  ASSERT_GT(clean.tracks.size(), 40u);
  ASSERT_GT(clean.num_tracks, 40);

  Injector inj;
  ladar_scan_t previous;
  inj.before_scan = [&](int i, const ladar_scan_t& scan, TrackerNode& node) {
    if (i == 5) {  // wrong type, too short, truncated, inflated npoints, garbage fingerprint
      Send(node, "LADAR_SCAN", Encode(pose_t{}));
      const auto b = Encode(scan);
      Send(node, "LADAR_SCAN", std::vector<std::uint8_t>(b.begin(), b.begin() + 5));
      Send(node, "LADAR_SCAN", std::vector<std::uint8_t>(b.begin(), b.begin() + b.size() / 2));
      auto inflated = b;
      const std::size_t at = 8 + 16 + 4 + scan.sensor_id.size() + 1 + 24 + 32 + 4 + 4 + 2;
      inflated[at] = 0x7f;  // npoints ~ 2^31
      Send(node, "LADAR_SCAN", inflated);
      auto garbage = b;
      for (int j = 0; j < 8; ++j) garbage[static_cast<std::size_t>(j)] ^= 0x5a;
      Send(node, "LADAR_SCAN", garbage);
      Send(node, "EGO_POSE", std::vector<std::uint8_t>(b.begin(), b.begin() + 100));  // a scan on the pose channel
    }
    if (i == 8) {  // empty and huge scans (same seq as the previous scan: not a gap)
      ladar_scan_t e = previous;
      e.utime = previous.utime + 1;
      e.npoints = 0;
      e.x.clear(); e.y.clear(); e.z.clear(); e.intensity.clear(); e.dt_us.clear(); e.ring.clear();
      Send(node, "LADAR_SCAN", Encode(e));
      ladar_scan_t h = previous;
      h.utime = previous.utime + 2;
      const int n = 6000;
      h.npoints = n;
      h.x.assign(n, 5.0f); h.y.assign(n, 1.0f); h.z.assign(n, 0.0f);
      h.intensity.assign(n, 0.0f); h.dt_us.assign(n, 0); h.ring.assign(n, 0);
      Send(node, "LADAR_SCAN", Encode(h));
    }
    if (i == 11) {  // sweep out of range, mounting not a rotation, NaN mounting, mounting 1e39 m up
      ladar_scan_t s = previous;
      s.utime = previous.utime + 3;
      s.sweep_duration_us = -5;
      Send(node, "LADAR_SCAN", Encode(s));
      s.sweep_duration_us = previous.sweep_duration_us;
      s.sensor_orientation[0] = 2.0;
      Send(node, "LADAR_SCAN", Encode(s));
      s.sensor_orientation[0] = previous.sensor_orientation[0];
      s.sensor_pos[1] = std::numeric_limits<double>::quiet_NaN();
      Send(node, "LADAR_SCAN", Encode(s));
      s.sensor_pos[1] = previous.sensor_pos[1];
      s.sensor_pos[2] = 1e39;  // finite, beyond a float
      Send(node, "LADAR_SCAN", Encode(s));
    }
    if (i == 14) {  // the previous scan again
      Send(node, "LADAR_SCAN", Encode(previous));
    }
    previous = scan;
  };
  std::vector<ladar_scan_t> history;
  auto before_scan_base = inj.before_scan;
  inj.before_scan = [&](int i, const ladar_scan_t& scan, TrackerNode& node) {
    before_scan_base(i, scan, node);
    if (i == 17) Send(node, "LADAR_SCAN", Encode(history[history.size() - 2]));  // out of order
    history.push_back(scan);
  };
  pose_t last_pose;
  inj.before_pose = [&](int k, const pose_t& pose, TrackerNode& node) {
    if (k == 50) Send(node, "EGO_POSE", Encode(last_pose));  // repeated
    if (k == 60) {
      pose_t p = last_pose;
      p.utime -= 20'000;  // older than the newest (out of order, within the reset threshold)
      Send(node, "EGO_POSE", Encode(p));
    }
    if (k == 70) {
      pose_t p = pose;
      p.utime -= 1;
      p.orientation[0] = 3.0;  // not a rotation
      Send(node, "EGO_POSE", Encode(p));
      p.orientation[0] = pose.orientation[0];
      p.pos[0] = std::numeric_limits<double>::quiet_NaN();
      Send(node, "EGO_POSE", Encode(p));
    }
    last_pose = pose;
  };
  std::unique_ptr<TrackerNode> node;
  const Output bad = Run(inj, &node);
  auto r = Reasons(*node);
  for (const auto& [k, v] : r) std::printf("  %s: %lld\n", k.c_str(), static_cast<long long>(v));
  EXPECT_EQ(r["decode_wrong_type"], 3);  // a pose on LADAR_SCAN, garbage fingerprint, a scan on EGO_POSE
  EXPECT_EQ(r["decode_too_short"], 1);
  EXPECT_EQ(r["decode_malformed"] + r["decode_bad_length"], 2);  // truncated, inflated npoints
  EXPECT_EQ(node->decode_errors(), 6);
  EXPECT_EQ(r["empty_scan"], 1);
  EXPECT_EQ(r["huge_scan"], 1);
  EXPECT_EQ(r["bad_scan"], 4);
  EXPECT_EQ(r["scan_repeated"], 1);
  EXPECT_EQ(r["scan_out_of_order"], 1);
  EXPECT_EQ(r["pose_repeated"], 1);
  EXPECT_EQ(r["pose_out_of_order"], 1);
  EXPECT_EQ(r["invalid_pose"], 2);
  EXPECT_EQ(r["scan_seq_gap"], 0);
  EXPECT_EQ(r["nan_point"], 0);
  EXPECT_EQ(node->tracker().resets(), 0);
  EXPECT_EQ(node->tracker().scans_dropped(), 8);  // empty, huge, 4 bad, repeated, older
  // The valid traffic around them: every TRACKS message as in the clean run, byte for byte.
  ASSERT_EQ(bad.utimes, clean.utimes);
  int differ = 0;
  for (std::size_t j = 0; j < clean.tracks.size(); ++j) differ += bad.tracks[j] != clean.tracks[j];
  EXPECT_EQ(differ, 0);
}

TEST_F(BadInputTest, NanAndInfReturnsGiveTheTracksOfTheScanWithoutThem) {
  const Output clean = Run({});
  Injector inj;
  int added = 0;
  inj.edit_scan = [&](int i, ladar_scan_t* s) {
    if (i % 4 != 2) return;
    const float nan = std::numeric_limits<float>::quiet_NaN(), inf = std::numeric_limits<float>::infinity();
    const float bad[][3] = {{nan, 1, 0}, {1, inf, 0}, {2, 2, -inf}, {nan, nan, nan}};
    for (const auto& p : bad) {
      s->x.push_back(p[0]); s->y.push_back(p[1]); s->z.push_back(p[2]);
      s->intensity.push_back(0.5f); s->dt_us.push_back(0); s->ring.push_back(0);
      ++added;
    }
    s->npoints = static_cast<std::int32_t>(s->x.size());
  };
  std::unique_ptr<TrackerNode> node;
  const Output nan = Run(inj, &node);
  EXPECT_EQ(Reasons(*node)["nan_point"], added);
  ASSERT_EQ(nan.utimes, clean.utimes);
  int differ = 0;
  for (std::size_t j = 0; j < clean.tracks.size(); ++j) differ += nan.tracks[j] != clean.tracks[j];
  EXPECT_EQ(differ, 0);
}

TEST_F(BadInputTest, AbsurdReturnsScansAndPosesAreRefusedAndCounted) {
  // Returns no sensor can have measured (3e38 m, twice the scan's max_range, a ring outside
  // [-1, num_rings), -1 meaning unknown) are refused one by one: the tracks are those of the scans without them.
  // Scans with a negative num_rings or a NaN / negative max_range, and ego poses 1e300 m or
  // 2e7 m away, are refused whole: every TRACKS message as in the clean run.
  const Output clean = Run({});
  Injector inj;
  int far = 0, bad_ring = 0;
  ladar_scan_t previous;
  inj.edit_scan = [&](int i, ladar_scan_t* s) {
    if (i % 3 != 1) return;
    auto add = [&](float x, float y, std::int16_t ring) {
      s->x.push_back(x); s->y.push_back(y); s->z.push_back(0.0f);
      s->intensity.push_back(0.5f); s->dt_us.push_back(0); s->ring.push_back(ring);
    };
    add(3e38f, 1.0f, 0); add(-2.0f, 3e38f, 0); add(2.0f * s->max_range, 0.0f, 0);
    far += 3;
    add(5.0f, 1.0f, s->num_rings); add(6.0f, -1.0f, -2); add(7.0f, 0.0f, 32767);
    bad_ring += 3;
    s->npoints = static_cast<std::int32_t>(s->x.size());
  };
  inj.before_scan = [&](int i, const ladar_scan_t& scan, TrackerNode& node) {
    if (i == 9) {  // same seq as the previous scan: not a gap
      ladar_scan_t s = previous;
      s.utime = previous.utime + 1;
      s.num_rings = -3;
      Send(node, "LADAR_SCAN", Encode(s));
      s.num_rings = previous.num_rings;
      s.max_range = std::numeric_limits<float>::quiet_NaN();
      Send(node, "LADAR_SCAN", Encode(s));
      s.max_range = -80.0f;
      Send(node, "LADAR_SCAN", Encode(s));
    }
    previous = scan;
  };
  inj.before_pose = [&](int k, const pose_t& pose, TrackerNode& node) {
    if (k == 40) {
      pose_t p = pose;
      p.utime -= 1;
      p.pos[0] = 1e300;
      Send(node, "EGO_POSE", Encode(p));
      p.pos[0] = pose.pos[0];
      p.pos[1] = -2e7;
      Send(node, "EGO_POSE", Encode(p));
    }
  };
  std::unique_ptr<TrackerNode> node;
  const Output bad = Run(inj, &node);
  auto r = Reasons(*node);
  for (const auto& [k, v] : r) std::printf("  %s: %lld\n", k.c_str(), static_cast<long long>(v));
  EXPECT_EQ(r["far_point"], far);
  EXPECT_EQ(r["bad_ring"], bad_ring);
  EXPECT_EQ(r["bad_scan"], 3);
  EXPECT_EQ(r["invalid_pose"], 2);
  EXPECT_EQ(node->tracker().scans_dropped(), 3);
  ASSERT_EQ(bad.utimes, clean.utimes);
  int differ = 0;
  for (std::size_t j = 0; j < clean.tracks.size(); ++j) differ += bad.tracks[j] != clean.tracks[j];
  EXPECT_EQ(differ, 0);
}

TEST_F(BadInputTest, LostScansAreCountedFromSeqGaps) {
  Injector inj;
  int lost = 0;
  inj.edit_scan = [&](int i, ladar_scan_t* s) {
    // Single losses and a burst of 4; never the last scan (a loss at the end shows no gap).
    if ((i % 7 == 3 || (i >= 30 && i < 34)) && i < sim_->NumScans() - 1) {
      s->npoints = -1;
      ++lost;
    }
  };
  std::unique_ptr<TrackerNode> node;
  const Output out = Run(inj, &node);
  EXPECT_EQ(Reasons(*node)["scan_seq_gap"], lost);
  EXPECT_EQ(node->tracker().scans_received(), sim_->NumScans() - lost);
  EXPECT_GT(out.num_tracks, 0);
}

TEST_F(BadInputTest, LostPosesAreCountedFromTheStreamsTiming) {
  // Poses have no seq: the node must infer the lost ones from the gaps in their timing. Single
  // losses, a burst of 7 and a burst of 30 (a stalled receiver), never in the first 10 poses
  // (the nominal period is not known yet) nor the last (a loss at the end shows no gap).
  Injector inj;
  int lost = 0;
  inj.lose_pose = [&](int k) {
    const bool lose = k >= 10 && k < sim_->NumPoses() - 1 &&
                      (k % 37 == 5 || (k >= 200 && k < 207) || (k >= 400 && k < 430));
    lost += lose;
    return lose;
  };
  std::unique_ptr<TrackerNode> node;
  const Output out = Run(inj, &node);
  ASSERT_GT(lost, 40);
  EXPECT_EQ(Reasons(*node)["pose_gap"], lost);
  EXPECT_EQ(node->tracker().poses_received(), sim_->NumPoses() - lost);
  EXPECT_GT(out.num_tracks, 0);
  // Without losses nothing is counted.
  std::unique_ptr<TrackerNode> clean;
  Run({}, &clean);
  EXPECT_EQ(Reasons(*clean)["pose_gap"], 0);
}

// The reasons that count a whole scan, as tracker/README.md lists them: every scan received and
// not processed is counted under exactly one of them.
std::int64_t SumOfScanReasons(std::map<std::string, std::int64_t> r) {
  std::int64_t sum = 0;
  for (const char* k : {"empty_scan", "huge_scan", "bad_scan", "scan_repeated", "scan_out_of_order",
                        "scan_overrun", "scan_time_jump", "scan_reset", "pose_missing", "stale_pose"}) {
    sum += r[k];
  }
  return sum;
}

TEST_F(BadInputTest, EveryScanAtTheSameTimeIsCountedOnceByReason) {
  // A sensor whose clock is stuck: every scan stamped with the first scan's time, the poses
  // moving on. All but the first are dropped, and each drop has one reason.
  Injector inj;
  std::int64_t first = 0;
  int sent = 0;
  inj.edit_scan = [&](int i, ladar_scan_t* s) {
    if (i == 0) first = s->utime;
    s->utime = first;
    ++sent;
  };
  std::unique_ptr<TrackerNode> node;
  Run(inj, &node);
  const tracker_status_t st = node->Status();
  const auto r = Reasons(*node);
  for (const auto& [k, v] : r) std::printf("  %s: %lld\n", k.c_str(), static_cast<long long>(v));
  ASSERT_EQ(sent, sim_->NumScans());
  EXPECT_GT(st.scans_dropped, sent / 2);
  EXPECT_EQ(st.scans_received, sent);
  EXPECT_EQ(SumOfScanReasons(r), st.scans_dropped);
  EXPECT_EQ(st.scans_dropped, sent - st.scans_processed);
}

// Sweeps shrinking, growing and empty, each decoded by the node into the arrays of the scan
// before (Tracker::TakeSpareScan): the tracks are those of the core tracker given each scan in
// arrays of its own (decoded by LCM's generated decoder), and every return processed is counted
// once.
TEST_F(BadInputTest, SweepsDecodedIntoTheArraysOfTheOneBeforeGiveTheirOwnTracks) {
  Injector inj;
  std::int64_t sent_returns = 0;
  inj.edit_scan = [&](int i, ladar_scan_t* scan) {
    // Every 1st, 2nd or 3rd return by turns; no return at all in every 7th sweep.
    const int step = 1 + i % 3;
    const auto keep = [&](auto* v) {
      std::size_t n = 0;
      for (std::size_t j = 0; j < v->size(); j += static_cast<std::size_t>(step)) (*v)[n++] = (*v)[j];
      v->resize(i % 7 == 6 ? 0 : n);
    };
    keep(&scan->x);
    keep(&scan->y);
    keep(&scan->z);
    keep(&scan->intensity);
    keep(&scan->dt_us);
    keep(&scan->ring);
    scan->npoints = static_cast<std::int32_t>(scan->x.size());
  };
  std::unique_ptr<TrackerNode> node;
  const Output recycled = Run(inj, &node);

  TrackerParams params;
  params.preprocess.max_points = 5000;
  Tracker direct(params);
  Output fresh;
  std::vector<ScanOutput> outs;
  const auto take = [&]() {
    for (const ScanOutput& o : outs) {
      const track_list_t m = TrackListToLcm(o, ToString(params.manager.mode), 0);
      fresh.utimes.push_back(m.utime);
      std::vector<std::uint8_t> bytes;
      for (const track_t& t : m.tracks) {
        const auto b = Encode(t);
        bytes.insert(bytes.end(), b.begin(), b.end());
      }
      fresh.tracks.push_back(std::move(bytes));
      fresh.num_tracks += m.num_tracks;
    }
    outs.clear();
  };
  const std::int64_t start = sim_->scenario().start_utime;
  int i = 0, k = 0;
  ladar_scan_t scan;
  object_list_t truth;
  pose_t pose;
  while (i < sim_->NumScans() || k < sim_->NumPoses()) {
    if (k < sim_->NumPoses() &&
        (i >= sim_->NumScans() || sim_->PoseOffsetUs(k) <= sim_->ScanPublishOffsetUs(i))) {
      sim_->MakePose(k++, start, &pose);
      direct.AddPose(PoseFromLcm(pose), &outs);
    } else {
      sim_->MakeScan(i, start, i, &scan, &truth);
      inj.edit_scan(i, &scan);
      sent_returns += scan.npoints;
      const auto b = Encode(scan);
      ladar_scan_t own;  // generated decoder, fresh arrays
      ASSERT_EQ(own.decode(b.data(), 0, static_cast<int>(b.size())), static_cast<int>(b.size()));
      direct.AddScan(ScanFromLcm(std::move(own)), &outs);
      ++i;
    }
    take();
  }
  direct.Flush(&outs);
  take();

  ASSERT_GT(fresh.tracks.size(), 40u);
  ASSERT_GT(fresh.num_tracks, 40);
  EXPECT_EQ(recycled.utimes, fresh.utimes);
  ASSERT_EQ(recycled.tracks.size(), fresh.tracks.size());
  for (std::size_t j = 0; j < fresh.tracks.size(); ++j) {
    EXPECT_EQ(recycled.tracks[j], fresh.tracks[j]) << "TRACKS message " << j;
  }
  EXPECT_EQ(node->tracker().returns_processed(), direct.returns_processed());
  EXPECT_EQ(direct.scans_processed() + direct.scans_dropped(), direct.scans_received());
  EXPECT_LE(direct.returns_processed(), sent_returns);
  EXPECT_GT(direct.returns_processed(), sent_returns / 2);
}

TEST_F(BadInputTest, ScansBeforeAnyPoseAreCountedOnceByReason) {
  // Three laps of scans (one continuous clock and seq) before the first pose, then the poses of
  // the first lap: the queue overflows, the poses jump back in time (a reset, confirmed by the
  // second pose), and the scans left are flushed without poses.
  TrackerParams params;
  params.preprocess.max_points = 5000;
  TrackerNode node(params, NodeOptions{}, [](std::int64_t, const std::string&, const void*, std::size_t) {});
  const std::int64_t start = sim_->scenario().start_utime;
  const std::int64_t lap_us = sim_->ScanOffsetUs(sim_->NumScans() - 1) + 100'000;
  ladar_scan_t scan;
  object_list_t truth;
  int sent = 0;
  for (int lap = 0; lap < 3; ++lap) {
    for (int i = 0; i < sim_->NumScans(); ++i) {
      sim_->MakeScan(i, start + lap * lap_us, lap * sim_->NumScans() + i, &scan, &truth);
      Send(node, "LADAR_SCAN", Encode(scan));
      ++sent;
    }
  }
  pose_t pose;
  for (int k = 0; k < sim_->NumPoses(); ++k) {
    sim_->MakePose(k, start, &pose);
    Send(node, "EGO_POSE", Encode(pose));
  }
  node.Flush();
  const tracker_status_t st = node.Status();
  const auto r = Reasons(node);
  for (const auto& [k, v] : r) std::printf("  %s: %lld\n", k.c_str(), static_cast<long long>(v));
  ASSERT_GT(sent, params.input.max_queued_scans);
  EXPECT_EQ(st.scans_received, sent);
  EXPECT_GT(st.scans_dropped, 0);
  EXPECT_EQ(SumOfScanReasons(r), st.scans_dropped);
  EXPECT_EQ(st.scans_dropped, sent - st.scans_processed);
}

TEST_F(BadInputTest, ScanWithoutAnyPoseIsCountedAsPoseMissing) {
  TrackerParams params;
  TrackerNode node(params, NodeOptions{}, [](std::int64_t, const std::string&, const void*, std::size_t) {});
  ladar_scan_t scan;
  object_list_t truth;
  sim_->MakeScan(0, sim_->scenario().start_utime, 0, &scan, &truth);
  const auto b = Encode(scan);
  node.Handle("LADAR_SCAN", b.data(), b.size());
  node.Flush();  // no pose ever came: the scan cannot be placed in the world
  EXPECT_EQ(Reasons(node)["pose_missing"], 1);
  EXPECT_EQ(node.tracker().scans_dropped(), 1);
  EXPECT_EQ(node.tracker().scans_processed(), 0);
}

TEST_F(BadInputTest, JumpForwardInTimeCarriesNoTrackAcrossIt) {
  // The second half of the run is shifted one hour later: nothing seen before the jump may be
  // reported after it as if it had been tracked through the hour.
  const std::int64_t hour = 3'600'000'000;
  std::int64_t before_max_id = -1, after_min_id = std::numeric_limits<std::int64_t>::max();
  TrackerParams params;
  TrackerNode node(params, NodeOptions{}, [&](std::int64_t, const std::string& channel, const void* data, std::size_t size) {
    if (channel != "TRACKS") return;
    track_list_t m;
    ASSERT_EQ(lcm_util::Decode(data, size, &m), lcm_util::DecodeError::kNone);
    const bool after = m.utime >= sim_->scenario().start_utime + hour;
    for (const track_t& t : m.tracks) {
      if (!after) {
        before_max_id = std::max(before_max_id, t.id);
      } else {
        after_min_id = std::min(after_min_id, t.id);
        EXPECT_TRUE(std::isfinite(t.x) && std::isfinite(t.cov[0]));
      }
    }
  });
  const std::int64_t start = sim_->scenario().start_utime;
  const int half = sim_->NumScans() / 2;
  int i = 0, k = 0;
  ladar_scan_t scan;
  object_list_t truth;
  pose_t pose;
  while (i < sim_->NumScans() || k < sim_->NumPoses()) {
    const bool pose_next = k < sim_->NumPoses() && (i >= sim_->NumScans() || sim_->PoseOffsetUs(k) <= sim_->ScanPublishOffsetUs(i));
    const bool late = (pose_next ? sim_->PoseOffsetUs(k) : sim_->ScanOffsetUs(i)) >= sim_->ScanOffsetUs(half);
    if (pose_next) {
      sim_->MakePose(k++, start + (late ? hour : 0), &pose);
      const auto b = Encode(pose);
      node.Handle("EGO_POSE", b.data(), b.size());
    } else {
      sim_->MakeScan(i, start + (late ? hour : 0), i, &scan, &truth);
      ++i;
      const auto b = Encode(scan);
      node.Handle("LADAR_SCAN", b.data(), b.size());
    }
  }
  node.Flush();
  ASSERT_GE(before_max_id, 0);
  ASSERT_LT(after_min_id, std::numeric_limits<std::int64_t>::max());  // tracking resumed
  EXPECT_GT(after_min_id, before_max_id);                            // with new tracks only
  EXPECT_EQ(node.tracker().resets(), 1);                             // and said so
  EXPECT_EQ(node.tracker().scans_received(), node.tracker().scans_processed() + node.tracker().scans_dropped());
}

}  // namespace
}  // namespace vtrack
