// The per-return loops of association (association.cc) and RANSAC (fitting.cc) that run two
// returns per step (double2.h). Each lane performs the operations of the one-return-at-a-time
// code, and counts, early exits and sums go return by return in the original order, so every
// result is bit for bit what a loop over one return at a time gives (no decision changes). With
// them, the test that spares the pair cost's loop where its answer is known from a bounding box
// (BoxOutsideGate). Internal to vtrack_core (compiled without floating-point contraction, like
// its callers); in a header of their own so that a test can hold them against scalar loops.
#pragma once

#include <Eigen/Core>

#include <algorithm>
#include <cmath>
#include <cstddef>
#include <cstdint>
#include <cstring>
#include <limits>
#include <random>
#include <vector>

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
inline Double2 NearestFaceSq2(Double2 qx, Double2 qy, std::uint8_t visible, double half_l,
                       double half_w);

// The sums of Associator::PairCost over the returns (x[idx[k]], y[idx[k]]), k < n.
struct GateSums {
  std::size_t inside = 0;   // returns inside the rectangle grown by the margin (the gate)
  std::size_t outside = 0;  // returns outside it
  double dist_sum = 0.0;    // over the inside returns: sqrt(NearestFaceSq2), in return order
  bool stopped = false;     // outside exceeded max_outside (the sums stop at that return)
};
// box: the rectangle's frame and half sizes; a return is outside the gate if |qx| > hl + margin
// or |qy| > hw + margin in that frame. blocks: null, or the returns' blocks (BoundBlocks), each
// wholly outside the gate (BlockOutsideGate) counted at once, its returns not visited: the same
// sums (blocks of another count than n's are not used).
inline GateSums SumGate(const Associator::RectFrame& box, double margin, std::uint8_t visible,
                 std::size_t max_outside, const std::int32_t* idx, std::size_t n,
                 const double* x, const double* y,
                 const std::vector<Associator::ReturnBlock>* blocks = nullptr);

// True if the axis-aligned box [lo, hi] lies wholly outside the gate (box's rectangle grown by
// margin) along one of the gate's axes: then SumGate finds every return in [lo, hi] outside.
// Exact, not merely conservative: each operation of a return's projection (as SumGate computes
// it: x - cx, times ax or ay, the sum) rounds to nearest, which is monotonic, so the computed
// projection is monotonic in x and in y, and over the box it lies between the computed
// projections of the box's corners. False where a corner's projection is not finite.
inline bool BoxOutsideGate(const Associator::RectFrame& box, double margin,
                           const Eigen::Vector2d& lo, const Eigen::Vector2d& hi);

// The returns (x[k], y[k]), k < n (an odd count padded with one more, whose answer is not
// used), inside the rectangle gate (|qx| <= hl and |qy| <= hw in its frame), counted in order up
// to limit (the count stops there).
inline int CountInside(const Associator::RectFrame& gate, std::size_t n, const double* x,
                       const double* y, int limit);

// For returns (x[k], y[k]), k < n (even), the signed distance d to the boundary of rectangle f
// (> 0 outside: the squared distance; <= 0 inside: minus the distance to the nearest side),
// kept with c in best_d[k], best[k] where d < best_d[k]. Two returns per step, without branches.
// Returns the largest best_d[k], k < n, after the update.
inline double KeepNearer(const Associator::RectFrame& f, std::int64_t c, std::size_t n, const double* x,
                const double* y, double* best_d, std::int64_t* best);

// Blocks of a segment's returns side by side, for the claims and the split of large segments
// (walls, vegetation), whose returns mostly lie far outside most of the gates and rectangles
// that overlap the segment's bounding box: a block's bound spares the loops over its returns
// where their answer is known from it. Block b holds returns [b * kBlockReturns, min((b + 1) *
// kBlockReturns, n)) (even-sized but the last, so that the two-lane loops keep their pairs).
inline constexpr std::size_t kBlockReturns = 64;
// Every return of the block lies within radius of (cx, cy) (padded for rounding, below).
using ReturnBlock = Associator::ReturnBlock;
// The blocks of returns (x[k], y[k]), k < n, or of (x[idx[k]], y[idx[k]]) if idx is given, and
// (lo, hi: if given) the bounding box of them all (+inf, -inf for none).
inline void BoundBlocks(std::size_t n, const double* x, const double* y, const std::int32_t* idx,
                        std::vector<ReturnBlock>* blocks, Eigen::Vector2d* lo = nullptr,
                        Eigen::Vector2d* hi = nullptr);
