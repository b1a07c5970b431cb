// Segmentation of the preprocessed returns into objects (not in the paper; docs/design.md,
// section 4.3).
//
// - Single-plane scans (num_rings == 1): returns are in scan order; a new segment starts where
//   two consecutive returns lie farther apart than max(jump_abs, jump_rel * range) (a range
//   jump). A full 360 deg sweep wraps: the last and first returns may belong to one segment.
// - 3-D clouds: returns are binned in a world-aligned grid around the sensor (cell_size) and
//   occupied cells are joined into connected components (8- or 4-neighbourhood). Cells are
//   stamped with a scan counter, so the grid is never cleared: the cost is linear in the returns.
//
// Segments with fewer than min_points returns or wider than max_extent are dropped (walls and
// buildings are not objects to track).
#pragma once

#include <Eigen/Core>

#include <cstdint>
#include <string>
#include <vector>

#include "tracker/core/preprocess.h"
#include "tracker/core/parameters.h"

namespace vtrack {

struct Segment {
  std::int32_t begin = 0;  // [-] range [begin, end) in Segments::point
  std::int32_t end = 0;
  Eigen::Vector2d min = Eigen::Vector2d::Zero();  // [m] world bounding box
  Eigen::Vector2d max = Eigen::Vector2d::Zero();
  Eigen::Vector2d centroid = Eigen::Vector2d::Zero();  // [m]
  std::int32_t size() const { return end - begin; }
};

struct Segments {
  std::vector<std::int32_t> point;  // indices into WorldPoints, grouped by segment
  std::vector<Segment> segments;
  std::int64_t dropped_small = 0;   // segments dropped for too few points
  std::int64_t dropped_large = 0;   // segments dropped for too large an extent
  void clear();
};

class Segmenter {
 public:
  explicit Segmenter(const SegmentationParams& params);

  // scan_line: true for single-plane scans (num_rings == 1). sensor_xy: the sensor origin in the
  // world frame (range of a return for the jump threshold; centre of the grid).
  void Run(const WorldPoints& pts, bool scan_line, const Eigen::Vector2d& sensor_xy,
           Segments* out);

 private:
  void RunScanLine(const WorldPoints& pts, const Eigen::Vector2d& sensor_xy, Segments* out);
  void RunGrid(const WorldPoints& pts, const Eigen::Vector2d& sensor_xy, Segments* out);
  // Grid steps: every return's cell slot; the returns sorted by slot; one connected component
  // of occupied cells from seed, its returns appended to out->point.
  void BinReturns(const WorldPoints& pts, const Eigen::Vector2d& sensor_xy);
  void SortReturnsByCell(std::size_t num_points);
  void CollectComponent(std::size_t seed, std::int32_t label, Segments* out);
  // Appends a segment from out->point[begin, end) if it passes the size filters.
  void Finish(const WorldPoints& pts, std::int32_t begin, Segments* out);

  SegmentationParams params_;
  int side_ = 0;
  std::uint32_t generation_ = 0;
  struct Cell {                  // side by side: one cache line per look-up
    std::uint32_t stamp = 0;     // == generation_ if occupied in this scan
    std::int32_t slot = 0;       // index into occupied_ for occupied cells
  };
  std::vector<Cell> cells_;
  std::vector<std::int32_t> occupied_;     // cell ids
  std::vector<std::int32_t> slot_count_, slot_start_, slot_label_;
  std::vector<std::int32_t> point_cell_, sorted_, stack_;
};

}  // namespace vtrack
