#include "tracker/core/return_kernels.h"

#include <cmath>
#include <cstring>
#include <limits>

namespace vtrack::internal {

Double2 NearestFaceSq2(Double2 qx, Double2 qy, std::uint8_t visible, double half_l,
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

GateSums SumGate(const Associator::RectFrame& box, double margin, std::uint8_t visible,
                 std::size_t max_outside, const std::int32_t* idx, std::size_t n,
                 const double* x, const double* y) {
  GateSums sums;
  // Two returns per step (an odd last one twice, its second lane unused), then lane by lane in
  // order: the same counts, early stop and sum as one return at a time.
  const Double2 cx = Splat(box.cx), cy = Splat(box.cy);
  const Double2 ax = Splat(box.ax), ay = Splat(box.ay);
  const Double2 gate_l = Splat(box.hl + margin), gate_w = Splat(box.hw + margin);
  for (std::size_t k = 0; k < n; k += 2) {
    const auto i0 = static_cast<std::size_t>(idx[k]);
    const auto i1 = static_cast<std::size_t>(idx[k + 1 < n ? k + 1 : k]);
    const Double2 dx = Double2{x[i0], x[i1]} - cx, dy = Double2{y[i0], y[i1]} - cy;
    const Double2 qx = dx * ax + dy * ay, qy = -dx * ay + dy * ax;  // the box frame
    const Mask2 out = (Abs2(qx) > gate_l) | (Abs2(qy) > gate_w);
    const Double2 d2 = NearestFaceSq2(qx, qy, visible, box.hl, box.hw);
    for (std::size_t lane = 0; lane < 2 && k + lane < n; ++lane) {
      if (out[lane]) {
        sums.stopped = ++sums.outside > max_outside;
        if (sums.stopped) return sums;
        continue;
      }
      ++sums.inside;
      sums.dist_sum += std::sqrt(d2[lane]);
    }
  }
  return sums;
}

int CountInside(const Associator::RectFrame& gate, const std::int32_t* idx, std::size_t n,
                const double* x, const double* y, int limit) {
  const Double2 cx = Splat(gate.cx), cy = Splat(gate.cy), ax = Splat(gate.ax), ay = Splat(gate.ay);
  const Double2 hl = Splat(gate.hl), hw = Splat(gate.hw);
  // Two returns per step (an odd last one twice, its second lane unused): lane by lane the
  // frame's doubles, counted lane by lane up to limit.
  int inside = 0;
  for (std::size_t k = 0; k < n && inside < limit; k += 2) {
    const auto i0 = static_cast<std::size_t>(idx[k]);
    const auto i1 = static_cast<std::size_t>(idx[k + 1 < n ? k + 1 : k]);
    const Double2 dx = Double2{x[i0], x[i1]} - cx;
    const Double2 dy = Double2{y[i0], y[i1]} - cy;
    const Mask2 in = (Abs2(dx * ax + dy * ay) <= hl) & (Abs2(-dx * ay + dy * ax) <= hw);
    inside += in[0] ? 1 : 0;
    if (k + 1 < n && inside < limit) inside += in[1] ? 1 : 0;
  }
  return inside;
}

void KeepNearer(const Associator::RectFrame& f, std::int64_t c, std::size_t n, const double* x,
                const double* y, double* best_d, std::int64_t* best) {
  const Double2 cx = Splat(f.cx), cy = Splat(f.cy), ax = Splat(f.ax), ay = Splat(f.ay);
  const Double2 hl = Splat(f.hl), hw = Splat(f.hw), zero = Splat(0.0);
  const Mask2 claimant = {c, c};
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
  }
}

double EdgeCost(const PerpNoise& noise, const Subset& sub, const Eigen::Vector2d& mid,
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

double CornerCost(const PerpNoise& noise, const Subset& sub, const Eigen::Vector2d& corner,
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
