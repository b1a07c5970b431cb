#include "tracker/core/preprocess.h"

#include <algorithm>
#include <array>
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

namespace {

// Fewer returns than this per thread are placed (and binned) on the calling thread: a loop on
// the pool costs the wake-up of its threads (a few us, at times 100 us or more on a busy
// machine), the time of placing some 10,000 returns at its worst.
constexpr std::size_t kMinReturnsPerThread = 16384;  // [returns]

// How many threads of pool (none: the calling one) to share n returns among.
int ChunksFor(std::size_t n, const WorkerPool* pool) {
  const int threads = pool != nullptr ? pool->threads() : 1;
  return static_cast<int>(std::clamp<std::size_t>(n / kMinReturnsPerThread, 1,
                                                  static_cast<std::size_t>(threads)));
}

// The first return of chunk c of `chunks` over n returns.
std::size_t ChunkBegin(std::size_t n, int c, int chunks) {
  return n * static_cast<std::size_t>(c) / static_cast<std::size_t>(chunks);
}

}  // namespace

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
  // Ground: a grid of local ground heights (3-D clouds; the returns binned in it as they are
  // placed), or a fixed band.
  const bool cloud_3d = scan.num_rings >= params_.ground_min_rings;
  const bool grid_ground = cloud_3d && params_.ground == PreprocessParams::Ground::kGrid;
  const GroundGrid grid = MakeGroundGrid(result.sensor_xy);
  Compensate(scan, grid_ground ? &grid : nullptr, &result.stats, out);
  if (grid_ground) {
    RemoveGround(grid, out, &result.stats);
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
  // world_from_sensor's rows x and y at each knot, in double until the intervals are made.
  std::vector<Eigen::Matrix<double, 2, 4>>& knot_m = knot_poses_;
  knot_m.resize(static_cast<std::size_t>(num_intervals + 1));
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
    knot_m[static_cast<std::size_t>(k)] = world_from_sensor.topRows<2>();
  }
  knots_.resize(static_cast<std::size_t>(num_intervals));
  for (std::int64_t k = 0; k < num_intervals; ++k) {
    const auto& m0 = knot_m[static_cast<std::size_t>(k)];
    const std::int64_t length = std::min((k + 1) * step, sweep) - k * step;  // [us]
    // A sweep of no duration has one interval of no length: no rate.
    const Eigen::Matrix<double, 2, 4> rate =
        length > 0 ? Eigen::Matrix<double, 2, 4>((knot_m[static_cast<std::size_t>(k + 1)] - m0) /
                                                 static_cast<double>(length))
                   : Eigen::Matrix<double, 2, 4>::Zero();
    Knot& knot = knots_[static_cast<std::size_t>(k)];
    knot.rotation.topRows<2>() = m0.leftCols<3>().cast<float>();
    knot.rotation.bottomRows<2>() = rate.leftCols<3>().cast<float>();
    knot.translation = m0.col(3);
    knot.translation_rate = rate.col(3);
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
  std::int32_t sweep = 0;         // [us]

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
    sweep = std::max<std::int32_t>(0, scan.sweep_duration_us);
  }

  // Why each return is refused (a Refusal per return, kKept for those kept) into reason[0, n),
  // in one pass that the compiler vectorises: no branch, every condition a lane mask. When
  // several hold, the one of highest value names the reason: not finite, then beyond what the
  // sensor measures, a bad ring, outside the tracker's range limits, a bad time.
  enum Refusal : std::uint8_t {
    kKept, kBadTime, kOutOfRange, kBadRing, kFar, kNonfinite, kNumRefusals
  };
  void Classify(const LadarScan& scan, std::uint8_t* reason) const {
    if (has_ring && has_dt) return Classify<true, true>(scan, reason);
    if (has_ring) return Classify<true, false>(scan, reason);
    if (has_dt) return Classify<false, true>(scan, reason);
    Classify<false, false>(scan, reason);
  }
  template <bool kRing, bool kDt>
  void Classify(const LadarScan& scan, std::uint8_t* reason) const {
    const std::size_t n = scan.size();
    const float* const x = scan.x.data();
    const float* const y = scan.y.data();
    const float* const z = scan.z.data();
    const std::int16_t* const ring = kRing ? scan.ring.data() : nullptr;
    const std::int32_t* const dt = kDt ? scan.dt_us.data() : nullptr;
    const float fmax = std::numeric_limits<float>::max();
    // ring + 1 must lie in [0, num_rings]; with num_rings < 0 no ring is valid, -1 included.
    const std::uint32_t ring_end = static_cast<std::uint32_t>(std::max(num_rings + 1, 0));
    const std::uint32_t time_limit = static_cast<std::uint32_t>(sweep);
    for (std::size_t i = 0; i < n; ++i) {
      // Not finite: NaN fails every comparison, Inf is beyond the largest float.
      const bool nonfinite =
          !((std::abs(x[i]) <= fmax) & (std::abs(y[i]) <= fmax) & (std::abs(z[i]) <= fmax));
      const double px = x[i], py = y[i], pz = z[i];
      const double r2 = px * px + py * py + pz * pz;
      // Ring in [-1, num_rings) (-1: unknown, a KITTI frame whose lasers could not be told
      // apart: kept), time in [0, sweep]: one unsigned comparison each.
      const bool bad_ring = kRing && static_cast<std::uint32_t>(ring[i] + 1) >= ring_end;
      const bool bad_time = kDt && static_cast<std::uint32_t>(dt[i]) > time_limit;
      const bool out_of_range = (r2 < min_r2) | (r2 > max_r2);
      std::uint8_t r = bad_time ? kBadTime : kKept;
      r = std::max<std::uint8_t>(r, out_of_range ? kOutOfRange : kKept);
      r = std::max<std::uint8_t>(r, bad_ring ? kBadRing : kKept);
      r = std::max<std::uint8_t>(r, r2 > far_r2 ? kFar : kKept);
      reason[i] = std::max<std::uint8_t>(r, nonfinite ? kNonfinite : kKept);
    }
  }
  // Counts the refused returns of each reason into *stats.
  static void Count(const std::int64_t (&count)[kNumRefusals], PreprocessStats* stats) {
    stats->nonfinite += count[kNonfinite];
    stats->far += count[kFar];
    stats->bad_ring += count[kBadRing];
    stats->out_of_range += count[kOutOfRange];
    stats->bad_time += count[kBadTime];
  }
};

}  // namespace

