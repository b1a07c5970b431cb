#include "tracker/core/segmentation.h"

#include <algorithm>
#include <cmath>
#include <limits>
#include <sstream>

namespace vtrack {
std::string SegmentationParams::CrossProblem() const {
  if (connectivity != 4 && connectivity != 8) return param::Problem("connectivity", connectivity, "-", "4 or 8");
  if (grid_radius / cell_size > 4000.0)
    return param::Problem("grid_radius", grid_radius, "m", "at most 4000 cells of cell_size");
  return {};
}

void Segments::clear() {
  point.clear();
  segments.clear();
  dropped_small = 0;
  dropped_large = 0;
}

Segmenter::Segmenter(const SegmentationParams& params) : params_(params) {
  side_ = static_cast<int>(std::ceil(2.0 * params_.grid_radius / params_.cell_size)) + 2;
}

void Segmenter::Run(const WorldPoints& pts, bool scan_line, const Eigen::Vector2d& sensor_xy,
                    Segments* out) {
  out->clear();
  if (pts.size() == 0) return;
  if (scan_line) {
    RunScanLine(pts, sensor_xy, out);
  } else {
    RunGrid(pts, sensor_xy, out);
  }
}

void Segmenter::Finish(const WorldPoints& pts, std::int32_t begin, Segments* out) {
  const auto end = static_cast<std::int32_t>(out->point.size());
  if (end - begin < params_.min_points) {
    ++out->dropped_small;
    out->point.resize(static_cast<std::size_t>(begin));
    return;
  }
  Segment s;
  s.begin = begin;
  s.end = end;
  s.min = Eigen::Vector2d::Constant(std::numeric_limits<double>::infinity());
  s.max = -s.min;
  Eigen::Vector2d sum = Eigen::Vector2d::Zero();
  for (std::int32_t k = begin; k < end; ++k) {
    const auto i = static_cast<std::size_t>(out->point[static_cast<std::size_t>(k)]);
    const Eigen::Vector2d p(pts.x[i], pts.y[i]);
    s.min = s.min.cwiseMin(p);
    s.max = s.max.cwiseMax(p);
    sum += p;
  }
  if ((s.max - s.min).norm() > params_.max_extent) {
    ++out->dropped_large;
    out->point.resize(static_cast<std::size_t>(begin));
    return;
  }
  s.centroid = sum / static_cast<double>(end - begin);
  out->segments.push_back(s);
}

void Segmenter::RunScanLine(const WorldPoints& pts, const Eigen::Vector2d& sensor_xy,
                            Segments* out) {
  const std::size_t n = pts.size();
  auto is_break = [&](std::size_t a, std::size_t b) {
    const double dx = pts.x[b] - pts.x[a], dy = pts.y[b] - pts.y[a];
    const double range = std::hypot(pts.x[b] - sensor_xy.x(), pts.y[b] - sensor_xy.y());
    const double thr = std::max(params_.jump_abs, params_.jump_rel * range);
    return pts.ring[a] != pts.ring[b] || dx * dx + dy * dy > thr * thr;
  };
  // Start at the first break so that an object spanning the end and start of a 360 deg sweep
  // becomes one segment.
  std::size_t start = 0;
  for (std::size_t i = 1; i < n; ++i) {
    if (is_break(i - 1, i)) {
      start = i;
      break;
    }
  }
  const bool wraps = start != 0 && !is_break(n - 1, 0);
  if (!wraps) start = 0;
  std::int32_t begin = 0;
  for (std::size_t k = 0; k < n; ++k) {
    const std::size_t i = (start + k) % n;
    if (k > 0 && is_break((start + k - 1) % n, i)) {
      Finish(pts, begin, out);
      begin = static_cast<std::int32_t>(out->point.size());
    }
    out->point.push_back(static_cast<std::int32_t>(i));
  }
  Finish(pts, begin, out);
}

void Segmenter::RunGrid(const WorldPoints& pts, const Eigen::Vector2d& sensor_xy, Segments* out) {
  BinReturns(pts, sensor_xy);
  SortReturnsByCell(pts.size());
  // Connected components of occupied cells (depth-first, explicit stack).
  const std::size_t m = occupied_.size();
  slot_label_.assign(m, -1);
  std::int32_t label = 0;
  for (std::size_t seed = 0; seed < m; ++seed) {
    if (slot_label_[seed] >= 0) continue;
    const auto begin = static_cast<std::int32_t>(out->point.size());
    CollectComponent(seed, label++, out);
    Finish(pts, begin, out);
  }
}

void Segmenter::BinReturns(const WorldPoints& pts, const Eigen::Vector2d& sensor_xy) {
  const std::size_t n = pts.size();
  const std::size_t cells = static_cast<std::size_t>(side_) * static_cast<std::size_t>(side_);
  if (cells_.size() != cells) {
    cells_.assign(cells, Cell{});
    generation_ = 0;
  }
  if (++generation_ == 0) {  // wrapped after 2^32 scans: clear once
    for (Cell& c : cells_) c.stamp = 0;
    generation_ = 1;
  }
  const double inv = 1.0 / params_.cell_size;
  const double x0 = sensor_xy.x() - 0.5 * side_ * params_.cell_size;
  const double y0 = sensor_xy.y() - 0.5 * side_ * params_.cell_size;
  occupied_.clear();
  slot_count_.clear();
  point_cell_.resize(n);
  // The cell slot of every return (outside the grid: -1), occupied cells and their counts. The
  // outermost ring of cells is never used, so neighbour look-ups need no bounds checks.
  for (std::size_t i = 0; i < n; ++i) {
    const double fx = (pts.x[i] - x0) * inv, fy = (pts.y[i] - y0) * inv;
    if (!(fx >= 1.0 && fy >= 1.0 && fx < side_ - 1 && fy < side_ - 1)) {
      point_cell_[i] = -1;
      continue;
    }
    const std::int32_t c = static_cast<std::int32_t>(fy) * side_ + static_cast<std::int32_t>(fx);
    const auto cu = static_cast<std::size_t>(c);
    Cell& cell = cells_[cu];
    if (cell.stamp != generation_) {
      cell.stamp = generation_;
      cell.slot = static_cast<std::int32_t>(occupied_.size());
      occupied_.push_back(c);
      slot_count_.push_back(0);
    }
    point_cell_[i] = cell.slot;
    ++slot_count_[static_cast<std::size_t>(cell.slot)];
  }
}

void Segmenter::SortReturnsByCell(std::size_t n) {
  // Counting sort of returns by cell slot.
  const std::size_t m = occupied_.size();
  slot_start_.resize(m + 1);
  slot_start_[0] = 0;
  for (std::size_t s = 0; s < m; ++s) slot_start_[s + 1] = slot_start_[s] + slot_count_[s];
  sorted_.resize(static_cast<std::size_t>(slot_start_[m]));
  for (std::size_t s = 0; s < m; ++s) slot_count_[s] = slot_start_[s];
  for (std::size_t i = 0; i < n; ++i) {
    if (point_cell_[i] < 0) continue;
    const auto s = static_cast<std::size_t>(point_cell_[i]);
    sorted_[static_cast<std::size_t>(slot_count_[s]++)] = static_cast<std::int32_t>(i);
  }
}

void Segmenter::CollectComponent(std::size_t seed, std::int32_t label, Segments* out) {
  static constexpr int kDx[8] = {1, -1, 0, 0, 1, 1, -1, -1};
  static constexpr int kDy[8] = {0, 0, 1, -1, 1, -1, 1, -1};
  const int num_nb = params_.connectivity;
  stack_.clear();
  stack_.push_back(static_cast<std::int32_t>(seed));
  slot_label_[seed] = label;
  while (!stack_.empty()) {
    const auto s = static_cast<std::size_t>(stack_.back());
    stack_.pop_back();
    for (std::int32_t k = slot_start_[s]; k < slot_start_[s + 1]; ++k) {
      out->point.push_back(sorted_[static_cast<std::size_t>(k)]);
    }
    const std::int32_t c = occupied_[s];
    for (int j = 0; j < num_nb; ++j) {
      const auto nc = static_cast<std::size_t>(c + kDy[j] * side_ + kDx[j]);
      if (cells_[nc].stamp != generation_) continue;
      const auto ns = static_cast<std::size_t>(cells_[nc].slot);
      if (slot_label_[ns] >= 0) continue;
      slot_label_[ns] = label;
      stack_.push_back(static_cast<std::int32_t>(ns));
    }
  }
}

}  // namespace vtrack
