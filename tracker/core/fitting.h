// Robust edge / corner fitting of one segment's LADAR points (paper Section 2.4): the
// measurement z = (x, y, theta) of the vehicle centre (Eq. 14, 17) and its covariance R (Eq. 18).
//
// Pipeline of SegmentFitter::Fit:
//  1. RANSAC on at most `max_scoring_points` points of the segment (a seeded random subset):
//     edge hypotheses from 2 points, corner hypotheses from 3 points (each triple gives the three
//     perpendicular corners of Figure 3, b-d), every hypothesis filtered by visibility (Eq. 15,
//     s = min_slant_deg) and scored with the truncated quadratic (MSAC) loss. The number of
//     iterations adapts to the best inlier fractions found (confidence `ransac_confidence`).
//  2. On all points: inliers are the points within inlier_sigmas * sigma_perp of an edge (for a
//     corner, of the edge's ray leaving the corner; a point near both goes to the nearer);
//     inliers separated from the main run of their edge by a gap larger than max_inlier_gap_m and
//     max_gap_spacings median spacings are dropped, and so are those beyond a gap larger than
//     max_inlier_gap_m that the scan's range profile sees through (FitRequest::profile).
//     Then `gauss_newton_iterations` (paper: one) weighted Gauss-Newton steps on Eq. (16), and
//     the inliers are classified again.
//  3. Choice: the corner if each of its edges holds >= min_edge_inliers and
//     >= min_second_edge_fraction of its inliers and the refined corner still passes Eq. (15);
//     otherwise the best edge. A candidate is rejected if it explains < min_inlier_fraction of
//     the points, or if its vehicle rectangle contains < FitRequest::min_inside_fraction of the
//     segment's points (then the edge is tried after a rejected corner).
//  4. z (Eq. 17) and R (Eq. 18), below.
//
// Noise model. The range noise sigma of a return moves it along its ray, so its distance from a
// face has std sigma_perp = sqrt(sigma^2 cos^2(a) + surface_std^2), a = angle between the ray and
// the face normal (surface_std covers non-planar bodies and beam-angle error). Gauss-Newton and R
// weight each point by 1 / sigma_perp^2. With equal weights this is exactly Eq. (18),
// R = sigma^2 (J^T J)^-1; without the weights, faces seen at a slant would get an R several times
// too large. If the weighted residuals are significantly larger than this model predicts
// (chi^2 / dof above 1 + variance_factor_sigmas * sqrt(2 / dof)), R is scaled by chi^2 / dof
// (the a-posteriori variance factor), so a vehicle that is not a perfect rectangle does not give
// an overconfident z.
//
// z and R at the vehicle centre (docs/design.md note 5). The residual of an inlier p on the face with unit
// normal n is r = n . (p - c) - h, with c the centre and h the half-dimension, so its Jacobian
// row in (x, y, theta) is [-n_x, -n_y, n x (p - c)] (the lever arm about the centre: Eq. 18 with
// the Hessian evaluated at the centre). For a corner the shape places the centre:
// c = corner + u_len * length / 2 + u_wid * width / 2, u_* the edge directions into the body.
// For a single edge the centre lies half the perpendicular dimension behind the face, and its
// position along the face is not observable from the residuals (J^T J is singular). It is taken
// from the inlier extent instead: the centre projects onto the middle of the extent, with a
// finite variance along the face,
//   sigma_along^2 = (d1^2 + d2^2) / 48 + sigma^2 (sin^2 a1 + sin^2 a2) / 4          (full view)
//                   + ((D - E)^2 + sigma_D^2) / 4                                 (partial view)
// d1, d2 = spacing of the two outermost inliers at either end (the true end lies uniformly within
// one spacing of the last return; ends are corrected outwards by half a spacing), a1, a2 their
// incidence angles, D the face's dimension from the shape estimate and E the corrected extent:
// when part of the face is hidden the centre may sit anywhere that keeps the seen part on the
// face, and (D - E)^2 / 4 is the largest variance such a position can have. This enters as one
// more row of the information matrix, e = [t_x, t_y, (perp t) . (c - m)] / sigma_along (t the
// face direction, m the extent's middle: moving the centre along the face or turning the body
// about it both move the face's middle), and R = (J^T W J + e^T e)^-1.
// The shape estimate's own uncertainty (length_std_m, width_std_m) adds (std / 2)^2 to the
// centre's variance along each body axis.
//
// Which vehicle corner or face (docs/design.md note 6). Orientation from a fit is known modulo 90 deg:
// the candidate headings are phi + k * 90 deg.
//  - With a predicted heading (existing track): theta is the candidate nearest to it (tau of
//    Eq. 17 is the multiple of 90 deg that brings phi nearest the prediction).
//  - Without (new object): the axis comes from the extents - for a corner the longer edge is the
//    length axis; a single edge is a side (length) face if its extent exceeds the width estimate
//    by side_face_min_excess_m or is seen at an incidence (its normal against the ray) beyond
//    side_face_min_incidence_deg, else the front or rear. The sign of the heading cannot be
//    observed: theta is taken in (-pi/2, pi/2]. The tracker resolves both ambiguities over time
//    (motion, and the two VASMs 90 deg apart, docs/design.md, section 4.13).
// The faces then follow from the outward normals: a fitted face's outward normal points to the
// sensor side; for a corner the body lies between the two edges. Faces are numbered as in box.h.
// The predicted position is deliberately not used: z depends on the prediction only through the
// discrete choice of tau, so the filter does not count its own prediction as a measurement.
//
// Shape. The dimensions used to place the centre are the shape estimate if shape_known, else the
// larger of the estimate (a default size) and the observed extent. An extent counts as a full
// view (both ends of that face seen) when the shape is known and the extent reaches the estimate
// within partial_view_sigmas standard deviations of the extent's own measurement noise; without a
// known shape nothing can tell a hidden end from a real one, so it is never flagged full.
//
// Cost: allocation-free after the first calls (the fitter reuses its scratch and the result's
// flag vector); O(iterations * max_scoring_points + N log N) per fit. Measured in
// tests/bench/fitting_bench.cc.
#pragma once

