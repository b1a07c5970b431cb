// KITTI 3-D multi-object tracking evaluation: the KITTI tracking devkit's CLEAR MOT counting
// (evaluate_tracking.py) with AB3DMOT's 3-D extension (3-D IoU matching and the score-threshold
// sweep giving sAMOTA, AMOTA, AMOTP), class "car". Figures are comparable with those published
// on KITTI by AB3DMOT and the papers that use its evaluation.
//
// Input, one file per sequence (NNNN.txt), space separated, one box per line:
//   frame track_id type truncated occluded alpha x1 y1 x2 y2 h w l x y z rotation_y [score]
// Ground truth: KITTI's label_02 files. Result: the same format with the score column (17
// columns are accepted, with score -1, as AB3DMOT does). (x, y, z) is the bottom centre of the
// box in camera 2's rectified frame (x right, y down, z forward), rotation_y its yaw about y.
//
// Rules (each as the devkit / AB3DMOT implement them):
//  1. Classes. Rows of type Car, Van and DontCare are read (case-insensitive), every other type
//     is skipped. Ground-truth rows with track id -1 that are not DontCare are skipped, and so
//     are result rows with id -1. A result may not hold one track id twice in a frame (an error,
//     as in the devkit). Result rows of type DontCare are skipped (the devkit would treat them
//     as ordinary tracker boxes; no tracker writes them).
//  2. Frames. Frames 0 .. the last frame in either file are evaluated (the devkit takes the
//     count from its seqmap; result rows in any frame of the sequence are scored).
//  3. Score threshold (AB3DMOT). A track's score is the mean of the scores of its rows in the
//     sequence; at threshold s, tracks whose mean score is below s are removed entirely.
//  4. Matching, per frame: one-to-one between ground-truth boxes (Car and Van) and the tracker's
//     boxes, by 3-D IoU; a pair is allowed if 1 - IoU <= 1 - min_iou (IoU >= 0.25 by default;
//     0.5 and 0.7 are the stricter settings). Among the allowed pairs, the matching with the
//     most pairs, then the least total (1 - IoU): the Hungarian method on 1 - IoU with
//     forbidden pairs at a prohibitive cost, as the devkit's Munkres call does. Ties between
//     equal-cost matchings may be broken differently from the Python Munkres package.
//  5. 3-D IoU (AB3DMOT's iou_3d): the intersection of the two rotated footprints in the ground
//     plane (x, z), with corners (x, z) + R(rotation_y) (+-l/2, +-w/2), R = [c s; -s c], times
//     the overlap of the height intervals [y - h, y] (y points down), over
//     l w h + l' w' h' - intersection. A box with a non-positive dimension has IoU 0.
//  6. Ignored ground truth: a ground-truth box is ignored if occluded > max_occlusion (2: only
//     "unknown", 3), truncated > max_truncation (0: the integer part of the field, as the devkit
//     reads it), or of type Van (a neighbouring class of Car). Matched to a track, it is an
//     ignored true positive (neither TP nor FP); unmatched, an ignored false negative (not FN).
//     The ground truth is not filtered by 2-D height (the devkit applies min_height to tracker
//     boxes only).
//  7. Ignored tracker boxes: an unmatched tracker box is not a false positive if it is of type
//     Van, or its 2-D box height |y2 - y1| <= min_height (25 px), or more than half of its 2-D
//     box area (intersection over the tracker box's area, > 0.5) lies in one DontCare box of
//     the frame. Every other unmatched tracker box is a false positive. A tracker box matched to
//     an ignored ground truth box is not a false positive either (rule 6).
//  8. Counts: gt = non-ignored ground-truth boxes = TP + FN; MOTA = 1 - (FN + FP + IDS) / gt;
//     MODA = 1 - (FN + FP) / gt; MOTP = mean IoU over all matched pairs (ignored TPs included,
//     as in the devkit); recall = matches / (matches + FN) and precision = matches /
//     (matches + FP), matches including ignored TPs (devkit).
//  9. Identity switches and fragmentations, per ground-truth trajectory: the list of the
//     tracker ids matched to it at each frame in which it appears (-1 if unmatched), with its
//     ignored flags. Let last = the id at its first appearance; then for each later appearance
//     f: if ignored, last = -1 and nothing is counted; else an identity switch if last != -1,
//     id[f] != -1, id[f-1] != -1 and id[f] != last; a fragmentation if id[f] != id[f-1],
//     last != -1, id[f] != -1 and (f is the last appearance or id[f+1] != -1); then last =
//     id[f] if id[f] != -1. So a switch needs matches in two consecutive appearances, a
//     re-acquisition after a gap is a fragmentation (under another id: not a switch), and a
//     switch is also a fragmentation. Trajectories ignored throughout are not counted.
//     Mostly tracked / lost: matched appearances over non-ignored appearances > 0.8 / < 0.2.
// 10. The sweep (AB3DMOT). Evaluate with every track (no threshold); the scores (track means)
//     of all matched pairs, sorted descending, and N = matches + FN give the thresholds: walking
//     down the list with a target recall r (start 0, step 1/(sample_points - 1) = 1/40), the
//     i-th score (0-based) is taken, with recall r, when (i + 1.5) / N >= r or it is the last
//     one, and then r += 1/40; the first taken (r = 0) is dropped. At each threshold s with
//     recall r: MOTA, MOTP and sMOTA = clip(1 - (FN + FP + IDS - (1 - r) gt) / (r gt), 0, 1).
//     AMOTA, AMOTP and sAMOTA are their sums over the thresholds divided by 40 (recall points
//     that were not reached count 0). The reported MOTA, MOTP, IDS, FRAG, FP, FN are those at
//     the threshold of the best MOTA (the first best, and only if > 0; else every track).
//     Over several sequences, counts and matched scores are pooled before any ratio is taken.
//     Without non-ignored ground truth MOTA and sMOTA are undefined (NaN; the reference gives
//     -inf) and add nothing to the sums.
//  Each threshold is evaluated from scratch (the reference script keeps a per-box "matched"
//  flag from earlier runs of its sweep, which can change rule 7 for a box that was matched at
//  another threshold; rare, and not reproduced).
#pragma once

