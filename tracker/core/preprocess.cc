#include "tracker/core/preprocess.h"

#include <algorithm>
#include <cmath>
#include <limits>
#include <sstream>

namespace vtrack {

std::string PreprocessParams::CrossProblem() const {
  if (!(max_range > min_range)) return param::Problem("max_range", max_range, "m", "> min_range");
  if (!(max_height > min_height)) return param::Problem("max_height", max_height, "m", "> min_height");
  return {};
}

void WorldPoints::clear() {
  x.clear();
  y.clear();
  height.clear();
  column_top.clear();
  index.clear();
  ring.clear();
}

void WorldPoints::reserve(std::size_t n) {
  x.reserve(n);
  y.reserve(n);
  height.reserve(n);
  index.reserve(n);
  ring.reserve(n);
}

void WorldPoints::push_back(double px, double py, float h, std::int32_t i, std::int16_t r) {
  x.push_back(px);
  y.push_back(py);
  height.push_back(h);
  index.push_back(i);
  ring.push_back(r);
}

Preprocessor::Preprocessor(const PreprocessParams& params) : params_(params) {}

PreprocessResult Preprocessor::Run(const LadarScan& scan, const PoseHistory& poses,
                                   std::int64_t max_extrapolation_us, WorldPoints* out) {
  PreprocessResult result;
  result.stats.input = static_cast<std::int64_t>(scan.size());
  // Compensation: the sensor's pose at knots over the sweep, each return placed with the pose
  // interpolated linearly between the knots around its time.
  if (!ComputeKnots(scan, poses, max_extrapolation_us, &result)) {
    out->clear();
    return result;
  }
  Compensate(scan, &result.stats, out);
  // Ground: a grid of local ground heights (3-D clouds), or a fixed band.
  const bool cloud_3d = scan.num_rings >= params_.ground_min_rings;
  if (cloud_3d && params_.ground == PreprocessParams::Ground::kGrid) {
    RemoveGround(result.sensor_xy, out, &result.stats);
  } else if (cloud_3d && params_.ground == PreprocessParams::Ground::kBand) {
    RemoveGroundBand(out, &result.stats);
  }
  result.stats.kept = static_cast<std::int64_t>(out->size());
  return result;
}

bool Preprocessor::ComputeKnots(const LadarScan& scan, const PoseHistory& poses,
                                std::int64_t max_extrapolation_us, PreprocessResult* result) {
  // Pose knots over the sweep [utime, utime + T].
  const std::int64_t sweep = std::max<std::int64_t>(0, scan.sweep_duration_us);
  const std::int64_t step = params_.knot_us;
  const std::int64_t num_intervals = std::max<std::int64_t>(1, (sweep + step - 1) / step);
  knot_m_.resize(static_cast<std::size_t>(num_intervals + 1));
  knot_d_.resize(static_cast<std::size_t>(num_intervals));
  bool extrapolated = false;
  Eigen::Isometry3d world_from_body_start = Eigen::Isometry3d::Identity();
  for (std::int64_t k = 0; k <= num_intervals; ++k) {
    const std::int64_t t = scan.utime + std::min(k * step, sweep);
    PoseHistory::LookupStatus st;
    const auto world_from_body = poses.At(t, max_extrapolation_us, &st);
    if (!world_from_body) {
      result->status = CompensationStatus::kNoPose;
      result->failed_lookup = st;
      return false;
    }
    if (st == PoseHistory::LookupStatus::kExtrapolated) extrapolated = true;
    if (k == 0) world_from_body_start = *world_from_body;
    const Eigen::Matrix4d world_from_sensor = (*world_from_body * scan.body_from_sensor).matrix();
    knot_m_[static_cast<std::size_t>(k)] = world_from_sensor.topRows<2>();
  }
  for (std::int64_t k = 0; k < num_intervals; ++k) {
    knot_d_[static_cast<std::size_t>(k)] =
        knot_m_[static_cast<std::size_t>(k + 1)] - knot_m_[static_cast<std::size_t>(k)];
  }
  result->status = extrapolated ? CompensationStatus::kExtrapolated : CompensationStatus::kOk;
  result->world_from_body_start = world_from_body_start;
  // The sensor's origin at mid-sweep (the centre of the ground grid and the segmentation).
  const std::int64_t mid = scan.utime + sweep / 2;
  PoseHistory::LookupStatus st;
  const auto world_from_body = poses.At(mid, max_extrapolation_us, &st);
  const Eigen::Isometry3d wb = world_from_body ? *world_from_body : world_from_body_start;
  result->sensor_xy = (wb * scan.body_from_sensor).translation().head<2>();
  return true;
}

namespace {

// Which returns of a scan are kept, and why the others are not.
struct ReturnFilter {
  double min_r2 = 0, max_r2 = 0;  // [m^2] the tracker's own range limits (out_of_range)
  double far_r2 = 0;              // [m^2] beyond what the sensor can measure (far)
  int num_rings = 1;
  bool has_ring = false;
  bool has_dt = false;
  std::int64_t sweep = 0;         // [us]