#include <Eigen/Core>

#include <array>
#include <cstdint>
#include <limits>
#include <optional>
#include <span>
#include <string>
#include <vector>

#include "base/box.h"
#include "tracker/core/parameters.h"

namespace vtrack {

class RangeProfile;

enum class FitKind : std::int8_t { kNone = 0, kEdge = 1, kCorner = 2 };  // = track_debug FIT_*

enum class FitFailure : std::int8_t {
  kNone = 0,
  kTooFewPoints,        // fewer than FitParams::min_points
  kNonFinitePoint,      // a coordinate is NaN or infinite (FitResult::bad_point names it)
  kNoConsensus,         // no visible edge with min_edge_inliers inliers
  kNotVisible,          // the refined edge violates Eq. (15) (face seen at a grazing angle)
  kTooFewInliers,       // inliers < min_inlier_fraction of the points
  kTooFewPointsInside,  // rectangle holds < FitRequest::min_inside_fraction of the points
};
const char* ToString(FitFailure failure);

struct FitRequest {
  // The segment's points, world frame, ego-motion compensated (parallel arrays, same size).
  std::span<const float> x;  // [m]
  std::span<const float> y;  // [m]
  Eigen::Vector2d sensor_xy = Eigen::Vector2d::Zero();  // [m] sensor origin, world frame
  // Current shape estimate. If !shape_known pass a default vehicle size and its spread.
  double length_m = 4.5;      // [m] along the heading, > 0
  double width_m = 1.8;       // [m] across, > 0
  double length_std_m = 0.0;  // [m] 1-sigma uncertainty of length_m, >= 0
  double width_std_m = 0.0;   // [m] 1-sigma uncertainty of width_m, >= 0
  bool shape_known = false;
  std::optional<double> predicted_theta;  // [rad] track's predicted heading; empty: new object
  // [m] track's predicted centre, in the frame of x and y; empty: new object. A single face seen
  // in part is placed along itself at this centre if the seen part lies on the predicted face;
  // otherwise, and if empty, at the seen part's middle.
  std::optional<Eigen::Vector2d> predicted_center;
  double range_sigma_m = 0.03;            // [m] LADAR range noise (1 sigma), > 0
  double min_inside_fraction = 0.0;       // [-] in [0, 1]: share of points inside the rectangle
  std::uint64_t seed = 0;                 // RANSAC sampling; equal requests give equal results
  // The scan's range profile (3-D scans; nullptr: none), in the world frame, and the world
  // position of the origin of x and y. A gap along a face that the sensor sees through
  // (RangeProfile::SeenThrough) ends the face's run of inliers.
  const RangeProfile* profile = nullptr;
  Eigen::Vector2d profile_offset = Eigen::Vector2d::Zero();  // [m]
};

struct FittedEdge {
  Eigen::Vector2d start = Eigen::Vector2d::Zero();  // [m] world; the corner for corner fits
  Eigen::Vector2d end = Eigen::Vector2d::Zero();    // [m] world; outermost kept inlier
  Face face = Face::kFront;                         // which face of the vehicle it is
  int num_inliers = 0;                              // [-]
};

struct FitResult {
  static constexpr std::int8_t kOutlier = -1;
  static constexpr double kNaN = std::numeric_limits<double>::quiet_NaN();

