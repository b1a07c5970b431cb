// Association of segments to tracks (not in the paper; docs/design.md, section 4.4): by the predicted
// rectangle and its visible faces, with one global assignment.
//
// For each track, the predicted rectangle grown by a gate margin (gate_margin + gate_sigma *
// predicted position std, at most max_gate_margin) is the gate. A segment is a candidate for a
// track if at least min_inside_fraction of its returns fall inside the gate. The cost of the
// pair is
//     cost = mean over inside returns of the distance to the nearest visible face of the
//            predicted rectangle (Eq. 15 per-face visibility, docs/design.md note 4)
//          + outside_penalty * (1 - inside fraction)
//          + outside_penalty * (most inside returns of any candidate - its inside returns)
//                            / all candidates' inside returns,
// so a segment that lies where the sensor should see the vehicle's faces is preferred over one
// that merely overlaps it, and a few returns on a face do not win the track over the rest of its
// object (which, on the track's rectangle but beyond the dimensions it has seen, could then
// neither merge nor start a track). One global minimum-cost assignment (Hungarian method, solved per
// connected component of the candidate graph, so its cubic cost applies only to small groups)
// pairs tracks and segments one to one; a track may stay unassigned at cost miss_cost.
//
// Around the assignment:
//  - split: a segment that is a candidate of two or more established tracks (two parked cars
//    merged by the grid) is split between them, each return going to the rectangle it is
//    nearest to, before the assignment;
//  - merge: an unassigned segment with at least merge_fraction of its returns inside the
//    predicted rectangle of an assigned track grown by gate_margin only (not by the position
//    uncertainty), which does not stretch the track's returns beyond the dimensions seen so far
//    (PredictedObject::seen_*) by more than gate_margin, joins that track (an object cut in two
//    by an occluder);
//  - a leftover with at least min_inside_fraction of its returns on the rectangle of some track
//    grown by gate_margin, or smaller than ignore_max_extent and inside some track's gate, but
//    not merged, is ignored (it would otherwise seed a duplicate of that track);
//  - what remains unassigned seeds new tracks.
#pragma once

#include <Eigen/Core>

#include <cstdint>
#include <limits>
#include <string>
#include <vector>

#include "base/assignment.h"
#include "base/box.h"
#include "tracker/core/parallel_for.h"
#include "tracker/core/preprocess.h"
#include "tracker/core/segmentation.h"
#include "tracker/core/parameters.h"

namespace vtrack {

// What association needs to know of a track: its predicted rectangle and uncertainty.
struct PredictedObject {
  OrientedBox box;                   // predicted rectangle at the scan time
  double position_std = 0.0;         // [m] sqrt of the largest eigenvalue of the xy covariance
  bool established = false;          // confirmed or coasting (may claim part of a split segment)
  // Dimensions seen so far (shape estimates; box holds at least a default vehicle's): a leftover
  // piece merges into the track only if the merged returns stay within these + gate_margin.
  // 0: unknown (the box bounds them).
  double seen_length = 0.0;          // [m]
  double seen_width = 0.0;           // [m]
  // A mover's rear end, +1 or -1 along the box's x axis (against its motion); 0: not a mover.
  // A leftover column of returns along the ray, within the mover's width behind it, is its own
  // side seen edge-on (a long vehicle coming head-on): it joins the mover up to
  // AssociationParams::mover_max_length.
  int rear_sign = 0;
};

struct AssociationResult {
  // For each track (same order as the input), the returns assigned to it (indices into
  // WorldPoints); empty if none.
  std::vector<std::vector<std::int32_t>> track_points;
  // Cost of the assignment of each track (NaN if unassigned).
  std::vector<double> track_cost;
  // Segments left over (new objects), as lists of WorldPoints indices.
  std::vector<std::vector<std::int32_t>> new_objects;
  std::int32_t num_split = 0;   // segments split between tracks
  std::int32_t num_merged = 0;  // leftover segments merged into a track
  std::int32_t num_ignored = 0; // leftover segments on a track's rectangle but not merged
};


class Associator {
 public:
  explicit Associator(const AssociationParams& params);
  // pool (null: none; else outliving this): its threads share the tracks' candidate pairs; the
  // result does not depend on how many there are.
  void SetPool(WorkerPool* pool) { pool_ = pool; }

