// Preprocessing of one LADAR sweep (not in the paper; docs/design.md, section 4.2):
//
//  1. drop returns that are not finite, closer than min_range or farther than max_range, or
//     whose time offset lies outside the sweep;
//  2. ego-motion compensation: every return is placed in the world frame with the ego pose
//     interpolated at its own time utime + dt_us[i] (PoseHistory);
//  3. for 3-D clouds (num_rings >= ground_min_rings), remove the ground and what is above the
//     vehicles: keep returns whose height above the local ground lies in [min_height,
//     max_height]. The local ground is either a fixed plane in the body frame ("band") or, by
//     default, the lowest return in the 3x3 neighbourhood of a coarse world grid cell, clamped
//     to within ground_tolerance + ground_max_slope * distance of the scan's overall ground
//     level ("grid"), which follows slopes and any sensor mounting height without
//     configuration. The clamp keeps a cell that sees only a roof from being taken as ground.
//     Far from the sensor that clamp is loose (2.25 m at 33 m), so where the local ground lies
//     more than ground_tolerance above the scan's level it is also kept below the lowest return
//     of every other cell plus ground_max_grade per metre between them (but not below that
//     tolerance: a single low outlier must not pull down the ground of the cells around it):
//     a car whose lower part another vehicle hides shows only its roof line, the ground around
//     it is unseen, and the lowest return of its cells is that roof line; the road seen beside
//     or in front of it bounds its ground instead.
//
// Speed: the pose is looked up at "knots" every knot_us over the sweep and the world_from_sensor
// matrix is interpolated linearly between knots per point. Against slerp at each point's own
// time this errs by at most (omega * knot_us)^2 / 8 * range, e.g. 1 rad/s, 1 ms, 80 m: 1e-5 m
// (tests/tracker/core/preprocess_test.cc checks it against PoseHistory::At per point).
// The rotation of a return runs in single precision, four lanes at once (the two rows of the
// rotation and of its rate); the world-scale translation stays in double. Against the same
// interpolation in double a return moves by at most kCompensationTolerance (below).
#pragma once

#include <Eigen/Core>

#include <cstdint>
#include <memory>
#include <string>
#include <type_traits>
#include <utility>
#include <vector>

#include "base/pose.h"
#include "tracker/core/parallel_for.h"
#include "tracker/core/parameters.h"
#include "tracker/core/scan.h"

namespace vtrack {

// std::allocator, but a resize() that grows leaves the new elements uninitialised (default-
// initialised) instead of zeroing them: the returns' arrays are sized for every return of a sweep,
// filled by index and trimmed to the returns kept, so each sweep would otherwise zero again what
// the last one trimmed off (2 MB of a 64-beam sweep, every element then overwritten).
template <class T>
struct UninitialisedAllocator : std::allocator<T> {
  template <class U>
  struct rebind {
    using other = UninitialisedAllocator<U>;
  };
  UninitialisedAllocator() = default;
  template <class U>
  UninitialisedAllocator(const UninitialisedAllocator<U>&) noexcept {}
  template <class U>
  void construct(U* p) noexcept(std::is_nothrow_default_constructible_v<U>) {
    ::new (static_cast<void*>(p)) U;
  }
  template <class U, class... Args>
  void construct(U* p, Args&&... args) {
    ::new (static_cast<void*>(p)) U(std::forward<Args>(args)...);
  }
};
// An array of one value per return (WorldPoints).
template <class T>
using ReturnArray = std::vector<T, UninitialisedAllocator<T>>;

// Returns kept after preprocessing, world frame, structure of arrays.
struct WorldPoints {
  ReturnArray<double> x, y;            // [m] world frame
  ReturnArray<float> height;           // [m] above the local ground (body z for 2-D scans)
  ReturnArray<std::int32_t> index;     // [-] index of the return in the scan
  ReturnArray<std::int16_t> ring;      // [-]
  // [m] 3-D clouds, grid ground only (else empty): the height above the local ground of the
  // highest return in the return's ground cell, those above max_height included (a car's roof,
  // a van's, a truck's, a tree crown, a building front). A vehicle-evidence feature
  // (vehicle_evidence.h).
  ReturnArray<float> column_top;

  std::size_t size() const { return x.size(); }
  void clear();
  void reserve(std::size_t n);
  void push_back(double px, double py, float h, std::int32_t i, std::int16_t r);
};

// How far the single-precision compensation may place a return from the same interpolation in
// double, per metre of the return's range from the sensor: the rotation of a return of range r
// is a few float operations on values up to r, each rounding by at most 2^-24 r (6e-8 r); the
// worst found over random poses, ranges to 1000 m and yaw rates to 8 rad/s is 2.3e-7 r, so
// 1e-6 r (1.2e-4 m at 120 m) leaves a margin of four. The height above the body's origin rounds
// its mounting term too, an absolute 1e-7 m: within 1e-6 of the range from 0.1 m on.
// tests/tracker/core/preprocess_test.cc holds the compensation to it against a double reference.
constexpr double kCompensationTolerance = 1e-6;  // [m per m of range]

// No LADAR measures farther than this (the longest-range automotive ones reach ~500 m): a
// return beyond it is refused as absurd ("far_point") when the scan states no max_range.
constexpr double kMaxReturnRange = 5000.0;  // [m]

struct PreprocessStats {
  std::int64_t input = 0;         // returns in the scan
  std::int64_t nonfinite = 0;     // NaN / Inf coordinates
  std::int64_t far = 0;           // beyond the sensor's max_range or kMaxReturnRange: absurd
  std::int64_t bad_ring = 0;      // ring outside [-1, num_rings) (-1: unknown)
  std::int64_t bad_time = 0;      // dt_us outside [0, sweep_duration_us]
  std::int64_t out_of_range = 0;  // nearer than min_range or farther than max_range
  std::int64_t ground = 0;        // removed as ground or above max_height
  std::int64_t kept = 0;
};

enum class CompensationStatus {
  kOk,            // every knot interpolated between poses
  kExtrapolated,  // some knot lies after the newest pose (within the allowed extrapolation)
  kNoPose,        // no pose for part of the sweep: the scan cannot be placed in the world
};

struct PreprocessResult {
  CompensationStatus status = CompensationStatus::kNoPose;
  PoseHistory::LookupStatus failed_lookup = PoseHistory::LookupStatus::kOk;  // if kNoPose
  PreprocessStats stats;
  Eigen::Vector2d sensor_xy = Eigen::Vector2d::Zero();  // [m] sensor origin at mid-sweep, world
  Eigen::Isometry3d world_from_body_start = Eigen::Isometry3d::Identity();
};

// Reuses its buffers from scan to scan: no allocation per point once warmed up.
class Preprocessor {
 public:
  explicit Preprocessor(const PreprocessParams& params);
  // pool (null: none; else outliving this): its threads place the returns and bin them in the
  // ground grid; the results do not depend on how many there are.
  void SetPool(WorkerPool* pool) { pool_ = pool; }

