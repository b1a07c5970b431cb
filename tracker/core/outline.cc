#include "tracker/core/outline.h"

#include <algorithm>
#include <cmath>
#include <limits>

#include "base/angle.h"

namespace vtrack {
namespace {

constexpr std::int64_t kBinScale = std::int64_t{1} << 32;  // key = bin * kBinScale + range^2

// The bin of a key bin * 2^32 + range^2 (range^2 < 2^32, bin of either sign).
std::int64_t BinOf(std::int64_t key) {
  return key >= 0 ? key / kBinScale : -((-key + kBinScale - 1) / kBinScale);
}

// Bins are uniform in tan(bearing - ref): this bounds tan for returns beside or behind the
// sensor (they fall in the outermost bins).
constexpr double kMaxTan = 1e6;
// A return this near the sensor's line across the reference direction is beside the sensor.
constexpr double kMinAlong = 1e-6;  // [m]

}  // namespace

void OutlineExtractor::Extract(const WorldPoints& points, const std::vector<std::int32_t>& idx,
                               const LadarScan& scan, const Eigen::Vector2d& sensor_xy,
                               PointSet* out) {
  const bool multi_ring = scan.num_rings > 1;
  Eigen::Vector2d lo, hi;
  Gather(points, idx, scan, out, &lo, &hi);
  out->outline = multi_ring && params_.bin_deg > 0.0;
  const double res = DegToRad(params_.bin_deg);
  if (!(res > 0.0 && out->x.size() > 1)) return;
  const Eigen::Vector2d s = sensor_xy - out->origin;
  const Eigen::Vector2d mid = 0.5 * (lo + hi) - out->origin - s;
  SortByBin(*out, s, mid.normalized(), res);
  outline_x_.clear();
  outline_y_.clear();
  PickPerBin(points, idx, *out, multi_ring ? params_.support_height : 0.0);
  if (outline_x_.empty() && multi_ring && params_.support_height > 0.0 &&
      LongestRingSpan(points, idx) >= params_.arc_span) {
    PickPerBin(points, idx, *out, 0.0);
  }
  out->x.assign(outline_x_.begin(), outline_x_.end());
  out->y.assign(outline_y_.begin(), outline_y_.end());
}

void OutlineExtractor::Gather(const WorldPoints& points, const std::vector<std::int32_t>& idx,
                              const LadarScan& scan, PointSet* ps, Eigen::Vector2d* lo_out,
                              Eigen::Vector2d* hi_out) const {
  ps->x.resize(idx.size());
  ps->y.resize(idx.size());
  const std::size_t i0 = static_cast<std::size_t>(idx.front());
  ps->origin = Eigen::Vector2d(std::round(points.x[i0]), std::round(points.y[i0]));
  Eigen::Vector2d lo = Eigen::Vector2d::Constant(std::numeric_limits<double>::infinity());
  Eigen::Vector2d hi = -lo;
  double dt_sum = 0.0;
  const bool has_dt = scan.dt_us.size() == scan.size();
  for (std::size_t k = 0; k < idx.size(); ++k) {
    const auto i = static_cast<std::size_t>(idx[k]);
    const Eigen::Vector2d p(points.x[i], points.y[i]);
    lo = lo.cwiseMin(p);
    hi = hi.cwiseMax(p);
    ps->x[k] = static_cast<float>(p.x() - ps->origin.x());
    ps->y[k] = static_cast<float>(p.y() - ps->origin.y());
    if (has_dt) dt_sum += scan.dt_us[static_cast<std::size_t>(points.index[i])];
  }
  ps->extent = (hi - lo).norm();
  ps->mean_utime = scan.utime + static_cast<std::int64_t>(std::llround(dt_sum / idx.size()));
  *lo_out = lo;
  *hi_out = hi;
}

void OutlineExtractor::SortByBin(const PointSet& ps, const Eigen::Vector2d& s,
                                 const Eigen::Vector2d& ref, double bin_rad) {
  // Bins uniform in tan(bearing - ref) (no atan2 per return; within +-30 deg of the segment's
  // middle, as wide as bin_rad to within 33%); the key orders by bin, then range^2.
  const double inv_res = 1.0 / std::tan(bin_rad);
  const std::size_t size = ps.x.size();
  keys_.resize(size);
  bins_.resize(size);
  std::int64_t bin_lo = std::numeric_limits<std::int64_t>::max(), bin_hi = -bin_lo;
  for (std::size_t k = 0; k < size; ++k) {
    const double dx = ps.x[k] - s.x(), dy = ps.y[k] - s.y();
    const double u = dx * ref.x() + dy * ref.y(), w = -dx * ref.y() + dy * ref.x();
    const double t = u > kMinAlong ? w / u : (w >= 0 ? kMaxTan : -kMaxTan);
    // floor() without a library call: |v| <= kMaxTan * inv_res is far inside the int64 range.
    const double v = std::clamp(t, -kMaxTan, kMaxTan) * inv_res;
    auto bin = static_cast<std::int64_t>(v);  // rounds towards zero
    if (static_cast<double>(bin) > v) --bin;
    // [cm^2], below 2^32 so that it cannot reach into the bin's part of the key: returns beyond
    // 655 m (max_range allows 1000 m) are ordered as if at 655 m, by k among themselves.
    const auto r2 = std::min(static_cast<std::int64_t>((dx * dx + dy * dy) * 1e4), kBinScale - 1);
    keys_[k] = {bin * kBinScale + r2, static_cast<std::int32_t>(k)};
    bins_[k] = bin;
    bin_lo = std::min(bin_lo, bin);
    bin_hi = std::max(bin_hi, bin);
  }
  bin_runs_.clear();
  if (keys_.size() < 2) {
    if (!keys_.empty()) bin_runs_.emplace_back(0, 1);
    return;
  }
  // A segment's returns fill a few dozen neighbouring bins: a counting sort by bin (stable, so
  // k ascending within a bin) costs about n steps instead of n log n comparisons. Within a bin
  // PickInBin orders only what it needs. Returns beside or behind the sensor (bins far apart)
  // take std::sort (the keys are distinct, k is: sorted by key within their bins).
  const auto n = static_cast<std::int64_t>(keys_.size());
  if (bin_hi - bin_lo > 4 * n + 256) {
    std::sort(keys_.begin(), keys_.end());
    std::size_t k = 0;
    while (k < keys_.size()) {
      std::size_t end = k + 1;
      while (end < keys_.size() && BinOf(keys_[end].first) == BinOf(keys_[k].first)) ++end;
      bin_runs_.emplace_back(k, end);
      k = end;
    }
    return;
  }
  bin_end_.assign(static_cast<std::size_t>(bin_hi - bin_lo + 2), 0);
  for (const std::int64_t b : bins_) ++bin_end_[static_cast<std::size_t>(b - bin_lo + 1)];
  for (std::size_t i = 1; i < bin_end_.size(); ++i) bin_end_[i] += bin_end_[i - 1];
  sorted_keys_.resize(keys_.size());
  for (std::size_t k = 0; k < keys_.size(); ++k) {
    sorted_keys_[bin_end_[static_cast<std::size_t>(bins_[k] - bin_lo)]++] = keys_[k];
  }
  keys_.swap(sorted_keys_);
  // bin_end_[j] is now the end of bin j (from the lowest): the runs without a scan for them.
  std::size_t begin = 0;
  for (std::size_t j = 0; j + 1 < bin_end_.size(); ++j) {
    const std::size_t end = bin_end_[j];
    if (end > begin) bin_runs_.emplace_back(begin, end);
    begin = end;
  }
}

void OutlineExtractor::SortBin(std::size_t begin, std::size_t end) {
  constexpr std::size_t kInsertionMax = 24;  // longer bins: std::sort (n^2 / 4 moves)
  auto* a = keys_.data();
  if (end - begin > kInsertionMax) {
    std::sort(a + begin, a + end);
    return;
  }
  // Entries arrive in k order: moving only past strictly larger keys keeps ties by k.
  for (std::size_t i = begin + 1; i < end; ++i) {
    const auto v = a[i];
    std::size_t j = i;
    for (; j > begin && a[j - 1].first > v.first; --j) a[j] = a[j - 1];
    a[j] = v;
  }
}

double OutlineExtractor::RangeOf(std::size_t a) const {
  return std::sqrt(static_cast<double>(keys_[a].first - BinOf(keys_[a].first) * kBinScale) * 1e-4);
}

void OutlineExtractor::PickPerBin(const WorldPoints& points, const std::vector<std::int32_t>& idx,
                                  const PointSet& ps, double support_h) {
  for (const auto& [begin, end] : bin_runs_) {
    const std::size_t pick = PickInBin(points, idx, begin, end, support_h);
    if (pick < end) {
      const auto src = static_cast<std::size_t>(keys_[pick].second);
      outline_x_.push_back(ps.x[src]);
      outline_y_.push_back(ps.y[src]);
    }
  }
}

std::size_t OutlineExtractor::PickInBin(const WorldPoints& points,
                                        const std::vector<std::int32_t>& idx, std::size_t begin,
                                        std::size_t end, double support_h) {
  // The least (key, k) first: the nearest return, which most bins of a face pick. Only a bin
  // whose nearest return has no support is sorted, to try the others nearest first.
  std::size_t least = begin;
  for (std::size_t a = begin + 1; a < end; ++a) {
    if (keys_[a] < keys_[least]) least = a;
  }
  if (!(support_h > 0.0)) return least;
  LoadBin(points, idx, begin, end);
  if (HasSupport(least - begin, support_h)) return least;
  SortBin(begin, end);  // keys_[begin] is now the least, which has no support
  LoadBin(points, idx, begin, end);
  for (std::size_t a = begin + 1; a < end; ++a) {
    if (HasSupport(a - begin, support_h)) return a;
  }
  return end;
}

void OutlineExtractor::LoadBin(const WorldPoints& points, const std::vector<std::int32_t>& idx,
                               std::size_t begin, std::size_t end) {
  // The bin's ranges and heights once, not once per entry tested (RangeOf's square root, two
  // indirections for the height): the same values.
  const std::int64_t base = BinOf(keys_[begin].first) * kBinScale;
  bin_range_.resize(end - begin);
  bin_height_.resize(end - begin);
  for (std::size_t e = begin; e < end; ++e) {
    bin_range_[e - begin] = std::sqrt(static_cast<double>(keys_[e].first - base) * 1e-4);
    bin_height_[e - begin] =
        points.height[static_cast<std::size_t>(idx[static_cast<std::size_t>(keys_[e].second)])];
  }
}

bool OutlineExtractor::HasSupport(std::size_t a, double support_h) const {
  const double support_r = params_.support_range;
  const double ra = bin_range_[a];
  const float ha = bin_height_[a];
  for (std::size_t b = 0; b < bin_range_.size(); ++b) {
    if (b == a) continue;
    const double rb = bin_range_[b];
    // Beyond ra + support_r: not tested. (Ranges grow with the key: in key order this was where
    // the search stopped, so the same entries are tested in any order.)
    if (rb > ra + support_r) continue;
    if (std::abs(rb - ra) <= support_r && std::abs(bin_height_[b] - ha) >= support_h) return true;
  }
  return false;
}

double OutlineExtractor::LongestRingSpan(const WorldPoints& points,
                                         const std::vector<std::int32_t>& idx) {
  // Rings grazing a bonnet and a roof hit them at different ranges, each at its own one range:
  // the span is taken per ring.
  ring_span_.clear();
  double span = 0.0;
  for (std::size_t a = 0; a < keys_.size(); ++a) {
    const auto i = static_cast<std::size_t>(idx[static_cast<std::size_t>(keys_[a].second)]);
    const std::int16_t ring = points.ring[i];
    const double r = RangeOf(a);
    auto it = std::find_if(ring_span_.begin(), ring_span_.end(),
                           [&](const RingSpan& e) { return e.ring == ring; });
    if (it == ring_span_.end()) {
      ring_span_.push_back({ring, r, r});
    } else {
      it->lo = std::min(it->lo, r);
      it->hi = std::max(it->hi, r);
      span = std::max(span, it->hi - it->lo);
    }
  }
  return span;
}

}  // namespace vtrack
