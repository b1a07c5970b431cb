#include "tracker/core/shape.h"

#include <algorithm>
#include <cmath>
#include <stdexcept>

#include "tracker/core/motion_model.h"

namespace vtrack {

std::string ShapeParams::CrossProblem() const {
  if (!(max_dimension >= 2.0 * bin_width && max_dimension <= 1e5 * bin_width))
    return param::Problem("max_dimension", max_dimension, "m", "between 2 and 1e5 bin widths");
  if (!(smoothing_std <= 100.0 * bin_width))
    return param::Problem("smoothing_std", smoothing_std, "m", "at most 100 bin widths");
  return {};
}

DimensionHistogram::DimensionHistogram(const ShapeParams& params) : params_(params) {
  std::string error;
  if (!params_.Validate(&error)) throw std::invalid_argument(error);
  bins_.assign(static_cast<std::size_t>(std::ceil(params_.max_dimension / params_.bin_width)),
               0.0);
  const int half = static_cast<int>(std::ceil(3.0 * params_.smoothing_std / params_.bin_width));
  kernel_.resize(2 * half + 1);
  for (int k = -half; k <= half; ++k) {
    const double d = k * params_.bin_width / std::max(params_.smoothing_std, 1e-300);
    kernel_[k + half] = params_.smoothing_std > 0.0 ? std::exp(-0.5 * d * d) : 1.0;
  }
}

bool DimensionHistogram::Add(double time_s, double value_m, double sample_weight) {
  if (!std::isfinite(time_s) || !std::isfinite(value_m) || value_m <= 0.0) return false;
  if (!(sample_weight > 0.0 && std::isfinite(sample_weight))) return false;
  double weight = sample_weight;
  if (empty_) {
    newest_time_ = time_s;
    empty_ = false;
  } else if (time_s > newest_time_) {
    // Decay everything to the new time: w *= 2^(-elapsed / half_life).
    const double decay = std::exp2(-(time_s - newest_time_) / params_.half_life);
    total_ *= decay;
    overflow_ *= decay;
    const double negligible = 1e-15 * total_;  // keeps long-gone bins out of denormal range
    // The bins outside the range hold 0, which the decay and the cut leave 0.
    for (int i = nonzero_lo_; i <= nonzero_hi_; ++i) {
      double& b = bins_[static_cast<std::size_t>(i)];
      b *= decay;
      if (b < negligible) b = 0.0;
    }
    while (nonzero_lo_ <= nonzero_hi_ && bins_[static_cast<std::size_t>(nonzero_lo_)] == 0.0) {
      ++nonzero_lo_;
    }
    while (nonzero_hi_ >= nonzero_lo_ && bins_[static_cast<std::size_t>(nonzero_hi_)] == 0.0) {
      --nonzero_hi_;
    }
    newest_time_ = time_s;
  } else {
    weight = sample_weight * std::exp2(-(newest_time_ - time_s) / params_.half_life);
  }
  if (value_m > params_.max_dimension) {
    overflow_ += weight;
  } else {
    // Linear binning: the weight is shared between the two bins whose centres enclose the value,
    // so a peak's position is resolved below the bin width (the parabola in Estimate() finds it).
    const double last = static_cast<double>(bins_.size() - 1);
    const double pos = std::clamp(value_m / params_.bin_width - 0.5, 0.0, last);
    const double lower = std::floor(pos);
    const double frac = pos - lower;
    const auto i = static_cast<std::size_t>(lower);
    bins_[i] += weight * (1.0 - frac);
    if (frac > 0.0) bins_[i + 1] += weight * frac;
    const int first = static_cast<int>(i), last_written = frac > 0.0 ? first + 1 : first;
    if (nonzero_hi_ < nonzero_lo_) {
      nonzero_lo_ = first;
      nonzero_hi_ = last_written;
    } else {
      nonzero_lo_ = std::min(nonzero_lo_, first);
      nonzero_hi_ = std::max(nonzero_hi_, last_written);
    }
  }
  total_ += weight;
  return true;
}

double DimensionSampleWeight(double std_m, double floor_std_m) {
  if (std::isinf(std_m)) return 0.0;
  if (!(std_m > 0.0)) return 1.0;  // NaN or <= 0: not known
  const double r = floor_std_m / std_m;
  return std::min(1.0, r * r);
}

double DimensionHistogram::TotalWeight(double time_s) const {
  if (empty_) return 0.0;
  return total_ * std::exp2(-std::max(0.0, time_s - newest_time_) / params_.half_life);
}

std::optional<double> DimensionHistogram::Estimate() const {
  if (empty_ || total_ <= 0.0) return std::nullopt;
  const int n = static_cast<int>(bins_.size());
  const double bw = params_.bin_width;
  // Only bins [i0, i1] hold weight (a track's samples span a few dozen of the hundreds of bins):
  // the steps below skip the empty ends, where nothing changes (no quantile step, a smoothed
  // value of exactly 0, no peak).
  // (bins outside [nonzero_lo_, nonzero_hi_] hold 0: the first and last non-zero bins lie in it).
  int i0 = nonzero_lo_, i1 = nonzero_hi_;
  while (i0 <= i1 && bins_[i0] == 0.0) ++i0;
  if (i0 > i1) return std::nullopt;  // only samples above the range: no peak (as in step 3)
  while (bins_[i1] == 0.0) --i1;

  // 1. The (1 - excluded_fraction) weighted quantile, weight spread evenly within a bin.
  double cutoff = params_.max_dimension;
  {
    const double excluded = params_.excluded_fraction * total_;
    double above = overflow_;
    for (int i = i1; i >= i0 && above < excluded; --i) {
      if (above + bins_[i] >= excluded) {
        cutoff = (i + 1.0 - (excluded - above) / bins_[i]) * bw;
      }
      above += bins_[i];
    }
  }

  // 2. Smoothed histogram, over the bins within the kernel's reach of [i0, i1]: s_[i - lo].
  const int half = static_cast<int>(kernel_.size() / 2);
  const int lo = std::max(0, i0 - half), hi = std::min(n - 1, i1 + half);
  std::vector<double> s(static_cast<std::size_t>(hi - lo + 1), 0.0);
  for (int i = i0; i <= i1; ++i) {
    if (bins_[i] == 0.0) continue;
    const int k0 = std::max(-half, -i), k1 = std::min(half, n - 1 - i);
    for (int k = k0; k <= k1; ++k) s[i + k - lo] += bins_[i] * kernel_[k + half];
  }
  auto at = [&](int i) { return i < lo || i > hi ? 0.0 : s[i - lo]; };

  // 3. Eligible local maxima (centre at or below the cutoff), the highest of them, then the
  // longest one of at least min_peak_fraction of that height.
  auto is_peak = [&](int i) {
    return at(i) > 0.0 && (i == 0 || at(i) > at(i - 1)) && (i == n - 1 || at(i) >= at(i + 1)) &&
           (i + 0.5) * bw <= cutoff;
  };
  double highest = 0.0;
  for (int i = lo; i <= hi; ++i) {
    if (is_peak(i)) highest = std::max(highest, at(i));
  }
  if (highest <= 0.0) {
    // Every sample lies in the excluded top or above the range: nothing to choose from.
    return std::nullopt;
  }
  int chosen = -1;
  for (int i = hi; i >= lo && chosen < 0; --i) {
    if (is_peak(i) && at(i) >= params_.min_peak_fraction * highest) chosen = i;
  }

  // Vertex of the parabola through the chosen bin and its neighbours, within half a bin.
  double offset = 0.0;
  if (chosen > 0 && chosen < n - 1) {
    const double curvature = at(chosen - 1) - 2.0 * at(chosen) + at(chosen + 1);
    if (curvature < 0.0) {
      offset = std::clamp(0.5 * (at(chosen - 1) - at(chosen + 1)) / curvature, -0.5, 0.5);
    }
  }
  return (chosen + 0.5 + offset) * bw;
}

}  // namespace vtrack
