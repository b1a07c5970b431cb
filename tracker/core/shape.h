// The vehicle shape model, paper Section 2.3 and docs/design.md note 8: the length and the width of the
// vehicle rectangle, each estimated from a histogram of its measurements.
//
// Each measurement adds its weight to the histogram (shared between the two nearest bins);
// weights decay exponentially, halving every half_life seconds, so the estimate follows a vehicle whose size was misjudged at first (the
// paper's "normalisation determines the half-life"). From the histogram:
//  1. Outliers: the largest excluded_fraction (5%) of the weight is excluded: peaks above the
//     (1 - excluded_fraction) weighted quantile cannot be chosen. (The excluded samples still
//     shape the histogram; removing them instead would cut the upper flank of the true peak and
//     bias it short.)
//  2. Peaks: the histogram is smoothed with a Gaussian kernel (smoothing_std, about the noise of
//     one dimension measurement) and its local maxima are found. A peak counts if its height is
//     at least min_peak_fraction of the highest eligible peak: without this, any small bump of
//     noise would be a "peak". (The paper leaves what a peak is open.)
//  3. Occlusion: partial views only ever give shorter lengths, so among the counted peaks the one
//     of greatest length is the estimate (refined by a parabola through the smoothed bins).
// Consequences of the longest-peak rule, by design: a size that grows is followed as soon as its
// peak reaches min_peak_fraction of the old one (for a steady stream of samples after
// half_life * log2(1 + min_peak_fraction), 0.32 half-lives at the default); a size that shrinks
// is followed only when the old peak has decayed below min_peak_fraction of the new one, after
// half_life * log2((1 + f) / f) (2.3 half-lives at f = 0.25), since a shorter peak looks just
// like an occluded view. These times are for samples of equal weight: where the new samples weigh
// w times as much as the old ones (Add's sample_weight), add about half_life * log2(1 / w).
#pragma once

#include <optional>
#include <utility>
#include <string>
#include <vector>
#include "tracker/core/parameters.h"

namespace vtrack {

// The decaying histogram of one dimension (length or width).
class DimensionHistogram {
 public:
  // Throws std::invalid_argument with the Validate() message if params are invalid.
  explicit DimensionHistogram(const ShapeParams& params = ShapeParams());

  // Adds a measurement value_m [m] taken at time_s [s], worth sample_weight full samples
  // (DimensionSampleWeight). A sample older than the newest one adds its already-decayed weight.
  // Returns false, leaving the histogram unchanged, if a value is not finite, value_m <= 0 or
  // sample_weight <= 0.
  bool Add(double time_s, double value_m, double sample_weight = 1.0);

  // The length of the longest counted peak [m]; empty before any sample.
  std::optional<double> Estimate() const;

  // Sum of the sample weights, decayed to time_s [s] (>= the newest sample's time); 0 if empty.
  double TotalWeight(double time_s) const;

  const ShapeParams& params() const { return params_; }

 private:
  ShapeParams params_;
  std::vector<double> bins_;    // decayed weights, bin i centred at (i + 1/2) * bin_width
  // Every bin outside [nonzero_lo_, nonzero_hi_] holds exactly 0 (inside, some may too): a
  // track's samples span a few dozen of the hundreds of bins, and only these are decayed and
  // searched. Empty (hi < lo) before any sample.
  int nonzero_lo_ = 0, nonzero_hi_ = -1;
  std::vector<double> kernel_;  // smoothing kernel, kernel_[k] for offsets -K..K
  double overflow_ = 0.0;       // decayed weight of samples above max_dimension
  double total_ = 0.0;          // decayed weight of all samples
  double newest_time_ = 0.0;    // [s] time the weights are decayed to
  bool empty_ = true;
};

// The weight of a dimension measurement whose value is known to std_m [m] (1 sigma):
// min(1, (floor_std_m / std_m)^2), its inverse variance relative to that of a measurement known
// to floor_std_m [m], which counts as one whole sample (as does any better one). The histogram
// reads only ratios of weights, so floor_std_m sets nothing but that cap. A face seen densely
// end to end weighs about 1; the long side of a car seen at a grazing angle, a few returns
// 0.5-1 m apart whose ends are each uncertain by about a spacing, weighs a hundredth or less, so
// that a handful of such views make no peak of their own and, by the longest-peak rule, no
// estimate (a 6 m length on a 4.5 m car). 1 if std_m is NaN or <= 0 (not known); 0 if it is
// infinite (nothing known: Add refuses the sample).
double DimensionSampleWeight(double std_m, double floor_std_m);

// Length and width of one tracked object.
class ShapeEstimator {
 public:
  explicit ShapeEstimator(const ShapeParams& params = ShapeParams())
      : length_(params), width_(params) {}

  bool AddLength(double time_s, double length_m, double weight = 1.0) {
    return length_.Add(time_s, length_m, weight);
  }
  bool AddWidth(double time_s, double width_m, double weight = 1.0) {
    return width_.Add(time_s, width_m, weight);
  }
  std::optional<double> Length() const { return length_.Estimate(); }
  std::optional<double> Width() const { return width_.Estimate(); }

  // Exchanges the length and width histograms: for a hypothesis whose orientation is turned by
  // 90 deg (Ekf::Convert with heading_offset pi/2).
  void SwapLengthAndWidth() { std::swap(length_, width_); }

  const DimensionHistogram& length_histogram() const { return length_; }
  const DimensionHistogram& width_histogram() const { return width_; }

 private:
  DimensionHistogram length_;
  DimensionHistogram width_;
};

}  // namespace vtrack
