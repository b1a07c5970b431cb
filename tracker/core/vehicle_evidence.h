// Vehicle evidence of a track: how likely it is a vehicle rather than a wall, a hedge, a tree
// or a pole, from what the scans measured of it, accumulated over its life.
//
// Per scan that gives the track returns, a feature vector f (EvidenceFeature, parameters.h):
// the returns' height profile above the local ground (3-D clouds), their number and range, the
// overhang above them, the extent of the segment they belong to, and the track's own footprint
// and motion. A logistic model gives the scan's log posterior odds at the fitting set's prior pi,
//   l(f) = bias + sum_k w_k ((f_k - c_k) / s_k)^p_k,
// one model for 3-D clouds and one for single-plane scans (which measure no heights). The
// track's log-odds start at logit(pi) and add each scan's log-likelihood ratio, discounted by
// scan_weight a (successive scans of one object are strongly correlated; a is fitted):
//   L <- clamp(L + a (l(f) - logit(pi)), -max_log_odds, +max_log_odds),
// and the track's vehicle probability is sigmoid(L). The terms, pi and a are fitted by
// scripts/fit-vehicle-evidence; nothing here is tuned by hand.
#pragma once

#include <array>
#include <cstdint>
#include <vector>

#include <Eigen/Core>

#include "tracker/core/parameters.h"

namespace vtrack {

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
  double overhang = 0.0;         // [-] share with returns above max_height in their cell
  double segment_extent = 0.0;   // [m]
};

// The returns idx of pts (non-empty), with segment_of[i] the segment index of return i (-1 for
// none) and segment_extent[s] each segment's bounding-box diagonal. scratch: reused buffer.
ReturnEvidence MeasureReturns(const WorldPoints& pts, const std::vector<std::int32_t>& idx,
                              const std::vector<std::int32_t>& segment_of,
                              const std::vector<float>& segment_extent,
                              const Eigen::Vector2d& sensor_xy, bool three_d,
                              std::vector<float>* scratch);

// The full feature vector: the returns' features and the track's state after its update
// (speed [m/s]: of the reported hypothesis' centre).
EvidenceFeatures FeaturesOf(const ReturnEvidence& r, const Track& t, double speed);

// The scan's logit l(f) under the 3-D or the single-plane model.
double ScanLogit(const EvidenceParams& p, bool three_d, const EvidenceFeatures& f);

// logit(prior): where every track starts.
double PriorLogOdds(const EvidenceParams& p);

// L after one more scan with logit l.
double AccumulateLogOdds(const EvidenceParams& p, double log_odds, double scan_logit);

// sigmoid(L).
double VehicleProbability(double log_odds);

}  // namespace vtrack