void Preprocessor::Compensate(const LadarScan& scan, const GroundGrid* grid,
                              PreprocessStats* stats, WorldPoints* out) {
  const std::size_t n = scan.size();
  // Written by index into arrays sized for every return, trimmed at the end (no push_back); their
  // resize() writes nothing (ReturnArray), each element is written below before it is read.
  out->x.resize(n);
  out->y.resize(n);
  out->height.resize(n);
  out->index.resize(n);
  out->ring.resize(n);
  out->column_top.clear();  // the grid ground's (RemoveGround); none otherwise
  refusal_.resize(n);
  const ReturnFilter filter(scan, params_);
  filter.Classify(scan, refusal_.data());
  // The returns in chunks, one per thread, each written from where the kept returns before it
  // end: the same arrays, in the same order, as one pass would write. Binned in the ground grid
  // as they are placed, each chunk lowers a grid of its own (below): only while the grid is no
  // larger than the returns (1 m cells within 80 m: 26,569 cells), else on this thread alone
  // (a grid of 0.1 m cells would have each thread fill and the caller merge 2.6 M cells).
  const std::size_t num_cells = grid != nullptr ? static_cast<std::size_t>(grid->side) * grid->side : 0;
  const int chunks = num_cells <= n ? ChunksFor(n, pool_) : 1;
  std::vector<std::size_t> first_out(static_cast<std::size_t>(chunks) + 1, 0);
  for (int c = 0; c < chunks; ++c) {
    first_out[static_cast<std::size_t>(c) + 1] =
        first_out[static_cast<std::size_t>(c)] +
        static_cast<std::size_t>(std::count(refusal_.begin() + static_cast<std::ptrdiff_t>(ChunkBegin(n, c, chunks)),
                                            refusal_.begin() + static_cast<std::ptrdiff_t>(ChunkBegin(n, c + 1, chunks)),
                                            std::uint8_t{ReturnFilter::kKept}));
  }
  // The chunks' grids of lowest returns (the first: cell_min_), then each cell the lowest over
  // them (a minimum: the same in any order).
  if (grid != nullptr) {
    cell_min_.assign(num_cells, std::numeric_limits<float>::infinity());
    point_cell_.resize(n);
    worker_cell_min_.resize(static_cast<std::size_t>(chunks) - 1);
  }
  std::vector<std::array<std::int64_t, ReturnFilter::kNumRefusals>> refused_by_chunk(
      static_cast<std::size_t>(chunks));
  const auto place = [&](std::size_t c, int) {
    refused_by_chunk[c].fill(0);
    float* lowest = nullptr;
    if (grid != nullptr) {
      lowest = cell_min_.data();
      if (c > 0) {
        std::vector<float>& own = worker_cell_min_[c - 1];
        own.assign(num_cells, std::numeric_limits<float>::infinity());
        lowest = own.data();
      }
    }
    PlaceReturns(scan, ChunkBegin(n, static_cast<int>(c), chunks),
                 ChunkBegin(n, static_cast<int>(c) + 1, chunks), first_out[c], grid,
                 point_cell_.data(), lowest, out, refused_by_chunk[c].data());
  };
  if (chunks == 1) {
    place(0, 0);
  } else {
    pool_->ParallelFor(static_cast<std::size_t>(chunks), place);
  }
  if (grid != nullptr) {
    float* const cmin = cell_min_.data();
    for (const std::vector<float>& own : worker_cell_min_) {
      for (std::size_t c = 0; c < num_cells; ++c) cmin[c] = std::min(cmin[c], own[c]);
    }
  }
  std::int64_t refused[ReturnFilter::kNumRefusals] = {};
  for (const auto& chunk : refused_by_chunk) {
    for (int r = 0; r < ReturnFilter::kNumRefusals; ++r) refused[r] += chunk[static_cast<std::size_t>(r)];
  }
  ReturnFilter::Count(refused, stats);
  const std::size_t kept = first_out.back();
  out->x.resize(kept);
  out->y.resize(kept);
  out->height.resize(kept);
  out->index.resize(kept);
  out->ring.resize(kept);
}

