// The returns of one track (or one new object) as the fit wants them (paper Section 2.4): in a
// local frame, with their mean measurement time and, for 3-D clouds, reduced to the outline the
// sensor sees.
//
// The outline: per bearing bin (bin_deg, seen from the sensor) the nearest return. A 3-D cloud
// also holds roofs, windows and returns stacked in columns; the edge / corner fit wants the
// visible outline, as a single-plane scanner gives it. It also bounds the fit's cost.
//
// 3-D clouds: the outline takes, per bin, the nearest return that stands on a vertical face:
// another return of the bin lies within support_range of its range at a height differing by
// support_height or more. A ring that grazes a horizontal surface (a roof, a bonnet) hits it at
// a fixed distance from the sensor, so those returns move with the ego vehicle; fitted as an
// edge they make a parked car look like a mover. Faces are hit by several rings at nearly the
// same range. Unless no bin of the segment has such support and the returns of one ring span
// more than arc_span of range: one ring seen over something nearer (the roof line of a car
// behind another), which a grazed roof or bonnet, at one range, cannot give. Then the nearest
// return per bin.
#pragma once

#include <Eigen/Core>

#include <cstdint>
#include <utility>
#include <vector>

#include "tracker/core/parameters.h"
#include "tracker/core/preprocess.h"
#include "tracker/core/scan.h"
#include "tracker/core/track.h"

namespace vtrack {

class OutlineExtractor {
 public:
  explicit OutlineExtractor(const OutlineParams& params) : params_(params) {}

  // Fills *out with the returns idx (non-empty, indices into points) of scan: relative to an
  // origin near them (floats keep full precision far from the world origin), their mean
  // measurement time, extent, and the outline seen from sensor_xy. out->size() is 0 if a 3-D
  // segment has no return on a vertical face (only roofs: nothing to fit).
  void Extract(const WorldPoints& points, const std::vector<std::int32_t>& idx,
               const LadarScan& scan, const Eigen::Vector2d& sensor_xy, PointSet* out);

 private:
  // Copies the returns into out's local frame; their bounding box (local) in *lo, *hi.
  void Gather(const WorldPoints& points, const std::vector<std::int32_t>& idx,
              const LadarScan& scan, PointSet* out, Eigen::Vector2d* lo,
              Eigen::Vector2d* hi) const;
  // Groups the returns by bearing bin into keys_: bins ascending, a bin's returns in k order
  // (or by key); bin_runs_ holds each non-empty bin's [begin, end) in keys_.
  void SortByBin(const PointSet& ps, const Eigen::Vector2d& sensor, const Eigen::Vector2d& ref,
                 double bin_rad);
  // Sorts keys_[begin, end), in k order, by key.
  void SortBin(std::size_t begin, std::size_t end);
  // Appends to outline_x_/y_ per bin the nearest return with support (support_height > 0), or
  // the nearest return (support_height 0).
  void PickPerBin(const WorldPoints& points, const std::vector<std::int32_t>& idx,
                  const PointSet& ps, double support_height);
  // The entry of the bin keys_[begin, end) PickPerBin takes, or end if none.
  std::size_t PickInBin(const WorldPoints& points, const std::vector<std::int32_t>& idx,
                        std::size_t begin, std::size_t end, double support_height);
  // Fills bin_range_ and bin_height_ with the range (RangeOf) and height of keys_[begin, end).
  void LoadBin(const WorldPoints& points, const std::vector<std::int32_t>& idx, std::size_t begin,
               std::size_t end);
  // Whether another return of the bin loaded by LoadBin within support_range of the range of
  // its entry a (from the bin's first) differs from its height by support_height or more.
  bool HasSupport(std::size_t a, double support_height) const;
  // The largest range span of one ring's returns.
  double LongestRingSpan(const WorldPoints& points, const std::vector<std::int32_t>& idx);
  // Range [m] of keys_[a].
  double RangeOf(std::size_t a) const;

  OutlineParams params_;
  // Scratch reused from segment to segment.
  std::vector<std::pair<std::int64_t, std::int32_t>> keys_;  // (bin * 2^32 + range^2 [cm^2], k)
  std::vector<std::pair<std::int64_t, std::int32_t>> sorted_keys_;
  std::vector<std::int64_t> bins_;       // bin of keys_[k]
  std::vector<std::uint32_t> bin_end_;   // counting sort: per bin (from the lowest) its end
  std::vector<std::pair<std::size_t, std::size_t>> bin_runs_;  // non-empty bins in keys_
  std::vector<double> bin_range_;        // [m] LoadBin: range of each entry of one bin
  std::vector<float> bin_height_;        // [m] LoadBin: height of each entry of one bin
  std::vector<float> outline_x_, outline_y_;
  struct RingSpan {
    std::int16_t ring;
    double lo, hi;  // [m] range of the ring's returns in a segment
  };
  std::vector<RingSpan> ring_span_;
};

}  // namespace vtrack
