#include "tracker/core/grazing_pieces.h"

#include <algorithm>
#include <cmath>
#include <vector>

#include "base/angle.h"

namespace vtrack {
namespace {

struct Piece {
  double bearing;   // [rad] of the centroid seen from the sensor
  double range;     // [m]
  std::int32_t seg;
};

struct Pair {
  double dist;
  std::int32_t a, b;  // indices into the segments
};

// A range below which the bearing window is not widened further (a piece at the sensor).
constexpr double kMinWindowRange = 0.5;  // [m]

// The small segments, sorted by bearing.
std::vector<Piece> SmallPieces(const std::vector<Segment>& segs, const Eigen::Vector2d& sensor_xy,
                               double max_piece) {
  std::vector<Piece> pieces;
  for (std::size_t k = 0; k < segs.size(); ++k) {
    const Segment& g = segs[k];
    if ((g.max - g.min).norm() >= max_piece) continue;
    const Eigen::Vector2d d = g.centroid - sensor_xy;
    pieces.push_back({std::atan2(d.y(), d.x()), d.norm(), static_cast<std::int32_t>(k)});
  }
  std::sort(pieces.begin(), pieces.end(), [](const Piece& a, const Piece& b) {
    return a.bearing < b.bearing || (a.bearing == b.bearing && a.seg < b.seg);
  });
  return pieces;
}

// Pairs of pieces on one line along the ray, nearest first. For B to lie within max_deg of A's
// ray at a distance <= gap, its bearing differs by at most asin(gap * sin(deg) / range(B)),
// range(B) >= range(A) - gap: pieces sorted by bearing are scanned within that window (both ways
// round the circle).
std::vector<Pair> CandidatePairs(const std::vector<Segment>& segs, const std::vector<Piece>& pieces,
                                 const Eigen::Vector2d& sensor_xy, const GrazingJoinParams& params) {
  const std::size_t n = pieces.size();
  const double sin_max = std::sin(DegToRad(params.max_deg));
  const double gap = params.max_gap;
  std::vector<Pair> pairs;
  for (std::size_t i = 0; i < n; ++i) {
    const double r_min = std::max(kMinWindowRange, pieces[i].range - gap);
    const double window = std::asin(std::min(1.0, gap * sin_max / r_min)) + 1e-9;
    for (std::size_t step = 1; step < n; ++step) {
      const Piece& q = pieces[(i + step) % n];
      double db = q.bearing - pieces[i].bearing;
      if (db < 0.0) db += 2.0 * kPi;
      if (db > window) break;
      const Eigen::Vector2d ca = segs[static_cast<std::size_t>(pieces[i].seg)].centroid;
      const Eigen::Vector2d cb = segs[static_cast<std::size_t>(q.seg)].centroid;
      const Eigen::Vector2d ab = cb - ca;
      const double dist = ab.norm();
      if (dist > gap || dist <= 0.0) continue;
      const Eigen::Vector2d ray = (0.5 * (ca + cb) - sensor_xy).normalized();
      if (std::abs(ray.x() * ab.y() - ray.y() * ab.x()) > sin_max * dist) continue;
      pairs.push_back({dist, pieces[i].seg, q.seg});
    }
  }
  std::sort(pairs.begin(), pairs.end(), [](const Pair& a, const Pair& b) {
    return a.dist < b.dist || (a.dist == b.dist && (a.a < b.a || (a.a == b.a && a.b < b.b)));
  });
  return pairs;
}

// Union-find over segments with the bounding box of each set at its root (the lowest index).
struct JoinedSets {
  std::vector<std::int32_t> parent;
  std::vector<Eigen::Vector2d> lo, hi;

  explicit JoinedSets(const std::vector<Segment>& segs)
      : parent(segs.size()), lo(segs.size()), hi(segs.size()) {
    for (std::size_t k = 0; k < segs.size(); ++k) {
      parent[k] = static_cast<std::int32_t>(k);
      lo[k] = segs[k].min;
      hi[k] = segs[k].max;
    }
  }
  std::int32_t Find(std::int32_t k) {
    while (parent[static_cast<std::size_t>(k)] != k) {
      parent[static_cast<std::size_t>(k)] = parent[static_cast<std::size_t>(parent[static_cast<std::size_t>(k)])];
      k = parent[static_cast<std::size_t>(k)];
    }
    return k;
  }
  // Joins the sets of a and b unless the joined bounding box exceeds max_extent.
  bool Join(std::int32_t a, std::int32_t b, double max_extent) {
    a = Find(a);
    b = Find(b);
    if (a == b) return false;
    const Eigen::Vector2d l = lo[static_cast<std::size_t>(a)].cwiseMin(lo[static_cast<std::size_t>(b)]);
    const Eigen::Vector2d h = hi[static_cast<std::size_t>(a)].cwiseMax(hi[static_cast<std::size_t>(b)]);
    if ((h - l).norm() > max_extent) return false;
    if (b < a) std::swap(a, b);
    parent[static_cast<std::size_t>(b)] = a;
    lo[static_cast<std::size_t>(a)] = l;
    hi[static_cast<std::size_t>(a)] = h;
    return true;
  }
};

// Rebuilds *segments: each root segment followed by the returns of the segments joined to it.
void Rebuild(const WorldPoints& pts, JoinedSets* sets, Segments* segments) {
  auto& segs = segments->segments;
  std::vector<std::vector<std::int32_t>> members(segs.size());
  for (std::size_t k = 0; k < segs.size(); ++k) {
    members[static_cast<std::size_t>(sets->Find(static_cast<std::int32_t>(k)))].push_back(static_cast<std::int32_t>(k));
  }
  std::vector<std::int32_t> point;
  point.reserve(segments->point.size());
  std::vector<Segment> out;
  out.reserve(segs.size());
  for (std::size_t k = 0; k < segs.size(); ++k) {
    if (members[k].empty()) continue;  // joined to another root
    Segment g;
    g.begin = static_cast<std::int32_t>(point.size());
    Eigen::Vector2d sum = Eigen::Vector2d::Zero();
    for (const std::int32_t m : members[k]) {
      const Segment& src = segs[static_cast<std::size_t>(m)];
      for (std::int32_t i = src.begin; i < src.end; ++i) {
        const std::int32_t p = segments->point[static_cast<std::size_t>(i)];
        point.push_back(p);
        sum += Eigen::Vector2d(pts.x[static_cast<std::size_t>(p)], pts.y[static_cast<std::size_t>(p)]);
      }
    }
    g.end = static_cast<std::int32_t>(point.size());
    g.min = sets->lo[k];
    g.max = sets->hi[k];
    g.centroid = sum / static_cast<double>(g.size());
    out.push_back(g);
  }
  segments->point.swap(point);
  segs.swap(out);
}

}  // namespace

int JoinGrazingPieces(const WorldPoints& pts, const Eigen::Vector2d& sensor_xy,
                      const GrazingJoinParams& params, Segments* segments) {
  const auto& segs = segments->segments;
  if (params.max_piece <= 0.0 || segs.size() < 2) return 0;
  const std::vector<Piece> pieces = SmallPieces(segs, sensor_xy, params.max_piece);
  if (pieces.size() < 2) return 0;
  const std::vector<Pair> pairs = CandidatePairs(segs, pieces, sensor_xy, params);
  if (pairs.empty()) return 0;
  JoinedSets sets(segs);
  int joins = 0;
  for (const Pair& pr : pairs) joins += sets.Join(pr.a, pr.b, params.max_extent) ? 1 : 0;
  if (joins == 0) return 0;
  Rebuild(pts, &sets, segments);
  return joins;
}

}  // namespace vtrack