// True if no return of the block lies inside the gate (|qx| <= hl, |qy| <= hw in its frame, as
// CountInside computes them): the block's centre lies beyond the gate by more than its radius
// along one of the gate's axes, with a margin for rounding (1e-9 of the distances involved,
// far beyond the last bits of either computation). False for anything not finite.
inline bool BlockOutsideGate(const Associator::RectFrame& gate, const ReturnBlock& block);
// A lower bound of the distance KeepNearer computes for any return of the block to rectangle f:
// the signed distance to a rectangle changes by at most the distance moved, so it is at least
// the centre's less the radius (and less a margin for rounding), and KeepNearer's d is a
// non-decreasing function of it (d = s^2 outside, s inside). NaN for anything not finite.
inline double BlockNearestBound(const Associator::RectFrame& f, const ReturnBlock& block);

// ---- RANSAC

// Indices uniform in [lo, hi] (hi - lo < 2^31 - 3) drawn from std::minstd_rand: one engine
// value r - min, redrawn while at or past the largest multiple of the range's size that the
// engine's range holds, divided by that multiple's factor. That is the rejection and scaling of
// libstdc++'s std::uniform_int_distribution for this engine (whose range, 2^31 - 2 values, is
// no power of two), so the draws are the same; written out because the library divides twice
// per draw in 64 bits and out of line, where this divides once in 32 bits with the factor
// computed once per range (the library's draws were 1.5 % of a KITTI scan's instructions). The
// same indices on any standard library.
class IndexDraw {
 public:
  IndexDraw(int lo, int hi)
      : lo_(lo),
        scaling_(kEngineRange / (static_cast<std::uint32_t>(hi - lo) + 1u)),
        past_((static_cast<std::uint32_t>(hi - lo) + 1u) * scaling_) {}
  int operator()(std::minstd_rand& rng) const {
    std::uint32_t r;
    do {
      r = static_cast<std::uint32_t>(rng() - std::minstd_rand::min());
    } while (r >= past_);
    return lo_ + static_cast<int>(r / scaling_);
  }

 private:
  static constexpr std::uint32_t kEngineRange =
      static_cast<std::uint32_t>(std::minstd_rand::max() - std::minstd_rand::min());
  int lo_;
  std::uint32_t scaling_, past_;
};

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
inline double EdgeCost(const PerpNoise& noise, const Subset& sub, const Eigen::Vector2d& mid,
                const Eigen::Vector2d& nrm, double bound, int* inliers);

// The truncated cost of the corner at `corner` with edge k leaving along u_k (u1 = Perp(u0)):
// per point p in order, with a_k = u_k . (p - corner), the residual of edge 0 is a_1 and that of
// edge 1 is a_0, t_k is PerpThreshold2 of edge k's normal's cosine with the ray, e_0 = a_1^2 / t_0
// and e_1 = a_0^2 / t_1 where below 1, else 1; edge k is not eligible (e_k = 1) where a_k < 0 and
// a_k^2 >= t_k (behind the corner). The term is e_0 if e_0 < 1 and e_0 <= e_1 (counted in *n0),
// else e_1 if e_1 < 1 (in *n1), else 1. Any value >= bound once the sum reaches bound, as
// EdgeCost.
inline double CornerCost(const PerpNoise& noise, const Subset& sub, const Eigen::Vector2d& corner,
                  const Eigen::Vector2d& u0, const Eigen::Vector2d& u1, double bound, int* n0,
                  int* n1);

// ---- Definitions: inline, as they run inside their callers' per-pair and per-sample loops
// (out of line, the pair cost took a third more instructions).