  ReturnFilter(const LadarScan& scan, const PreprocessParams& params) {
    const std::size_t n = scan.size();
    min_r2 = params.min_range * params.min_range;
    max_r2 = params.max_range * params.max_range;
    // Returns a sensor cannot have measured (finite but absurd: 3e38 m) are refused and counted,
    // apart from the tracker's own range limits: beyond the sensor's stated max_range (1 % margin
    // for the rounding of coordinates sent as floats), or beyond kMaxReturnRange if it stated
    // none (0).
    const double sensor_max = scan.max_range > 0.0f
                                  ? std::min<double>(kMaxReturnRange, 1.01 * scan.max_range)
                                  : kMaxReturnRange;
    far_r2 = sensor_max * sensor_max;
    num_rings = scan.num_rings;
    has_ring = scan.ring.size() == n;
    has_dt = scan.dt_us.size() == n;
    sweep = std::max<std::int64_t>(0, scan.sweep_duration_us);
  }

  // True if return i is kept (its time after utime in *dt), else counts why not in *stats.
  bool Keep(const LadarScan& scan, std::size_t i, PreprocessStats* stats, std::int64_t* dt) const {
    const double px = scan.x[i], py = scan.y[i], pz = scan.z[i];
    if (!std::isfinite(px) || !std::isfinite(py) || !std::isfinite(pz)) {
      ++stats->nonfinite;
      return false;
    }
    const double r2 = px * px + py * py + pz * pz;
    if (r2 > far_r2) {
      ++stats->far;
      return false;
    }
    // -1: the ring is unknown (a KITTI frame whose lasers could not be told apart): kept.
    if (has_ring && (scan.ring[i] < -1 || scan.ring[i] >= num_rings)) {
      ++stats->bad_ring;
      return false;
    }
    if (r2 < min_r2 || r2 > max_r2) {
      ++stats->out_of_range;
      return false;
    }
    *dt = has_dt ? scan.dt_us[i] : 0;
    if (*dt < 0 || *dt > sweep) {
      ++stats->bad_time;
      return false;
    }
    return true;
  }
};

}  // namespace

void Preprocessor::Compensate(const LadarScan& scan, PreprocessStats* stats, WorldPoints* out) {
  const std::size_t n = scan.size();
  const std::int64_t sweep = std::max<std::int64_t>(0, scan.sweep_duration_us);
  const std::int64_t step = params_.knot_us;
  const std::int64_t num_intervals = static_cast<std::int64_t>(knot_d_.size());
  // Body-frame height of a return: the z row of body_from_sensor (the mounting is rigid).
  const Eigen::Matrix<double, 1, 4> body_z = scan.body_from_sensor.matrix().row(2);
  const ReturnFilter filter(scan, params_);
  const bool has_ring = filter.has_ring;
  const double inv_step = 1.0 / static_cast<double>(step);
  if (fraction_.size() != static_cast<std::size_t>(step) + 1) {
    fraction_.resize(static_cast<std::size_t>(step) + 1);
    for (std::int64_t r = 0; r <= step; ++r) {
      fraction_[static_cast<std::size_t>(r)] = static_cast<double>(r) / static_cast<double>(step);
    }
  }
  const double* const fraction = fraction_.data();
  // Written by index into arrays sized for every return, trimmed at the end (no push_back). Not
  // cleared first: resize() then value-initialises only what the previous scan did not use.
  out->x.resize(n);
  out->y.resize(n);
  out->height.resize(n);
  out->index.resize(n);
  out->ring.resize(n);
  double* const ox = out->x.data();
  double* const oy = out->y.data();
  float* const oh = out->height.data();
  std::int32_t* const oi = out->index.data();
  std::int16_t* const orng = out->ring.data();
  std::size_t w = 0;
  for (std::size_t i = 0; i < n; ++i) {
    std::int64_t dt = 0;
    if (!filter.Keep(scan, i, stats, &dt)) continue;
    const double px = scan.x[i], py = scan.y[i], pz = scan.z[i];
    // dt / step without a 64-bit division per return: a floating-point guess, corrected to the
    // exact quotient.
    std::int64_t q = static_cast<std::int64_t>(static_cast<double>(dt) * inv_step);
    if (q * step > dt) --q;
    if ((q + 1) * step <= dt) ++q;
    const std::int64_t k = std::min<std::int64_t>(q, num_intervals - 1);
    const std::int64_t t0 = k * step;
    const std::int64_t t1 = std::min((k + 1) * step, sweep);
    const double f = t1 - t0 == step ? fraction[dt - t0]
                     : t1 > t0       ? static_cast<double>(dt - t0) / static_cast<double>(t1 - t0)
                                     : 0.0;
    const auto& m = knot_m_[static_cast<std::size_t>(k)];
    const auto& d = knot_d_[static_cast<std::size_t>(k)];
    // Both rows at once: a column of a 2x4 matrix is one SIMD pair, and each row gets the
    // operations a row written out would, in the same order (the same doubles).
    const Eigen::Vector2d wxy = (m.col(0) + f * d.col(0)) * px + (m.col(1) + f * d.col(1)) * py +
                                (m.col(2) + f * d.col(2)) * pz + (m.col(3) + f * d.col(3));
    const double wx = wxy.x(), wy = wxy.y();
    const double zb = body_z(0) * px + body_z(1) * py + body_z(2) * pz + body_z(3);
    ox[w] = wx;
    oy[w] = wy;
    oh[w] = static_cast<float>(zb);
    oi[w] = static_cast<std::int32_t>(i);
    orng[w] = has_ring ? scan.ring[i] : std::int16_t{0};
    ++w;
  }
  out->x.resize(w);
  out->y.resize(w);
  out->height.resize(w);
  out->index.resize(w);
  out->ring.resize(w);
}

namespace {

// The ground level of a scan is the median of the lowest return per occupied cell within this
// distance of the sensor, where most cells see the road.
constexpr double kGroundLevelRadius = 20.0;  // [m]

// Keeps the returns whose height above the ground (ground_of(i, height)) lies in
// [min_h, max_h], storing that height; counts the others as ground. column(i, h) is called for
// each return at least min_h high (kept or above max_h); cells (if not null) is compacted like
// the returns.
template <class GroundOf, class Column>
void KeepAboveGround(double min_h, double max_h, GroundOf ground_of, Column column, WorldPoints* pts,
                     std::vector<std::int32_t>* cells, PreprocessStats* stats) {
  const std::size_t n = pts->size();
  std::size_t w = 0;
  for (std::size_t i = 0; i < n; ++i) {
    const float h = pts->height[i] - ground_of(i);
    if (h < min_h) continue;
    column(i, h);
    if (h > max_h) continue;
    pts->x[w] = pts->x[i];
    pts->y[w] = pts->y[i];
    pts->height[w] = h;
    pts->index[w] = pts->index[i];
    pts->ring[w] = pts->ring[i];
    if (cells != nullptr) (*cells)[w] = (*cells)[i];
    ++w;
  }
  stats->ground = static_cast<std::int64_t>(n - w);
  pts->x.resize(w);
  pts->y.resize(w);
  pts->height.resize(w);
  pts->index.resize(w);
  pts->ring.resize(w);
}

}  // namespace

void Preprocessor::RemoveGroundBand(WorldPoints* out, PreprocessStats* stats) const {
  // Heights above a flat ground at ground_height_body.
  const float ground = static_cast<float>(params_.ground_height_body);
  KeepAboveGround(params_.min_height, params_.max_height, [ground](std::size_t) { return ground; },
                  [](std::size_t, float) {}, out, nullptr, stats);
}

void Preprocessor::RemoveGround(const Eigen::Vector2d& center, WorldPoints* pts,
                                PreprocessStats* stats) {
  const double cell = params_.ground_cell;
  GroundGrid grid;
  grid.side = static_cast<int>(std::ceil(2.0 * params_.max_range / cell)) + 3;
  grid.x0 = center.x() - 0.5 * grid.side * cell;
  grid.y0 = center.y() - 0.5 * grid.side * cell;
  BinLowestReturns(grid, *pts);
  BoundByGrade(grid);
  const float level = GroundLevel(grid);
  cell_ground_.assign(static_cast<std::size_t>(grid.side) * grid.side,
                      std::numeric_limits<float>::quiet_NaN());
  // Locals: the stores below could alias the parameters, which would be reloaded per return.
  const double min_h = params_.min_height, max_h = params_.max_height;
  cell_top_.assign(cell_ground_.size(), 0.0f);
  KeepAboveGround(
      min_h, max_h, [&](std::size_t i) { return CellGround(grid, point_cell_[i], level); },
      [&](std::size_t i, float h) {
        float& top = cell_top_[static_cast<std::size_t>(point_cell_[i])];
        top = std::max(top, h);
      },
      pts, &point_cell_, stats);
  // The top of each kept return's column: the highest return of its cell.
  const std::size_t kept = pts->size();
  pts->column_top.resize(kept);
  for (std::size_t i = 0; i < kept; ++i) {
    pts->column_top[i] = cell_top_[static_cast<std::size_t>(point_cell_[i])];
  }
}

void Preprocessor::BinLowestReturns(const GroundGrid& grid, const WorldPoints& pts) {
  const double cell = params_.ground_cell;
  const int side = grid.side;
  cell_min_.assign(static_cast<std::size_t>(side) * side, std::numeric_limits<float>::infinity());
  const std::size_t n = pts.size();
  point_cell_.resize(n);
  const double* const px = pts.x.data();
  const double* const py = pts.y.data();
  const float* const ph = pts.height.data();
  std::int32_t* const pc = point_cell_.data();
  float* const cmin = cell_min_.data();
  // Within max_range of the sensor, hence inside the grid (with one spare ring of cells) — unless
  // the ego pose jumps within the sweep: clamped before the conversion to int (which would be
  // undefined for a return 1e9 m away; found by tests/fuzz/tracker_fuzzer.cc), NaN to the edge.
  // offset / cell, by a multiplication when 1 / cell is exact (cell a power of two, as the
  // default 1 m): the same quotient without a division per return.
  int cell_exp = 0;
  const bool exact_inverse = std::frexp(cell, &cell_exp) == 0.5;
  const double inv_cell = 1.0 / cell;
  const auto cell_index = [&](double offset) {
    const double c = exact_inverse ? offset * inv_cell : offset / cell;
    return c >= 1.0 && c <= side - 2.0 ? static_cast<int>(c) : (c > side - 2.0 ? side - 2 : 1);
  };
  for (std::size_t i = 0; i < n; ++i) {
    const int cx = cell_index(px[i] - grid.x0);
    const int cy = cell_index(py[i] - grid.y0);
    const std::int32_t c = cy * side + cx;
    pc[i] = c;
    cmin[c] = std::min(cmin[c], ph[i]);
  }
}

void Preprocessor::BoundByGrade(const GroundGrid& grid) {
  // Upper bound of the ground per cell: min over cells c' of cell_min(c') + grade * |c - c'|, by
  // the two raster passes of a 3x3 chamfer distance transform (Borgefors 1986; diagonal steps
  // weighted sqrt(2), which overstates a Euclidean distance by at most 8 %). Written here: OpenCV's
  // distanceTransform computes distances to zero pixels, not this lower envelope of heights.
  const int side = grid.side;
  cell_bound_ = cell_min_;
  const float a = static_cast<float>(params_.ground_max_grade * params_.ground_cell);
  const float d = a * static_cast<float>(std::sqrt(2.0));
  float* const b = cell_bound_.data();
  for (int cy = 1; cy < side - 1; ++cy) {
    for (int cx = 1; cx < side - 1; ++cx) {
      const std::ptrdiff_t c = static_cast<std::ptrdiff_t>(cy) * side + cx;
      b[c] = std::min({b[c], b[c - 1] + a, b[c - side - 1] + d, b[c - side] + a,
                       b[c - side + 1] + d});
    }
  }
  for (int cy = side - 2; cy >= 1; --cy) {
    for (int cx = side - 2; cx >= 1; --cx) {
      const std::ptrdiff_t c = static_cast<std::ptrdiff_t>(cy) * side + cx;
      b[c] = std::min({b[c], b[c + 1] + a, b[c + side + 1] + d, b[c + side] + a,
                       b[c + side - 1] + d});
    }
  }
}

float Preprocessor::GroundLevel(const GroundGrid& grid) const {
  const int side = grid.side;
  std::vector<float> near_mins;
  const int r_cells = static_cast<int>(std::ceil(kGroundLevelRadius / params_.ground_cell));
  const int ccx = side / 2, ccy = side / 2;
  for (int cy = std::max(0, ccy - r_cells); cy <= std::min(side - 1, ccy + r_cells); ++cy) {
    for (int cx = std::max(0, ccx - r_cells); cx <= std::min(side - 1, ccx + r_cells); ++cx) {
      const float m = cell_min_[static_cast<std::size_t>(cy * side + cx)];
      if (m < std::numeric_limits<float>::infinity()) near_mins.push_back(m);
    }
  }
  float level = static_cast<float>(params_.ground_height_body);
  if (!near_mins.empty()) {
    auto mid = near_mins.begin() + static_cast<std::ptrdiff_t>(near_mins.size() / 2);
    std::nth_element(near_mins.begin(), mid, near_mins.end());
    level = *mid;
  }
  return level;
}

float Preprocessor::CellGround(const GroundGrid& grid, std::int32_t c, float level) {
  float& g = cell_ground_[static_cast<std::size_t>(c)];
  if (!std::isnan(g)) return g;  // computed once per cell
  const int side = grid.side;
  // The lowest return of the 3 x 3 cells around, within the tolerance (growing with the
  // distance from the sensor by ground_max_slope) of the scan's level.
  float m = std::numeric_limits<float>::infinity();
  for (int dy = -1; dy <= 1; ++dy) {
    for (int dx = -1; dx <= 1; ++dx) {
      m = std::min(m, cell_min_[static_cast<std::size_t>(c + dy * side + dx)]);
    }
  }
  const float tol = static_cast<float>(params_.ground_tolerance);
  const int cx = c % side, cy = c / side;
  const float tol_here =
      tol + static_cast<float>(params_.ground_max_slope * params_.ground_cell *
                               std::hypot(cx - side / 2, cy - side / 2));
  g = std::clamp(m, level - tol_here, level + tol_here);
  // Above the scan's level by more than the tolerance (far cells only): no higher than the
  // lowest returns around allow, and no lower than that tolerance (a single low outlier, which
  // real clouds have, must not pull down the ground of the cells around it).
  if (g > level + tol) g = std::max(level + tol, std::min(g, cell_bound_[static_cast<std::size_t>(c)]));
  return g;
}

}  // namespace vtrack
