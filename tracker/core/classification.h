// What a track is: a mover or not (the mover test on its velocity), and its object class
// (vehicle or other) from its estimated size and motion (track_manager.h describes both).
#pragma once

#include <cstddef>
#include <limits>
#include <optional>

#include "tracker/core/ekf.h"
#include "tracker/core/track.h"
#include "tracker/core/parameters.h"

namespace vtrack {

// The mover test of one scan. The centre velocity v and its covariance C of the reported
// hypothesis give d^2 = v^T C^-1 v; the scan is evidence of motion if d^2 exceeds the
// chi-square (2 dof) quantile of `confidence` and |v| >= min_speed. After a single-edge fit only
// the velocity across the edge counts (1 dof): along it the centre follows the extent of the
// returns, which slides as the ego passes a parked car.
class MoverTest {
 public:
  MoverTest(double confidence, double min_speed);
  // Evidence of motion on this scan; nullopt without a fit (a centroid slides with the view
  // just the same, so it is no evidence either way). pose_measured: the scan measured the
  // whole pose (a detector's box): the 2-dof test.
  std::optional<bool> Evidence(const Ekf& ekf, const Track& t, bool pose_measured = false) const;

 private:
  double d2_quantile_ = 0.0;  // chi-square quantile, 2 dof
  double d1_quantile_ = 0.0;  // chi-square quantile, 1 dof
  double min_speed_ = 0.0;    // [m/s]
};

// Whether a track's returns moved with its estimated velocity between two scans: the two scans'
// returns lie nearer to each other with `before` displaced by d (the velocity times the time
// between the scans) than in place. The measure is the sum of each return's distance to the
// nearest return of the other scan, both ways (a chamfer distance); at most kMotionCheckPoints
// evenly strided returns of each scan take part, in the order the outline gives them.
//
// The filter's velocity also takes up a change of view: the fitted centre of a partly seen parked
// car moves as its fit changes, and the returns of a bush or a building corner change from scan
// to scan. Returns that stayed where they were fit worse displaced, and the scan is no evidence
// of motion (MoverTest). The returns of a moving object lie where its last returns went. Along a
// single straight face a displacement along it cannot be told from none (the aperture problem of
// any matching of returns), and a face that grows or a window that slides along a wall favours
// the displacement: TrackManager's mover test tests only the velocity across a single fitted
// face; the restart of a lost still object (track_manager.h) tests the whole velocity.
bool ReturnsMovedWith(const PointSet& now, const ReturnsSnapshot& before, const Eigen::Vector2d& d);

// Keeps at most kMotionCheckPoints evenly strided returns of `points` for the next scan's check.
void SnapshotReturns(const PointSet& points, ReturnsSnapshot* out);

// [-] Returns per scan taking part in the motion check: bounds its cost to 64 x 64 distances per
// tested track.
constexpr std::size_t kMotionCheckPoints = 64;

// The class of t. A track a detector's box measured: from its boxes (below). Otherwise, with
// evidence.classifier_3d (classifier_2d for tracks seen by single-plane scans) = evidence: as its
// accumulated vehicle evidence decides (Track::evidence_vehicle, VehicleByEvidence: a vehicle from
// evidence.vehicle_probability on, and one stays a vehicle down to evidence.keep_probability;
// vehicle_evidence.h). With the rules: a vehicle if its
// estimated size (not the default lower bound) fits a vehicle, or a face of a car's front or rear
// width was seen whole and the rest fits, or it is a mover of any plausible size; small objects
// are other.
ObjectClass Classify(const TrackManagerParams& params, const EvidenceParams& evidence,
                     const Track& t, bool vehicle_needs_box = false, std::int64_t utime = 0,
                     double vehicle_box_score = -std::numeric_limits<double>::infinity());

}  // namespace vtrack
