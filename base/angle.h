// Angle helpers shared by every part of vtrack: one definition of wrapping, used everywhere.
#pragma once

#include <cmath>
#include <numbers>

namespace vtrack {

inline constexpr double kPi = std::numbers::pi;

// Wraps an angle to (-pi, pi]. docs/design.md note 4: every angle difference is wrapped to this range.
inline double WrapToPi(double a) {
  // Most angles are in range already: returned as they are, which is what std::remainder gives
  // for them (the quotient a / 2 pi rounds to 0, pi included: a tie rounds to even), without
  // its cost (a remainder is tens of cycles, and this is called per point in the fits).
  if (a > -kPi && a <= kPi) return a;
  double r = std::remainder(a, 2.0 * kPi);  // in [-pi, pi]
  if (r <= -kPi) r += 2.0 * kPi;
  return r;
}

// Smallest signed difference a - b, wrapped to (-pi, pi].
inline double AngleDiff(double a, double b) { return WrapToPi(a - b); }

inline constexpr double DegToRad(double d) { return d * kPi / 180.0; }
inline constexpr double RadToDeg(double r) { return r * 180.0 / kPi; }

}  // namespace vtrack