namespace {

// Places returns [0, n) of one knot interval (x, y, z in the sensor frame; dt null: each at the
// interval's start lo, else dt[m] - lo microseconds into it) into wx, wy (world) and wh (body
// height): rows x and y of the rotation at the interval's start (rotation rows 0-1) and their
// rates per microsecond (rows 2-3) in single precision, the translation and its rate in double.
// The operations of one return at a time, lane by lane, which the compiler vectorises.
void PlaceRun(const Eigen::Matrix<float, 4, 3>& rotation, const Eigen::Vector2d& translation,
              const Eigen::Vector2d& rate, const Eigen::Vector4f& body_z,
              const float* __restrict px, const float* __restrict py, const float* __restrict pz,
              const std::int32_t* __restrict dt, std::int32_t lo, std::size_t n,
              double* __restrict wx, double* __restrict wy, float* __restrict wh) {
  const float r00 = rotation(0, 0), r01 = rotation(0, 1), r02 = rotation(0, 2);
  const float r10 = rotation(1, 0), r11 = rotation(1, 1), r12 = rotation(1, 2);
  const float d00 = rotation(2, 0), d01 = rotation(2, 1), d02 = rotation(2, 2);
  const float d10 = rotation(3, 0), d11 = rotation(3, 1), d12 = rotation(3, 2);
  const double tx = translation.x(), ty = translation.y(), vx = rate.x(), vy = rate.y();
  const float bz0 = body_z(0), bz1 = body_z(1), bz2 = body_z(2), bz3 = body_z(3);
  const auto place = [&](std::size_t m, float u) {
    const float x = px[m], y = py[m], z = pz[m];
    const float a = r00 * x + r01 * y + r02 * z;
    const float b = r10 * x + r11 * y + r12 * z;
    const float da = d00 * x + d01 * y + d02 * z;
    const float db = d10 * x + d11 * y + d12 * z;
    const double ud = static_cast<double>(u);
    wx[m] = (tx + ud * vx) + static_cast<double>(a + u * da);
    wy[m] = (ty + ud * vy) + static_cast<double>(b + u * db);
    wh[m] = bz0 * x + bz1 * y + bz2 * z + bz3;
  };
  if (dt != nullptr) {
    for (std::size_t m = 0; m < n; ++m) place(m, static_cast<float>(dt[m] - lo));
  } else {
    for (std::size_t m = 0; m < n; ++m) place(m, 0.0f);
  }
}

}  // namespace