  void Run(const std::vector<PredictedObject>& tracks, const WorldPoints& pts,
           const Segments& segments, const Eigen::Vector2d& sensor_xy, AssociationResult* out);

  // Grown gate of a predicted object.
  double GateMargin(const PredictedObject& t) const;

  // A rectangle's frame: centre, cos and sin of its heading, half length and half width.
  struct RectFrame {
    double cx, cy, ax, ay, hl, hw;
  };
  // A block of a segment's returns: every one lies within radius of (cx, cy)
  // (internal::BoundBlocks).
  struct ReturnBlock {
    double cx, cy, radius;
  };

 private:
  struct Part {  // a segment, or one piece of a split segment
    std::vector<std::int32_t> points;
    Eigen::Vector2d min, max;
    std::vector<ReturnBlock> blocks;  // of points, in order (internal::BoundBlocks)
  };
  // Boxes sorted by their lower x bound, for the overlap tests of boxes against boxes (tracks'
  // gates against segments or parts): those are O(tracks x segments), most of them disjoint.
  struct SortedBoxes {
    std::vector<double> lo_x;                // ascending
    std::vector<Eigen::Vector2d> lo, hi;     // the boxes, in lo_x order
    std::vector<std::int32_t> id;            // caller's index of each box, in lo_x order
    double max_width = 0.0;                  // [m] largest hi_x - lo_x
    std::vector<std::int32_t> order;         // scratch
    // Sorts the boxes k with use[k] != 0 (every box if use is empty).
    void Build(const std::vector<Eigen::Vector2d>& lo, const std::vector<Eigen::Vector2d>& hi,
               const std::vector<char>& use);
    // Sets *ids to the boxes that overlap [lo, hi] (closed), ascending.
    void Overlapping(const Eigen::Vector2d& lo, const Eigen::Vector2d& hi,
                     std::vector<std::int32_t>* ids) const;
  };
  struct Pair {  // a candidate (track, part) and its cost
    int track, part;
    double cost, inside;
  };
  struct MergeChoice {  // what becomes of a leftover part
    int track = -1;            // the track it merges into, or -1
    bool on_some_box = false;  // on some track's rectangle (grown by gate_margin)
    bool candidate = false;    // a candidate of some track
  };

  // Split: parts_ from the segments, a segment claimed by two or more established tracks split
  // between them.
  void BuildParts(const std::vector<PredictedObject>& tracks, const WorldPoints& pts,
                  const Segments& segments);
  // What one thread of BuildParts and CandidatePairs works with (reused from scan to scan).
  struct Scratch {
    std::vector<std::int32_t> candidates;  // gates (or parts) overlapping a box
    std::vector<std::size_t> claim;        // the tracks claiming one segment
    std::vector<RectFrame> claimants;      // their rectangles
    // The segment's returns side by side (an odd count padded with a copy of the last).
    ReturnArray<double> seg_x, seg_y;
    std::vector<double> split_d;           // split: per return, its distance to the nearest claimant
    std::vector<std::int64_t> split_best;  // split: per return, that claimant
    std::vector<ReturnBlock> blocks;       // the segment's returns in blocks (internal::kBlockReturns)
    std::vector<double> block_max;         // split: per block, the largest split_d in it
  };
  void IndexClaimingGates(const std::vector<PredictedObject>& tracks);
  // The parts of segments [seg_begin, seg_end), in segment order, into (*parts)[0, returned
  // count); the other elements of *parts keep their buffers.
  std::size_t PartsOf(const std::vector<PredictedObject>& tracks, const WorldPoints& pts,
                      const Segments& segments, std::size_t seg_begin, std::size_t seg_end,
                      Scratch* scratch, std::vector<Part>* parts) const;
  // The established tracks whose gates hold split_min_points of segment s's returns
  // (scratch->seg_x, seg_y), into scratch->claim.
  void ClaimingTracks(const Segment& s, Scratch* scratch) const;
  // The segment's returns [begin, end) (scratch->seg_x, seg_y) among the claimants, into
  // parts[0, claimants).
  void SplitAmong(const std::vector<PredictedObject>& tracks, const std::int32_t* begin,
                  const std::int32_t* end, Scratch* scratch, Part* parts) const;
  // Bounding boxes of the pieces [first, end) of a split; drops those too small to fit. Returns
  // the new end.
  std::size_t BoundSplit(const WorldPoints& pts, std::size_t first, std::size_t end,
                         std::vector<Part>* parts) const;
  // Candidate pairs with their costs, in (track, part) order.
  void CandidatePairs(const std::vector<PredictedObject>& tracks, const WorldPoints& pts,
                      const Eigen::Vector2d& sensor_xy, std::vector<Pair>* pairs);
  // Cost of (track, part), or +inf if the part is not a candidate of the track.
  double PairCost(const PredictedObject& t, double margin, std::uint8_t visible, const Part& p,
                  const WorldPoints& pts, double* inside_fraction) const;
  // The global assignment, per connected component; returns the track of each part (or -1).
  std::vector<int> Assign(std::size_t num_tracks, const std::vector<Pair>& pairs,
                          AssociationResult* out);
  void AssignComponent(const std::vector<int>& tracks, const std::vector<int>& parts,
                       const std::vector<Pair>& pairs, const std::size_t* pair_begin,
                       const std::size_t* pair_end, std::vector<int>* part_track,
                       AssociationResult* out);
  // Merge, ignore, join a mover, or a new object: each part left unassigned.
  void Leftovers(const std::vector<PredictedObject>& tracks, const WorldPoints& pts,
                 const Eigen::Vector2d& sensor_xy, const std::vector<Pair>& pairs,
                 const std::vector<int>& part_track, AssociationResult* out);
  MergeChoice ChooseMerge(const std::vector<PredictedObject>& tracks, const WorldPoints& pts,
                          const Part& part, const std::vector<const Pair*>& part_pairs,
                          const AssociationResult& out);
  // A leftover piece joining a mover as its side seen edge-on (PredictedObject::rear_sign).
  bool JoinMover(const std::vector<PredictedObject>& tracks, const WorldPoints& pts,
                 const Eigen::Vector2d& sensor_xy, const std::vector<std::int32_t>& piece,
                 AssociationResult* out, std::vector<char>* own_valid) const;

