#include "tracker/core/association.h"

#include <algorithm>
#include <cmath>
#include <cstring>
#include <limits>
#include <numeric>
#include <sstream>

#include "base/angle.h"
#include "tracker/core/return_kernels.h"

namespace vtrack {
namespace {

constexpr double kInf = std::numeric_limits<double>::infinity();
// Slack on the bounds of a created rectangle, for the rounding of its corners.
constexpr double kBoundsSlack = 1e-3;  // [m]

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

std::string AssociationParams::CrossProblem() const {
  if (!(max_gate_margin >= gate_margin))
    return param::Problem("max_gate_margin", max_gate_margin, "m", ">= gate_margin");
  return {};
}


Associator::Associator(const AssociationParams& params) : params_(params) {}

namespace {

// The candidate pairs of fewer than twice this many tracks are found on the calling thread: a
// loop on the pool costs the wake-up of its threads (a few us, at times 100 us or more on a busy
// machine), the pairs of some 30 tracks of a KITTI sweep.
constexpr std::size_t kMinTracksPerThread = 32;  // [tracks]

// The parts of fewer than twice this many segments are built on the calling thread (a KITTI
// sweep has about 1,000; a single-plane scan a few dozen).
constexpr std::size_t kMinSegmentsPerBlock = 64;  // [segments]

}  // namespace

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
  const BoxFrame frame(t.box);
  const RectFrame box{frame.c.x(), frame.c.y(), frame.ax, frame.ay, 0.5 * t.box.length,
                      0.5 * t.box.width};
  // A part beside the gate, though within its bounds along the world's axes (a long facade
  // passing a gate at an angle): every return outside, as the loop below would find.
  if (internal::BoxOutsideGate(box, margin, part.min, part.max)) return kInf;
  // The fewest returns inside the gate for a candidate (inside >= 1 and inside / n >=
  // min_inside_fraction, evaluated as below); once more returns than n - need lie outside, the
  // part is no candidate whatever the rest, and the loop stops (large segments, facades, overlap
  // the gates of many tracks with few of their returns inside).
  const double nd = static_cast<double>(n);
  std::size_t need = static_cast<std::size_t>(std::max(1.0, std::ceil(params_.min_inside_fraction * nd)));
  while (need > 1 && static_cast<double>(need - 1) / nd >= params_.min_inside_fraction) --need;
  while (need <= n && static_cast<double>(need) / nd < params_.min_inside_fraction) ++need;
  if (need > n) return kInf;
  const internal::GateSums sums = internal::SumGate(box, margin, visible, n - need,
                                                    part.points.data(), n, pts.x.data(),
                                                    pts.y.data(), &part.blocks);
  if (sums.stopped) return kInf;
  const std::size_t inside = sums.inside;
  const double dist_sum = sums.dist_sum;
  const double frac = static_cast<double>(inside) / nd;
  *inside_fraction = frac;
  if (inside == 0 || frac < params_.min_inside_fraction) return kInf;
  return dist_sum / static_cast<double>(inside) + params_.outside_penalty * (1.0 - frac);
}

namespace {

// Part buffers are kept from scan to scan, but not beyond twice what this scan's segments hold
// (plus this many returns): otherwise every slot would keep the largest part it ever held (RSS
// creeping up over a long run although nothing leaks).
constexpr std::size_t kRetainedSlack = 4096;

}  // namespace

void Associator::IndexClaimingGates(const std::vector<PredictedObject>& tracks) {
  // Per track once per scan: gate bounds, frame (cos/sin) and grown half sizes. Only established
  // tracks claim, so only their gates are indexed.
  const std::size_t nt = tracks.size();
  std::vector<Eigen::Vector2d> lo(nt), hi(nt);
  std::vector<char> established(nt, 0);
  gates_.clear();
  for (std::size_t j = 0; j < nt; ++j) {
    const double margin = GateMargin(tracks[j]);
    GateBounds(tracks[j].box, margin, &lo[j], &hi[j]);
    established[j] = tracks[j].established ? 1 : 0;
    const BoxFrame frame(tracks[j].box);
    gates_.push_back({frame.c.x(), frame.c.y(), frame.ax, frame.ay,
                      0.5 * tracks[j].box.length + margin, 0.5 * tracks[j].box.width + margin});
  }
  sorted_.Build(lo, hi, established);
}

void Associator::ClaimingTracks(const Segment& s, Scratch* scratch) const {
  // Established tracks with at least split_min_points of this segment's returns inside their
  // gate, in track order.
  std::vector<std::size_t>& claim = scratch->claim;
  claim.clear();
  sorted_.Overlapping(s.min, s.max, &scratch->candidates);
  const auto n = static_cast<std::size_t>(s.end - s.begin);
  const int need = params_.split_min_points;
  for (const std::int32_t jj : scratch->candidates) {
    const auto j = static_cast<std::size_t>(jj);
    // Counted up to split_min_points (all the claim needs), block by block in order; a block
    // wholly outside the gate adds nothing.
    int inside = 0;
    for (std::size_t b = 0; b < scratch->blocks.size() && inside < need; ++b) {
      if (internal::BlockOutsideGate(gates_[j], scratch->blocks[b])) continue;
      const std::size_t first = b * internal::kBlockReturns;
      inside += internal::CountInside(gates_[j], std::min(n - first, internal::kBlockReturns),
                                      scratch->seg_x.data() + first, scratch->seg_y.data() + first,
                                      need - inside);
    }
    if (inside >= need) claim.push_back(j);
  }
}

void Associator::SplitAmong(const std::vector<PredictedObject>& tracks, const std::int32_t* begin,
                            const std::int32_t* end, Scratch* scratch, Part* parts) const {
  // Each return goes to the claimant it is nearest to, ordered by the signed distance to the
  // rectangle boundary (> 0 outside, <= 0 inside): the distance inside, its square outside.
  // Most segments of a KITTI scan are claimed by two or more tracks (clutter tracks on
  // vegetation and walls overlap): the claimants' frames side by side.
  std::vector<RectFrame>& claimants = scratch->claimants;
  claimants.clear();
  for (const std::size_t j : scratch->claim) {
    const RectFrame& g = gates_[j];
    claimants.push_back({g.cx, g.cy, g.ax, g.ay, 0.5 * tracks[j].box.length,
                         0.5 * tracks[j].box.width});
  }
  // Claimant by claimant over the segment's returns side by side (its padding's answer is not
  // used): each return still meets the claimants in order and keeps the first of the nearest.
  // Block by block: a claimant none of whose distances to a block's returns can be below the
  // nearest so far of any of them (BlockNearestBound above the block's largest) changes nothing
  // there (a return takes a later claimant only if strictly nearer).
  const auto n = static_cast<std::size_t>(end - begin);
  const std::size_t padded = n + (n & 1);
  scratch->split_d.assign(padded, kInf);
  scratch->split_best.assign(padded, 0);
  const std::size_t num_blocks = scratch->blocks.size();
  scratch->block_max.assign(num_blocks, kInf);
  for (std::size_t c = 0; c < claimants.size(); ++c) {
    for (std::size_t b = 0; b < num_blocks; ++b) {
      if (internal::BlockNearestBound(claimants[c], scratch->blocks[b]) > scratch->block_max[b]) {
        continue;
      }
      const std::size_t first = b * internal::kBlockReturns;
      const std::size_t len = std::min(padded - first, internal::kBlockReturns);
      scratch->block_max[b] = internal::KeepNearer(
          claimants[c], static_cast<std::int64_t>(c), len, scratch->seg_x.data() + first,
          scratch->seg_y.data() + first, scratch->split_d.data() + first,
          scratch->split_best.data() + first);
    }
  }
  for (std::size_t k = 0; k < n; ++k) {
    parts[static_cast<std::size_t>(scratch->split_best[k])].points.push_back(begin[k]);
  }
}

std::size_t Associator::BoundSplit(const WorldPoints& pts, std::size_t first, std::size_t end,
                                   std::vector<Part>* parts) const {
  // Bounding boxes; drops pieces that are too small to fit (their buffers are kept for reuse:
  // swapped, not moved, to the end). Returns the new end of the parts in use.
  std::size_t w = first;
  for (std::size_t q = first; q < end; ++q) {
    Part& part = (*parts)[q];
    if (static_cast<int>(part.points.size()) < params_.split_min_points) continue;
    internal::BoundBlocks(part.points.size(), pts.x.data(), pts.y.data(), part.points.data(),
                          &part.blocks, &part.min, &part.max);
    if (w != q) {
      std::swap((*parts)[w].points, part.points);
      std::swap((*parts)[w].blocks, part.blocks);
      (*parts)[w].min = part.min;
      (*parts)[w].max = part.max;
    }
    ++w;
  }
  return w;
}

std::size_t Associator::PartsOf(const std::vector<PredictedObject>& tracks, const WorldPoints& pts,
                                const Segments& segments, std::size_t seg_begin,
                                std::size_t seg_end, Scratch* scratch,
                                std::vector<Part>* parts) const {
  std::size_t used = 0;
  for (std::size_t k = seg_begin; k < seg_end; ++k) {
    const Segment& s = segments.segments[k];
    // The segment's returns gathered side by side once, for the claims and the split.
    const std::int32_t* seg_begin_point = segments.point.data() + s.begin;
    const std::int32_t* seg_end_point = segments.point.data() + s.end;
    const auto n = static_cast<std::size_t>(s.end - s.begin);
    scratch->seg_x.resize(n + (n & 1));
    scratch->seg_y.resize(n + (n & 1));
    for (std::size_t r = 0; r < n; ++r) {
      scratch->seg_x[r] = pts.x[static_cast<std::size_t>(seg_begin_point[r])];
      scratch->seg_y[r] = pts.y[static_cast<std::size_t>(seg_begin_point[r])];
    }
    if ((n & 1) != 0) {
      scratch->seg_x[n] = scratch->seg_x[n - 1];
      scratch->seg_y[n] = scratch->seg_y[n - 1];
    }
    Eigen::Vector2d seg_lo, seg_hi;
    internal::BoundBlocks(n, scratch->seg_x.data(), scratch->seg_y.data(), nullptr, &scratch->blocks,
                          &seg_lo, &seg_hi);
    ClaimingTracks(s, scratch);
    const std::size_t first = used;
    const std::size_t num_parts = scratch->claim.size() >= 2 ? scratch->claim.size() : 1;
    if (parts->size() < first + num_parts) parts->resize(first + num_parts);
    for (std::size_t q = first; q < first + num_parts; ++q) (*parts)[q].points.clear();
    if (num_parts == 1) {
      Part& part = (*parts)[first];
      part.points.assign(seg_begin_point, seg_end_point);
      part.min = seg_lo;
      part.max = seg_hi;
      part.blocks = scratch->blocks;
      used = first + 1;
    } else {
      SplitAmong(tracks, seg_begin_point, seg_end_point, scratch, parts->data() + first);
      used = BoundSplit(pts, first, first + num_parts, parts);
    }
  }
  return used;
}

void Associator::BuildParts(const std::vector<PredictedObject>& tracks, const WorldPoints& pts,
                            const Segments& segments) {
  // Segments in blocks, each block's parts gathered apart (the first block's in parts_) and
  // appended in block order: the parts, in the order, of one pass over the segments. More
  // blocks than threads: segments differ in size by thousands of returns.
  const std::size_t ns = segments.segments.size();
  const int threads = pool_ != nullptr ? pool_->threads() : 1;
  const std::size_t blocks =
      threads > 1 && ns >= 2 * kMinSegmentsPerBlock
          ? std::min<std::size_t>(ns / kMinSegmentsPerBlock, 4 * static_cast<std::size_t>(threads))
          : 1;
  block_parts_.resize(blocks - 1);
  block_num_parts_.assign(blocks, 0);
  std::size_t retained = 0;
  for (const Part& part : parts_) retained += part.points.capacity();
  for (const std::vector<Part>& block : block_parts_) {
    for (const Part& part : block) retained += part.points.capacity();
  }
  if (retained > 2 * segments.point.size() + kRetainedSlack) {
    parts_.clear();
    for (std::vector<Part>& block : block_parts_) block.clear();
  }
  IndexClaimingGates(tracks);
  scratch_.resize(static_cast<std::size_t>(threads));
  const auto parts_of_block = [&](std::size_t b, int worker) {
    block_num_parts_[b] = PartsOf(tracks, pts, segments, ns * b / blocks, ns * (b + 1) / blocks,
                                  &scratch_[static_cast<std::size_t>(worker)],
                                  b == 0 ? &parts_ : &block_parts_[b - 1]);
  };
  if (blocks == 1) {
    parts_of_block(0, 0);
  } else {
    pool_->ParallelFor(blocks, parts_of_block);
  }
  num_parts_ = block_num_parts_[0];
  for (std::size_t b = 1; b < blocks; ++b) {
    std::vector<Part>& block = block_parts_[b - 1];
    if (parts_.size() < num_parts_ + block_num_parts_[b]) parts_.resize(num_parts_ + block_num_parts_[b]);
    for (std::size_t q = 0; q < block_num_parts_[b]; ++q, ++num_parts_) {
      std::swap(parts_[num_parts_].points, block[q].points);  // buffers swapped, kept for reuse
      std::swap(parts_[num_parts_].blocks, block[q].blocks);
      parts_[num_parts_].min = block[q].min;
      parts_[num_parts_].max = block[q].max;
    }
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
    // Its side is seen edge-on only if its axis lies near the ray (within mover_column_deg):
    // behind a crossing mover the band would be a strip across the ray, a pedestrian's place.
    if (std::abs(std::cos(t.box.theta) * ray.x() + std::sin(t.box.theta) * ray.y()) <
        std::cos(DegToRad(params_.mover_column_deg))) {
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

void Associator::CandidatePairs(const std::vector<PredictedObject>& tracks, const WorldPoints& pts,
                                const Eigen::Vector2d& sensor_xy, std::vector<Pair>* pairs) {
  // Candidate pairs and their costs, in (track, part) order; each track's gate is tested only
  // against the parts whose x range may overlap it.
  pairs->clear();
  const std::size_t np = num_parts_;
  {
    std::vector<Eigen::Vector2d> part_lo(np), part_hi(np);
    for (std::size_t q = 0; q < np; ++q) {
      part_lo[q] = parts_[q].min;
      part_hi[q] = parts_[q].max;
    }
    sorted_.Build(part_lo, part_hi, {});
  }
  const double slant = DegToRad(params_.min_slant_deg);
  const auto inside_returns = [this](const Pair& pr) {
    return pr.inside * static_cast<double>(parts_[static_cast<std::size_t>(pr.part)].points.size());
  };
  // Each track's pairs depend on that track and the parts alone: the tracks in blocks, one per
  // thread, each block's pairs gathered apart and appended in block order (the order of one
  // loop over the tracks).
  const std::size_t nt = tracks.size();
  const int blocks = pool_ != nullptr && nt >= 2 * kMinTracksPerThread ? pool_->threads() : 1;
  block_pairs_.resize(static_cast<std::size_t>(blocks) - 1);
  scratch_.resize(static_cast<std::size_t>(pool_ != nullptr ? pool_->threads() : 1));
  const auto pairs_of_block = [&](std::size_t b, int worker) {
    std::vector<Pair>& block = b == 0 ? *pairs : block_pairs_[b - 1];
    std::vector<std::int32_t>& candidates = scratch_[static_cast<std::size_t>(worker)].candidates;
    block.clear();
    Eigen::Vector2d lo, hi;
    const std::size_t end = nt * (b + 1) / static_cast<std::size_t>(blocks);
    for (std::size_t j = nt * b / static_cast<std::size_t>(blocks); j < end; ++j) {
      const std::size_t first = block.size();
      const double margin = GateMargin(tracks[j]);
      GateBounds(tracks[j].box, margin, &lo, &hi);
      sorted_.Overlapping(lo, hi, &candidates);
      std::uint8_t visible = 0;
      bool have_visible = false;
      for (const std::int32_t qq : candidates) {
        const auto q = static_cast<std::size_t>(qq);
        if (!have_visible) {
          visible = VisibleFaces(tracks[j].box, sensor_xy, slant);
          if (visible == 0) visible = 0xF;  // sensor inside or on the rectangle: any face
          have_visible = true;
        }
        double inside = 0.0;
        const double c = PairCost(tracks[j], margin, visible, parts_[q], pts, &inside);
        if (std::isfinite(c)) block.push_back({static_cast<int>(j), static_cast<int>(q), c, inside});
      }
      // The share of the track's candidate returns inside its gate that a part holds fewer of
      // than the part holding the most: a few returns of one face must not win the track over
      // the rest of its object. The part holding the most pays nothing, so the term decides which
      // part the track takes, not whether it takes one (miss_cost).
      double gate_returns = 0.0, most = 0.0;
      for (std::size_t k = first; k < block.size(); ++k) {
        gate_returns += inside_returns(block[k]);
        most = std::max(most, inside_returns(block[k]));
      }
      for (std::size_t k = first; k < block.size(); ++k) {
        Pair& pr = block[k];
        pr.cost += params_.outside_penalty * (most - inside_returns(pr)) / gate_returns;
      }
    }
  };
  if (blocks == 1) {
    pairs_of_block(0, 0);
  } else {
    pool_->ParallelFor(static_cast<std::size_t>(blocks), pairs_of_block);
  }
  for (const std::vector<Pair>& block : block_pairs_) pairs->insert(pairs->end(), block.begin(), block.end());
}

namespace {

// Not a candidate: far more than leaving the track unassigned, so never chosen.
constexpr double kForbidden = 1e6;

double FractionOnRectangle(const OrientedBox& box, double margin, const WorldPoints& pts,
                           const std::vector<std::int32_t>& idx, Eigen::Vector2d* lo = nullptr,
                           Eigen::Vector2d* hi = nullptr) {
  // The returns' fraction within the rectangle grown by margin, and their bounding box in the
  // rectangle's frame (lo, hi optional).
  const BoxFrame frame(box);
  const double hl = 0.5 * box.length + margin;
  const double hw = 0.5 * box.width + margin;
  Eigen::Vector2d lo_all = Eigen::Vector2d::Constant(kInf), hi_all = -lo_all;
  int on_box = 0;
  for (const std::int32_t i : idx) {
    const auto iu = static_cast<std::size_t>(i);
    const Eigen::Vector2d p = frame.To(pts.x[iu], pts.y[iu]);
    on_box += std::abs(p.x()) <= hl && std::abs(p.y()) <= hw;
    lo_all = lo_all.cwiseMin(p);
    hi_all = hi_all.cwiseMax(p);
  }
  if (lo) *lo = lo_all;
  if (hi) *hi = hi_all;
  return idx.empty() ? 0.0 : static_cast<double>(on_box) / static_cast<double>(idx.size());
}

// Items grouped by a key in [0, num_keys), each group in input order (a counting sort).
struct Groups {
  std::vector<std::size_t> start;  // group k is item[start[k], start[k + 1])
  std::vector<std::size_t> item;
  template <class KeyOf>
  Groups(std::size_t num_items, std::size_t num_keys, KeyOf key_of)
      : start(num_keys + 1, 0), item(num_items) {
    for (std::size_t i = 0; i < num_items; ++i) ++start[key_of(i) + 1];
    for (std::size_t k = 0; k < num_keys; ++k) start[k + 1] += start[k];
    std::vector<std::size_t> fill(start.begin(), start.end() - 1);
    for (std::size_t i = 0; i < num_items; ++i) item[fill[key_of(i)]++] = i;
  }
};

}  // namespace

std::vector<int> Associator::Assign(std::size_t nt, const std::vector<Pair>& pairs,
                                    AssociationResult* out) {
  // Connected components of the candidate graph: nodes 0..nt-1 tracks, nt.. parts; one
  // minimum-cost assignment per component, with one "unassigned" column per track at miss_cost.
  const std::size_t np = num_parts_;
  const std::size_t nn = nt + np;
  UnionFind uf(static_cast<int>(nn));
  for (const Pair& pr : pairs) uf.Join(pr.track, static_cast<int>(nt) + pr.part);
  std::vector<std::size_t> root(nn);
  for (std::size_t k = 0; k < nn; ++k) root[k] = static_cast<std::size_t>(uf.Find(static_cast<int>(k)));
  const Groups nodes(nn, nn, [&](std::size_t k) { return root[k]; });
  const Groups comp_pairs(pairs.size(), nn, [&](std::size_t i) {
    return root[static_cast<std::size_t>(pairs[i].track)];
  });
  std::vector<int> part_track(np, -1);
  std::vector<int> ct, cp;
  for (std::size_t c = 0; c < nn; ++c) {
    ct.clear();
    cp.clear();
    for (std::size_t k = nodes.start[c]; k < nodes.start[c + 1]; ++k) {
      const int node = static_cast<int>(nodes.item[k]);
      if (node < static_cast<int>(nt)) ct.push_back(node);
      else cp.push_back(node - static_cast<int>(nt));
    }
    if (ct.empty() || cp.empty()) continue;
    AssignComponent(ct, cp, pairs, comp_pairs.item.data() + comp_pairs.start[c],
                    comp_pairs.item.data() + comp_pairs.start[c + 1], &part_track, out);
  }
  return part_track;
}

void Associator::AssignComponent(const std::vector<int>& ct, const std::vector<int>& cp,
                                 const std::vector<Pair>& pairs, const std::size_t* pair_begin,
                                 const std::size_t* pair_end, std::vector<int>* part_track,
                                 AssociationResult* out) {
  const int rows = static_cast<int>(ct.size());
  const int cols = static_cast<int>(cp.size()) + rows;  // + one "unassigned" column per row
  row_of_.resize(out->track_points.size());
  col_of_.resize(part_track->size());
  for (int r = 0; r < rows; ++r) row_of_[static_cast<std::size_t>(ct[static_cast<std::size_t>(r)])] = r;
  for (std::size_t k = 0; k < cp.size(); ++k) col_of_[static_cast<std::size_t>(cp[k])] = static_cast<int>(k);
  cost_.assign(static_cast<std::size_t>(rows) * static_cast<std::size_t>(cols), kForbidden);
  for (int r = 0; r < rows; ++r) {
    cost_[static_cast<std::size_t>(r) * cols + cp.size() + static_cast<std::size_t>(r)] = params_.miss_cost;
  }
  for (const std::size_t* k = pair_begin; k != pair_end; ++k) {
    const Pair& pr = pairs[*k];
    const int r = row_of_[static_cast<std::size_t>(pr.track)];
    const int col = col_of_[static_cast<std::size_t>(pr.part)];
    cost_[static_cast<std::size_t>(r) * cols + static_cast<std::size_t>(col)] = pr.cost;
  }
  const std::vector<int> assign = SolveAssignment(cost_, rows, cols);
  for (int r = 0; r < rows; ++r) {
    const int k = assign[static_cast<std::size_t>(r)];
    if (k < 0 || k >= static_cast<int>(cp.size())) continue;
    const double c_rk = cost_[static_cast<std::size_t>(r) * cols + static_cast<std::size_t>(k)];
    if (c_rk >= kForbidden) continue;
    const int j = ct[static_cast<std::size_t>(r)];
    const int q = cp[static_cast<std::size_t>(k)];
    (*part_track)[static_cast<std::size_t>(q)] = j;
    out->track_cost[static_cast<std::size_t>(j)] = c_rk;
    // The part is not read again once assigned: its returns move to the track.
    std::swap(out->track_points[static_cast<std::size_t>(j)], parts_[static_cast<std::size_t>(q)].points);
  }
}

Associator::MergeChoice Associator::ChooseMerge(const std::vector<PredictedObject>& tracks,
                                                const WorldPoints& pts, const Part& part,
                                                const std::vector<const Pair*>& part_pairs,
                                                const AssociationResult& out) {
  MergeChoice choice;
  double best_inside = 0.0;
  for (const Pair* pp : part_pairs) {
    const Pair& pr = *pp;
    choice.candidate = true;
    // A piece of the same object lies on its rectangle (the gate without the growth for the
    // position uncertainty) and does not stretch the object beyond the dimensions seen so far
    // by more than gate_margin. The gate alone would take in a car parked 1 m away, whose
    // returns then lengthen the shape estimate, which lengthens the rectangle and takes in the
    // next car of the row.
    const PredictedObject& t = tracks[static_cast<std::size_t>(pr.track)];
    const BoxFrame frame(t.box);
    Eigen::Vector2d lo_all, hi_all;
    const double frac = FractionOnRectangle(t.box, params_.gate_margin, pts, part.points, &lo_all, &hi_all);
    if (frac >= params_.min_inside_fraction) choice.on_some_box = true;
    // What follows decides only whether this track takes the part: not if frac cannot win.
    if (!(frac >= params_.merge_fraction && frac > best_inside)) continue;
    const auto tu = static_cast<std::size_t>(pr.track);
    const auto& own_points = out.track_points[tu];
    if (own_points.empty()) continue;
    // The track's own returns in its frame: computed once, again only after a merge into it.
    if (!own_valid_[tu]) {
      own_lo_[tu] = Eigen::Vector2d::Constant(kInf);
      own_hi_[tu] = -own_lo_[tu];
      for (const std::int32_t i : own_points) {
        const auto iu = static_cast<std::size_t>(i);
        const Eigen::Vector2d p = frame.To(pts.x[iu], pts.y[iu]);
        own_lo_[tu] = own_lo_[tu].cwiseMin(p);
        own_hi_[tu] = own_hi_[tu].cwiseMax(p);
      }
      own_valid_[tu] = 1;
    }
    const Eigen::Vector2d lo_own = own_lo_[tu], hi_own = own_hi_[tu];
    lo_all = lo_all.cwiseMin(lo_own);
    hi_all = hi_all.cwiseMax(hi_own);
    const Eigen::Vector2d own = hi_own - lo_own, all = hi_all - lo_all;
    const double max_l = (t.seen_length > 0.0 ? std::max(t.seen_length, own.x()) : t.box.length) +
                         params_.gate_margin;
    const double max_w = (t.seen_width > 0.0 ? std::max(t.seen_width, own.y()) : t.box.width) +
                         params_.gate_margin;
    if (all.x() > max_l || all.y() > max_w) continue;
    best_inside = frac;
    choice.track = pr.track;
  }
  return choice;
}

void Associator::Leftovers(const std::vector<PredictedObject>& tracks, const WorldPoints& pts,
                           const Eigen::Vector2d& sensor_xy, const std::vector<Pair>& pairs,
                           const std::vector<int>& part_track, AssociationResult* out) {
  // Leftover parts: merge into an assigned track that holds most of them, else new objects.
  const std::size_t nt = tracks.size();
  const std::size_t np = num_parts_;
  const Groups by_part(pairs.size(), np, [&](std::size_t i) {
    return static_cast<std::size_t>(pairs[i].part);
  });
  own_valid_.assign(nt, 0);
  own_lo_.resize(nt);
  own_hi_.resize(nt);
  std::vector<const Pair*> part_pairs;
  for (std::size_t q = 0; q < np; ++q) {
    if (part_track[q] >= 0) continue;
    part_pairs.clear();
    for (std::size_t k = by_part.start[q]; k < by_part.start[q + 1]; ++k) {
      part_pairs.push_back(&pairs[by_part.item[k]]);
    }
    const MergeChoice choice = ChooseMerge(tracks, pts, parts_[q], part_pairs, *out);
    if (choice.track >= 0) {
      auto& dst = out->track_points[static_cast<std::size_t>(choice.track)];
      dst.insert(dst.end(), parts_[q].points.begin(), parts_[q].points.end());
      own_valid_[static_cast<std::size_t>(choice.track)] = 0;
      ++out->num_merged;
    } else if (choice.on_some_box ||
               (choice.candidate && (parts_[q].max - parts_[q].min).norm() < params_.ignore_max_extent)) {
      // On a track's rectangle (grown by gate_margin), or a small piece inside its gate (a
      // column of returns off a side seen at a grazing angle), but not merged: not a new object
      // (it would seed a duplicate of that track), not a measurement.
      ++out->num_ignored;
    } else if (!JoinMover(tracks, pts, sensor_xy, parts_[q].points, out, &own_valid_)) {
      // A larger piece only inside the grown gate of a track (its position uncertainty):
      // another object.
      out->new_objects.push_back(std::move(parts_[q].points));
    }
  }
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
  // Split segments claimed by two or more established tracks.
  BuildParts(tracks, pts, segments);
  out->num_split = std::max<std::int32_t>(
      0, static_cast<std::int32_t>(num_parts_) - static_cast<std::int32_t>(segments.segments.size()));
  // Candidate pairs, then one assignment per connected component.
  CandidatePairs(tracks, pts, sensor_xy, &pairs_);
  const std::vector<int> part_track = Assign(nt, pairs_, out);
  // What is left: merged into a track, ignored, joined to a mover, or new objects.
  Leftovers(tracks, pts, sensor_xy, pairs_, part_track, out);
}

void OrderNewObjects(const WorldPoints& pts, double small_extent,
                     std::vector<std::vector<std::int32_t>>* objects) {
  auto& objs = *objects;
  std::vector<std::pair<std::pair<bool, std::size_t>, std::size_t>> order(objs.size());
  for (std::size_t k = 0; k < objs.size(); ++k) {
    Eigen::Vector2d lo = Eigen::Vector2d::Constant(kInf);
    Eigen::Vector2d hi = -lo;
    for (const std::int32_t i : objs[k]) {
      const Eigen::Vector2d p(pts.x[static_cast<std::size_t>(i)], pts.y[static_cast<std::size_t>(i)]);
      lo = lo.cwiseMin(p);
      hi = hi.cwiseMax(p);
    }
    const bool small = objs[k].empty() || (hi - lo).norm() < small_extent;
    order[k] = {{small, objs[k].size()}, k};
  }
  std::stable_sort(order.begin(), order.end(), [](const auto& a, const auto& b) {
    if (a.first.first != b.first.first) return !a.first.first;  // rectangles first
    return a.first.second > b.first.second;
  });
  std::vector<std::vector<std::int32_t>> sorted(objs.size());
  for (std::size_t k = 0; k < order.size(); ++k) sorted[k] = std::move(objs[order[k].second]);
  objs.swap(sorted);
}

void CreatedRectangles::Clear() {
  boxes_.clear();
  lo_.clear();
  hi_.clear();
}

void CreatedRectangles::Add(const OrientedBox& box) {
  // Bounds of the rectangle grown by gate_margin, plus kBoundsSlack for rounding: an object
  // whose bounding box misses them has no return inside and is not tested return by return.
  Eigen::Vector2d lo, hi;
  GateBounds(box, params_.gate_margin + kBoundsSlack, &lo, &hi);
  boxes_.push_back(box);
  lo_.push_back(lo);
  hi_.push_back(hi);
}

bool CreatedRectangles::Holds(const WorldPoints& pts, const std::vector<std::int32_t>& idx) const {
  if (boxes_.empty() || idx.empty()) return false;
  Eigen::Vector2d lo = Eigen::Vector2d::Constant(kInf), hi = -lo;
  for (const std::int32_t i : idx) {
    const Eigen::Vector2d p(pts.x[static_cast<std::size_t>(i)], pts.y[static_cast<std::size_t>(i)]);
    lo = lo.cwiseMin(p);
    hi = hi.cwiseMax(p);
  }
  for (std::size_t c = 0; c < boxes_.size(); ++c) {
    if (!Overlap(lo, hi, lo_[c], hi_[c])) continue;
    if (FractionOnRectangle(boxes_[c], params_.gate_margin, pts, idx) >= params_.merge_fraction) {
      return true;
    }
  }
  return false;
}

}  // namespace vtrack
