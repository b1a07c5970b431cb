// The per-return loops of association (association.cc) and RANSAC (fitting.cc) that run two
// returns per step (double2.h). Each lane performs the operations of the one-return-at-a-time
// code, and counts, early exits and sums go return by return in the original order, so every
// result is bit for bit what a loop over one return at a time gives (no decision changes).
// Internal to vtrack_core (compiled without floating-point contraction, like its callers); in a
// header of their own so that a test can hold them against a scalar loop.
#pragma once

#include <Eigen/Core>

#include <cstddef>
#include <cstdint>

#include "tracker/core/association.h"
#include "tracker/core/double2.h"

namespace vtrack::internal {

// ---- Association

// The distances of a return to a rectangle's faces are compared and summed once per return and
// track, the costliest loops of a KITTI scan: squares are compared instead (sqrt is monotonic,
// so sqrt(min(a, b)) = min(sqrt(a), sqrt(b)) exactly) and std::hypot's care for overflow,
// needless for distances in metres, is left out (exact when one term is 0, within one ulp
// otherwise).
//
// Squared distance of two box-frame points (qx, qy, lane by lane) to the nearest face in visible
// (bit f: Face f, a segment of the boundary of the rectangle of half sizes half_l, half_w about
// the origin), +inf if none; the faces in order, as std::min over them one point at a time.
Double2 NearestFaceSq2(Double2 qx, Double2 qy, std::uint8_t visible, double half_l,
                       double half_w);

// The sums of Associator::PairCost over the returns (x[idx[k]], y[idx[k]]), k < n.
struct GateSums {
  std::size_t inside = 0;   // returns inside the rectangle grown by the margin (the gate)
  std::size_t outside = 0;  // returns outside it
  double dist_sum = 0.0;    // over the inside returns: sqrt(NearestFaceSq2), in return order
  bool stopped = false;     // outside exceeded max_outside (the sums stop at that return)
};
// box: the rectangle's frame and half sizes; a return is outside the gate if |qx| > hl + margin
// or |qy| > hw + margin in that frame.
GateSums SumGate(const Associator::RectFrame& box, double margin, std::uint8_t visible,
                 std::size_t max_outside, const std::int32_t* idx, std::size_t n,
                 const double* x, const double* y);

// The returns (x[idx[k]], y[idx[k]]), k < n, inside the rectangle gate (|qx| <= hl and
// |qy| <= hw in its frame), counted in order up to limit (the count stops there).
int CountInside(const Associator::RectFrame& gate, const std::int32_t* idx, std::size_t n,
                const double* x, const double* y, int limit);

// For returns (x[k], y[k]), k < n (even), the signed distance d to the boundary of rectangle f
// (> 0 outside: the squared distance; <= 0 inside: minus the distance to the nearest side),
// kept with c in best_d[k], best[k] where d < best_d[k]. Two returns per step, without branches.
void KeepNearer(const Associator::RectFrame& f, std::int64_t c, std::size_t n, const double* x,
                const double* y, double* best_d, std::int64_t* best);

// ---- RANSAC

// Floor of a point's distance variance [m^2]: keeps weights finite for a ray along a face.
constexpr double kMinPerpVar = 1e-3 * 1e-3;

// The noise model of a fit's inlier threshold.
struct PerpNoise {
  double sigma2 = 0.0;    // range variance
  double surface2 = 0.0;  // surface variance
  double k2 = 0.0;        // inlier_sigmas^2
  double min_t2 = 0.0;    // squared threshold floor
  // The squared threshold max(k2 * var, min_t2) of a face whose unit normal makes cosine cos_a
  // with the ray, var = max(sigma2 * cos_a^2 + surface2, kMinPerpVar); two cosines, lane by lane.
  Double2 PerpThreshold2(Double2 cos_a) const {
    const Double2 var = Max2(Splat(sigma2) * cos_a * cos_a + Splat(surface2), Splat(kMinPerpVar));
    return Max2(Splat(k2) * var, Splat(min_t2));
  }
};

// The scoring subset of RANSAC: positions and unit rays from the sensor, side by side.
struct Subset {
  const double *x, *y, *rx, *ry;
  int size;
  Eigen::Vector2d P(int i) const { return {x[i], y[i]}; }
};

// The truncated cost of the edge through mid with unit normal nrm over the subset: per point in
// order, r^2 / t where r^2 < t (an inlier, counted in *inliers), else 1 (r: the distance to the
// edge, t: PerpThreshold2 of the normal's cosine with the ray); or any value >= bound once the
// sum reaches bound (its terms are >= 0, so the full sum would too: the sample cannot be the
// best, and the rest of the subset is not scored).
double EdgeCost(const PerpNoise& noise, const Subset& sub, const Eigen::Vector2d& mid,
                const Eigen::Vector2d& nrm, double bound, int* inliers);

// The truncated cost of the corner at `corner` with edge k leaving along u_k (u1 = Perp(u0)):
// per point p in order, with a_k = u_k . (p - corner), the residual of edge 0 is a_1 and that of
// edge 1 is a_0, t_k is PerpThreshold2 of edge k's normal's cosine with the ray, e_0 = a_1^2 / t_0
// and e_1 = a_0^2 / t_1 where below 1, else 1; edge k is not eligible (e_k = 1) where a_k < 0 and
// a_k^2 >= t_k (behind the corner). The term is e_0 if e_0 < 1 and e_0 <= e_1 (counted in *n0),
// else e_1 if e_1 < 1 (in *n1), else 1. Any value >= bound once the sum reaches bound, as
// EdgeCost.
double CornerCost(const PerpNoise& noise, const Subset& sub, const Eigen::Vector2d& corner,
                  const Eigen::Vector2d& u0, const Eigen::Vector2d& u1, double bound, int* n0,
                  int* n1);

}  // namespace vtrack::internal
