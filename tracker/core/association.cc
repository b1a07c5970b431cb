#include "tracker/core/association.h"

#include <algorithm>
#include <cmath>
#include <limits>
#include <numeric>
#include <sstream>

#include "tracker/core/angle.h"

namespace vtrack {
namespace {

constexpr double kInf = std::numeric_limits<double>::infinity();

std::string Bad(const char* key, double value, const char* constraint) {
  std::ostringstream os;
  os << "association." << key << " = " << value << ": " << constraint;
  return os.str();
}

// The per-return distances below are compared and summed once per return and track, the
// costliest loops of a KITTI scan: squares are compared instead (sqrt is monotonic, so
// sqrt(min(a, b)) = min(sqrt(a), sqrt(b)) exactly) and std::hypot's care for overflow, needless
// for distances in metres, is left out (exact when one term is 0, within one ulp otherwise).
inline double Sq(double a, double b) { return a * a + b * b; }

// Squared distance of a box-frame point to face f (a segment of the rectangle boundary).
double FaceDistanceSq(const Eigen::Vector2d& q, Face f, double half_l, double half_w) {
  switch (f) {
    case Face::kFront: return Sq(q.x() - half_l, std::max(std::abs(q.y()) - half_w, 0.0));
    case Face::kRear: return Sq(q.x() + half_l, std::max(std::abs(q.y()) - half_w, 0.0));
    case Face::kLeft: return Sq(q.y() - half_w, std::max(std::abs(q.x()) - half_l, 0.0));
    case Face::kRight: return Sq(q.y() + half_w, std::max(std::abs(q.x()) - half_l, 0.0));
  }
  return kInf;
}

// OrientedBox::ToBoxFrame with cos/sin computed once per box, not per point.
struct BoxFrame {
  explicit BoxFrame(const OrientedBox& b)
      : c(b.center), ax(std::cos(b.theta)), ay(std::sin(b.theta)) {}
  Eigen::Vector2d To(double x, double y) const {
    const double dx = x - c.x(), dy = y - c.y();
    return {dx * ax + dy * ay, -dx * ay + dy * ax};
  }
  Eigen::Vector2d c;
  double ax, ay;
};

bool Overlap(const Eigen::Vector2d& amin, const Eigen::Vector2d& amax, const Eigen::Vector2d& bmin,
             const Eigen::Vector2d& bmax) {
  return amin.x() <= bmax.x() && bmin.x() <= amax.x() && amin.y() <= bmax.y() &&
         bmin.y() <= amax.y();
}

void GateBounds(const OrientedBox& box, double margin, Eigen::Vector2d* lo, Eigen::Vector2d* hi) {
  OrientedBox grown = box;
  grown.length += 2.0 * margin;
  grown.width += 2.0 * margin;
  *lo = Eigen::Vector2d::Constant(kInf);
  *hi = -*lo;
  for (const auto& c : grown.Corners()) {
    *lo = lo->cwiseMin(c);
    *hi = hi->cwiseMax(c);
  }
}

struct UnionFind {
  std::vector<int> parent;
  explicit UnionFind(int n) : parent(static_cast<std::size_t>(n)) {
    std::iota(parent.begin(), parent.end(), 0);
  }
  int Find(int a) {
    while (parent[static_cast<std::size_t>(a)] != a) {
      parent[static_cast<std::size_t>(a)] =
          parent[static_cast<std::size_t>(parent[static_cast<std::size_t>(a)])];
      a = parent[static_cast<std::size_t>(a)];
    }
    return a;
  }
  void Join(int a, int b) { parent[static_cast<std::size_t>(Find(a))] = Find(b); }
};

}  // namespace

bool AssociationParams::Validate(std::string* error) const {
  const std::string e = FirstProblem();
  if (!e.empty() && error) *error = e;
  return e.empty();
}

std::string AssociationParams::FirstProblem() const {
  if (!(gate_margin >= 0.0)) return Bad("gate_margin", gate_margin, "must be >= 0");
  if (!(gate_sigma >= 0.0)) return Bad("gate_sigma", gate_sigma, "must be >= 0");
  if (!(max_gate_margin >= gate_margin))
    return Bad("max_gate_margin", max_gate_margin, "must be >= gate_margin");
  if (!(min_inside_fraction > 0.0 && min_inside_fraction <= 1.0))
    return Bad("min_inside_fraction", min_inside_fraction, "must be in (0, 1]");
  if (!(outside_penalty >= 0.0)) return Bad("outside_penalty", outside_penalty, "must be >= 0");
  if (!(miss_cost > 0.0)) return Bad("miss_cost", miss_cost, "must be > 0");
  if (!(mover_max_length >= 0.0)) return Bad("mover_max_length", mover_max_length, "must be >= 0");
  if (!(mover_column_width >= 0.0))
    return Bad("mover_column_width", mover_column_width, "must be >= 0");
  if (!(merge_fraction > 0.0 && merge_fraction <= 1.0))
    return Bad("merge_fraction", merge_fraction, "must be in (0, 1]");
  if (!(ignore_max_extent >= 0.0 && ignore_max_extent <= 10.0))
    return Bad("ignore_max_extent", ignore_max_extent, "must be in [0, 10] m");
  if (split_min_points < 1) return Bad("split_min_points", split_min_points, "must be >= 1");
  if (!(min_slant_deg >= 0.0 && min_slant_deg < 90.0))
    return Bad("min_slant_deg", min_slant_deg, "must be in [0, 90)");
  if (!(join_max_piece >= 0.0 && join_max_piece <= 10.0))
    return Bad("join_max_piece", join_max_piece, "must be in [0, 10] m");
  if (!(join_max_gap > 0.0 && join_max_gap <= 20.0))
    return Bad("join_max_gap", join_max_gap, "must be in (0, 20] m");
  if (!(join_max_deg >= 0.0 && join_max_deg < 90.0))
    return Bad("join_max_deg", join_max_deg, "must be in [0, 90) deg");
  if (!(join_max_extent >= join_max_piece && join_max_extent <= 50.0))
    return Bad("join_max_extent", join_max_extent, "must be in [join_max_piece, 50] m");
  return {};
}

int JoinGrazingPieces(const WorldPoints& pts, const Eigen::Vector2d& sensor_xy,
                      const AssociationParams& params, Segments* segments) {
  auto& segs = segments->segments;
  if (params.join_max_piece <= 0.0 || segs.size() < 2) return 0;
  struct Piece {
    double bearing;   // [rad] of the centroid seen from the sensor
    double range;     // [m]
    std::int32_t seg;
  };
  std::vector<Piece> pieces;
  for (std::size_t k = 0; k < segs.size(); ++k) {
    const Segment& g = segs[k];
    if ((g.max - g.min).norm() >= params.join_max_piece) continue;
    const Eigen::Vector2d d = g.centroid - sensor_xy;
    pieces.push_back({std::atan2(d.y(), d.x()), d.norm(), static_cast<std::int32_t>(k)});
  }
  const std::size_t n = pieces.size();
  if (n < 2) return 0;
  std::sort(pieces.begin(), pieces.end(), [](const Piece& a, const Piece& b) {
    return a.bearing < b.bearing || (a.bearing == b.bearing && a.seg < b.seg);
  });
  // Candidate pairs. For B to lie within join_max_deg of A's ray at a distance <= gap, its
  // bearing differs by at most asin(gap * sin(deg) / range(B)), range(B) >= range(A) - gap:
  // pieces sorted by bearing are scanned within that window (both ways round the circle).
  const double sin_max = std::sin(DegToRad(params.join_max_deg));
  const double gap = params.join_max_gap;
  struct Pair {
    double dist;
    std::int32_t a, b;  // indices into segs
  };
  std::vector<Pair> pairs;
  for (std::size_t i = 0; i < n; ++i) {
    const double r_min = std::max(0.5, pieces[i].range - gap);
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
  if (pairs.empty()) return 0;
  std::sort(pairs.begin(), pairs.end(), [](const Pair& a, const Pair& b) {
    return a.dist < b.dist || (a.dist == b.dist && (a.a < b.a || (a.a == b.a && a.b < b.b)));
  });
  // Union-find over segments with the bounding box of each set at its root.
  std::vector<std::int32_t> parent(segs.size());
  for (std::size_t k = 0; k < segs.size(); ++k) parent[k] = static_cast<std::int32_t>(k);
  std::vector<Eigen::Vector2d> lo(segs.size()), hi(segs.size());
  for (std::size_t k = 0; k < segs.size(); ++k) {
    lo[k] = segs[k].min;
    hi[k] = segs[k].max;
  }
  auto find = [&](std::int32_t k) {
    while (parent[static_cast<std::size_t>(k)] != k) {
      parent[static_cast<std::size_t>(k)] = parent[static_cast<std::size_t>(parent[static_cast<std::size_t>(k)])];
      k = parent[static_cast<std::size_t>(k)];
    }
    return k;
  };
  int joins = 0;
  for (const Pair& pr : pairs) {
    std::int32_t a = find(pr.a), b = find(pr.b);
    if (a == b) continue;
    const Eigen::Vector2d l = lo[static_cast<std::size_t>(a)].cwiseMin(lo[static_cast<std::size_t>(b)]);
    const Eigen::Vector2d h = hi[static_cast<std::size_t>(a)].cwiseMax(hi[static_cast<std::size_t>(b)]);
    if ((h - l).norm() > params.join_max_extent) continue;
    if (b < a) std::swap(a, b);
    parent[static_cast<std::size_t>(b)] = a;  // the lowest segment index is the root
    lo[static_cast<std::size_t>(a)] = l;
    hi[static_cast<std::size_t>(a)] = h;
    ++joins;
  }
  if (joins == 0) return 0;
  // Rebuild: each root segment followed by the returns of the segments joined to it.
  std::vector<std::vector<std::int32_t>> members(segs.size());
  for (std::size_t k = 0; k < segs.size(); ++k) {
    members[static_cast<std::size_t>(find(static_cast<std::int32_t>(k)))].push_back(static_cast<std::int32_t>(k));
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
    g.min = lo[k];
    g.max = hi[k];
    g.centroid = sum / static_cast<double>(g.size());
    out.push_back(g);
  }
  segments->point.swap(point);
  segs.swap(out);
  return joins;
}

std::vector<int> SolveAssignment(const std::vector<double>& cost, int rows, int cols) {
  // Shortest augmenting paths with row/column potentials (Kuhn-Munkres, Jonker-Volgenant
  // style); 1-based arrays with column 0 as the virtual start.
  std::vector<double> u(static_cast<std::size_t>(rows) + 1, 0.0);
  std::vector<double> v(static_cast<std::size_t>(cols) + 1, 0.0);
  std::vector<int> p(static_cast<std::size_t>(cols) + 1, 0);    // row matched to column
  std::vector<int> way(static_cast<std::size_t>(cols) + 1, 0);
  std::vector<double> minv(static_cast<std::size_t>(cols) + 1);
  std::vector<char> used(static_cast<std::size_t>(cols) + 1);
  auto a = [&](int r, int c) {
    return cost[static_cast<std::size_t>(r - 1) * static_cast<std::size_t>(cols) +
                static_cast<std::size_t>(c - 1)];
  };
  for (int i = 1; i <= rows; ++i) {
    p[0] = i;
    int j0 = 0;
    std::fill(minv.begin(), minv.end(), kInf);
    std::fill(used.begin(), used.end(), 0);
    do {
      used[static_cast<std::size_t>(j0)] = 1;
      const int i0 = p[static_cast<std::size_t>(j0)];
      double delta = kInf;
      int j1 = 0;
      for (int j = 1; j <= cols; ++j) {
        if (used[static_cast<std::size_t>(j)]) continue;
        const double cur = a(i0, j) - u[static_cast<std::size_t>(i0)] - v[static_cast<std::size_t>(j)];
        if (cur < minv[static_cast<std::size_t>(j)]) {
          minv[static_cast<std::size_t>(j)] = cur;
          way[static_cast<std::size_t>(j)] = j0;
        }
        if (minv[static_cast<std::size_t>(j)] < delta) {
          delta = minv[static_cast<std::size_t>(j)];
          j1 = j;
        }
      }
      for (int j = 0; j <= cols; ++j) {
        if (used[static_cast<std::size_t>(j)]) {
          u[static_cast<std::size_t>(p[static_cast<std::size_t>(j)])] += delta;
          v[static_cast<std::size_t>(j)] -= delta;
        } else {
          minv[static_cast<std::size_t>(j)] -= delta;
        }
      }
      j0 = j1;
    } while (p[static_cast<std::size_t>(j0)] != 0);
    do {
      const int j1 = way[static_cast<std::size_t>(j0)];
      p[static_cast<std::size_t>(j0)] = p[static_cast<std::size_t>(j1)];
      j0 = j1;
    } while (j0 != 0);
  }
  std::vector<int> assign(static_cast<std::size_t>(rows), -1);
  for (int j = 1; j <= cols; ++j) {
    if (p[static_cast<std::size_t>(j)] > 0) assign[static_cast<std::size_t>(p[static_cast<std::size_t>(j)] - 1)] = j - 1;
  }
  return assign;
}

Associator::Associator(const AssociationParams& params) : params_(params) {}

double Associator::GateMargin(const PredictedObject& t) const {
  return std::min(params_.max_gate_margin,
                  params_.gate_margin + params_.gate_sigma * std::max(0.0, t.position_std));
}

void Associator::SortedBoxes::Build(const std::vector<Eigen::Vector2d>& box_lo,
                                     const std::vector<Eigen::Vector2d>& box_hi,
                                     const std::vector<char>& use) {
  order.clear();
  max_width = 0.0;
  for (std::size_t k = 0; k < box_lo.size(); ++k) {
    if (!use.empty() && !use[k]) continue;
    order.push_back(static_cast<std::int32_t>(k));
    max_width = std::max(max_width, box_hi[k].x() - box_lo[k].x());
  }
  std::sort(order.begin(), order.end(), [&](std::int32_t a, std::int32_t b) {
    const double xa = box_lo[static_cast<std::size_t>(a)].x(), xb = box_lo[static_cast<std::size_t>(b)].x();
    return xa < xb || (xa == xb && a < b);
  });
  lo_x.resize(order.size());
  lo.resize(order.size());
  hi.resize(order.size());
  id.resize(order.size());
  for (std::size_t k = 0; k < order.size(); ++k) {
    const auto o = static_cast<std::size_t>(order[k]);
    id[k] = order[k];
    lo[k] = box_lo[o];
    hi[k] = box_hi[o];
    lo_x[k] = box_lo[o].x();
  }
}

void Associator::SortedBoxes::Overlapping(const Eigen::Vector2d& q_lo, const Eigen::Vector2d& q_hi,
                                          std::vector<std::int32_t>* ids) const {
  ids->clear();
  // A box overlapping [q_lo, q_hi] in x has lo_x <= q_hi.x and hi_x >= q_lo.x, hence lo_x >=
  // q_lo.x - max_width (1 m of slack for the rounding of the widths); each is then tested exactly.
  const auto b = std::lower_bound(lo_x.begin(), lo_x.end(), q_lo.x() - max_width - 1.0);
  const auto e = std::upper_bound(b, lo_x.end(), q_hi.x());
  for (auto k = static_cast<std::size_t>(b - lo_x.begin()); k < static_cast<std::size_t>(e - lo_x.begin()); ++k) {
    if (Overlap(q_lo, q_hi, lo[k], hi[k])) ids->push_back(id[k]);
  }
  std::sort(ids->begin(), ids->end());  // the caller's order
}

double Associator::PairCost(const PredictedObject& t, double margin, std::uint8_t visible,
                            const Part& part, const WorldPoints& pts,
                            double* inside_fraction) const {
  *inside_fraction = 0.0;
  const std::size_t n = part.points.size();
  if (n == 0) return kInf;
  // The fewest returns inside the gate for a candidate (inside >= 1 and inside / n >=
  // min_inside_fraction, evaluated as below); once more returns than n - need lie outside, the
  // part is no candidate whatever the rest, and the loop stops (large segments, facades, overlap
  // the gates of many tracks with few of their returns inside).
  const double nd = static_cast<double>(n);
  std::size_t need = static_cast<std::size_t>(std::max(1.0, std::ceil(params_.min_inside_fraction * nd)));
  while (need > 1 && static_cast<double>(need - 1) / nd >= params_.min_inside_fraction) --need;
  while (need <= n && static_cast<double>(need) / nd < params_.min_inside_fraction) ++need;
  if (need > n) return kInf;
  const std::size_t max_outside = n - need;
  const double hl = 0.5 * t.box.length, hw = 0.5 * t.box.width;
  std::size_t inside = 0, outside = 0;
  double dist_sum = 0.0;
  const BoxFrame frame(t.box);
  for (const std::int32_t i : part.points) {
    const auto iu = static_cast<std::size_t>(i);
    const Eigen::Vector2d q = frame.To(pts.x[iu], pts.y[iu]);
    if (std::abs(q.x()) > hl + margin || std::abs(q.y()) > hw + margin) {
      if (++outside > max_outside) return kInf;
      continue;
    }
    ++inside;
    double d2 = kInf;
    for (int f = 0; f < 4; ++f) {
      if (visible & (1u << f)) d2 = std::min(d2, FaceDistanceSq(q, static_cast<Face>(f), hl, hw));
    }
    dist_sum += std::sqrt(d2);
  }
  const double frac = static_cast<double>(inside) / nd;
  *inside_fraction = frac;
  if (inside == 0 || frac < params_.min_inside_fraction) return kInf;
  return dist_sum / static_cast<double>(inside) + params_.outside_penalty * (1.0 - frac);
}

void Associator::BuildParts(const std::vector<PredictedObject>& tracks, const WorldPoints& pts,
                            const Segments& segments) {
  num_parts_ = 0;
  // Part buffers are kept from scan to scan, but not beyond twice what this scan's segments
  // hold: otherwise every slot would keep the largest part it ever held (RSS creeping up over a
  // long run although nothing leaks).
  std::size_t retained = 0;
  for (const Part& part : parts_) retained += part.points.capacity();
  if (retained > 2 * segments.point.size() + 4096) parts_.clear();
  const std::size_t nt = tracks.size();
  // Per track once per scan: gate bounds, frame (cos/sin) and grown half sizes. Only established
  // tracks claim, so only their gates are indexed.
  std::vector<Eigen::Vector2d> lo(nt), hi(nt);
  std::vector<char> established(nt, 0);
  std::vector<BoxFrame> frames;
  frames.reserve(nt);
  std::vector<double> gate_hl(nt), gate_hw(nt);
  for (std::size_t j = 0; j < nt; ++j) {
    const double margin = GateMargin(tracks[j]);
    GateBounds(tracks[j].box, margin, &lo[j], &hi[j]);
    established[j] = tracks[j].established ? 1 : 0;
    frames.emplace_back(tracks[j].box);
    gate_hl[j] = 0.5 * tracks[j].box.length + margin;
    gate_hw[j] = 0.5 * tracks[j].box.width + margin;
  }
  sorted_.Build(lo, hi, established);
  std::vector<std::size_t> claim;
  for (const Segment& s : segments.segments) {
    // Established tracks with enough of this segment's returns inside their gate, in track order.
    claim.clear();
    sorted_.Overlapping(s.min, s.max, &candidates_);
    for (const std::int32_t jj : candidates_) {
      const auto j = static_cast<std::size_t>(jj);
      const double hl = gate_hl[j], hw = gate_hw[j];
      const BoxFrame& frame = frames[j];
      int inside = 0;  // counted up to split_min_points: all the claim needs
      for (std::int32_t k = s.begin; k < s.end && inside < params_.split_min_points; ++k) {
        const auto i = static_cast<std::size_t>(segments.point[static_cast<std::size_t>(k)]);
        const Eigen::Vector2d q = frame.To(pts.x[i], pts.y[i]);
        if (std::abs(q.x()) <= hl && std::abs(q.y()) <= hw) ++inside;
      }
      if (inside >= params_.split_min_points) claim.push_back(j);
    }
    const std::size_t first = num_parts_;
    const std::size_t num_parts = claim.size() >= 2 ? claim.size() : 1;
    if (parts_.size() < first + num_parts) parts_.resize(first + num_parts);
    for (std::size_t q = first; q < first + num_parts; ++q) parts_[q].points.clear();
    num_parts_ = first + num_parts;
    const auto seg_begin = segments.point.begin() + s.begin;
    const auto seg_end = segments.point.begin() + s.end;
    if (num_parts == 1) {
      parts_[first].points.assign(seg_begin, seg_end);
    } else {
      // Each return goes to the claimant it is nearest to, ordered by the signed distance to
      // the rectangle boundary (> 0 outside, <= 0 inside): the distance inside, its square
      // outside. Most segments of a KITTI scan are claimed by two or more tracks (clutter
      // tracks on vegetation and walls overlap): the claimants' frames side by side.
      claimants_.clear();
      for (const std::size_t j : claim) {
        claimants_.push_back({frames[j].c.x(), frames[j].c.y(), frames[j].ax, frames[j].ay,
                              0.5 * tracks[j].box.length, 0.5 * tracks[j].box.width});
      }
      const Claimant* const cl = claimants_.data();
      const std::size_t nc = claimants_.size();
      for (auto it = seg_begin; it != seg_end; ++it) {
        const std::int32_t i = *it;
        const auto iu = static_cast<std::size_t>(i);
        const double px = pts.x[iu], py = pts.y[iu];
        std::size_t best = 0;
        double best_d = kInf;
        for (std::size_t c = 0; c < nc; ++c) {
          const double dx = px - cl[c].cx, dy = py - cl[c].cy;
          const double qx = dx * cl[c].ax + dy * cl[c].ay, qy = -dx * cl[c].ay + dy * cl[c].ax;
          const double ex = std::abs(qx) - cl[c].hl, ey = std::abs(qy) - cl[c].hw;
          const double ox = std::max(ex, 0.0), oy = std::max(ey, 0.0);
          const double d = ex > 0.0 || ey > 0.0 ? ox * ox + oy * oy : std::max(ex, ey);
          if (d < best_d) {
            best_d = d;
            best = c;
          }
        }
        parts_[first + best].points.push_back(i);
      }
    }
    // Bounding boxes; drop pieces of a split that are too small to fit (their buffers are kept
    // for reuse: swapped, not moved, to the end).
    std::size_t w = first;
    for (std::size_t q = first; q < num_parts_; ++q) {
      Part& part = parts_[q];
      if (num_parts > 1 && static_cast<int>(part.points.size()) < params_.split_min_points) continue;
      part.min = Eigen::Vector2d::Constant(kInf);
      part.max = -part.min;
      for (const std::int32_t i : part.points) {
        const Eigen::Vector2d p(pts.x[static_cast<std::size_t>(i)], pts.y[static_cast<std::size_t>(i)]);
        part.min = part.min.cwiseMin(p);
        part.max = part.max.cwiseMax(p);
      }
      if (w != q) {
        std::swap(parts_[w].points, part.points);
        parts_[w].min = part.min;
        parts_[w].max = part.max;
      }
      ++w;
    }
    num_parts_ = w;
  }
}

bool Associator::JoinMover(const std::vector<PredictedObject>& tracks, const WorldPoints& pts,
                           const Eigen::Vector2d& sensor_xy, const std::vector<std::int32_t>& piece,
                           AssociationResult* out, std::vector<char>* own_valid) const {
  if (piece.empty() || !(params_.mover_max_length > 0.0)) return false;
  // Across the ray: a side seen edge-on is a line along the ray; a following car shows its front.
  Eigen::Vector2d mean = Eigen::Vector2d::Zero();
  for (const std::int32_t i : piece) {
    mean += Eigen::Vector2d(pts.x[static_cast<std::size_t>(i)], pts.y[static_cast<std::size_t>(i)]);
  }
  mean /= static_cast<double>(piece.size());
  const Eigen::Vector2d ray = (mean - sensor_xy).normalized();
  double across_lo = kInf, across_hi = -kInf;
  for (const std::int32_t i : piece) {
    const Eigen::Vector2d d(pts.x[static_cast<std::size_t>(i)] - mean.x(), pts.y[static_cast<std::size_t>(i)] - mean.y());
    const double a = -ray.y() * d.x() + ray.x() * d.y();
    across_lo = std::min(across_lo, a);
    across_hi = std::max(across_hi, a);
  }
  if (across_hi - across_lo > params_.mover_column_width) return false;
  for (std::size_t j = 0; j < tracks.size(); ++j) {
    const PredictedObject& t = tracks[j];
    if (t.rear_sign == 0 || out->track_points[j].empty()) continue;
    // Its side is seen edge-on only if its axis lies near the ray (within join_max_deg x 2):
    // behind a crossing mover the band would be a strip across the ray, a pedestrian's place.
    if (std::abs(std::cos(t.box.theta) * ray.x() + std::sin(t.box.theta) * ray.y()) <
        std::cos(2.0 * DegToRad(params_.join_max_deg))) {
      continue;
    }
    const BoxFrame frame(t.box);
    const double hl = 0.5 * t.box.length, hw = 0.5 * t.box.width + params_.gate_margin;
    // The front end stays; the box reaches back to mover_max_length.
    const double front = -t.rear_sign * hl;
    bool inside = true;
    double lo = kInf, hi = -kInf;
    auto extend = [&](const Eigen::Vector2d& p) {
      lo = std::min(lo, p.x());
      hi = std::max(hi, p.x());
    };
    for (const std::int32_t i : piece) {
      const Eigen::Vector2d p = frame.To(pts.x[static_cast<std::size_t>(i)], pts.y[static_cast<std::size_t>(i)]);
      const double back = t.rear_sign * (p.x() - front);  // distance behind the front end
      if (std::abs(p.y()) > hw || back < 0.0 || back > params_.mover_max_length) {
        inside = false;
        break;
      }
      extend(p);
    }
    if (!inside) continue;
    for (const std::int32_t i : out->track_points[j]) {
      extend(frame.To(pts.x[static_cast<std::size_t>(i)], pts.y[static_cast<std::size_t>(i)]));
    }
    if (hi - lo > params_.mover_max_length + params_.gate_margin) continue;
    auto& dst = out->track_points[j];
    dst.insert(dst.end(), piece.begin(), piece.end());
    (*own_valid)[j] = 0;
    ++out->num_merged;
    return true;
  }
  return false;
}

void Associator::Run(const std::vector<PredictedObject>& tracks, const WorldPoints& pts,
                     const Segments& segments, const Eigen::Vector2d& sensor_xy,
                     AssociationResult* out) {
  const std::size_t nt = tracks.size();
  out->track_points.resize(nt);
  for (auto& v : out->track_points) v.clear();
  out->track_cost.assign(nt, std::numeric_limits<double>::quiet_NaN());
  out->new_objects.clear();
  out->num_split = 0;
  out->num_merged = 0;
  out->num_ignored = 0;

  BuildParts(tracks, pts, segments);
  out->num_split = static_cast<std::int32_t>(num_parts_) -
                   static_cast<std::int32_t>(segments.segments.size());
  if (out->num_split < 0) out->num_split = 0;
  const std::size_t np = num_parts_;

  // Candidate pairs and their costs, in (track, part) order; each track's gate is tested only
  // against the parts whose x range may overlap it.
  struct Pair {
    int track, part;
    double cost, inside;
  };
  std::vector<Pair> pairs;
  std::vector<double> margins(nt);
  std::vector<Eigen::Vector2d> lo(nt), hi(nt);
  {
    std::vector<Eigen::Vector2d> part_lo(np), part_hi(np);
    for (std::size_t q = 0; q < np; ++q) {
      part_lo[q] = parts_[q].min;
      part_hi[q] = parts_[q].max;
    }
    sorted_.Build(part_lo, part_hi, {});
  }
  const double slant = DegToRad(params_.min_slant_deg);
  for (std::size_t j = 0; j < nt; ++j) {
    margins[j] = GateMargin(tracks[j]);
    GateBounds(tracks[j].box, margins[j], &lo[j], &hi[j]);
    sorted_.Overlapping(lo[j], hi[j], &candidates_);
    std::uint8_t visible = 0;
    bool have_visible = false;
    for (const std::int32_t qq : candidates_) {
      const auto q = static_cast<std::size_t>(qq);
      if (!have_visible) {
        visible = VisibleFaces(tracks[j].box, sensor_xy, slant);
        if (visible == 0) visible = 0xF;  // sensor inside or on the rectangle: any face
        have_visible = true;
      }
      double inside = 0.0;
      const double c = PairCost(tracks[j], margins[j], visible, parts_[q], pts, &inside);
      if (std::isfinite(c)) pairs.push_back({static_cast<int>(j), static_cast<int>(q), c, inside});
    }
  }

  // Connected components of the candidate graph: nodes 0..nt-1 tracks, nt.. parts. Members of
  // each component (by root) and its pairs are listed by a counting sort, in index order.
  const std::size_t nn = nt + np;
  UnionFind uf(static_cast<int>(nn));
  for (const Pair& pr : pairs) uf.Join(pr.track, static_cast<int>(nt) + pr.part);
  std::vector<int> part_track(np, -1);
  {
    std::vector<int> root(nn);
    std::vector<std::size_t> node_start(nn + 1, 0), pair_start(nn + 1, 0);
    for (std::size_t k = 0; k < nn; ++k) {
      root[k] = uf.Find(static_cast<int>(k));
      ++node_start[static_cast<std::size_t>(root[k]) + 1];
    }
    for (const Pair& pr : pairs) ++pair_start[static_cast<std::size_t>(root[static_cast<std::size_t>(pr.track)]) + 1];
    for (std::size_t c = 0; c < nn; ++c) {
      node_start[c + 1] += node_start[c];
      pair_start[c + 1] += pair_start[c];
    }
    std::vector<int> nodes(nn);
    std::vector<const Pair*> comp_pairs(pairs.size());
    {
      std::vector<std::size_t> fill(node_start.begin(), node_start.end() - 1);
      for (std::size_t k = 0; k < nn; ++k) nodes[fill[static_cast<std::size_t>(root[k])]++] = static_cast<int>(k);
      fill.assign(pair_start.begin(), pair_start.end() - 1);
      for (const Pair& pr : pairs) comp_pairs[fill[static_cast<std::size_t>(root[static_cast<std::size_t>(pr.track)])]++] = &pr;
    }
    std::vector<int> row_of(nt, -1), col_of(np, -1);
    std::vector<int> ct, cp;
    std::vector<double> cost;
    for (std::size_t c = 0; c < nn; ++c) {
      ct.clear();
      cp.clear();
      for (std::size_t k = node_start[c]; k < node_start[c + 1]; ++k) {
        const int node = nodes[k];
        if (node < static_cast<int>(nt)) ct.push_back(node);
        else cp.push_back(node - static_cast<int>(nt));
      }
      if (ct.empty() || cp.empty()) continue;
      const int rows = static_cast<int>(ct.size());
      const int cols = static_cast<int>(cp.size()) + rows;  // + one "unassigned" column per row
      for (int r = 0; r < rows; ++r) row_of[static_cast<std::size_t>(ct[static_cast<std::size_t>(r)])] = r;
      for (std::size_t k = 0; k < cp.size(); ++k) col_of[static_cast<std::size_t>(cp[k])] = static_cast<int>(k);
      // Not a candidate: far more than leaving the track unassigned, so never chosen.
      const double kForbidden = 1e6;
      cost.assign(static_cast<std::size_t>(rows) * static_cast<std::size_t>(cols), kForbidden);
      for (int r = 0; r < rows; ++r) {
        cost[static_cast<std::size_t>(r) * cols + cp.size() + static_cast<std::size_t>(r)] = params_.miss_cost;
      }
      for (std::size_t k = pair_start[c]; k < pair_start[c + 1]; ++k) {
        const Pair* pr = comp_pairs[k];
        const int r = row_of[static_cast<std::size_t>(pr->track)];
        const int col = col_of[static_cast<std::size_t>(pr->part)];
        cost[static_cast<std::size_t>(r) * cols + static_cast<std::size_t>(col)] = pr->cost;
      }
      const std::vector<int> assign = SolveAssignment(cost, rows, cols);
      for (int r = 0; r < rows; ++r) {
        const int k = assign[static_cast<std::size_t>(r)];
        if (k < 0 || k >= static_cast<int>(cp.size())) continue;
        const double c_rk = cost[static_cast<std::size_t>(r) * cols + static_cast<std::size_t>(k)];
        if (c_rk >= kForbidden) continue;
        const int j = ct[static_cast<std::size_t>(r)];
        const int q = cp[static_cast<std::size_t>(k)];
        part_track[static_cast<std::size_t>(q)] = j;
        out->track_cost[static_cast<std::size_t>(j)] = c_rk;
        // The part is not read again once assigned: its returns move to the track.
        std::swap(out->track_points[static_cast<std::size_t>(j)], parts_[static_cast<std::size_t>(q)].points);
      }
    }
  }

  // The candidate pairs of each part, in pair order (counting sort).
  std::vector<std::size_t> part_pair_start(np + 1, 0);
  for (const Pair& pr : pairs) ++part_pair_start[static_cast<std::size_t>(pr.part) + 1];
  for (std::size_t q = 0; q < np; ++q) part_pair_start[q + 1] += part_pair_start[q];
  std::vector<const Pair*> part_pairs(pairs.size());
  {
    std::vector<std::size_t> fill(part_pair_start.begin(), part_pair_start.end() - 1);
    for (const Pair& pr : pairs) part_pairs[fill[static_cast<std::size_t>(pr.part)]++] = &pr;
  }

  // Leftover parts: merge into an assigned track that holds most of them, else new objects.
  std::vector<char> own_valid(nt, 0);
  std::vector<Eigen::Vector2d> own_lo(nt), own_hi(nt);
  for (std::size_t q = 0; q < np; ++q) {
    if (part_track[q] >= 0) continue;
    int best = -1;
    double best_inside = 0.0;
    bool on_some_box = false, candidate = false;
    for (std::size_t k = part_pair_start[q]; k < part_pair_start[q + 1]; ++k) {
      const Pair& pr = *part_pairs[k];
      candidate = true;
      // A piece of the same object lies on its rectangle (the gate without the growth for the
      // position uncertainty) and does not stretch the object beyond the dimensions seen so far
      // by more than gate_margin. The gate alone would take in a car parked 1 m away, whose
      // returns then lengthen the shape estimate, which lengthens the rectangle and takes in the
      // next car of the row.
      const PredictedObject& t = tracks[static_cast<std::size_t>(pr.track)];
      const BoxFrame frame(t.box);
      const double hl = 0.5 * t.box.length + params_.gate_margin;
      const double hw = 0.5 * t.box.width + params_.gate_margin;
      Eigen::Vector2d lo_all = Eigen::Vector2d::Constant(kInf), hi_all = -lo_all;
      int on_box = 0;
      for (const std::int32_t i : parts_[q].points) {
        const auto iu = static_cast<std::size_t>(i);
        const Eigen::Vector2d p = frame.To(pts.x[iu], pts.y[iu]);
        on_box += std::abs(p.x()) <= hl && std::abs(p.y()) <= hw;
        lo_all = lo_all.cwiseMin(p);
        hi_all = hi_all.cwiseMax(p);
      }
      const double frac = parts_[q].points.empty()
                              ? 0.0
                              : static_cast<double>(on_box) / static_cast<double>(parts_[q].points.size());
      if (frac >= params_.min_inside_fraction) on_some_box = true;
      // What follows decides only whether this track takes the part: not if frac cannot win.
      if (!(frac >= params_.merge_fraction && frac > best_inside)) continue;
      const auto tu = static_cast<std::size_t>(pr.track);
      const auto& own_points = out->track_points[tu];
      if (own_points.empty()) continue;
      // The track's own returns in its frame: computed once, again only after a merge into it.
      if (!own_valid[tu]) {
        own_lo[tu] = Eigen::Vector2d::Constant(kInf);
        own_hi[tu] = -own_lo[tu];
        for (const std::int32_t i : own_points) {
          const auto iu = static_cast<std::size_t>(i);
          const Eigen::Vector2d p = frame.To(pts.x[iu], pts.y[iu]);
          own_lo[tu] = own_lo[tu].cwiseMin(p);
          own_hi[tu] = own_hi[tu].cwiseMax(p);
        }
        own_valid[tu] = 1;
      }
      const Eigen::Vector2d lo_own = own_lo[tu], hi_own = own_hi[tu];
      lo_all = lo_all.cwiseMin(lo_own);
      hi_all = hi_all.cwiseMax(hi_own);
      const Eigen::Vector2d own = hi_own - lo_own, all = hi_all - lo_all;
      const double max_l = (t.seen_length > 0.0 ? std::max(t.seen_length, own.x()) : t.box.length) +
                           params_.gate_margin;
      const double max_w = (t.seen_width > 0.0 ? std::max(t.seen_width, own.y()) : t.box.width) +
                           params_.gate_margin;
      if (all.x() > max_l || all.y() > max_w) continue;
      if (frac >= params_.merge_fraction && frac > best_inside) {
        best_inside = frac;
        best = pr.track;
      }
    }
    if (best >= 0) {
      auto& dst = out->track_points[static_cast<std::size_t>(best)];
      dst.insert(dst.end(), parts_[q].points.begin(), parts_[q].points.end());
      own_valid[static_cast<std::size_t>(best)] = 0;
      ++out->num_merged;
    } else if (on_some_box || (candidate && (parts_[q].max - parts_[q].min).norm() < params_.ignore_max_extent)) {
      // On a track's rectangle (grown by gate_margin), or a small piece inside its gate (a
      // column of returns off a side seen at a grazing angle), but not merged: not a new object
      // (it would seed a duplicate of that track), not a measurement.
      ++out->num_ignored;
    } else if (!JoinMover(tracks, pts, sensor_xy, parts_[q].points, out, &own_valid)) {
      // A larger piece only inside the grown gate of a track (its position uncertainty):
      // another object.
      out->new_objects.push_back(std::move(parts_[q].points));
    }
  }
}

}  // namespace vtrack
