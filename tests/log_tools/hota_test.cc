// HOTA (Luiten et al. 2021) on hand-worked cases, with S(d) = max(0, 1 - d / gate) and the 19
// thresholds alpha = 0.05 ... 0.95.
#include <gtest/gtest.h>

#include <cmath>
#include <vector>

#include "log_tools/eval/clear_mot.h"
#include "tests/log_tools/scoring_frames.h"

namespace vtrack::eval {
namespace {

using testing::FrameBuilder;
using testing::Scans;

HotaResult Hota(const std::vector<ScoringFrame>& frames, double gate = 2.0) {
  HotaParams p;
  p.similarity_gate_m = gate;
  return ComputeHota(frames, p);
}

TEST(HotaTest, Similarity) {
  EXPECT_DOUBLE_EQ(HotaSimilarity(0.0, 2.0), 1.0);
  EXPECT_DOUBLE_EQ(HotaSimilarity(1.0, 2.0), 0.5);
  EXPECT_DOUBLE_EQ(HotaSimilarity(3.0, 2.0), 0.0);
}

TEST(HotaTest, PerfectTrackingScoresOne) {
  const auto r = Hota(Scans(5, [](int t) {
    return FrameBuilder(t).Gt(1, 0.0).Gt(2, 10.0).Tr(5, 0.0).Tr(6, 10.0).f;
  }));
  ASSERT_EQ(r.alphas.size(), 19u);
  EXPECT_DOUBLE_EQ(r.hota, 1.0);
  EXPECT_DOUBLE_EQ(r.deta, 1.0);
  EXPECT_DOUBLE_EQ(r.assa, 1.0);
  EXPECT_DOUBLE_EQ(r.loca, 1.0);
}

TEST(HotaTest, IdentitySwitchHalvesAssociation) {
  // One truth, 10 scans, exactly on it track 7 (scans 0-4) then track 8 (5-9).
  // Every TP c: TPA = 5, FNA = 5, FPA = 0 -> A(c) = 0.5; DetA = 1; HOTA = sqrt(0.5).
  const auto r =
      Hota(Scans(10, [](int t) { return FrameBuilder(t).Gt(1, 0.0).Tr(t < 5 ? 7 : 8, 0.0).f; }));
  EXPECT_NEAR(r.deta, 1.0, 1e-12);
  EXPECT_NEAR(r.assa, 0.5, 1e-12);
  EXPECT_NEAR(r.hota, std::sqrt(0.5), 1e-12);
}

TEST(HotaTest, GapLowersDetectionAndAssociation) {
  // Track 7 misses scans 3 and 4 of 10: TP 8, FN 2 -> DetA 0.8; A = 8 / (10 + 8 - 8) = 0.8.
  const auto r = Hota(testing::TrackMissingScans3And4());
  EXPECT_NEAR(r.deta, 0.8, 1e-12);
  EXPECT_NEAR(r.assa, 0.8, 1e-12);
  EXPECT_NEAR(r.hota, 0.8, 1e-12);
}

TEST(HotaTest, LocalisationThresholds) {
  // d = 1 m with a 2 m gate: S = 0.5, a match for the 10 thresholds alpha <= 0.5 (HOTA_alpha = 1)
  // and none for the other 9 (HOTA_alpha = 0): HOTA = 10/19; LocA = 0.5.
  const auto r = Hota(Scans(10, [](int t) { return FrameBuilder(t).Gt(1, 0.0).Tr(7, 1.0).f; }));
  EXPECT_NEAR(r.hota, 10.0 / 19.0, 1e-12);
  EXPECT_NEAR(r.loca, 0.5, 1e-12);
  EXPECT_NEAR(r.hota_alpha[9], 1.0, 1e-12);   // alpha = 0.50
  EXPECT_NEAR(r.hota_alpha[10], 0.0, 1e-12);  // alpha = 0.55
}

TEST(HotaTest, FalsePositivesLowerDetectionOnly) {
  // Truth 1 tracked exactly for 10 scans, plus a track far away in 5 scans:
  // TP 10, FN 0, FP 5 -> DetA = 10/15; AssA = 1 -> HOTA = sqrt(2/3).
  const auto r = Hota(Scans(10, [](int t) {
    FrameBuilder b(t);
    b.Gt(1, 0.0).Tr(7, 0.0);
    if (t < 5) b.Tr(9, 50.0);
    return b.f;
  }));
  EXPECT_NEAR(r.deta, 2.0 / 3.0, 1e-12);
  EXPECT_NEAR(r.assa, 1.0, 1e-12);
  EXPECT_NEAR(r.hota, std::sqrt(2.0 / 3.0), 1e-12);
}

TEST(HotaTest, MatchingPrefersTheBetterAssociation) {
  // Truths 1 (at 0) and 2 (at 1); tracks 7 and 8 exactly on them in scans 0-8. In scan 9 track 7
  // is at 0.55 and track 8 at 0.45, so distance alone would swap the pairs (0.45 + 0.45 < 0.55 +
  // 0.55). With gate 1.2 and alpha = 0.5 the cross pairs are potential matches only in scan 9
  // (S = 1 - 1/1.2 < 0.5 before): A_max(1,7) = 10/10 = 1 but A_max(1,8) = 1/19, so HOTA's
  // matching (Sec. 5) keeps (1,7) and (2,8): every TP has A = 1, AssA = 1.
  const auto r = Hota(Scans(10, [](int t) {
    const double a = t < 9 ? 0.0 : 0.55, b = t < 9 ? 1.0 : 0.45;
    return FrameBuilder(t).Gt(1, 0.0).Gt(2, 1.0).Tr(7, a).Tr(8, b).f;
  }), 1.2);
  ASSERT_NEAR(r.alphas[9], 0.5, 1e-12);
  EXPECT_NEAR(r.deta_alpha[9], 1.0, 1e-12);
  EXPECT_NEAR(r.assa_alpha[9], 1.0, 1e-12);
}

TEST(HotaTest, EmptyIsUndefined) {
  const auto r = Hota({FrameBuilder(0).f});
  EXPECT_TRUE(std::isnan(r.hota));
}

}  // namespace
}  // namespace vtrack::eval