inline Double2 NearestFaceSq2(Double2 qx, Double2 qy, std::uint8_t visible, double half_l,
                       double half_w) {
  const Double2 hl = Splat(half_l), hw = Splat(half_w), zero = Splat(0.0);
  const Double2 off_x = Max2(Abs2(qx) - hl, zero), off_y = Max2(Abs2(qy) - hw, zero);
  const auto sq = [](Double2 a, Double2 b) { return a * a + b * b; };
  static_assert(static_cast<int>(Face::kFront) == 0 && static_cast<int>(Face::kLeft) == 1 &&
                static_cast<int>(Face::kRear) == 2 && static_cast<int>(Face::kRight) == 3);
  const Double2 face[4] = {sq(qx - hl, off_y), sq(qy - hw, off_x), sq(qx + hl, off_y),
                           sq(qy + hw, off_x)};
  Double2 d2 = Splat(std::numeric_limits<double>::infinity());
  for (int f = 0; f < 4; ++f) {
    if (visible & (1u << f)) d2 = face[f] < d2 ? face[f] : d2;  // std::min(d2, face)
  }
  return d2;
}

inline void SumGateRange(const Associator::RectFrame& box, double margin, std::uint8_t visible,
                         std::size_t max_outside, const std::int32_t* idx, std::size_t begin,
                         std::size_t n, const double* x, const double* y, GateSums* sums_out);

inline GateSums SumGate(const Associator::RectFrame& box, double margin, std::uint8_t visible,
                 std::size_t max_outside, const std::int32_t* idx, std::size_t n,
                 const double* x, const double* y,
                 const std::vector<Associator::ReturnBlock>* blocks) {
  GateSums sums;
  // Blocks not of these n returns (none given, or another count): the returns one by one.
  if (blocks == nullptr || blocks->size() != (n + kBlockReturns - 1) / kBlockReturns) {
    SumGateRange(box, margin, visible, max_outside, idx, 0, n, x, y, &sums);
    return sums;
  }
  const Associator::RectFrame gate{box.cx, box.cy, box.ax, box.ay, box.hl + margin, box.hw + margin};
  for (std::size_t b = 0; b < blocks->size(); ++b) {
    const std::size_t begin = b * kBlockReturns, end = std::min(n, begin + kBlockReturns);
    if (BlockOutsideGate(gate, (*blocks)[b])) {
      // Every return outside: the count, or the stop at the return that passes max_outside.
      sums.outside += end - begin;
      sums.stopped = sums.outside > max_outside;
      if (sums.stopped) {
        sums.outside = max_outside + 1;
        return sums;
      }
      continue;
    }
    SumGateRange(box, margin, visible, max_outside, idx, begin, end, x, y, &sums);
    if (sums.stopped) return sums;
  }
  return sums;
}

// SumGate's sums continued over the returns idx[k], begin <= k < n.
inline void SumGateRange(const Associator::RectFrame& box, double margin, std::uint8_t visible,
                         std::size_t max_outside, const std::int32_t* idx, std::size_t begin,
                         std::size_t n, const double* x, const double* y, GateSums* sums_out) {
  GateSums& sums = *sums_out;
  // Two returns per step (an odd last one twice, its second lane unused), then lane by lane in
  // order: the same counts, early stop and sum as one return at a time.
  const Double2 cx = Splat(box.cx), cy = Splat(box.cy);
  const Double2 ax = Splat(box.ax), ay = Splat(box.ay);
  const Double2 gate_l = Splat(box.hl + margin), gate_w = Splat(box.hw + margin);
  for (std::size_t k = begin; k < n; k += 2) {
    const auto i0 = static_cast<std::size_t>(idx[k]);
    const auto i1 = static_cast<std::size_t>(idx[k + 1 < n ? k + 1 : k]);
    const Double2 dx = Double2{x[i0], x[i1]} - cx, dy = Double2{y[i0], y[i1]} - cy;
    const Double2 qx = dx * ax + dy * ay, qy = -dx * ay + dy * ax;  // the box frame
    const Mask2 out = (Abs2(qx) > gate_l) | (Abs2(qy) > gate_w);
    const Double2 d2 = NearestFaceSq2(qx, qy, visible, box.hl, box.hw);
    for (std::size_t lane = 0; lane < 2 && k + lane < n; ++lane) {
      if (out[lane]) {
        sums.stopped = ++sums.outside > max_outside;
        if (sums.stopped) return;
        continue;
      }
      ++sums.inside;
      sums.dist_sum += std::sqrt(d2[lane]);
    }
  }
}