#include <array>
#include <cstddef>
#include <cstdint>
#include <functional>
#include <limits>
#include <map>
#include <string>
#include <vector>

namespace vtrack::eval::kitti_mot {

// A 3-D box in camera 2's rectified frame: (x, y, z) the bottom centre [m], y down.
struct Box3d {
  double h = 0.0, w = 0.0, l = 0.0;  // height, width, length [m]
  double x = 0.0, y = 0.0, z = 0.0;  // bottom centre [m]
  double ry = 0.0;                   // rotation_y [rad]
};

// Area of the intersection of the two boxes' footprints in the (x, z) plane [m^2].
double FootprintIntersection(const Box3d& a, const Box3d& b);
// 3-D IoU of two boxes (rule 5); 0 if either has a non-positive or non-finite dimension.
double Iou3d(const Box3d& a, const Box3d& b);

enum class ObjectType { kCar, kVan, kDontCare };

struct KittiObject {
  std::int64_t frame = 0;
  std::int64_t track_id = -1;
  ObjectType type = ObjectType::kCar;
  int truncation = 0;  // integer part of the field (devkit)
  int occlusion = 0;
  double x1 = 0.0, y1 = 0.0, x2 = 0.0, y2 = 0.0;  // 2-D box [px]
  Box3d box;
  double score = -1.0;  // results only
  int line = 0;         // 1-based line in its file
};

// Reads one label or result file, keeping the rows that rule 1 keeps. Throws
// std::runtime_error "path:line: reason" for a malformed line (field count, a field that is
// not a number, a frame or id that is not an integer, a negative frame, a duplicate id in a
// frame of a result), or "path: reason" if it cannot be opened. If last_frame is given, it is
// set to the largest frame of any well-formed row, of any type (-1 for a file without rows).
std::vector<KittiObject> ReadTrackingFile(const std::string& path, bool is_result,
                                          std::int64_t* last_frame = nullptr);

// The rows of `result` in frames after last_label_frame: no labelled object lies in those
// frames, so each such car row that is not ignored (a Van, 25 px or less) is a false positive,
// and many of them usually mean that the results are of another sequence or counted from
// another first frame.
struct RowsAfter {
  std::int64_t count = 0;
  std::int64_t first_frame = -1;  // of those rows; -1 if there are none
  std::int64_t last_frame = -1;
};
RowsAfter RowsAfterFrame(const std::vector<KittiObject>& result, std::int64_t last_label_frame);

struct Params {
  double min_iou = 0.25;         // rule 4: a match needs IoU >= this; (0, 1]
  int max_truncation = 0;        // rule 6
  int max_occlusion = 2;         // rule 6
  double min_height_px = 25.0;   // rule 7
  double dontcare_overlap = 0.5; // rule 7
  int sample_points = 41;        // rule 10: recall points + 1 (AB3DMOT's 41)
  std::string Validate() const;  // "" if valid, else names the field and value
};

// Counts at one score threshold, over one sequence or summed over several.
struct Counts {
  std::int64_t frames = 0;
  std::int64_t gt = 0;              // non-ignored ground-truth boxes (= tp + fn)
  std::int64_t tp = 0;              // matches to non-ignored ground truth
  std::int64_t ignored_tp = 0;      // matches to ignored ground truth
  std::int64_t fn = 0;
  std::int64_t ignored_fn = 0;
  std::int64_t fp = 0;
  std::int64_t ignored_tracker = 0; // unmatched tracker boxes not counted (rule 7)
  std::int64_t tracker_boxes = 0;   // tracker boxes scored (after the threshold)
  std::int64_t ids = 0;
  std::int64_t frag = 0;
  std::int64_t gt_trajectories = 0; // not ignored throughout
  std::int64_t mostly_tracked = 0;
  std::int64_t partly_tracked = 0;
  std::int64_t mostly_lost = 0;
  double iou_sum = 0.0;             // over all matches (tp + ignored_tp)

