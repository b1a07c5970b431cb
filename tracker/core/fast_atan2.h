// atan2 for per-return loops (the range profile bins every return of a scan by bearing).
//
// Hand-written rather than std::atan2: glibc's atan2 is correctly rounded, with the branches
// and argument checks that takes, and was the largest single cost of binning a KITTI scan.
// Callers that need results identical to std::atan2 use Atan2Approx with its error bound and
// fall back to std::atan2 where the bound leaves the answer open (e.g. near a bin boundary).
#pragma once

#include <cmath>

#include "tracker/core/double2.h"

namespace vtrack {

// Bound on |Atan2Approx(y, x) - atan2(y, x)| [rad] for finite (x, y) != (0, 0): the series
// below is truncated after the u^17 term, |u| <= tan(pi/12), so the truncation error is below
// tan(pi/12)^19 / 19 = 7e-13; rounding adds a few 1e-16. Checked against std::atan2 in
// tests/tracker/core/fast_atan2_test.cc.
inline constexpr double kAtan2ApproxMaxError = 1e-11;

// atan2(y, x) in [-pi, pi] to within kAtan2ApproxMaxError for finite (x, y) != (0, 0), two at
// once (lane by lane; Double2, double2.h). At (0, 0) it returns 0 and it does not distinguish
// signed zeros (atan2(+-0, -1) = +-pi, this gives pi for both). Octant reduction to t = min / max
// in [0, 1], then atan(t) = pi/6 + atan((t - 1/sqrt(3)) / (1 + t/sqrt(3))) for t > tan(pi/12),
// and the Taylor series of atan on |u| <= tan(pi/12). Without branches (both reductions are
// computed and one is selected), so that a loop over returns runs two per step; each lane is
// exactly the value the same steps give one at a time.
inline Double2 Atan2Approx2(Double2 y, Double2 x) {
  constexpr double kPi = 3.14159265358979323846;
  constexpr double kTanPi12 = 0.26794919243112270;  // tan(pi/12) = 2 - sqrt(3)
  constexpr double kInvSqrt3 = 0.57735026918962576;
  const Double2 ax = Abs2(x), ay = Abs2(y);
  const Mask2 x_wide = ax > ay;
  const Double2 hi = x_wide ? ax : ay, lo = x_wide ? ay : ax;
  const Double2 t0 = lo / hi;  // NaN at (0, 0): that lane is 0 at the end
  const Mask2 reduce = t0 > Splat(kTanPi12);
  const Double2 t1 = (t0 - Splat(kInvSqrt3)) / (Splat(1.0) + t0 * Splat(kInvSqrt3));
  const Double2 t = reduce ? t1 : t0;
  const Double2 base = reduce ? Splat(kPi / 6.0) : Splat(0.0);
  const Double2 u2 = t * t;
  // u - u^3/3 + u^5/5 - ... + u^17/17 (Horner in u^2).
  Double2 s = Splat(1.0 / 17.0);
  s = Splat(1.0 / 15.0) - u2 * s;
  s = Splat(1.0 / 13.0) - u2 * s;
  s = Splat(1.0 / 11.0) - u2 * s;
  s = Splat(1.0 / 9.0) - u2 * s;
  s = Splat(1.0 / 7.0) - u2 * s;
  s = Splat(1.0 / 5.0) - u2 * s;
  s = Splat(1.0 / 3.0) - u2 * s;
  s = Splat(1.0) - u2 * s;
  Double2 a = base + t * s;
  a = ay > ax ? Splat(0.5 * kPi) - a : a;
  a = x < Splat(0.0) ? Splat(kPi) - a : a;
  a = y < Splat(0.0) ? -a : a;
  return hi > Splat(0.0) ? a : Splat(0.0);
}

// One at a time: the first lane of Atan2Approx2.
inline double Atan2Approx(double y, double x) { return Atan2Approx2(Splat(y), Splat(x))[0]; }

}  // namespace vtrack
