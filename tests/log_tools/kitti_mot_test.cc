// The KITTI 3-D MOT evaluation (log_tools/eval/kitti_mot.h): 3-D IoU on hand-computed boxes, the
// matching, the devkit's counting on a hand-built sequence, AB3DMOT's sweep on a case whose
// sAMOTA is worked out below, vtrack-eval-kitti as a process, and the real KITTI sequence 0000
// (skipped without ../shared/data/kitti_tracking_boxes).
#include <gtest/gtest.h>
#include <yaml-cpp/yaml.h>

#include <cmath>
#include <cstdio>
#include <filesystem>
#include <fstream>
#include <numbers>
#include <sstream>
#include <string>
#include <vector>

#include "log_tools/eval/kitti_mot.h"
#include "tests/support/subprocess.h"
#include "tests/support/test_env.h"
#include "tests/support/tool_test.h"

namespace vtrack::testing {
namespace {

namespace fs = std::filesystem;
using namespace vtrack::eval::kitti_mot;

constexpr double kEps = 1e-9;
constexpr double kNoThreshold = -std::numeric_limits<double>::infinity();

Box3d Car(double x, double z, double ry = 0.0) {
  Box3d b;
  b.h = 2.0;
  b.w = 2.0;
  b.l = 4.0;
  b.x = x;
  b.y = 1.5;
  b.z = z;
  b.ry = ry;
  return b;
}

// ---------------------------------------------------------------------------------------------
// 3-D IoU

TEST(KittiMotIou, AxisAligned) {
  // Footprints x in [-2, 2] and [-1, 3], z in [-1, 1]: 3 x 2 = 6 m^2; full height 2:
  // intersection 12, union 16 + 16 - 12 = 20.
  EXPECT_NEAR(Iou3d(Car(0, 10), Car(1, 10)), 12.0 / 20.0, kEps);
  EXPECT_NEAR(FootprintIntersection(Car(0, 10), Car(1, 10)), 6.0, kEps);
  // Shifted 1 m along z (the width): 4 x 1 = 4 m^2, intersection 8, union 24.
  EXPECT_NEAR(Iou3d(Car(0, 10), Car(0, 11)), 8.0 / 24.0, kEps);
  EXPECT_NEAR(Iou3d(Car(0, 10), Car(0, 10)), 1.0, kEps);
  EXPECT_NEAR(Iou3d(Car(0, 10), Car(1, 10)), Iou3d(Car(1, 10), Car(0, 10)), kEps);
}

TEST(KittiMotIou, Rotated) {
  // 4 x 2 footprint against itself turned 90 deg about the same centre: a 2 x 2 square in
  // common = 4 m^2; height 2: intersection 8, union 16 + 16 - 8 = 24.
  EXPECT_NEAR(Iou3d(Car(0, 10), Car(0, 10, std::numbers::pi / 2)), 8.0 / 24.0, kEps);
  EXPECT_NEAR(Iou3d(Car(0, 10), Car(0, 10, -std::numbers::pi / 2)), 8.0 / 24.0, kEps);
  // Turned 180 deg: the same box.
  EXPECT_NEAR(Iou3d(Car(0, 10), Car(0, 10, std::numbers::pi)), 1.0, kEps);
  // A 2 x 2 square against itself turned 45 deg: the regular octagon with inradius 1,
  // area 8 (sqrt 2 - 1); IoU = 8 (sqrt 2 - 1) / (8 - 8 (sqrt 2 - 1)) = 1 / sqrt 2.
  Box3d a = Car(0, 10), b = Car(0, 10, std::numbers::pi / 4);
  a.l = b.l = 2.0;
  EXPECT_NEAR(FootprintIntersection(a, b), 8.0 * (std::sqrt(2.0) - 1.0), 1e-9);
  EXPECT_NEAR(Iou3d(a, b), 1.0 / std::sqrt(2.0), 1e-9);
  // The footprint turns about the camera's y axis: length along x at ry = 0, along z at
  // ry = 90 deg. A box turned 90 deg and moved 1 m along z still overlaps the turned one in
  // 2 x 3 = 6 m^2 (its z extent [9, 13] against [8, 12]); moved 1 m along x only in 1 x 4.
  const Box3d t = Car(0, 10, std::numbers::pi / 2);
  EXPECT_NEAR(FootprintIntersection(t, Car(0, 11, std::numbers::pi / 2)), 6.0, kEps);
  EXPECT_NEAR(FootprintIntersection(t, Car(1, 10, std::numbers::pi / 2)), 4.0, kEps);
}

TEST(KittiMotIou, PartialHeight) {
  // Same footprint (8 m^2); heights [y - h, y] = [-0.5, 1.5] and [-1.5, 0.5]: 1 m in common.
  // Intersection 8, union 16 + 16 - 8 = 24.
  Box3d b = Car(0, 10);
  b.y = 0.5;
  EXPECT_NEAR(Iou3d(Car(0, 10), b), 8.0 / 24.0, kEps);
  // A box half as tall standing on the same ground: intersection 8, union 16 + 8 - 8 = 16.
  Box3d c = Car(0, 10);
  c.h = 1.0;
  EXPECT_NEAR(Iou3d(Car(0, 10), c), 0.5, kEps);
}

TEST(KittiMotIou, Disjoint) {
  EXPECT_EQ(Iou3d(Car(0, 10), Car(10, 10)), 0.0);                             // apart in x
  EXPECT_EQ(Iou3d(Car(0, 10), Car(4, 10)), 0.0);                              // edges touch
  // Turned 90 deg at z = 13.5: z in [11.5, 15.5] against [9, 11].
  EXPECT_EQ(Iou3d(Car(0, 10), Car(0, 13.5, std::numbers::pi / 2)), 0.0);
  Box3d above = Car(0, 10);
  above.y = -1.0;  // spans [-3, -1], the other [-0.5, 1.5]
  EXPECT_EQ(Iou3d(Car(0, 10), above), 0.0);
  Box3d flat = Car(0, 10);
  flat.h = 0.0;
  EXPECT_EQ(Iou3d(Car(0, 10), flat), 0.0);
}

// ---------------------------------------------------------------------------------------------
// Matching

TEST(KittiMotMatch, MostPairsBeforeLeastCost) {
  // Row 0 pairs best with column 0 (cost 0.1) but row 1 can only pair with column 0: the
  // matching with two pairs (0-1 at 0.5, 1-0 at 0.5; total 1.0) beats the cheaper single pair.
  const std::vector<double> cost = {0.1, 0.5,  //
                                    0.5, 0.0};
  const std::vector<bool> allowed = {true, true,  //
                                     true, false};
  const auto m = MatchMostPairsMinCost(cost, allowed, 2, 2);
  EXPECT_EQ(m, (std::vector<int>{1, 0}));
}

TEST(KittiMotMatch, RectangularAndForbidden) {
  // Three rows, two columns (the solver turns the problem around): row 1 is cheapest for
  // both columns but can take one; row 2 is allowed nowhere.
  const std::vector<double> cost = {0.3, 0.6,  //
                                    0.1, 0.2,  //
                                    0.0, 0.0};
  const std::vector<bool> allowed = {true, true,  //
                                     true, true,  //
                                     false, false};
  // Options with two pairs: {0-0, 1-1} = 0.5, {0-1, 1-0} = 0.7. The first.
  EXPECT_EQ(MatchMostPairsMinCost(cost, allowed, 3, 2), (std::vector<int>{0, 1, -1}));
  EXPECT_EQ(MatchMostPairsMinCost({}, {}, 0, 3), (std::vector<int>{}));
  EXPECT_EQ(MatchMostPairsMinCost({}, {}, 2, 0), (std::vector<int>{-1, -1}));
}

// ---------------------------------------------------------------------------------------------
// Files

struct Row {
  int frame;
  int id;
  std::string type;
  int truncated = 0, occluded = 0;
  double x1 = 100, y1 = 100, x2 = 200, y2 = 200;
  Box3d box = Car(0, 10);
  double score = 1.0;
};

std::string Line(const Row& r, bool with_score) {
  char buf[512];
  std::snprintf(buf, sizeof(buf), "%d %d %s %d %d -1 %.2f %.2f %.2f %.2f %.6f %.6f %.6f %.6f %.6f "
                "%.6f %.6f", r.frame, r.id, r.type.c_str(), r.truncated, r.occluded, r.x1, r.y1,
                r.x2, r.y2, r.box.h, r.box.w, r.box.l, r.box.x, r.box.y, r.box.z, r.box.ry);
  std::string s = buf;
  if (with_score) {
    std::snprintf(buf, sizeof(buf), " %.6f", r.score);
    s += buf;
  }
  s += '\n';
  return s;
}

std::string DontCare(int frame, double x1, double y1, double x2, double y2) {
  char buf[256];
  std::snprintf(buf, sizeof(buf), "%d -1 DontCare -1 -1 -10 %.2f %.2f %.2f %.2f -1 -1 -1 -1000 "
                "-1000 -1000 -10\n", frame, x1, y1, x2, y2);
  return buf;
}

void WriteFile(const std::string& path, const std::string& text) {
  fs::create_directories(fs::path(path).parent_path());
  std::ofstream(path) << text;
}

TEST(KittiMotFiles, ReadsClassesAndRejectsMalformedLines) {
  const std::string dir = ScratchDir("kitti_mot_read");
  Row car{0, 1, "Car"}, van{0, 2, "Van"}, ped{0, 3, "Pedestrian"}, noid{1, -1, "Car"};
  WriteFile(dir + "/gt.txt", Line(car, false) + Line(van, false) + Line(ped, false) +
                                 Line(noid, false) + DontCare(1, 0, 0, 10, 10));
  const auto gt = ReadTrackingFile(dir + "/gt.txt", false);
  ASSERT_EQ(gt.size(), 3u);  // Car, Van, DontCare; the pedestrian and the id -1 car are skipped
  EXPECT_EQ(gt[0].type, ObjectType::kCar);
  EXPECT_EQ(gt[1].type, ObjectType::kVan);
  EXPECT_EQ(gt[2].type, ObjectType::kDontCare);
  EXPECT_EQ(gt[2].line, 5);
  // The last frame counts every row, the skipped pedestrian's too.
  WriteFile(dir + "/ped_last.txt", Line(car, false) + Line({4, 3, "Pedestrian"}, false));
  std::int64_t last_frame = 0;
  EXPECT_EQ(ReadTrackingFile(dir + "/ped_last.txt", false, &last_frame).size(), 1u);
  EXPECT_EQ(last_frame, 4);
  WriteFile(dir + "/empty.txt", "\n");
  EXPECT_TRUE(ReadTrackingFile(dir + "/empty.txt", false, &last_frame).empty());
  EXPECT_EQ(last_frame, -1);
  // Frames 4, 0, 3, 1, 2 (out of order, as rows of several tracks may come).
  std::vector<KittiObject> rows;
  for (const std::int64_t f : {4, 0, 3, 1, 2}) rows.emplace_back().frame = f;
  const RowsAfter two = RowsAfterFrame(rows, 2);
  EXPECT_EQ(two.count, 2);
  EXPECT_EQ(two.first_frame, 3);
  EXPECT_EQ(two.last_frame, 4);
  const RowsAfter none = RowsAfterFrame(rows, 4);
  EXPECT_EQ(none.count, 0);
  EXPECT_EQ(none.first_frame, -1);
  EXPECT_EQ(none.last_frame, -1);
  const RowsAfter all = RowsAfterFrame(rows, -1);
  EXPECT_EQ(all.count, 5);
  EXPECT_EQ(all.first_frame, 0);
  EXPECT_EQ(all.last_frame, 4);

  // A result without the score column reads as score -1 (AB3DMOT).
  WriteFile(dir + "/res17.txt", Line(car, false));
  EXPECT_EQ(ReadTrackingFile(dir + "/res17.txt", true).at(0).score, -1.0);

  auto expect_error = [&](const std::string& text, const std::string& needle) {
    WriteFile(dir + "/bad.txt", text);
    try {
      ReadTrackingFile(dir + "/bad.txt", true);
      ADD_FAILURE() << "no error for: " << text;
    } catch (const std::runtime_error& e) {
      EXPECT_NE(std::string(e.what()).find(needle), std::string::npos) << e.what();
    }
  };
  expect_error(Line(car, true) + "0 1 Car 0 0\n", "bad.txt:2: 5 fields");
  expect_error(Line(car, true) + Line(car, true), "bad.txt:2: track id 1 occurs twice in frame 0");
  std::string s = Line(car, true);
  s.replace(s.find("Car 0 0 -1"), 10, "Car 0 0 xx");
  expect_error(s, "bad.txt:1: alpha 'xx'");
  expect_error("1.5 2 Car 0 0 -1 0 0 1 1 1 1 1 0 0 0 0 1\n", "bad.txt:1: frame '1.5'");
  expect_error("0 2 Car 0 0 -1 0 0 1 1 1.5 -1.8 4 0 0 0 0 1\n",
               "bad.txt:1: a Car's box needs h, w and l > 0, got 1.5 -1.8 4");
  try {
    ReadTrackingFile(dir + "/missing.txt", false);
    ADD_FAILURE();
  } catch (const std::runtime_error& e) {
    EXPECT_NE(std::string(e.what()).find("missing.txt: cannot open"), std::string::npos);
  }
}

// ---------------------------------------------------------------------------------------------
// The devkit's counting on a hand-built sequence (3 frames; every box 4 x 2 x 2 m, ry = 0).
//
// Ground truth:          frame 0          frame 1            frame 2
//   car 1 (x 0, z 10)    track 10 (IoU    track 11           track 11
//                        0.6: 1 m off)
//   car 2 (x 6, z 20)    track 20         - (missed)         track 20
//   car 3 (x -6, z 15),  track 30         -                  -
//     occluded 3: ignored
//   van 4                                                    - (unmatched)
//   DontCare 2-D boxes                    [500,150,700,250]  [0,0,100,100]
// Other tracker boxes:   60: unmatched,   40: unmatched,     50: unmatched, 2-D 100 px tall;
//                        2-D 20 px tall   2-D box inside     70: unmatched, half its 2-D box
//                                         the DontCare box   in the DontCare box
//
// Counts (devkit rules, see kitti_mot.h):
//   non-ignored gt = car 1 x 3 + car 2 x 3 = 6
//   TP = car 1 x 3 + car 2 x 2 = 5; FN = car 2 in frame 1 = 1
//   ignored TP = car 3 / track 30 (frame 0) = 1; ignored FN = car 3 in frames 1, 2 + van = 3
//   FP = 50 (tall, no DontCare) + 70 (overlap exactly 0.5, not > 0.5) = 2
//   ignored tracker = 60 (20 px <= 25 px) + 40 (DontCare) = 2
//   car 1: ids [10, 11, 11]: switch at frame 1 (matched at 0 and 1, 11 != 10) = 1 IDS, and a
//          fragmentation there (10 != 11, matched, next matched) = 1 FRAG
//   car 2: ids [20, -1, 20]: no switch (not matched at frame 1), a fragmentation at its last
//          appearance (-1 -> 20) = 1 FRAG
//   IDS = 1, FRAG = 2; MOTA = 1 - (1 + 2 + 1) / 6 = 1/3
//   MOTP over the 6 matches (ignored TP included) = (0.6 + 5 x 1) / 6
//   car 1 tracked 3/3 (mostly tracked), car 2 2/3 (partly tracked); car 3 ignored throughout.
struct HandCase {
  std::string labels, results;
};

HandCase MakeHandCase() {
  HandCase c;
  const Box3d g1 = Car(0, 10), g2 = Car(6, 20), g3 = Car(-6, 15);
  for (int f = 0; f < 3; ++f) {
    c.labels += Line({f, 1, "Car", 0, 0, 100, 100, 200, 200, g1}, false);
    c.labels += Line({f, 2, "Car", 0, 0, 300, 100, 400, 200, g2}, false);
    c.labels += Line({f, 3, "Car", 0, 3, 400, 100, 500, 200, g3}, false);
  }
  c.labels += DontCare(1, 500, 150, 700, 250);
  c.labels += Line({2, 4, "Van", 0, 0, 900, 100, 1000, 200, Car(-12, 30)}, false);
  c.labels += DontCare(2, 0, 0, 100, 100);

  c.results += Line({0, 10, "Car", -1, -1, 100, 100, 200, 200, Car(1, 10)}, true);
  c.results += Line({0, 20, "Car", -1, -1, 300, 100, 400, 200, g2}, true);
  c.results += Line({0, 30, "Car", -1, -1, 400, 100, 500, 200, g3}, true);
  c.results += Line({0, 60, "Car", -1, -1, 800, 100, 850, 120, Car(20, 40)}, true);
  c.results += Line({1, 11, "Car", -1, -1, 100, 100, 200, 200, g1}, true);
  c.results += Line({1, 40, "Car", -1, -1, 520, 160, 600, 240, Car(-20, 50)}, true);
  c.results += Line({2, 11, "Car", -1, -1, 100, 100, 200, 200, g1}, true);
  c.results += Line({2, 20, "Car", -1, -1, 300, 100, 400, 200, g2}, true);
  c.results += Line({2, 50, "Car", -1, -1, 800, 100, 900, 200, Car(20, 40)}, true);
  c.results += Line({2, 70, "Car", -1, -1, 50, 0, 150, 100, Car(-20, 60)}, true);
  return c;
}

// A case of the given label rows and result rows (with their scores).
HandCase FromRows(const std::vector<Row>& labels, const std::vector<Row>& results) {
  HandCase c;
  for (const Row& r : labels) c.labels += Line(r, false);
  for (const Row& r : results) c.results += Line(r, true);
  return c;
}

PreparedSequence Prepare(const HandCase& c, const std::string& name, const Params& params) {
  const std::string dir = ScratchDir("kitti_mot_" + name);
  WriteFile(dir + "/labels/0000.txt", c.labels);
  WriteFile(dir + "/results/0000.txt", c.results);
  return PreparedSequence(name, ReadTrackingFile(dir + "/labels/0000.txt", false),
                          ReadTrackingFile(dir + "/results/0000.txt", true), params);
}

// The figures every counting case below states.
struct KeyCounts {
  int ids = 0, frag = 0, tp = 0;
  double mota = 0.0;
};

// Counts the case without a score threshold and checks its key counts; returns all the counts.
Counts CountAndCheck(const HandCase& c, const std::string& name, const Params& params,
                     const KeyCounts& want) {
  SCOPED_TRACE(name);
  const Counts n = Prepare(c, name, params).Evaluate(kNoThreshold);
  EXPECT_EQ(n.ids, want.ids);
  EXPECT_EQ(n.frag, want.frag);
  EXPECT_EQ(n.tp, want.tp);
  EXPECT_NEAR(n.Mota(), want.mota, kEps);
  return n;
}

TEST(KittiMotCounting, HandBuiltSequence) {
  const PreparedSequence seq = Prepare(MakeHandCase(), "hand", Params{});
  const Counts c = seq.Evaluate(kNoThreshold);
  EXPECT_EQ(c.frames, 3);
  EXPECT_EQ(c.gt, 6);
  EXPECT_EQ(c.tp, 5);
  EXPECT_EQ(c.fn, 1);
  EXPECT_EQ(c.ignored_tp, 1);
  EXPECT_EQ(c.ignored_fn, 3);
  EXPECT_EQ(c.fp, 2);
  EXPECT_EQ(c.ignored_tracker, 2);
  EXPECT_EQ(c.tracker_boxes, 10);
  EXPECT_EQ(c.ids, 1);
  EXPECT_EQ(c.frag, 2);
  EXPECT_NEAR(c.Mota(), 1.0 / 3.0, kEps);
  EXPECT_NEAR(c.Motp(), 5.6 / 6.0, kEps);
  EXPECT_NEAR(c.Recall(), 6.0 / 7.0, kEps);     // matches / (matches + FN)
  EXPECT_NEAR(c.Precision(), 6.0 / 8.0, kEps);  // matches / (matches + FP)
  EXPECT_EQ(c.gt_trajectories, 2);
  EXPECT_EQ(c.mostly_tracked, 1);
  EXPECT_EQ(c.partly_tracked, 1);
  EXPECT_EQ(c.mostly_lost, 0);
}

TEST(KittiMotCounting, StricterIouThreshold) {
  // At IoU 0.7 track 10 (IoU 0.6) no longer matches car 1 in frame 0: one more FN and, its 2-D
  // box being 100 px tall and outside any DontCare box, one more FP. Car 1's ids become
  // [-1, 11, 11]: no switch (nothing matched before), no fragmentation (nothing to resume).
  // TP 4, FN 2, FP 3, IDS 0, FRAG 1 (car 2); MOTA = 1 - (2 + 3 + 0) / 6 = 1/6.
  Params p;
  p.min_iou = 0.7;
  const Counts c =
      CountAndCheck(MakeHandCase(), "hand07", p, {.ids = 0, .frag = 1, .tp = 4, .mota = 1.0 / 6.0});
  EXPECT_EQ(c.fn, 2);
  EXPECT_EQ(c.fp, 3);
}

TEST(KittiMotCounting, ReacquiredUnderAnotherIdIsAFragmentationNotASwitch) {
  // One car over 4 frames: track 1, missed, track 2, track 2. Ids [1, -1, 2, 2]: the devkit
  // counts a switch only between consecutive matched appearances, so none here; a
  // fragmentation where track 2 resumes it (frame 2: -1 -> 2, matched before, next matched).
  // TP 3, FN 1: MOTA = 1 - 1/4.
  const HandCase c = FromRows({{0, 7, "Car"}, {1, 7, "Car"}, {2, 7, "Car"}, {3, 7, "Car"}},
                              {{0, 1, "Car"}, {2, 2, "Car"}, {3, 2, "Car"}});
  const Counts n =
      CountAndCheck(c, "reacquire", Params{}, {.ids = 0, .frag = 1, .tp = 3, .mota = 0.75});
  EXPECT_EQ(n.fn, 1);
}

TEST(KittiMotCounting, AnIgnoredAppearanceBreaksTheIdentityChain) {
  // One car over 3 frames, occluded 3 (ignored) in frame 1: tracks 1, 2, 2. Ids [1, 2, 2] with
  // frame 1 ignored: the ignored appearance resets the last id, so frame 1 -> 2 is no switch and
  // no fragmentation (without the reset it would be one of each). Frame 1's match is an ignored
  // TP: TP 2, ignored TP 1, FN 0, FP 0, MOTA 1.
  const HandCase c = FromRows({{0, 7, "Car"}, {1, 7, "Car", 0, 3}, {2, 7, "Car"}},
                              {{0, 1, "Car"}, {1, 2, "Car"}, {2, 2, "Car"}});
  const Counts n =
      CountAndCheck(c, "ignored_middle", Params{}, {.ids = 0, .frag = 0, .tp = 2, .mota = 1.0});
  EXPECT_EQ(n.ignored_tp, 1);
  EXPECT_EQ(n.fp, 0);
}

// ---------------------------------------------------------------------------------------------
// AB3DMOT's sweep

TEST(KittiMotSweep, ThresholdsFollowRecallSteps) {
  // 80 matched scores, N = 80: recall steps of 1/40 = 2 matches. Walking down, with target r
  // (0 at first): score i is taken when (i + 1.5) / 80 >= r. Taken: i = 0 (r = 0, dropped),
  // i = 1 (r = 1/40), then i = 2 is skipped (3.5/80 < 2/40), i = 3 taken (r = 2/40), and so
  // every odd i; i = 79 (the last) with r = 40/40. So 40 thresholds: score[2k - 1] at r = k/40.
  std::vector<double> scores;
  for (int i = 0; i < 80; ++i) scores.push_back(1.0 - i / 100.0);
  std::vector<double> t, r;
  SampleThresholds(scores, 80, 41, &t, &r);
  ASSERT_EQ(t.size(), 40u);
  for (int k = 1; k <= 40; ++k) {
    EXPECT_DOUBLE_EQ(t[k - 1], scores[2 * k - 1]) << k;
    EXPECT_NEAR(r[k - 1], k / 40.0, 1e-12) << k;
  }
  // With N below 40 every score is taken (each step of 1/N is more than 1/40).
  SampleThresholds({0.5, 0.9, 0.7}, 10, 41, &t, &r);
  EXPECT_EQ(t, (std::vector<double>{0.7, 0.5}));
}

// One car (id 1) at the same place in frames 0..39, 2-D box 100 px tall.
//   track 1: frames 0..19, exact box, score 0.9          -> mean 0.9
//   track 2: frames 20..39, exact box, scores 0.3 / 0.5  -> mean 0.4 (the threshold uses means)
//   track 3: frames 0..9, 20 m away (false positives), score 0.6
// Without threshold: 40 matches, scores 20 x 0.9 and 20 x 0.4; N = 40 + 0 FN = 40: every score
// is a threshold (see above); dropping the first: 19 x 0.9 at recalls 1/40..19/40, then
// 20 x 0.4 at recalls 20/40..39/40.
//   at 0.9: only track 1. TP 20, FN 20, FP 0, IDS 0: MOTA = 0.5, MOTP 1;
//           sMOTA(r) = 1 - (20 - (1 - r) 40) / (40 r) = 20 / (40 r) >= 1 for r <= 19/40: 1.
//   at 0.4: all three. TP 40, FN 0, FP 10, IDS 1 (1 -> 2 at frame 20), FRAG 1:
//           MOTA = 1 - 11/40 = 0.725; sMOTA(k/40) = 29 / k: 1 for k = 20..29.
// sAMOTA = (19 + 10 + sum_{k=30..39} 29/k) / 40 = 0.93662...
// AMOTA = (19 x 0.5 + 20 x 0.725) / 40 = 0.6; AMOTP = 39 x 1 / 40 = 0.975.
// Best MOTA 0.725 at threshold 0.4: FP 10, FN 0, IDS 1, FRAG 1.
TEST(KittiMotSweep, HandWorkedSamota) {
  HandCase c;
  for (int f = 0; f < 40; ++f) c.labels += Line({f, 1, "Car"}, false);
  for (int f = 0; f < 20; ++f) {
    Row r{f, 1, "Car"};
    r.score = 0.9;
    c.results += Line(r, true);
  }
  for (int f = 20; f < 40; ++f) {
    Row r{f, 2, "Car"};
    r.score = f % 2 == 0 ? 0.3 : 0.5;
    c.results += Line(r, true);
  }
  for (int f = 0; f < 10; ++f) {
    Row r{f, 3, "Car", 0, 0, 500, 100, 600, 200, Car(20, 30)};
    r.score = 0.6;
    c.results += Line(r, true);
  }
  const PreparedSequence seq = Prepare(c, "sweep", Params{});
  const Result res = Score({&seq}, Params{});
  double tail = 0.0;
  for (int k = 30; k <= 39; ++k) tail += 29.0 / k;
  ASSERT_EQ(res.sweep.size(), 39u);
  EXPECT_NEAR(res.samota, (19.0 + 10.0 + tail) / 40.0, 1e-9);
  EXPECT_NEAR(res.samota, 0.93662, 1e-5);
  EXPECT_NEAR(res.amota, 0.6, 1e-9);
  EXPECT_NEAR(res.amotp, 0.975, 1e-9);
  EXPECT_TRUE(res.thresholded);
  EXPECT_NEAR(res.best_threshold, 0.4, 1e-9);
  EXPECT_NEAR(res.best.Mota(), 0.725, 1e-9);
  EXPECT_EQ(res.best.fp, 10);
  EXPECT_EQ(res.best.fn, 0);
  EXPECT_EQ(res.best.ids, 1);
  EXPECT_EQ(res.best.frag, 1);
  EXPECT_NEAR(res.sweep.front().mota, 0.5, 1e-9);
  // Pooled over two copies of the sequence: every count doubles, MOTA at each threshold is the
  // same, but N = 80 now spaces the recall points two matches apart (score[2k - 1] at k/40, see
  // ThresholdsFollowRecallSteps): 0.9 at k = 1..20 (sMOTA 1), 0.4 at k = 21..40 (29/k, 1 up to
  // k = 29). One more point than above, k = 40 with sMOTA 29/40:
  // sAMOTA = (20 + 9 + sum_{k=30..39} 29/k + 29/40) / 40.
  const Result twice = Score({&seq, &seq}, Params{});
  ASSERT_EQ(twice.sweep.size(), 40u);
  EXPECT_NEAR(twice.samota, (29.0 + tail + 29.0 / 40.0) / 40.0, 1e-9);
  EXPECT_NEAR(twice.amota, (20 * 0.5 + 20 * 0.725) / 40.0, 1e-9);
  EXPECT_EQ(twice.best.fp, 20);
  EXPECT_EQ(twice.best.ids, 2);
}

// ---------------------------------------------------------------------------------------------
// vtrack-eval-kitti as a process

class KittiMotCliTest : public ToolTest {
 protected:
  KittiMotCliTest() : ToolTest("vtrack-eval-kitti", "kitti_mot_cli") {}
  void Prepare() override {
    const HandCase c = MakeHandCase();
    WriteFile(dir_ + "/labels/0000.txt", c.labels);
    WriteFile(dir_ + "/results/0000.txt", c.results);
  }
};

TEST_F(KittiMotCliTest, HandCaseThroughTheCommand) {
  std::string out;
  ASSERT_EQ(RunTool({"--labels", dir_ + "/labels", "--results", dir_ + "/results", "--sequences",
                     "0", "--json", dir_ + "/m.json"},
                    &out),
            0)
      << out;
  EXPECT_NE(out.find("[1/1] 0000"), std::string::npos) << out;  // progress line
  const YAML::Node j = YAML::LoadFile(dir_ + "/m.json");
  // Every score is 1: the one threshold (1) keeps every track: the counts of HandBuiltSequence.
  for (const std::string key : {"all", "0000"}) {
    const YAML::Node s = key == "all" ? j["all"] : j["sequences"][key];
    EXPECT_NEAR(s["mota"].as<double>(), 1.0 / 3.0, 1e-6);
    EXPECT_EQ(s["ids"].as<int>(), 1);
    EXPECT_EQ(s["frag"].as<int>(), 2);
    EXPECT_EQ(s["fp"].as<int>(), 2);
    EXPECT_EQ(s["fn"].as<int>(), 1);
  }
  EXPECT_NEAR(j["params"]["min_iou"].as<double>(), 0.25, 1e-12);
  ASSERT_EQ(RunTool({"--labels", dir_ + "/labels", "--results", dir_ + "/results", "--iou", "0.7",
                     "-q", "--json", dir_ + "/m7.json"},
                    &out),
            0)
      << out;
  EXPECT_EQ(out.find("[1/1]"), std::string::npos) << out;  // -q
  EXPECT_NEAR(YAML::LoadFile(dir_ + "/m7.json")["all"]["mota"].as<double>(), 1.0 / 6.0, 1e-6);
  // Without --sequences: every NNNN.txt in --labels, nothing else.
  WriteFile(dir_ + "/labels/notes.txt", "not a sequence\n");
  EXPECT_EQ(RunTool({"--labels", dir_ + "/labels", "--results", dir_ + "/results"}, &out), 0)
      << out;
  EXPECT_NE(out.find("[1/1] 0000"), std::string::npos) << out;
  EXPECT_EQ(out.find("warning"), std::string::npos) << out;
}

TEST_F(KittiMotCliTest, ResultsAfterTheLastLabelledFrameAreFalsePositivesAndWarned) {
  // The hand case's labels end at frame 2; two more result rows in frames 5 and 7.
  const HandCase c = MakeHandCase();
  WriteFile(dir_ + "/late/0000.txt",
            c.results + Line({5, 90, "Car", -1, -1, 100, 100, 200, 200, Car(0, 10)}, true) +
                Line({7, 90, "Car", -1, -1, 100, 100, 200, 200, Car(0, 10)}, true));
  std::string out;
  ASSERT_EQ(RunTool({"--labels", dir_ + "/labels", "--results", dir_ + "/late", "-q", "--json",
                     dir_ + "/late.json"},
                    &out),
            0)
      << out;
  EXPECT_NE(out.find("warning: " + dir_ + "/late/0000.txt: 2 car/van rows in frames 5-7, after "
                     "frame 2, the last with a row in " + dir_ + "/labels/0000.txt"),
            std::string::npos)
      << out;
  // Counted: the hand case's 2 false positives and these 2; 6 labelled cars, 1 miss, 1 switch.
  const YAML::Node all = YAML::LoadFile(dir_ + "/late.json")["all"];
  EXPECT_EQ(all["fp"].as<int>(), 4);
  EXPECT_NEAR(all["mota"].as<double>(), 1.0 - (1.0 + 4.0 + 1.0) / 6.0, 1e-6);
}

TEST_F(KittiMotCliTest, HelpAndErrors) {
  std::string out;
  EXPECT_EQ(RunTool({"--help"}, &out), 0);
  EXPECT_NE(out.find("--sequences"), std::string::npos) << out;
  EXPECT_EQ(RunTool({"--results", dir_ + "/results"}, &out), 2);
  EXPECT_NE(out.find("--labels DIR is required"), std::string::npos) << out;
  EXPECT_EQ(RunTool({"--labels", dir_ + "/labels", "--results", dir_ + "/results", "--iou", "0"},
                    &out),
            2);
  EXPECT_NE(out.find("--iou must be in (0, 1]"), std::string::npos) << out;
  EXPECT_EQ(RunTool({"--labels", dir_ + "/nowhere", "--results", dir_ + "/results"}, &out), 2);
  EXPECT_NE(out.find("nowhere: not a directory"), std::string::npos) << out;
  // A sequence without a result file.
  WriteFile(dir_ + "/labels/0002.txt", MakeHandCase().labels);
  EXPECT_EQ(RunTool({"--labels", dir_ + "/labels", "--results", dir_ + "/results", "--sequences",
                     "0000,0002"},
                    &out),
            1);
  EXPECT_NE(out.find("results/0002.txt: cannot open"), std::string::npos) << out;
  // A malformed line names the file and the line.
  WriteFile(dir_ + "/bad/0000.txt", MakeHandCase().results + "3 1 Car 0 0 -1 1 2 3\n");
  EXPECT_EQ(RunTool({"--labels", dir_ + "/labels", "--results", dir_ + "/bad"}, &out), 1);
  EXPECT_NE(out.find("bad/0000.txt:11: 9 fields"), std::string::npos) << out;
}

// ---------------------------------------------------------------------------------------------
// Real data: KITTI tracking sequence 0000

std::string BoxesDir() {
  const std::string d = DataDir() + "/kitti_tracking_boxes";
  return fs::exists(d + "/label_02/0000.txt") ? d : "";
}

TEST(KittiMotReal, GroundTruthAgainstItself) {
  const std::string data = BoxesDir();
  if (data.empty()) GTEST_SKIP() << "KITTI boxes not found (" << DataDir() << "/kitti_tracking_boxes)";
  // The labels as a result (score 1), and the expected split of the ground truth counted here
  // from the file: a Car with truncated 0 and occluded <= 2 is scored, any other car or van
  // row is ignored.
  std::ifstream in(data + "/label_02/0000.txt");
  std::string line, result;
  std::int64_t scored = 0, ignored = 0;
  while (std::getline(in, line)) {
    std::istringstream ss(line);
    std::string frame, id, type;
    int trunc = 0, occ = 0;
    ss >> frame >> id >> type >> trunc >> occ;
    if (type == "DontCare") continue;
    result += line + " 1\n";
    if (type == "Car" && trunc == 0 && occ <= 2) ++scored;
    if ((type == "Car" && !(trunc == 0 && occ <= 2)) || type == "Van") ++ignored;
  }
  ASSERT_GT(scored, 100);
  const std::string dir = ScratchDir("kitti_mot_gt");
  WriteFile(dir + "/0000.txt", result);
  const PreparedSequence seq("0000", ReadTrackingFile(data + "/label_02/0000.txt", false),
                             ReadTrackingFile(dir + "/0000.txt", true), Params{});
  const Result r = Score({&seq}, Params{});
  EXPECT_EQ(r.best.Mota(), 1.0);
  EXPECT_EQ(r.best.ids, 0);
  EXPECT_EQ(r.best.frag, 0);
  EXPECT_EQ(r.best.fp, 0);
  EXPECT_EQ(r.best.fn, 0);
  EXPECT_EQ(r.best.tp, scored);
  EXPECT_EQ(r.best.ignored_tp, ignored);
  EXPECT_NEAR(r.best.Motp(), 1.0, 1e-9);
  // Every recall point reached with MOTA 1.
  EXPECT_NEAR(r.samota, 1.0, 1e-9);
  EXPECT_NEAR(r.amota, 1.0, 1e-9);
}

TEST(KittiMotReal, DetectionsWithANewIdEachFrame) {
  const std::string data = BoxesDir();
  if (data.empty()) GTEST_SKIP() << "KITTI boxes not found (" << DataDir() << "/kitti_tracking_boxes)";
  // PointRCNN's car detections (frame,type,x1,y1,x2,y2,score,h,w,l,x,y,z,rot_y,alpha) as a
  // result in which every detection is its own track: every object matched in two consecutive
  // frames is an identity switch, so a good detector gives many switches and a MOTA well below
  // the ground truth's 1.
  std::ifstream in(data + "/detections/pointrcnn_Car/0000.txt");
  std::string line, result;
  int id = 0;
  while (std::getline(in, line)) {
    std::vector<std::string> f;
    std::stringstream ss(line);
    for (std::string tok; std::getline(ss, tok, ',');) f.push_back(tok);
    ASSERT_EQ(f.size(), 15u) << line;
    result += f[0] + " " + std::to_string(id++) + " Car -1 -1 " + f[14] + " " + f[2] + " " + f[3] +
              " " + f[4] + " " + f[5] + " " + f[7] + " " + f[8] + " " + f[9] + " " + f[10] + " " +
              f[11] + " " + f[12] + " " + f[13] + " " + f[6] + "\n";
  }
  const std::string dir = ScratchDir("kitti_mot_det");
  WriteFile(dir + "/0000.txt", result);
  const PreparedSequence seq("0000", ReadTrackingFile(data + "/label_02/0000.txt", false),
                             ReadTrackingFile(dir + "/0000.txt", true), Params{});
  const Result r = Score({&seq}, Params{});
  const Counts& all = r.all_tracks;
  ASSERT_GT(all.tp, 100);                  // the detector finds most cars
  EXPECT_GT(all.ids, all.tp / 2);          // most matches follow a match in the frame before
  EXPECT_LT(r.best.Mota(), 0.9);
  EXPECT_GT(r.best.Mota(), -1.0);
  EXPECT_GT(r.best.ids, 0);
  std::printf("PointRCNN 0000, new id per detection: sAMOTA %.4f AMOTA %.4f; best threshold %.4g:"
              " MOTA %.4f MOTP %.4f IDS %lld FRAG %lld FP %lld FN %lld TP %lld; every track: MOTA "
              "%.4f IDS %lld TP %lld FP %lld FN %lld\n",
              r.samota, r.amota, r.best_threshold, r.best.Mota(), r.best.Motp(),
              static_cast<long long>(r.best.ids), static_cast<long long>(r.best.frag),
              static_cast<long long>(r.best.fp), static_cast<long long>(r.best.fn),
              static_cast<long long>(r.best.tp), all.Mota(), static_cast<long long>(all.ids),
              static_cast<long long>(all.tp), static_cast<long long>(all.fp),
              static_cast<long long>(all.fn));
}

}  // namespace
}  // namespace vtrack::testing