inline bool BoxOutsideGate(const Associator::RectFrame& box, double margin,
                           const Eigen::Vector2d& lo, const Eigen::Vector2d& hi) {
  constexpr double kInf = std::numeric_limits<double>::infinity();
  double u_lo = kInf, u_hi = -kInf, v_lo = kInf, v_hi = -kInf;
  bool finite = true;
  for (const double x : {lo.x(), hi.x()}) {
    for (const double y : {lo.y(), hi.y()}) {
      const double dx = x - box.cx, dy = y - box.cy;
      const double u = dx * box.ax + dy * box.ay, v = -dx * box.ay + dy * box.ax;
      finite = finite && std::isfinite(u) && std::isfinite(v);
      u_lo = std::min(u_lo, u);
      u_hi = std::max(u_hi, u);
      v_lo = std::min(v_lo, v);
      v_hi = std::max(v_hi, v);
    }
  }
  const double gate_l = box.hl + margin, gate_w = box.hw + margin;  // as SumGate's
  return finite && (u_lo > gate_l || u_hi < -gate_l || v_lo > gate_w || v_hi < -gate_w);
}

inline int CountInside(const Associator::RectFrame& gate, std::size_t n, const double* x,
                       const double* y, int limit) {
  const Double2 cx = Splat(gate.cx), cy = Splat(gate.cy), ax = Splat(gate.ax), ay = Splat(gate.ay);
  const Double2 hl = Splat(gate.hl), hw = Splat(gate.hw);
  // Two returns per step (the padding in the second lane of an odd last step, unused): lane by
  // lane the frame's doubles, counted lane by lane up to limit.
  int inside = 0;
  for (std::size_t k = 0; k < n && inside < limit; k += 2) {
    const Double2 dx = Load2(x + k) - cx;
    const Double2 dy = Load2(y + k) - cy;
    const Mask2 in = (Abs2(dx * ax + dy * ay) <= hl) & (Abs2(-dx * ay + dy * ax) <= hw);
    inside += in[0] ? 1 : 0;
    if (k + 1 < n && inside < limit) inside += in[1] ? 1 : 0;
  }
  return inside;
}

inline double KeepNearer(const Associator::RectFrame& f, std::int64_t c, std::size_t n, const double* x,
                const double* y, double* best_d, std::int64_t* best) {
  const Double2 cx = Splat(f.cx), cy = Splat(f.cy), ax = Splat(f.ax), ay = Splat(f.ay);
  const Double2 hl = Splat(f.hl), hw = Splat(f.hw), zero = Splat(0.0);
  const Mask2 claimant = {c, c};
  Double2 largest = Splat(-std::numeric_limits<double>::infinity());
  for (std::size_t k = 0; k < n; k += 2) {
    const Double2 px = Load2(x + k), py = Load2(y + k), old = Load2(best_d + k);
    Mask2 old_best;
    std::memcpy(&old_best, best + k, sizeof old_best);
    const Double2 dx = px - cx, dy = py - cy;  // the rectangle's frame
    const Double2 qx = dx * ax + dy * ay, qy = -dx * ay + dy * ax;
    const Double2 ex = Abs2(qx) - hl, ey = Abs2(qy) - hw;
    const Double2 ox = Max2(ex, zero), oy = Max2(ey, zero);
    const Double2 d = ((ex > zero) | (ey > zero)) ? ox * ox + oy * oy : Max2(ex, ey);
    const Mask2 nearer = d < old;
    const Double2 new_d = nearer ? d : old;
    const Mask2 new_best = nearer ? claimant : old_best;
    std::memcpy(best_d + k, &new_d, sizeof new_d);
    std::memcpy(best + k, &new_best, sizeof new_best);
    largest = Max2(largest, new_d);
  }
  return std::max(largest[0], largest[1]);
}