void Preprocessor::PlaceReturns(const LadarScan& scan, std::size_t begin, std::size_t end,
                                std::size_t first_out, const GroundGrid* grid,
                                std::int32_t* cells, float* lowest, WorldPoints* out,
                                std::int64_t* refused) const {
  const std::int64_t step = params_.knot_us;
  const std::int64_t last_interval = static_cast<std::int64_t>(knots_.size()) - 1;
  // Body-frame height of a return: the z row of body_from_sensor (the mounting is rigid).
  const Eigen::Vector4f body_z = scan.body_from_sensor.matrix().row(2).transpose().cast<float>();
  // dt / step without a 64-bit division per return: a floating-point guess, corrected to the
  // exact quotient.
  const double inv_step = 1.0 / static_cast<double>(step);
  // The arrays through local pointers: the stores below could alias the vectors' own members,
  // and the compiler would reload each pointer per return.
  double* const ox = out->x.data();
  double* const oy = out->y.data();
  float* const oh = out->height.data();
  std::int32_t* const oi = out->index.data();
  std::int16_t* const orng = out->ring.data();
  const Knot* const knots = knots_.data();
  const float* const sx = scan.x.data();
  const float* const sy = scan.y.data();
  const float* const sz = scan.z.data();
  const std::int16_t* const sring = scan.ring.size() == scan.size() ? scan.ring.data() : nullptr;
  const std::int32_t* const dts = scan.dt_us.size() == scan.size() ? scan.dt_us.data() : nullptr;
  const std::uint8_t* const refusal = refusal_.data();
  std::size_t w = first_out;
  std::size_t i = begin;
  while (i < end) {
    if (refusal[i] != ReturnFilter::kKept) {
      ++refused[refusal[i]];
      ++i;
      continue;
    }
    // The knot interval of return i, and the run of kept returns from i on in the same interval
    // (a sensor measures in time order, so runs are long: ~40 returns of a 64-beam sweep per 1 ms
    // interval, ring by ring).
    const std::int64_t dt = dts != nullptr ? dts[i] : 0;
    std::int64_t q = static_cast<std::int64_t>(static_cast<double>(dt) * inv_step);
    if (q * step > dt) --q;
    if ((q + 1) * step <= dt) ++q;
    const std::int64_t k = std::min(q, last_interval);
    const std::int64_t lo = k * step;
    // The last interval takes every later time (q beyond it: the sweep's end).
    const std::int64_t hi = k == last_interval ? std::numeric_limits<std::int64_t>::max() : lo + step;
    std::size_t run_end = i + 1;
    if (dts != nullptr) {
      while (run_end < end && refusal[run_end] == ReturnFilter::kKept && dts[run_end] >= lo &&
             dts[run_end] < hi) {
        ++run_end;
      }
    } else {
      while (run_end < end && refusal[run_end] == ReturnFilter::kKept) ++run_end;
    }
    const std::size_t n = run_end - i;
    double* const wx = ox + w;
    double* const wy = oy + w;
    float* const wh = oh + w;
    PlaceRun(knots[k].rotation, knots[k].translation, knots[k].translation_rate, body_z, sx + i,
             sy + i, sz + i, dts != nullptr ? dts + i : nullptr, static_cast<std::int32_t>(lo), n,
             wx, wy, wh);
    for (std::size_t m = 0; m < n; ++m) {
      oi[w + m] = static_cast<std::int32_t>(i + m);
      orng[w + m] = sring != nullptr ? sring[i + m] : std::int16_t{0};
    }
    // Binned while the run is at hand (a pass of its own over the placed returns read them back
    // from memory).
    if (grid != nullptr) grid->Bin(wx, wy, wh, n, cells + w, lowest);
    w += n;
    i = run_end;
  }
}