  std::int64_t Matches() const { return tp + ignored_tp; }
  double Mota() const;   // NaN if gt == 0
  double Moda() const;
  double Motp() const;   // mean IoU over matches; 0 if none (AB3DMOT)
  double Recall() const;
  double Precision() const;
  double SMota(double recall) const;  // rule 10; NaN if gt == 0
  Counts& operator+=(const Counts& o);
};

// A sequence's ground truth and result, ready to be scored at any threshold (IoU computed once).
class PreparedSequence {
 public:
  // Throws std::runtime_error on invalid params.
  PreparedSequence(std::string name, const std::vector<KittiObject>& gt,
                   const std::vector<KittiObject>& result, const Params& params);

  const std::string& name() const { return name_; }
  std::int64_t frames() const { return static_cast<std::int64_t>(frames_.size()); }
  std::int64_t result_boxes() const { return result_boxes_; }
  // Counts with the tracks whose mean score is below `threshold` removed; the track means of the
  // matched pairs are appended to matched_scores if given.
  Counts Evaluate(double threshold, std::vector<double>* matched_scores = nullptr) const;

 private:
  struct GtBox {
    std::int64_t id;
    bool ignored;
  };
  struct TrackerBox {
    std::int64_t id;
    double mean_score;
    bool ignorable;  // not a false positive when unmatched (rule 7)
  };
  struct Frame {
    std::vector<GtBox> gt;
    std::vector<TrackerBox> tracker;
    std::vector<double> iou;  // gt.size() x tracker.size(), row-major
  };
  std::string name_;
  Params params_;
  std::vector<Frame> frames_;
  std::int64_t result_boxes_ = 0;
};

// Rule 10's thresholds from the matched scores and N = matches + FN. recalls[i] is the recall
// point of thresholds[i].
void SampleThresholds(std::vector<double> scores, std::int64_t num_gt, int sample_points,
                      std::vector<double>* thresholds, std::vector<double>* recalls);

struct SweepPoint {
  double threshold = 0.0, recall = 0.0, mota = 0.0, motp = 0.0, smota = 0.0;
};

struct Result {
  Counts all_tracks;                // no threshold
  std::vector<SweepPoint> sweep;
  double samota = 0.0, amota = 0.0, amotp = 0.0;
  bool thresholded = false;         // false: no threshold beat MOTA 0, every track is kept
  double best_threshold = -std::numeric_limits<double>::infinity();
  Counts best;                      // at best_threshold
};

// Rule 10 over the pooled sequences. progress(done, total), if given, is called after each
// evaluation pass (one without threshold, one per threshold, one at the best).
Result Score(const std::vector<const PreparedSequence*>& sequences, const Params& params,
             const std::function<void(std::size_t, std::size_t)>& progress = {});

// The minimum-cost matching with the most allowed pairs: allowed[i * cols + j] says whether row
// i and column j may pair, cost the pair's cost (>= 0 and <= 1). Returns the column of each row,
// -1 if none.
std::vector<int> MatchMostPairsMinCost(const std::vector<double>& cost,
                                       const std::vector<bool>& allowed, int rows, int cols);

}  // namespace vtrack::eval::kitti_mot