  AssociationParams params_;
  WorkerPool* pool_ = nullptr;
  // Scratch reused from scan to scan (no allocation per segment or part once warm).
  std::vector<Part> parts_;                // [0, num_parts_) in use; the rest keep their buffers
  std::size_t num_parts_ = 0;
  SortedBoxes sorted_;
  std::vector<RectFrame> gates_;           // per track: frame, half sizes grown by its gate
  std::vector<Scratch> scratch_;           // per thread of the pool (one without)
  // Parts: per block of segments but the first (which writes parts_), its parts and their count.
  std::vector<std::vector<Part>> block_parts_;
  std::vector<std::size_t> block_num_parts_;
  std::vector<Pair> pairs_;
  // Candidate pairs: per block of tracks but the first, its pairs.
  std::vector<std::vector<Pair>> block_pairs_;
  std::vector<int> row_of_, col_of_;       // assignment: track -> row, part -> column
  std::vector<double> cost_;               // assignment: cost matrix, row-major
  std::vector<char> own_valid_;            // merge: own_lo_/own_hi_ of a track are current
  std::vector<Eigen::Vector2d> own_lo_, own_hi_;  // merge: a track's returns in its frame
};

// New objects (what association left unassigned) in the order they become tracks: rectangles
// before small objects (bounding-box diagonal < small_extent), each group largest first. A
// car's end face seen edge-on at 30-40 m is a piece of a few returns beside its side, and may
// hold more returns than the side: created first, it became a second track of the car, which
// grew into a rectangle a few scans later and replaced the car's track (an identity switch).
void OrderNewObjects(const WorldPoints& pts, double small_extent,
                     std::vector<std::vector<std::int32_t>>* objects);

// The rectangles of the tracks created from one scan. A new object with merge_fraction of its
// returns on one of them (grown by gate_margin) is part of that object (a face cut off by a
// range jump), not a new one: the same test as the merge of a leftover into a track.
class CreatedRectangles {
 public:
  explicit CreatedRectangles(const AssociationParams& params) : params_(params) {}
  void Clear();
  void Add(const OrientedBox& box);
  bool Holds(const WorldPoints& pts, const std::vector<std::int32_t>& idx) const;

 private:
  AssociationParams params_;
  std::vector<OrientedBox> boxes_;
  std::vector<Eigen::Vector2d> lo_, hi_;  // bounds of each grown rectangle
};

}  // namespace vtrack