namespace {

// The ground level of a scan is the median of the lowest return per occupied cell within this
// distance of the sensor, where most cells see the road.
constexpr double kGroundLevelRadius = 20.0;  // [m]

// Keeps, of returns [begin, end) of *pts, those whose height above the ground (ground_of(i))
// lies in [min_h, max_h], moved up to begin on in their order, with that height; column(i, h) is
// called for each return at least min_h high (kept or above max_h); cells (if not null) is
// moved like the returns. Returns the end of the kept ones.
template <class GroundOf, class Column>
std::size_t KeepAboveGround(double min_h, double max_h, GroundOf ground_of, Column column,
                            std::size_t begin, std::size_t end, WorldPoints* pts,
                            std::vector<std::int32_t>* cells) {
  std::size_t w = begin;
  for (std::size_t i = begin; i < end; ++i) {
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
  return w;
}

// Returns [begin[c], kept_end[c]) of each range c moved to follow those of the ranges before (in
// order, forward: a range never moves past its own start), the arrays trimmed to them; cells (if
// not null) moved alike. Returns how many are kept.
std::size_t JoinKeptRanges(const std::vector<std::size_t>& begin,
                           const std::vector<std::size_t>& kept_end, WorldPoints* pts,
                           std::vector<std::int32_t>* cells) {
  std::size_t w = kept_end.front();
  for (std::size_t c = 1; c < begin.size(); ++c) {
    if (w == begin[c]) {  // nothing dropped before this range: already in place
      w = kept_end[c];
      continue;
    }
    const auto move = [&](auto& v) {
      std::copy(v.begin() + static_cast<std::ptrdiff_t>(begin[c]),
                v.begin() + static_cast<std::ptrdiff_t>(kept_end[c]),
                v.begin() + static_cast<std::ptrdiff_t>(w));
    };
    move(pts->x);
    move(pts->y);
    move(pts->height);
    move(pts->index);
    move(pts->ring);
    if (cells != nullptr) move(*cells);
    w += kept_end[c] - begin[c];
  }
  pts->x.resize(w);
  pts->y.resize(w);
  pts->height.resize(w);
  pts->index.resize(w);
  pts->ring.resize(w);
  return w;
}

}  // namespace

void Preprocessor::RemoveGroundBand(WorldPoints* out, PreprocessStats* stats) const {
  // Heights above a flat ground at ground_height_body.
  const float ground = static_cast<float>(params_.ground_height_body);
  const std::size_t n = out->size();
  const std::size_t kept = KeepAboveGround(
      params_.min_height, params_.max_height, [ground](std::size_t) { return ground; },
      [](std::size_t, float) {}, 0, n, out, nullptr);
  stats->ground = static_cast<std::int64_t>(n - JoinKeptRanges({0}, {kept}, out, nullptr));
}

Preprocessor::GroundGrid Preprocessor::MakeGroundGrid(const Eigen::Vector2d& center) const {
  GroundGrid grid;
  grid.cell = params_.ground_cell;
  grid.side = static_cast<int>(std::ceil(2.0 * params_.max_range / grid.cell)) + 3;
  grid.x0 = center.x() - 0.5 * grid.side * grid.cell;
  grid.y0 = center.y() - 0.5 * grid.side * grid.cell;
  // offset / cell by a multiplication when 1 / cell is exact (cell a power of two, as the default
  // 1 m): the same quotient without a division per return.
  int cell_exp = 0;
  grid.exact_inverse = std::frexp(grid.cell, &cell_exp) == 0.5;
  grid.inv_cell = 1.0 / grid.cell;
  return grid;
}

void Preprocessor::RemoveGround(const GroundGrid& grid, WorldPoints* pts,
                                PreprocessStats* stats) {
  BoundByGrade(grid);
  const float level = GroundLevel(grid);
  // The ground of every cell holding a return (those with a lowest return; never on the grid's
  // edge, where no return is binned).
  const std::size_t num_cells = static_cast<std::size_t>(grid.side) * grid.side;
  cell_ground_.assign(num_cells, std::numeric_limits<float>::quiet_NaN());
  for (std::size_t c = 0; c < num_cells; ++c) {
    if (cell_min_[c] < std::numeric_limits<float>::infinity()) {
      CellGround(grid, static_cast<std::int32_t>(c), level);
    }
  }
  // Returns in chunks, one per thread, each keeping its own within its range and the highest
  // return of each cell in a grid of its own (the first: cell_top_), merged by the maximum; the
  // ranges' kept returns then joined in order: what one pass would keep, where it would.
  const std::size_t n = pts->size();
  const int chunks = num_cells <= n ? ChunksFor(n, pool_) : 1;
  // Locals: the stores below could alias the parameters, which would be reloaded per return.
  const double min_h = params_.min_height, max_h = params_.max_height;
  const float* const ground = cell_ground_.data();
  const std::int32_t* const point_cell = point_cell_.data();
  cell_top_.assign(num_cells, 0.0f);
  worker_cell_top_.resize(static_cast<std::size_t>(chunks) - 1);
  std::vector<std::size_t> begin(static_cast<std::size_t>(chunks)), kept_end(begin.size());
  const auto keep = [&](std::size_t c, int) {
    float* top = cell_top_.data();
    if (c > 0) {
      worker_cell_top_[c - 1].assign(num_cells, 0.0f);
      top = worker_cell_top_[c - 1].data();
    }
    begin[c] = ChunkBegin(n, static_cast<int>(c), chunks);
    kept_end[c] = KeepAboveGround(
        min_h, max_h, [&](std::size_t i) { return ground[point_cell[i]]; },
        [&](std::size_t i, float h) {
          float& t = top[static_cast<std::size_t>(point_cell[i])];
          t = std::max(t, h);
        },
        begin[c], ChunkBegin(n, static_cast<int>(c) + 1, chunks), pts, &point_cell_);
  };
  if (chunks == 1) {
    keep(0, 0);
  } else {
    pool_->ParallelFor(static_cast<std::size_t>(chunks), keep);
  }
  for (const std::vector<float>& own : worker_cell_top_) {
    for (std::size_t c = 0; c < num_cells; ++c) cell_top_[c] = std::max(cell_top_[c], own[c]);
  }
  const std::size_t kept = JoinKeptRanges(begin, kept_end, pts, &point_cell_);
  stats->ground = static_cast<std::int64_t>(n - kept);
  // The top of each kept return's column: the highest return of its cell.
  pts->column_top.resize(kept);
  for (std::size_t i = 0; i < kept; ++i) {
    pts->column_top[i] = cell_top_[static_cast<std::size_t>(point_cell_[i])];
  }
}

void Preprocessor::GroundGrid::Bin(const double* x, const double* y, const float* height,
                                    std::size_t n, std::int32_t* cells, float* lowest) const {
  // Within max_range of the sensor, hence inside the grid (with one spare ring of cells) — unless
  // the ego pose jumps within the sweep: clamped before the conversion to int (which would be
  // undefined for a return 1e9 m away; found by tests/fuzz/tracker_fuzzer.cc), NaN to the edge.
  // offset / cell, by a multiplication when 1 / cell is exact (exact_inverse).
  const double last = side - 2.0;
  // Without branches (selects that give the same cell: below 1, or NaN, to 1; beyond the last to
  // it), so that the compiler vectorises the loop; then each return's cell lowered, in order.
  const auto cell_of = [last](double c) {
    c = c > last ? last : c;
    return static_cast<std::int32_t>(c >= 1.0 ? c : 1.0);
  };
  const double gx = x0, gy = y0, size = cell, inv = inv_cell;
  const int s = side;
  std::int32_t* __restrict const out = cells;
  const double* __restrict const xs = x;
  const double* __restrict const ys = y;
  if (exact_inverse) {
    for (std::size_t k = 0; k < n; ++k) {
      out[k] = cell_of((ys[k] - gy) * inv) * s + cell_of((xs[k] - gx) * inv);
    }
  } else {
    for (std::size_t k = 0; k < n; ++k) {
      out[k] = cell_of((ys[k] - gy) / size) * s + cell_of((xs[k] - gx) / size);
    }
  }
  for (std::size_t k = 0; k < n; ++k) lowest[cells[k]] = std::min(lowest[cells[k]], height[k]);
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