  // Fills *out (cleared first). max_extrapolation_us: how far past the newest pose a return's
  // time may lie. With no pose for part of the sweep, status is kNoPose and *out is empty.
  // (The size limit max_points is enforced by the caller, Tracker, before any work.)
  PreprocessResult Run(const LadarScan& scan, const PoseHistory& poses,
                       std::int64_t max_extrapolation_us, WorldPoints* out);

  const PreprocessParams& params() const { return params_; }

 private:
  // The knots' poses and the sensor's origin at mid-sweep in *result; false (status kNoPose)
  // if a knot has no pose.
  bool ComputeKnots(const LadarScan& scan, const PoseHistory& poses,
                    std::int64_t max_extrapolation_us, PreprocessResult* result);
  // The ground grid (cells of ground_cell around the sensor, one spare ring at the edge).
  struct GroundGrid {
    int side = 0;           // [cells]
    double x0 = 0, y0 = 0;  // [m] world corner
    double cell = 1.0;      // [m]
    double inv_cell = 1.0;  // [1/m] 1 / cell
    bool exact_inverse = true;  // 1 / cell is exact (cell a power of two): x * inv_cell = x / cell
    // The cell of each of n returns (x, y) into cells[0, n), each cell's lowest height
    // lowered by theirs in lowest[].
    void Bin(const double* x, const double* y, const float* height, std::size_t n,
             std::int32_t* cells, float* lowest) const;
  };
  GroundGrid MakeGroundGrid(const Eigen::Vector2d& center) const;
  // Every usable return placed in the world (counts what is not in *stats); with grid (3-D
  // clouds, grid ground), each also binned in it (point_cell_, cell_min_) in the same pass.
  void Compensate(const LadarScan& scan, const GroundGrid* grid, PreprocessStats* stats,
                  WorldPoints* out);
  // The kept returns of [begin, end) of the scan (refusal_ says which) placed in the world,
  // written to *out's arrays (sized already) from index first_out on; each refused one counted
  // by its reason in refused[0, kNumRefusals); with grid, binned in it (the cell of output
  // return k in cells[k]; lowest: this call's grid of lowest heights).
  void PlaceReturns(const LadarScan& scan, std::size_t begin, std::size_t end,
                    std::size_t first_out, const GroundGrid* grid, std::int32_t* cells,
                    float* lowest, WorldPoints* out, std::int64_t* refused) const;
  // Ground: per cell the local ground height (the lowest return around, bounded by the scan's
  // level and the grade), and returns within [min_height, max_height] above it kept.
  // The returns are binned (Compensate).
  void RemoveGround(const GroundGrid& grid, WorldPoints* pts, PreprocessStats* stats);
  void BoundByGrade(const GroundGrid& grid);
  float GroundLevel(const GroundGrid& grid) const;
  // The ground of a cell, computed and stored in cell_ground_.
  float CellGround(const GroundGrid& grid, std::int32_t cell, float level);
  void RemoveGroundBand(WorldPoints* pts, PreprocessStats* stats) const;

  PreprocessParams params_;
  WorkerPool* pool_ = nullptr;
  // One interval between two knots, [t0, t0 + knot_us] of the sweep (the last one may be
  // shorter): rows x and y of world_from_sensor at t0 and their rate of change, for a return u
  // microseconds into it: world = (rotation rows 0-1 + u rows 2-3) p + translation + u rate.
  struct Knot {
    Eigen::Matrix<float, 4, 3> rotation;  // [-] rows 0-1 at t0, [1/us] rows 2-3 their rate
    Eigen::Vector2d translation;          // [m] at t0
    Eigen::Vector2d translation_rate;     // [m/us]
  };
  std::vector<Knot> knots_;
  std::vector<Eigen::Matrix<double, 2, 4>> knot_poses_;  // rows x and y at each knot (scratch)
  std::vector<std::uint8_t> refusal_;  // per return of the scan: why it is refused, 0 if kept
  // Ground grid.
  std::vector<float> cell_min_, cell_ground_, cell_bound_, cell_top_;
  std::vector<std::vector<float>> worker_cell_min_;  // per thread but the first: its cell_min_
  std::vector<std::vector<float>> worker_cell_top_;  // per thread but the first: its cell_top_
  std::vector<std::int32_t> point_cell_;
};

}  // namespace vtrack
