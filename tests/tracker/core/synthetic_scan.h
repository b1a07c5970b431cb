// Synthetic single-plane LADAR returns from one rectangular vehicle, for the fitting tests and
// benchmark: beams from the sensor at a fixed angular step (random phase) are intersected with the
// rectangle's four faces (ray-segment intersection, written here independently of the fitter),
// the range gets Gaussian noise, and outliers are added. Seeded: equal specs and generators give
// equal scans.
#pragma once

#include <Eigen/Core>

#include <algorithm>
#include <cmath>
#include <random>
#include <vector>

#include "base/box.h"

namespace vtrack::testing {

enum class OutlierKind {
  kSpurious,  // a beam that hits the vehicle returns early (dust, rain): 0.5 m or more in front
  kClutter,   // extra points anywhere within 1 m around the vehicle, never inside it
};

struct ScanSpec {
  OrientedBox truth;
  Eigen::Vector2d sensor = Eigen::Vector2d::Zero();  // [m]
  double angular_step_rad = 0.25 * M_PI / 180.0;    // [rad] beam spacing
  double range_sigma_m = 0.03;                       // [m]
  double outlier_fraction = 0.0;                     // [-] share of the returned points
  OutlierKind outlier_kind = OutlierKind::kSpurious;
  // Occlusion: beams in this share of the vehicle's bearing span are dropped, at the
  // counter-clockwise end (occlude_ccw) or the clockwise end.
  double occluded_fraction = 0.0;
  bool occlude_ccw = true;
};

struct SyntheticScan {
  std::vector<float> x, y;
  std::vector<int> face;  // face hit by the beam (box.h numbering), -1 for an outlier
  std::size_t size() const { return x.size(); }
};

// Range along the unit ray from origin to the nearest face of the box, and that face; false if
// the ray misses.
inline bool CastRay(const OrientedBox& box, const Eigen::Vector2d& origin,
                    const Eigen::Vector2d& dir, double* range, int* face) {
  double best = INFINITY;
  for (int f = 0; f < 4; ++f) {
    Eigen::Vector2d a, b;
    box.FaceEndpoints(static_cast<Face>(f), &a, &b);
    // origin + t dir = a + s (b - a), t > 0, s in [0, 1]: Cramer's rule on [dir, a - b].
    const Eigen::Vector2d e = b - a, rhs = a - origin;
    const double det = dir.x() * (-e.y()) - dir.y() * (-e.x());
    if (std::abs(det) < 1e-15) continue;
    const double t = (rhs.x() * (-e.y()) - rhs.y() * (-e.x())) / det;
    const double s = (dir.x() * rhs.y() - dir.y() * rhs.x()) / det;
    if (t > 0.0 && s >= 0.0 && s <= 1.0 && t < best) {
      best = t;
      *face = f;
    }
  }
  *range = best;
  return std::isfinite(best);
}

template <class Rng>
SyntheticScan MakeScan(const ScanSpec& spec, Rng& rng) {
  SyntheticScan out;
  const OrientedBox& box = spec.truth;
  // Bearing span of the box as seen from the sensor, relative to the bearing of its centre.
  const Eigen::Vector2d to_center = box.center - spec.sensor;
  const double bearing0 = std::atan2(to_center.y(), to_center.x());
  double lo = INFINITY, hi = -INFINITY;
  for (const Eigen::Vector2d& c : box.Corners()) {
    const Eigen::Vector2d d = c - spec.sensor;
    const double rel = std::remainder(std::atan2(d.y(), d.x()) - bearing0, 2.0 * M_PI);
    lo = std::min(lo, rel);
    hi = std::max(hi, rel);
  }
  const double cut = spec.occluded_fraction * (hi - lo);
  if (spec.occlude_ccw) hi -= cut; else lo += cut;
  std::uniform_real_distribution<double> unit(0.0, 1.0);
  std::normal_distribution<double> noise(0.0, spec.range_sigma_m);
  const double phase = unit(rng) * spec.angular_step_rad;
  std::vector<Eigen::Vector2d> beams;  // (range, bearing) of the hits
  for (double rel = lo + phase; rel <= hi; rel += spec.angular_step_rad) {
    const double bearing = bearing0 + rel;
    const Eigen::Vector2d dir(std::cos(bearing), std::sin(bearing));
    double range;
    int face = -1;
    if (!CastRay(box, spec.sensor, dir, &range, &face)) continue;
    const Eigen::Vector2d p = spec.sensor + dir * (range + noise(rng));
    out.x.push_back(static_cast<float>(p.x()));
    out.y.push_back(static_cast<float>(p.y()));
    out.face.push_back(face);
  }
  const int hits = static_cast<int>(out.size());
  if (spec.outlier_fraction <= 0.0 || hits == 0) return out;
  if (spec.outlier_kind == OutlierKind::kSpurious) {
    // Replace the returns of a random share of the beams by an early return.
    const int num = static_cast<int>(std::lround(spec.outlier_fraction * hits));
    std::vector<int> order(hits);
    for (int i = 0; i < hits; ++i) order[i] = i;
    std::shuffle(order.begin(), order.end(), rng);
    for (int k = 0; k < num; ++k) {
      const int i = order[k];
      const Eigen::Vector2d p(out.x[i], out.y[i]);
      const Eigen::Vector2d d = p - spec.sensor;
      const double r = d.norm();
      const double early = 0.3 * r + unit(rng) * std::max(0.7 * r - 0.5, 0.0);
      const Eigen::Vector2d q = spec.sensor + d / r * early;
      out.x[i] = static_cast<float>(q.x());
      out.y[i] = static_cast<float>(q.y());
      out.face[i] = -1;
    }
  } else {
    const int num = static_cast<int>(
        std::lround(spec.outlier_fraction / (1.0 - spec.outlier_fraction) * hits));
    const OrientedBox grown{box.center, box.theta, box.length + 2.0, box.width + 2.0};
    std::uniform_real_distribution<double> ux(-0.5 * grown.length, 0.5 * grown.length);
    std::uniform_real_distribution<double> uy(-0.5 * grown.width, 0.5 * grown.width);
    for (int k = 0; k < num;) {
      const Eigen::Vector2d p = grown.ToWorld({ux(rng), uy(rng)});
      if (box.Contains(p)) continue;
      out.x.push_back(static_cast<float>(p.x()));
      out.y.push_back(static_cast<float>(p.y()));
      out.face.push_back(-1);
      ++k;
    }
    // Mix them into the scan order (a segment's order carries no meaning for the fitter).
    std::vector<int> order(out.size());
    for (std::size_t i = 0; i < order.size(); ++i) order[i] = static_cast<int>(i);
    std::shuffle(order.begin(), order.end(), rng);
    SyntheticScan mixed;
    for (int i : order) {
      mixed.x.push_back(out.x[i]);
      mixed.y.push_back(out.y[i]);
      mixed.face.push_back(out.face[i]);
    }
    out = std::move(mixed);
  }
  return out;
}

}  // namespace vtrack::testing
