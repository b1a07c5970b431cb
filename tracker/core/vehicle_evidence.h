// Vehicle evidence of a track: how likely it is a vehicle rather than a wall, a hedge, a tree
// or a pole, from what the scans measured of it, accumulated over its life.
//
// Per scan that gives the track returns, a feature vector f (EvidenceFeature, parameters.h):
// the returns' height profile above the local ground (3-D clouds), their number and range, how
// high their columns reach (crowns and building fronts above max_height), the extent of the
// segment they belong to, how many of their ends are hidden, and the track's own footprint and
// motion. A per-scan model gives the scan's log posterior odds at its fitting set's prior pi
// (`prior` for the 3-D model, `prior_2d` for the single-plane one):
// boosted trees, l(f) = bias + the sum over the trees of the leaf f reaches (a missing feature
// goes left at every split), or a logistic model,
//   l(f) = bias + sum_k w_k ((f_k - c_k) / s_k)^p_k,
// where a missing feature (a length or width not estimated yet: NaN) adds nothing, i.e. sits at
// its training mean c_k, and an indicator feature says that it is missing;
// one model for 3-D clouds and one for single-plane scans (which measure no heights). The
// track's log-odds L start at logit(pi) of the model that first measures it; each scan moves them by scan_weight a, either adding
// its log-likelihood ratio (accumulation: sum) or moving towards its log posterior odds
// (average, an exponential average: successive scans of one object are strongly correlated, and
// a sum of their ratios turns a run of weak evidence into certainty):
//   sum:     L <- clamp(L + a (l(f) - logit(pi)), -max_log_odds, +max_log_odds),
//   average: L <- clamp(L + a (l(f) - L), ...),
// and the track's vehicle probability is sigmoid(L). It is a vehicle from vehicle_probability on
// and stays one down to keep_probability (VehicleByEvidence). The terms, the priors, the
// accumulation, a and keep_probability are fitted by scripts/fit-vehicle-evidence; nothing here is
// tuned by hand.
#pragma once

#include <array>
#include <cstdint>
#include <limits>
#include <vector>

#include <Eigen/Core>

#include "tracker/core/parameters.h"

