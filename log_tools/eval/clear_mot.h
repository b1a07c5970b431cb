// Multi-object tracking metrics on plain per-scan data: CLEAR MOT and HOTA.
//
// Objects are points in the world plane (vehicle centres); the distance between a truth object
// and a track is the Euclidean distance d of their centres [m].
//
// CLEAR MOT (K. Bernardin, R. Stiefelhagen, "Evaluating Multiple Object Tracking Performance:
// The CLEAR MOT Metrics", EURASIP J. Image and Video Processing, 2008), Sec. 2.1, per scan t:
//   1. every correspondence (o, h) of scan t-1 whose truth o and track h are both present at t
//      and still within the gate (d < gate_m) is kept;
//   2. the remaining truths and tracks are matched by one global assignment within the gate:
//      maximum number of pairs, then minimum total distance (GatedAssignment);
//   3. a new pair (o, h) whose truth o was last matched (at any earlier scan) to a track other
//      than h is an identity switch (mismatch).
// Then  MOTA = 1 - sum_t (FN_t + FP_t + IDSW_t) / sum_t GT_t     (Eq. 2 of the paper, "m", "fp")
//       MOTP = sum_{t,i} d_{t,i} / sum_t c_t   [m]               (Eq. 1, distance form)
// From Li, Huang, Nevatia, "Learning to associate: HybridBoosted multi-target tracker for
// crowded scene", CVPR 2009:
//   mostly tracked: a truth object matched in more than 80 % of the scans in which it is scored;
//   mostly lost: matched in less than 20 %; partially tracked: the others;
//   fragmentations: the number of times a truth trajectory is interrupted, i.e. for each truth
//   object (over the scans in which it is scored) the number of matched runs minus one.
//
// HOTA (J. Luiten et al., "HOTA: A Higher Order Metric for Evaluating Multi-object Tracking",
// IJCV 129:548-578, 2021). Localisation similarity of a pair (instead of the paper's box IoU):
//     S(d) = max(0, 1 - d / similarity_gate_m).
// For each alpha in {0.05, 0.10, ..., 0.95} (Sec. 4 of the paper):
//   matching (Sec. 5): per scan, among pairs with S >= alpha, one assignment that maximises first
//     the number of pairs, then A_max (the pair's association IoU if it were matched in every
//     scan where S >= alpha), then S; the matched pairs are TP, unmatched truths FN, unmatched
//     tracks FP;
//   A(c) = |TPA(c)| / (|TPA(c)| + |FNA(c)| + |FPA(c)|) for a TP c = (o, h): TPA the TPs of the
//     same pair over the whole log, FNA the scans of o not matched to h, FPA those of h not
//     matched to o;
//   DetA = |TP| / (|TP| + |FN| + |FP|),  AssA = (1/|TP|) sum_{c in TP} A(c),
//   HOTA_alpha = sqrt(DetA * AssA),  LocA = mean S over TP.
// The reported HOTA, DetA, AssA and LocA are the means over the 19 thresholds.
#pragma once

#include <Eigen/Core>

#include <cstdint>
#include <string>
#include <utility>
#include <vector>

namespace vtrack::eval {

// What the metrics see of one scan: the scored truth objects and the scored tracks. Ids are
// persistent over the log (truth ids and track ids are separate name spaces).
struct ScoringFrame {
  std::int64_t utime = 0;                  // [us] scan time
  std::vector<std::int64_t> gt_ids;        // [-] truth ids, unique within the frame
  std::vector<Eigen::Vector2d> gt_xy;      // [m] truth centres, world frame
  std::vector<std::int64_t> track_ids;     // [-] track ids, unique within the frame
  std::vector<Eigen::Vector2d> track_xy;   // [m] track centres, world frame
};

struct ClearMotParams {
  double gate_m = 2.0;               // [m] a pair is a match only if d < gate_m; > 0
  double mostly_tracked_ratio = 0.8; // [-] matched fraction above which a truth is mostly tracked
  double mostly_lost_ratio = 0.2;    // [-] matched fraction below which it is mostly lost
  std::string Validate() const;      // "" if valid, else names the key and the value
};

// A match of truth index gt (into ScoringFrame::gt_ids) and track index track.
struct Match {
  int gt = -1;
  int track = -1;
  double distance_m = 0.0;
  bool id_switch = false;            // this match is an identity switch (step 3 above)
};

struct ClearMotResult {
  std::int64_t gt_detections = 0;    // sum_t GT_t
  std::int64_t true_positives = 0;   // sum_t c_t
  std::int64_t false_positives = 0;
  std::int64_t false_negatives = 0;
  std::int64_t id_switches = 0;
  std::int64_t fragmentations = 0;
  std::int64_t gt_objects = 0;       // distinct truth ids scored at least once
  std::int64_t mostly_tracked = 0;
  std::int64_t partially_tracked = 0;
  std::int64_t mostly_lost = 0;
  double mota = 0.0;                 // [-] NaN if there is no truth
  double motp_m = 0.0;               // [m] NaN if there is no match
  std::vector<std::vector<Match>> matches;  // per frame, sorted by gt index
};

ClearMotResult ComputeClearMot(const std::vector<ScoringFrame>& frames,
                               const ClearMotParams& params);

struct HotaParams {
  double similarity_gate_m = 2.0;    // [m] distance at which S reaches 0; > 0
  std::string Validate() const;
};

struct HotaResult {
  std::vector<double> alphas;        // the thresholds 0.05 ... 0.95
  std::vector<double> hota_alpha, deta_alpha, assa_alpha, loca_alpha;  // per threshold
  double hota = 0.0, deta = 0.0, assa = 0.0, loca = 0.0;  // means over alphas; NaN if undefined
};

HotaResult ComputeHota(const std::vector<ScoringFrame>& frames, const HotaParams& params);

// The HOTA similarity S(d) above.
double HotaSimilarity(double distance_m, double similarity_gate_m);

}  // namespace vtrack::eval