inline void BoundBlocks(std::size_t n, const double* x, const double* y, const std::int32_t* idx,
                        std::vector<ReturnBlock>* blocks, Eigen::Vector2d* lo,
                        Eigen::Vector2d* hi) {
  blocks->clear();
  constexpr double kInf = std::numeric_limits<double>::infinity();
  Eigen::Vector2d all_lo(kInf, kInf), all_hi(-kInf, -kInf);
  const auto at = [idx](std::size_t k) { return idx != nullptr ? static_cast<std::size_t>(idx[k]) : k; };
  for (std::size_t begin = 0; begin < n; begin += kBlockReturns) {
    const std::size_t end = std::min(n, begin + kBlockReturns);
    double x_lo = x[at(begin)], x_hi = x_lo, y_lo = y[at(begin)], y_hi = y_lo;
    for (std::size_t k = begin + 1; k < end; ++k) {
      const std::size_t i = at(k);
      x_lo = std::min(x_lo, x[i]);
      x_hi = std::max(x_hi, x[i]);
      y_lo = std::min(y_lo, y[i]);
      y_hi = std::max(y_hi, y[i]);
    }
    const double cx = 0.5 * (x_lo + x_hi), cy = 0.5 * (y_lo + y_hi);
    // Half the diagonal, padded for the rounding of the centre (1e-9 of the coordinates).
    const double scale = 1.0 + std::max({std::abs(x_lo), std::abs(x_hi), std::abs(y_lo), std::abs(y_hi)});
    const double radius = 0.5 * std::sqrt((x_hi - x_lo) * (x_hi - x_lo) + (y_hi - y_lo) * (y_hi - y_lo)) +
                          1e-9 * scale;
    blocks->push_back({cx, cy, radius});
    all_lo = all_lo.cwiseMin(Eigen::Vector2d(x_lo, y_lo));
    all_hi = all_hi.cwiseMax(Eigen::Vector2d(x_hi, y_hi));
  }
  if (lo != nullptr) *lo = all_lo;
  if (hi != nullptr) *hi = all_hi;
}

inline bool BlockOutsideGate(const Associator::RectFrame& gate, const ReturnBlock& block) {
  const double dx = block.cx - gate.cx, dy = block.cy - gate.cy;
  const double qx = dx * gate.ax + dy * gate.ay, qy = -dx * gate.ay + dy * gate.ax;
  const double pad = block.radius + 1e-9 * (1.0 + std::abs(dx) + std::abs(dy) + gate.hl + gate.hw);
  return std::abs(qx) - pad > gate.hl || std::abs(qy) - pad > gate.hw;  // NaN: false
}

inline double BlockNearestBound(const Associator::RectFrame& f, const ReturnBlock& block) {
  const double dx = block.cx - f.cx, dy = block.cy - f.cy;
  const double qx = dx * f.ax + dy * f.ay, qy = -dx * f.ay + dy * f.ax;
  const double ex = std::abs(qx) - f.hl, ey = std::abs(qy) - f.hw;
  const double s = ex > 0.0 || ey > 0.0
                       ? std::sqrt(std::max(ex, 0.0) * std::max(ex, 0.0) + std::max(ey, 0.0) * std::max(ey, 0.0))
                       : std::max(ex, ey);
  const double lb = s - block.radius - 1e-9 * (1.0 + std::abs(dx) + std::abs(dy) + f.hl + f.hw);
  if (!std::isfinite(lb)) return std::numeric_limits<double>::quiet_NaN();
  // d's own rounding (a relative few 1e-16 of a square): 1e-9 of it below.
  return lb > 0.0 ? lb * lb * (1.0 - 1e-9) : lb;
}