  FitKind kind = FitKind::kNone;
  FitFailure failure = FitFailure::kNone;  // why kind == kNone
  int bad_point = -1;                      // index of the offending point (kNonFinitePoint)

  // Fitted geometry. Edge 0 runs along phi, edge 1 (corners only) along phi + 90 deg.
  Eigen::Vector2d corner = Eigen::Vector2d::Constant(kNaN);  // [m] world; NaN for an edge fit
  double phi = kNaN;                                         // [rad] direction of edge 0
  int num_edges = 0;
  std::array<FittedEdge, 2> edges;
  std::vector<std::int8_t> point_edge;  // per input point: 0, 1 (edge) or kOutlier
  // Per input point: 1 if its residual entered Eq. (16) and (18). Inliers whose face is
  // ambiguous (near a corner, within the threshold of both edges or of a perpendicular face
  // seen at a grazing angle) count for the extents but not here.
  std::vector<std::uint8_t> point_in_fit;

  // Measurement of the vehicle centre (Eq. 17) and its covariance (Eq. 18), world frame.
  Eigen::Vector3d z = Eigen::Vector3d::Constant(kNaN);  // [m, m, rad], theta in (-pi, pi]
  Eigen::Matrix3d R = Eigen::Matrix3d::Constant(kNaN);  // [m^2, m rad, rad^2]
  double length_used_m = kNaN;  // [m] rectangle dimensions used to place the centre
  double width_used_m = kNaN;

  // Observed dimensions from the inlier extents (ends corrected by half a point spacing), NaN if
  // no fitted edge runs along that axis; full_view: both ends of that face were seen.
  double observed_length_m = kNaN;
  double observed_width_m = kNaN;
  double observed_length_std_m = kNaN;  // [m] their 1-sigma uncertainty (end model, see above)
  double observed_width_std_m = kNaN;
  bool length_full_view = false;
  bool width_full_view = false;

  int num_inliers = 0;          // [-] over both edges
  double inside_fraction = kNaN; // [-] share of the points inside the (margin-grown) rectangle
  double variance_factor = kNaN; // [-] factor applied to the Eq. (18) part of R (1 = none)
  double rms_residual_m = kNaN;  // [m] root mean square inlier distance to the fitted edges
};

// Fits segments. Holds only the validated parameters and scratch memory: the result of Fit
// depends on the request alone. One instance per thread.
class SegmentFitter {
 public:
  // Throws std::invalid_argument with the Validate() message if params are invalid.
  explicit SegmentFitter(const FitParams& params = FitParams());

