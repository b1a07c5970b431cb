#include "tracker/core/vehicle_evidence.h"

#include <algorithm>
#include <cmath>

#include "tracker/core/preprocess.h"
#include "tracker/core/track.h"

namespace vtrack {

ReturnEvidence MeasureReturns(const WorldPoints& pts, const std::vector<std::int32_t>& idx,
                              const std::vector<std::int32_t>& segment_of,
                              const std::vector<float>& segment_extent,
                              const Eigen::Vector2d& sensor_xy, bool three_d,
                              std::vector<float>* scratch) {
  ReturnEvidence r;
  r.three_d = three_d;
  r.num_points = static_cast<int>(idx.size());
  if (idx.empty()) return r;
  double sx = 0.0, sy = 0.0;
  int overhung = 0;
  float extent = 0.0f;
  scratch->clear();
  const bool has_overhang = pts.overhang.size() == pts.size();
  for (const std::int32_t i : idx) {
    const auto k = static_cast<std::size_t>(i);
    sx += pts.x[k];
    sy += pts.y[k];
    scratch->push_back(pts.height[k]);
    if (has_overhang && pts.overhang[k] > 0.0f) ++overhung;
    const std::int32_t s = k < segment_of.size() ? segment_of[k] : -1;
    if (s >= 0) extent = std::max(extent, segment_extent[static_cast<std::size_t>(s)]);
  }
  const double n = static_cast<double>(idx.size());
  r.range = (Eigen::Vector2d(sx / n, sy / n) - sensor_xy).norm();
  r.segment_extent = extent;
  r.overhang = overhung / n;
  if (three_d) {
    auto& h = *scratch;
    const auto [lo, hi] = std::minmax_element(h.begin(), h.end());
    r.height_min = *lo;
    r.height_max = *hi;
    auto mid = h.begin() + static_cast<std::ptrdiff_t>(h.size() / 2);
    std::nth_element(h.begin(), mid, h.end());
    r.height_median = *mid;
  }
  return r;
}

EvidenceFeatures FeaturesOf(const ReturnEvidence& r, const Track& t, double speed) {
  EvidenceFeatures f{};
  auto set = [&f](EvidenceFeature k, double v) { f[static_cast<std::size_t>(k)] = v; };
  const TrackHypothesis& sel = t.hyps[static_cast<std::size_t>(t.selected)];
  set(EvidenceFeature::kLogPoints, std::log(std::max(1, r.num_points)));
  set(EvidenceFeature::kLogRange, std::log(std::max(1.0, r.range)));
  set(EvidenceFeature::kHeightMax, r.height_max);
  set(EvidenceFeature::kHeightMedian, r.height_median);
  set(EvidenceFeature::kHeightMin, r.height_min);
  set(EvidenceFeature::kOverhang, r.overhang);
  set(EvidenceFeature::kLength, sel.length_est.value_or(0.0));
  set(EvidenceFeature::kWidth, sel.width_est.value_or(0.0));
  set(EvidenceFeature::kSegmentExtent, r.segment_extent);
  // Speed from the reported hypothesis (bounded: a diverging filter says nothing more at 60 m/s).
  set(EvidenceFeature::kSpeed, std::isfinite(speed) ? std::min(30.0, std::abs(speed)) : 0.0);
  set(EvidenceFeature::kMover, t.mover ? 1.0 : 0.0);
  set(EvidenceFeature::kSmall, t.small_object ? 1.0 : 0.0);
  return f;
}

double ScanLogit(const EvidenceParams& p, bool three_d, const EvidenceFeatures& f) {
  double l = three_d ? p.bias_3d : p.bias_2d;
  for (const EvidenceTerm& term : three_d ? p.terms_3d : p.terms_2d) {
    const double z = (f[static_cast<std::size_t>(term.feature)] - term.center) / term.scale;
    l += term.weight * (term.power == 2 ? z * z : z);
  }
  return l;
}

double PriorLogOdds(const EvidenceParams& p) { return std::log(p.prior / (1.0 - p.prior)); }

double AccumulateLogOdds(const EvidenceParams& p, double log_odds, double scan_logit) {
  const double l = log_odds + p.scan_weight * (scan_logit - PriorLogOdds(p));
  return std::clamp(l, -p.max_log_odds, p.max_log_odds);
}

double VehicleProbability(double log_odds) { return 1.0 / (1.0 + std::exp(-log_odds)); }

}  // namespace vtrack
