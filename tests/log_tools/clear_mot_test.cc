// CLEAR MOT (Bernardin & Stiefelhagen 2008) on hand-worked cases, and on a large random case
// against a second implementation written here from the paper's procedure (exhaustive matching
// instead of the Hungarian method, per-object run lists instead of running counters).
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <functional>
#include <map>
#include <optional>
#include <random>
#include <set>
#include <vector>

#include "log_tools/eval/clear_mot.h"
#include "tests/log_tools/scoring_frames.h"

namespace vtrack::eval {
namespace {

using testing::FrameBuilder;
using testing::Scans;

ClearMotResult Clear(const std::vector<ScoringFrame>& frames, double gate = 2.0) {
  ClearMotParams p;
  p.gate_m = gate;
  return ComputeClearMot(frames, p);
}

// The counts of a ClearMotResult a case states (those left empty are not checked).
struct Counts {
  std::optional<std::int64_t> gt_detections = {}, true_positives = {}, false_positives = {},
                              false_negatives = {}, id_switches = {}, fragmentations = {},
                              gt_objects = {}, mostly_tracked = {}, partially_tracked = {},
                              mostly_lost = {};
};

void ExpectCounts(const ClearMotResult& r, const Counts& want) {
  const auto check = [](const char* name, std::int64_t got, std::optional<std::int64_t> expected) {
    if (expected) {
      EXPECT_EQ(got, *expected) << name;
    }
  };
  check("gt_detections", r.gt_detections, want.gt_detections);
  check("true_positives", r.true_positives, want.true_positives);
  check("false_positives", r.false_positives, want.false_positives);
  check("false_negatives", r.false_negatives, want.false_negatives);
  check("id_switches", r.id_switches, want.id_switches);
  check("fragmentations", r.fragmentations, want.fragmentations);
  check("gt_objects", r.gt_objects, want.gt_objects);
  check("mostly_tracked", r.mostly_tracked, want.mostly_tracked);
  check("partially_tracked", r.partially_tracked, want.partially_tracked);
  check("mostly_lost", r.mostly_lost, want.mostly_lost);
}

TEST(ClearMotTest, PerfectTracking) {
  const auto r = Clear(Scans(10, [](int t) {
    return FrameBuilder(t).Gt(1, t).Gt(2, 50, t).Tr(7, t).Tr(8, 50, t).f;
  }));
  ExpectCounts(r, {.gt_detections = 20,
                   .true_positives = 20,
                   .false_positives = 0,
                   .false_negatives = 0,
                   .id_switches = 0,
                   .fragmentations = 0,
                   .mostly_tracked = 2});
  EXPECT_DOUBLE_EQ(r.mota, 1.0);
  EXPECT_DOUBLE_EQ(r.motp_m, 0.0);
}

TEST(ClearMotTest, OneIdentitySwitch) {
  // Truth 1 for 10 scans; track 7 covers scans 0-4, track 8 scans 5-9.
  // MOTA = 1 - (0 + 0 + 1) / 10 = 0.9; no gap, so no fragmentation.
  const auto r =
      Clear(Scans(10, [](int t) { return FrameBuilder(t).Gt(1, 0).Tr(t < 5 ? 7 : 8, 0.5).f; }));
  ExpectCounts(r, {.id_switches = 1, .fragmentations = 0});
  EXPECT_DOUBLE_EQ(r.mota, 0.9);
  EXPECT_DOUBLE_EQ(r.motp_m, 0.5);
  ASSERT_EQ(r.matches[5].size(), 1u);
  EXPECT_TRUE(r.matches[5][0].id_switch);
  EXPECT_FALSE(r.matches[6][0].id_switch);
}

TEST(ClearMotTest, GapIsAFragmentationAndTwoMisses) {
  // Track 7 misses scans 3 and 4: FN 2, MOTA = 1 - 2/10 = 0.8, one fragmentation, no switch.
  const auto r = Clear(testing::TrackMissingScans3And4());
  // 8/10 scans tracked is not more than 80 %: partially tracked.
  ExpectCounts(r, {.false_negatives = 2,
                   .id_switches = 0,
                   .fragmentations = 1,
                   .mostly_tracked = 0,
                   .partially_tracked = 1});
  EXPECT_DOUBLE_EQ(r.mota, 0.8);
}

TEST(ClearMotTest, SwitchAfterAGapCountsAgainstTheLastMatch) {
  // Scans 0-2 track 7, scan 3 missed, scans 4-5 track 8: the last match (7) persists through the
  // gap, so the return with 8 is a switch; and the gap is a fragmentation.
  const auto r = Clear(Scans(6, [](int t) {
    FrameBuilder b(t);
    b.Gt(1, 0);
    if (t < 3) b.Tr(7, 0);
    if (t > 3) b.Tr(8, 0);
    return b.f;
  }));
  ExpectCounts(r, {.false_negatives = 1, .id_switches = 1, .fragmentations = 1});
  EXPECT_NEAR(r.mota, 1.0 - 2.0 / 6.0, 1e-12);
}

TEST(ClearMotTest, PreviousCorrespondenceIsKeptOverACheaperSwap) {
  // Scan 0: track 1 on truth A at 0, track 2 on truth B at 1.5. Scan 1: track 1 at 1.0 (1.0 from A,
  // 0.5 from B), track 2 at 0.3 (0.3 from A, 1.2 from B). A fresh assignment would swap (0.8 total
  // vs 2.2), but both old pairs are still inside the gate, so CLEAR MOT keeps them: no switch,
  // MOTP = (0 + 0 + 1.0 + 1.2) / 4.
  std::vector<ScoringFrame> frames = {
      FrameBuilder(0).Gt(1, 0.0).Gt(2, 1.5).Tr(1, 0.0).Tr(2, 1.5).f,
      FrameBuilder(1).Gt(1, 0.0).Gt(2, 1.5).Tr(1, 1.0).Tr(2, 0.3).f};
  const auto r = Clear(frames);
  EXPECT_EQ(r.id_switches, 0);
  EXPECT_NEAR(r.motp_m, 2.2 / 4.0, 1e-12);
  // With a gate of 0.9 the old pairs are no longer valid: the swap is made, two switches.
  const auto r2 = Clear(frames, 0.9);
  EXPECT_EQ(r2.id_switches, 2);
  EXPECT_NEAR(r2.motp_m, (0.0 + 0.0 + 0.3 + 0.5) / 4.0, 1e-12);
}

TEST(ClearMotTest, OutsideTheGateIsAMissAndAFalsePositive) {
  const auto r = Clear(Scans(4, [](int t) { return FrameBuilder(t).Gt(1, 0).Tr(7, 2.5).f; }));
  ExpectCounts(r, {.false_positives = 4, .false_negatives = 4, .mostly_lost = 1});
  EXPECT_DOUBLE_EQ(r.mota, -1.0);
  EXPECT_TRUE(std::isnan(r.motp_m));
}

TEST(ClearMotTest, MostlyTrackedAndLostThresholds) {
  // Four truth objects over 10 scans, matched in 9, 8, 2 and 1 scans: MT (> 80 %), PT, PT, ML.
  const int matched[4] = {9, 8, 2, 1};
  const auto r = Clear(Scans(10, [&](int t) {
    FrameBuilder b(t);
    for (int k = 0; k < 4; ++k) {
      b.Gt(k, 100.0 * k);
      if (t < matched[k]) b.Tr(10 + k, 100.0 * k);
    }
    return b.f;
  }));
  ExpectCounts(r, {.gt_objects = 4, .mostly_tracked = 1, .partially_tracked = 2, .mostly_lost = 1});
}

TEST(ClearMotTest, AbsenceFromTheScoredSetIsNotAMiss) {
  // Truth 1 leaves the scored set in scans 3-4 (e.g. outside the labelled region): neither a miss
  // nor a fragmentation.
  const auto r = Clear(Scans(8, [](int t) {
    FrameBuilder b(t);
    if (t != 3 && t != 4) b.Gt(1, 0).Tr(7, 0);
    return b.f;
  }));
  ExpectCounts(r, {.gt_detections = 6, .false_negatives = 0, .fragmentations = 0});
  EXPECT_DOUBLE_EQ(r.mota, 1.0);
}

TEST(ClearMotTest, RejectsDuplicateIdsAndBadParams) {
  std::vector<ScoringFrame> frames = {FrameBuilder(42).Gt(1, 0).Gt(1, 5).f};
  try {
    Clear(frames);
    FAIL() << "duplicate truth id accepted";
  } catch (const std::invalid_argument& e) {
    EXPECT_NE(std::string(e.what()).find("truth id 1"), std::string::npos) << e.what();
    EXPECT_NE(std::string(e.what()).find("42"), std::string::npos) << e.what();
  }
  ClearMotParams p;
  p.gate_m = -1.0;
  EXPECT_NE(p.Validate().find("gate_m"), std::string::npos);
  EXPECT_THROW(ComputeClearMot({}, p), std::invalid_argument);
}

// ---------------------------------------------------------------------------------------------
// The second implementation: the CLEAR MOT procedure, matching by exhaustive search.

struct Reference {
  std::int64_t tp = 0, fp = 0, fn = 0, idsw = 0, frag = 0, mt = 0, pt = 0, ml = 0, gt = 0;
  double dist = 0.0;
};

// Best partial matching of free truths/tracks within the gate: most pairs, then least distance.
std::vector<std::pair<int, int>> ExhaustiveMatch(const ScoringFrame& f, const std::vector<int>& gts,
                                                 const std::vector<int>& trs, double gate) {
  std::vector<std::pair<int, int>> best, cur;
  double best_cost = 0.0;
  std::set<int> used;
  std::function<void(std::size_t, double)> rec = [&](std::size_t k, double cost) {
    if (k == gts.size()) {
      if (cur.size() > best.size() || (cur.size() == best.size() && cost < best_cost)) {
        best = cur;
        best_cost = cost;
      }
      return;
    }
    rec(k + 1, cost);
    for (const int j : trs) {
      if (used.count(j)) continue;
      const double d = (f.gt_xy[gts[k]] - f.track_xy[j]).norm();
      if (d >= gate) continue;
      used.insert(j);
      cur.emplace_back(gts[k], j);
      rec(k + 1, cost + d);
      cur.pop_back();
      used.erase(j);
    }
  };
  rec(0, 0.0);
  return best;
}

Reference ReferenceClearMot(const std::vector<ScoringFrame>& frames, double gate) {
  Reference r;
  std::map<std::int64_t, std::int64_t> prev_frame_map, last_ever;
  std::map<std::int64_t, std::vector<bool>> tracked;  // per truth: matched flag per scored scan
  for (const ScoringFrame& f : frames) {
    std::map<std::int64_t, std::int64_t> map_now;   // truth id -> track id
    std::set<int> gt_done, tr_done;
    for (std::size_t i = 0; i < f.gt_ids.size(); ++i) {
      auto it = prev_frame_map.find(f.gt_ids[i]);
      if (it == prev_frame_map.end()) continue;
      for (std::size_t j = 0; j < f.track_ids.size(); ++j) {
        if (f.track_ids[j] == it->second && (f.gt_xy[i] - f.track_xy[j]).norm() < gate) {
          map_now[f.gt_ids[i]] = f.track_ids[j];
          r.dist += (f.gt_xy[i] - f.track_xy[j]).norm();
          gt_done.insert(static_cast<int>(i));
          tr_done.insert(static_cast<int>(j));
        }
      }
    }
    std::vector<int> gts, trs;
    for (std::size_t i = 0; i < f.gt_ids.size(); ++i) {
      if (!gt_done.count(static_cast<int>(i))) gts.push_back(static_cast<int>(i));
    }
    for (std::size_t j = 0; j < f.track_ids.size(); ++j) {
      if (!tr_done.count(static_cast<int>(j))) trs.push_back(static_cast<int>(j));
    }
    for (const auto& [i, j] : ExhaustiveMatch(f, gts, trs, gate)) {
      const std::int64_t g = f.gt_ids[i], h = f.track_ids[j];
      if (last_ever.count(g) && last_ever[g] != h) ++r.idsw;
      map_now[g] = h;
      r.dist += (f.gt_xy[i] - f.track_xy[j]).norm();
    }
    for (const auto& [g, h] : map_now) last_ever[g] = h;
    for (const auto g : f.gt_ids) tracked[g].push_back(map_now.count(g) > 0);
    r.tp += static_cast<std::int64_t>(map_now.size());
    r.gt += static_cast<std::int64_t>(f.gt_ids.size());
    r.fn += static_cast<std::int64_t>(f.gt_ids.size() - map_now.size());
    r.fp += static_cast<std::int64_t>(f.track_ids.size() - map_now.size());
    prev_frame_map = map_now;
  }
  for (const auto& [g, seq] : tracked) {
    int runs = 0, hits = 0;
    for (std::size_t k = 0; k < seq.size(); ++k) {
      hits += seq[k];
      if (seq[k] && (k == 0 || !seq[k - 1])) ++runs;
    }
    r.frag += std::max(0, runs - 1);
    const double ratio = static_cast<double>(hits) / seq.size();
    if (ratio > 0.8) ++r.mt;
    else if (ratio < 0.2) ++r.ml;
    else ++r.pt;
  }
  return r;
}

TEST(ClearMotTest, LargeRandomCaseAgreesWithSecondImplementation) {
  // 1500 scans of up to ~8 truth objects in a 40 m square (so that objects meet and gates
  // overlap), tracked with noise, misses, identity changes, swaps and false positives.
  std::mt19937 rng(20240611);
  std::normal_distribution<double> noise(0.0, 0.6), step(0.0, 0.8);
  std::uniform_real_distribution<double> unit(0.0, 1.0), pos(0.0, 40.0);
  struct Obj {
    std::int64_t id, track;
    Eigen::Vector2d p;
    int life;
  };
  std::vector<Obj> objs;
  std::int64_t next_gt = 0, next_track = 1000;
  std::vector<ScoringFrame> frames;
  for (int t = 0; t < 1500; ++t) {
    while (objs.size() < 8 && unit(rng) < 0.3) {
      objs.push_back({next_gt++, next_track++, {pos(rng), pos(rng)}, 20 + static_cast<int>(unit(rng) * 150)});
    }
    ScoringFrame f;
    f.utime = t;
    for (auto& o : objs) {
      o.p += Eigen::Vector2d(step(rng), step(rng));
      if (unit(rng) < 0.01) o.track = next_track++;              // a new identity
      f.gt_ids.push_back(o.id);
      f.gt_xy.push_back(o.p);
    }
    if (objs.size() >= 2 && unit(rng) < 0.02) std::swap(objs[0].track, objs[1].track);  // a swap
    for (const auto& o : objs) {
      if (unit(rng) < 0.12) continue;                              // a miss
      f.track_ids.push_back(o.track);
      f.track_xy.push_back(o.p + Eigen::Vector2d(noise(rng), noise(rng)));
    }
    const int fps = unit(rng) < 0.5 ? 0 : (unit(rng) < 0.5 ? 1 : 2);
    for (int k = 0; k < fps; ++k) {
      f.track_ids.push_back(500000 + t * 4 + k);
      f.track_xy.emplace_back(pos(rng), pos(rng));
    }
    frames.push_back(f);
    for (auto& o : objs) --o.life;
    objs.erase(std::remove_if(objs.begin(), objs.end(), [](const Obj& o) { return o.life <= 0; }),
               objs.end());
  }
  const double gate = 2.0;
  const ClearMotResult r = Clear(frames, gate);
  const Reference ref = ReferenceClearMot(frames, gate);
  // The case must exercise every kind of event.
  ASSERT_GT(ref.idsw, 20);
  ASSERT_GT(ref.frag, 20);
  ASSERT_GT(ref.fp, 200);
  ASSERT_GT(ref.gt, 5000);
  ExpectCounts(r, {.gt_detections = ref.gt,
                   .true_positives = ref.tp,
                   .false_positives = ref.fp,
                   .false_negatives = ref.fn,
                   .id_switches = ref.idsw,
                   .fragmentations = ref.frag,
                   .mostly_tracked = ref.mt,
                   .partially_tracked = ref.pt,
                   .mostly_lost = ref.ml});
  EXPECT_NEAR(r.mota, 1.0 - static_cast<double>(ref.fn + ref.fp + ref.idsw) / ref.gt, 1e-12);
  EXPECT_NEAR(r.motp_m, ref.dist / ref.tp, 1e-9);
}

}  // namespace
}  // namespace vtrack::eval
