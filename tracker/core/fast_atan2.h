// atan2 for per-return loops (the range profile bins every return of a scan by bearing).
//
// Hand-written rather than std::atan2: glibc's atan2 is correctly rounded, with the branches
// and argument checks that takes, and was the largest single cost of binning a KITTI scan.
// Callers that need results identical to std::atan2 use Atan2Approx with its error bound and
// fall back to std::atan2 where the bound leaves the answer open (e.g. near a bin boundary).
#pragma once

#include <cmath>

namespace vtrack {

// Bound on |Atan2Approx(y, x) - atan2(y, x)| [rad] for finite (x, y) != (0, 0): the series
// below is truncated after the u^17 term, |u| <= tan(pi/12), so the truncation error is below
// tan(pi/12)^19 / 19 = 7e-13; rounding adds a few 1e-16. Checked against std::atan2 in
// tests/tracker/core/fast_atan2_test.cc.
inline constexpr double kAtan2ApproxMaxError = 1e-11;

// atan2(y, x) in [-pi, pi] to within kAtan2ApproxMaxError for finite (x, y) != (0, 0). At
// (0, 0) it returns 0 and it does not distinguish signed zeros (atan2(+-0, -1) = +-pi, this
// gives pi for both). Octant reduction to t = min / max in [0, 1], then
// atan(t) = pi/6 + atan((t - 1/sqrt(3)) / (1 + t/sqrt(3))) for t > tan(pi/12), and the Taylor
// series of atan on |u| <= tan(pi/12).
inline double Atan2Approx(double y, double x) {
  constexpr double kPi = 3.14159265358979323846;
  constexpr double kTanPi12 = 0.26794919243112270;  // tan(pi/12) = 2 - sqrt(3)
  constexpr double kInvSqrt3 = 0.57735026918962576;
  const double ax = std::abs(x), ay = std::abs(y);
  const double hi = ax > ay ? ax : ay, lo = ax > ay ? ay : ax;
  if (!(hi > 0.0)) return 0.0;
  double t = lo / hi;
  double base = 0.0;
  if (t > kTanPi12) {
    t = (t - kInvSqrt3) / (1.0 + t * kInvSqrt3);
    base = kPi / 6.0;
  }
  const double u2 = t * t;
  // u - u^3/3 + u^5/5 - ... + u^17/17 (Horner in u^2).
  double s = 1.0 / 17.0;
  s = 1.0 / 15.0 - u2 * s;
  s = 1.0 / 13.0 - u2 * s;
  s = 1.0 / 11.0 - u2 * s;
  s = 1.0 / 9.0 - u2 * s;
  s = 1.0 / 7.0 - u2 * s;
  s = 1.0 / 5.0 - u2 * s;
  s = 1.0 / 3.0 - u2 * s;
  s = 1.0 - u2 * s;
  double a = base + t * s;
  if (ay > ax) a = 0.5 * kPi - a;
  if (x < 0.0) a = kPi - a;
  return y < 0.0 ? -a : a;
}

}  // namespace vtrack