inline double EdgeCost(const PerpNoise& noise, const Subset& sub, const Eigen::Vector2d& mid,
                const Eigen::Vector2d& nrm, double bound, int* inliers) {
  double cost = 0.0;
  // Two points per step (an odd last one twice, its second lane unused), lane by lane the same
  // doubles as one at a time; then summed and stopped at the bound one by one.
  const Double2 mx = Splat(mid.x()), my = Splat(mid.y()), nx = Splat(nrm.x()), ny = Splat(nrm.y());
  for (int s = 0; s < sub.size && cost < bound; s += 2) {
    const int s1 = s + 1 < sub.size ? s + 1 : s;
    const Double2 r = nx * (Double2{sub.x[s], sub.x[s1]} - mx) + ny * (Double2{sub.y[s], sub.y[s1]} - my);
    const Double2 ca = nx * Double2{sub.rx[s], sub.rx[s1]} + ny * Double2{sub.ry[s], sub.ry[s1]};
    // r^2 / t is only used below 1 (NoDivisionAbove in fitting.cc; both lanes divided at once).
    const Double2 r2 = r * r, t = noise.PerpThreshold2(ca);
    const Double2 e = r2 < t ? r2 / t : Splat(1.0);
    for (int lane = 0; lane < 2 && s + lane < sub.size && (lane == 0 || cost < bound); ++lane) {
      if (e[lane] < 1.0) {
        cost += e[lane];
        ++*inliers;
      } else {
        cost += 1.0;
      }
    }
  }
  return cost;
}

inline double CornerCost(const PerpNoise& noise, const Subset& sub, const Eigen::Vector2d& corner,
                  const Eigen::Vector2d& u0, const Eigen::Vector2d& u1, double bound, int* n0,
                  int* n1) {
  double cost = 0.0;
  *n0 = *n1 = 0;
  // Two points per step (an odd last one twice, its second lane unused), lane by lane the same
  // doubles as one at a time; then classified, summed and stopped at the bound one by one.
  const Double2 cx = Splat(corner.x()), cy = Splat(corner.y()), zero = Splat(0.0), one = Splat(1.0);
  const Double2 u0x = Splat(u0.x()), u0y = Splat(u0.y()), u1x = Splat(u1.x()), u1y = Splat(u1.y());
  for (int s = 0; s < sub.size && cost < bound; s += 2) {
    const int s1 = s + 1 < sub.size ? s + 1 : s;
    const Double2 vx = Double2{sub.x[s], sub.x[s1]} - cx, vy = Double2{sub.y[s], sub.y[s1]} - cy;
    const Double2 rx = {sub.rx[s], sub.rx[s1]}, ry = {sub.ry[s], sub.ry[s1]};
    const Double2 a0 = u0x * vx + u0y * vy;  // along edge 0 = residual of edge 1
    const Double2 a1 = u1x * vx + u1y * vy;  // along edge 1 = residual of edge 0
    const Double2 t0 = noise.PerpThreshold2(u1x * rx + u1y * ry);
    const Double2 t1 = noise.PerpThreshold2(u0x * rx + u0y * ry);
    // e0 and e1 are only used below 1 (e0 <= e1 only once e0 < 1; for finite returns and rays,
    // where neither is NaN): NoDivisionAbove in fitting.cc (both lanes divided at once; a
    // quotient not chosen is not used).
    const Double2 a0s = a0 * a0, a1s = a1 * a1;
    const Double2 e0 = (((a0 >= zero) | (a0s < t0)) & (a1s < t0)) ? a1s / t0 : one;
    const Double2 e1 = (((a1 >= zero) | (a1s < t1)) & (a0s < t1)) ? a0s / t1 : one;
    for (int lane = 0; lane < 2 && s + lane < sub.size && (lane == 0 || cost < bound); ++lane) {
      if (e0[lane] < 1.0 && e0[lane] <= e1[lane]) {
        cost += e0[lane];
        ++*n0;
      } else if (e1[lane] < 1.0) {
        cost += e1[lane];
        ++*n1;
      } else {
        cost += 1.0;
      }
    }
  }
  return cost;
}

}  // namespace vtrack::internal