namespace vtrack {

class RangeProfile;
struct LadarScan;
struct Track;
struct WorldPoints;

constexpr std::size_t kNumEvidenceFeatures = static_cast<std::size_t>(EvidenceFeature::kCount);
using EvidenceFeatures = std::array<double, kNumEvidenceFeatures>;

// What one scan's returns of a track show, before the track's own state is added.
struct ReturnEvidence {
  bool three_d = false;          // a 3-D cloud (num_rings > 1)
  int num_points = 0;            // [-]
  double range = 0.0;            // [m] of their centroid from the sensor
  double height_max = 0.0;       // [m] above the local ground (3-D; 0 otherwise)
  double height_median = 0.0;    // [m]
  double height_min = 0.0;       // [m]
  double column_top = 0.0;       // [m] median of their cells' highest returns, at most 10 m
  int top_beam = 0;              // [-] of them from the scan's highest beam
  double segment_extent = 0.0;   // [m]
  // [-] Ends of the returns (their extreme bearings from the sensor) that are not free: a nearer
  // return just beyond hides the end, or the object goes on at the same range (a wall seen in a
  // gap between parked cars: 2; a car seen whole: 0). NaN without a range profile.
  double hidden_ends = std::numeric_limits<double>::quiet_NaN();
  double roughness = std::numeric_limits<double>::quiet_NaN();  // [m] SurfaceRoughness
};

// One return in SurfaceRoughness' order: by ring, then by bearing from the sensor.
struct RingReturn {
  std::int32_t ring;
  double bearing;  // [-] monotonic in the bearing (tan of its offset from the centroid's)
  std::int32_t index;
};

// [m] How far a track's returns scatter off a surface: over every three returns idx[a], idx[b],
// idx[c] consecutive in bearing on one ring whose outer two lie within kRoughnessMaxChord of each
// other, the distance (on the ground plane) of the middle one from the chord through the outer
// two; their median. A smooth face (a body panel, a wall) gives the range noise, at any angle of
// incidence; foliage gives the depth its rays travel in (a hedge, a crown). NaN with fewer than
// kRoughnessMinTriplets such triplets. three_d: a 3-D cloud, whose returns of unknown ring (-1)
// are left out (a single-plane scan's returns are all on its one ring, whatever their ring
// field says). centroid: the returns' mean; order, distances: reused buffers.
double SurfaceRoughness(const WorldPoints& pts, const std::vector<std::int32_t>& idx,
                        const Eigen::Vector2d& centroid, const Eigen::Vector2d& sensor_xy,
                        bool three_d, std::vector<RingReturn>* order,
                        std::vector<float>* distances);
constexpr double kRoughnessMaxChord = 1.0;  // [m] farther apart: not one surface between them
constexpr int kRoughnessMinTriplets = 5;    // [-] fewer: no median worth the name

// The ring of a 3-D scan's highest beam: the largest mean elevation over a sample of its returns
// (ring numbers run up or down depending on the sensor and its driver); -1 for a single-plane
// scan or none found.
int TopRing(const LadarScan& scan);

// The returns idx of pts (non-empty), with segment_of[i] the segment index of return i (-1 for
// none) and segment_extent[s] each segment's bounding-box diagonal; top_ring: TopRing of the
// scan; profile: the scan's range profile (null or empty: hidden_ends stays NaN). scratch:
// reused buffer.
// roughness: null leaves ReturnEvidence::roughness NaN (not measured), else its scratch buffer.
// column_top: false leaves ReturnEvidence::column_top 0 (not measured: a model without it).
ReturnEvidence MeasureReturns(const WorldPoints& pts, const std::vector<std::int32_t>& idx,
                              const std::vector<std::int32_t>& segment_of,
                              const std::vector<float>& segment_extent,
                              const Eigen::Vector2d& sensor_xy, bool three_d, int top_ring,
                              const RangeProfile* profile, std::vector<float>* scratch,
                              std::vector<RingReturn>* roughness = nullptr,
                              bool column_top = true);

// Of the returns idx (centroid: their mean), the ends (extreme bearings from sensor_xy) that
// are not free in profile (RangeProfile::FreeBeyond): 0, 1 or 2; 2 if they span no bearing.
int HiddenEnds(const WorldPoints& pts, const std::vector<std::int32_t>& idx,
               const Eigen::Vector2d& centroid, const Eigen::Vector2d& sensor_xy,
               const RangeProfile& profile);

// The full feature vector: the returns' features and the track's state after its update
// (speed [m/s]: of the reported hypothesis' centre).
EvidenceFeatures FeaturesOf(const ReturnEvidence& r, const Track& t, double speed);

// True if the 3-D or the single-plane model has a term on feature k (else it need not be measured).
bool UsesFeature(const EvidenceParams& p, bool three_d, EvidenceFeature k);

// The index of each tree's first node in a list of boosted trees' nodes (EvidenceNode: a tree's
// nodes are contiguous, its root first), in order.
std::vector<std::int32_t> TreeRoots(const std::vector<EvidenceNode>& nodes);

// The roots of both tree models of an EvidenceParams (TreeRoots of trees_3d and trees_2d), found
// once: finding them walks every node (748 in the shipped 3-D model), which per track and scan
// cost more than the 50 walks from root to leaf.
struct EvidenceRoots {
  EvidenceRoots() = default;
  explicit EvidenceRoots(const EvidenceParams& p)
      : three_d(TreeRoots(p.trees_3d)), two_d(TreeRoots(p.trees_2d)) {}
  std::vector<std::int32_t> three_d, two_d;
};

// The scan's logit l(f) under the 3-D or the single-plane model; roots: EvidenceRoots(p).
double ScanLogit(const EvidenceParams& p, bool three_d, const EvidenceFeatures& f,
                 const EvidenceRoots& roots);
// The same, the roots found on each call.
double ScanLogit(const EvidenceParams& p, bool three_d, const EvidenceFeatures& f);

// logit(prior) of the 3-D or the single-plane model (prior, prior_2d): where a track starts, at
// the prior of the model its first evidence comes from (before any: the 3-D one).
double PriorLogOdds(const EvidenceParams& p, bool three_d);

// L after one more scan with logit l of the 3-D or the single-plane model.
double AccumulateLogOdds(const EvidenceParams& p, bool three_d, double log_odds, double scan_logit);

// sigmoid(L).
double VehicleProbability(double log_odds);

// Whether a track is a vehicle by its accumulated log-odds L, with hysteresis: one that was
// (was_vehicle) stays one while sigmoid(L) >= keep_probability, another becomes one when
// sigmoid(L) >= vehicle_probability.
bool VehicleByEvidence(const EvidenceParams& p, bool was_vehicle, double log_odds);

}  // namespace vtrack
