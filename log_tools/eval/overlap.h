// An axis-aligned image box and KITTI's "a" overlap of two of them: what the devkit's DontCare
// rule tests (the share of a tracker box inside a DontCare box). Used by vtrack-eval and by the
// independent KITTI scorer vtrack-eval-kitti alike.
#pragma once

#include <algorithm>

namespace vtrack::eval {

// [px], u right, v down; u0 <= u1 and v0 <= v1 for a non-empty box.
struct ImageBox {
  double u0 = 0.0, v0 = 0.0, u1 = 0.0, v1 = 0.0;
  double Area() const { return (u1 - u0) * (v1 - v0); }
};

// Area of a's intersection with b over a's own area (0 if a is empty or they are disjoint).
inline double OverlapOfFirst(const ImageBox& a, const ImageBox& b) {
  const double area = a.Area();
  if (!(area > 0.0)) return 0.0;
  const double iw = std::min(a.u1, b.u1) - std::max(a.u0, b.u0);
  const double ih = std::min(a.v1, b.v1) - std::max(a.v0, b.v0);
  return iw > 0.0 && ih > 0.0 ? iw * ih / area : 0.0;
}

}  // namespace vtrack::eval
