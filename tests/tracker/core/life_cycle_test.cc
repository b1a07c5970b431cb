// MarkDuplicates (life_cycle.h): which of two tracks on one object goes. The tracks are built by
// hand, the rectangles placed so that their overlap is known.
#include "tracker/core/life_cycle.h"

#include <gtest/gtest.h>

#include <random>
#include <vector>

namespace vtrack {
namespace {

Track MakeTrack(std::int64_t id, int num_updates, bool evidence_seen, double log_odds) {
  Track t;
  t.id = id;
  t.status = TrackStatus::kConfirmed;
  t.num_updates = num_updates;
  t.evidence_seen = evidence_seen;
  t.vehicle_log_odds = log_odds;
  return t;
}

PredictedObject Rect(double x, double y, double length = 4.5, double width = 1.8) {
  PredictedObject p;
  p.box.center = {x, y};
  p.box.theta = 0.0;
  p.box.length = length;
  p.box.width = width;
  return p;
}

std::vector<char> Duplicates(const std::vector<Track>& tracks, const std::vector<PredictedObject>& boxes) {
  std::vector<char> remove(tracks.size(), 0);
  MarkDuplicates(TrackManagerParams{}, tracks, boxes, &remove);
  return remove;
}

TEST(LifeCycleTest, OverlapIsTheShareOfFifteenPointsOfTheSmallerBoxInsideTheOther) {
  // Against the definition through OrientedBox's own methods, bit for bit: random boxes of any
  // heading, size and offset, points of the smaller one on a 5 x 3 grid (0.2 of its length and
  // 0.33 of its width apart) tested for lying inside the other.
  std::mt19937 rng(23);
  std::uniform_real_distribution<double> pos(-4.0, 4.0), yaw(-4.0, 4.0), size(0.3, 12.0);
  int partial = 0;
  for (int trial = 0; trial < 20000; ++trial) {
    const OrientedBox a{{pos(rng), pos(rng)}, yaw(rng), size(rng), size(rng)};
    const OrientedBox b{{pos(rng), pos(rng)}, yaw(rng), size(rng), size(rng)};
    const OrientedBox& small = a.length * a.width <= b.length * b.width ? a : b;
    const OrientedBox& other = &small == &a ? b : a;
    int inside = 0;
    for (int i = 0; i < 5; ++i) {
      for (int j = 0; j < 3; ++j) {
        inside += other.Contains(
            small.ToWorld({(i - 2) * 0.2 * small.length, (j - 1) * 0.33 * small.width}));
      }
    }
    ASSERT_EQ(Overlap(a, b), inside / 15.0) << "trial " << trial;
    ASSERT_EQ(Overlap(b, a), inside / 15.0) << "trial " << trial;
    partial += inside > 0 && inside < 15;
  }
  EXPECT_GT(partial, 1000);  // the boxes cross each other's edges often, not just miss or hold
}

TEST(LifeCycleTest, OfTwoDuplicatesTheOneWithLessVehicleEvidenceGoes) {
  // Two rectangles 0.3 m apart along their length: each lies almost wholly in the other.
  const std::vector<PredictedObject> boxes = {Rect(0.0, 0.0), Rect(0.3, 0.0)};
  ASSERT_GT(Overlap(boxes[0].box, boxes[1].box), TrackManagerParams{}.duplicate_overlap);
  // The older track (35 updates) started on a pole beside the car: little vehicle evidence.
  const Track pole_first = MakeTrack(1, 35, true, -3.0), car = MakeTrack(2, 14, true, 1.2);
  EXPECT_EQ(Duplicates({pole_first, car}, boxes), (std::vector<char>{1, 0}));
  EXPECT_EQ(Duplicates({car, pole_first}, boxes), (std::vector<char>{0, 1}));
  // Without evidence on one of them (a detector's box alone measured it): the one with more
  // updates stays, then the older one.
  Track unseen = car;
  unseen.evidence_seen = false;
  EXPECT_EQ(Duplicates({pole_first, unseen}, boxes), (std::vector<char>{0, 1}));
  // A tentative track's evidence (a scan or two) does not decide: the one with more updates stays.
  Track tentative = car;
  tentative.status = TrackStatus::kTentative;
  EXPECT_EQ(Duplicates({pole_first, tentative}, boxes), (std::vector<char>{0, 1}));
  Track same = MakeTrack(3, 35, true, -3.0);
  EXPECT_EQ(Duplicates({same, pole_first}, boxes), (std::vector<char>{1, 0}));  // id 3 is younger
  // A small object inside a vehicle's rectangle goes whatever its evidence.
  Track small = MakeTrack(4, 50, true, 4.0);
  small.small_object = true;
  EXPECT_EQ(Duplicates({small, car}, {Rect(0.5, 0.2, 0.5, 0.5), Rect(0.0, 0.0)}),
            (std::vector<char>{1, 0}));
  // Rectangles side by side (1 m gap): no duplicates.
  EXPECT_EQ(Duplicates({pole_first, car}, {Rect(0.0, 0.0), Rect(0.0, 2.8)}),
            (std::vector<char>{0, 0}));
}

}  // namespace
}  // namespace vtrack