  // Throws std::invalid_argument if the request breaks its contract (x and y of different
  // sizes, non-finite sensor position, shape or sigma, fraction outside [0, 1]); bad point data
  // gives kind == kNone with the failure. result's buffers are reused across calls.
  void Fit(const FitRequest& request, FitResult* result);
  FitResult Fit(const FitRequest& request);

  const FitParams& params() const { return params_; }

 private:
  FitParams params_;
  std::vector<double> sx_, sy_, srx_, sry_;  // scoring subset: local coordinates, ray directions
  std::vector<double> px_, py_, rx_, ry_;    // all points: local coordinates, ray directions
  std::vector<double> proj_;                 // projections of one edge's inliers (sorting)
  std::vector<double> gaps_;                 // their spacings
  std::vector<std::int8_t> mask_;            // single edge: points marked ambiguous or excluded

  // RANSAC's best edge and corner for the last request. They depend on its returns, sensor,
  // range noise and seed only, not on the heading, shape or centre it predicts, and the
  // hypotheses of one track are fitted to the same returns with the same seed: they draw their
  // samples once. The key is compared in full, bit for bit (every return), so a hit gives
  // exactly the models that drawing again would.
  struct Consensus {
    std::vector<float> x, y;
    Eigen::Vector2d sensor_xy = Eigen::Vector2d::Zero();
    double range_sigma_m = 0.0;
    std::uint64_t seed = 0;
    bool valid = false;
    int num_edges[2] = {0, 0};  // [0] the edge, [1] the corner; 0: RANSAC found none
    Eigen::Vector2d c[2] = {Eigen::Vector2d::Zero(), Eigen::Vector2d::Zero()};
    double phi[2] = {0.0, 0.0};
    bool Matches(const FitRequest& req) const;
  };
  Consensus consensus_;
};

// The three perpendicular corners defined by three points (Figure 3 b-d): for each point k, the
// corner is the foot of the perpendicular from p_k onto the line through the other two; edge a
// runs along that line, edge b from the corner towards p_k. If the two points lie on both sides
// of the foot (a "T", not an L) edge a leaves the corner both ways (a_both_ways).
struct CornerHypothesis {
  Eigen::Vector2d corner = Eigen::Vector2d::Zero();
  Eigen::Vector2d dir_a = Eigen::Vector2d::Zero();  // unit direction of edge a from the corner
  Eigen::Vector2d dir_b = Eigen::Vector2d::Zero();  // unit direction of edge b from the corner
  bool a_both_ways = false;
  bool degenerate = true;  // coincident or collinear points: no corner
};
std::array<CornerHypothesis, 3> CornerHypothesesFromPoints(const Eigen::Vector2d& p0,
                                                           const Eigen::Vector2d& p1,
                                                           const Eigen::Vector2d& p2);

// Eq. (15): both edges are visible iff |theta_c - theta_a| < 90 deg - s and
// |theta_c - theta_b| < 90 deg - s, theta_c the viewing direction (sensor to corner) and
// theta_a, theta_b the directions of the edges leaving the corner; differences wrapped to
// (-pi, pi]. An edge that leaves both ways (a "T") fails one of the two. False if degenerate or
// the sensor sits on the corner.
bool CornerVisible(const CornerHypothesis& h, const Eigen::Vector2d& sensor_xy,
                   double min_slant_rad);

// Eq. (15) in its per-face form for one straight edge through `point` along `dir`: the face
// normal on the sensor's side points back at the sensor within 90 deg - s.
bool EdgeVisible(const Eigen::Vector2d& point, const Eigen::Vector2d& dir,
                 const Eigen::Vector2d& sensor_xy, double min_slant_rad);

}  // namespace vtrack
