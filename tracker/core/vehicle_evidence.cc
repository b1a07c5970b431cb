#include "tracker/core/vehicle_evidence.h"

#include <algorithm>
#include <cmath>
#include <limits>
#include <sstream>
#include <string>

#include "tracker/core/preprocess.h"
#include "tracker/core/range_profile.h"
#include "tracker/core/scan.h"
#include "tracker/core/track.h"

namespace vtrack {
namespace {

// [m] Above this a column says nothing more (a crown or a building either way), and a far
// outlier return would only add leverage to the fit.
constexpr float kMaxColumnTop = 10.0f;

// The bearing of v (from the sensor) as its offset from c's, as tan(offset) = cross / dot:
// monotonic in the offset within +-90 deg (a track's returns span far less), no atan2. False
// (no offset) for v at 90 deg or more from c.
inline bool BearingOffset(const Eigen::Vector2d& c, double vx, double vy, double* t) {
  const double dot = c.x() * vx + c.y() * vy;
  if (!(dot > 0.0)) return false;
  *t = (c.x() * vy - c.y() * vx) / dot;
  return true;
}

}  // namespace

int TopRing(const LadarScan& scan) {
  if (scan.num_rings <= 1 || scan.ring.size() != scan.size()) return -1;
  // Every 8th return: the mean elevation of a ring is settled long before (a ring has ~2000
  // returns per sweep), at an eighth of the cost.
  constexpr std::size_t kStride = 8;
  std::vector<double> sum(static_cast<std::size_t>(scan.num_rings), 0.0);
  std::vector<int> count(sum.size(), 0);
  for (std::size_t i = 0; i < scan.size(); i += kStride) {
    const int r = scan.ring[i];
    const double rho = std::hypot(scan.x[i], scan.y[i]);
    if (r < 0 || r >= scan.num_rings || !(rho > 1.0) || !std::isfinite(scan.z[i])) continue;
    sum[static_cast<std::size_t>(r)] += scan.z[i] / rho;  // tan(elevation)
    ++count[static_cast<std::size_t>(r)];
  }
  int top = -1;
  double best = -std::numeric_limits<double>::infinity();
  for (std::size_t r = 0; r < sum.size(); ++r) {
    if (count[r] == 0) continue;
    const double mean = sum[r] / count[r];
    if (mean > best) {
      best = mean;
      top = static_cast<int>(r);
    }
  }
  return top;
}

int HiddenEnds(const WorldPoints& pts, const std::vector<std::int32_t>& idx,
               const Eigen::Vector2d& centroid, const Eigen::Vector2d& sensor_xy,
               const RangeProfile& profile) {
  // The extreme bearings about the centroid's (BearingOffset).
  const Eigen::Vector2d c = centroid - sensor_xy;
  double lo = std::numeric_limits<double>::infinity(), hi = -lo;
  Eigen::Vector2d a = centroid, b = centroid;
  for (const std::int32_t i : idx) {
    const Eigen::Vector2d p(pts.x[static_cast<std::size_t>(i)], pts.y[static_cast<std::size_t>(i)]);
    const Eigen::Vector2d v = p - sensor_xy;
    double t;
    if (!BearingOffset(c, v.x(), v.y(), &t)) continue;
    if (t < lo) {
      lo = t;
      a = p;
    }
    if (t > hi) {
      hi = t;
      b = p;
    }
  }
  if (!(hi > lo)) return 2;  // one bearing: no extent seen, no end free of the other
  return (profile.FreeBeyond(a, b, kEndOccluderMargin, kEndBinsBeyond) ? 0 : 1) +
         (profile.FreeBeyond(b, a, kEndOccluderMargin, kEndBinsBeyond) ? 0 : 1);
}

double SurfaceRoughness(const WorldPoints& pts, const std::vector<std::int32_t>& idx,
                        const Eigen::Vector2d& centroid, const Eigen::Vector2d& sensor_xy,
                        bool three_d, std::vector<RingReturn>* order,
                        std::vector<float>* distances) {
  const Eigen::Vector2d c = centroid - sensor_xy;
  order->clear();
  for (const std::int32_t i : idx) {
    const auto k = static_cast<std::size_t>(i);
    // A return of unknown ring (-1) in a 3-D cloud: its neighbours in bearing may lie on another.
    if (three_d && pts.ring[k] < 0) continue;
    double t;
    if (!BearingOffset(c, pts.x[k] - sensor_xy.x(), pts.y[k] - sensor_xy.y(), &t)) continue;
    order->push_back({three_d ? pts.ring[k] : std::int16_t{0}, t, i});
  }
  std::sort(order->begin(), order->end(), [](const RingReturn& a, const RingReturn& b) {
    return a.ring != b.ring ? a.ring < b.ring : a.bearing < b.bearing;
  });
  distances->clear();
  const auto& o = *order;
  for (std::size_t k = 0; k + 2 < o.size(); ++k) {
    if (o[k].ring != o[k + 2].ring) continue;
    const auto a = static_cast<std::size_t>(o[k].index), b = static_cast<std::size_t>(o[k + 1].index),
               e = static_cast<std::size_t>(o[k + 2].index);
    const double cx = pts.x[e] - pts.x[a], cy = pts.y[e] - pts.y[a];
    const double chord = std::hypot(cx, cy);
    if (!(chord > 1e-6) || chord > kRoughnessMaxChord) continue;
    const double bx = pts.x[b] - pts.x[a], by = pts.y[b] - pts.y[a];
    distances->push_back(static_cast<float>(std::abs(cx * by - cy * bx) / chord));
  }
  if (distances->size() < static_cast<std::size_t>(kRoughnessMinTriplets)) {
    return std::numeric_limits<double>::quiet_NaN();
  }
  auto& d = *distances;
  const auto half = static_cast<std::ptrdiff_t>(d.size() / 2);
  std::nth_element(d.begin(), d.begin() + half, d.end());
  return d[static_cast<std::size_t>(half)];
}

namespace {

// The height profile and (column_top) column top of the returns idx of a 3-D cloud; heights:
// theirs, in idx order (reused as a buffer).
void MeasureHeights(const WorldPoints& pts, const std::vector<std::int32_t>& idx, bool column_top,
                    ReturnEvidence* r, std::vector<float>* heights) {
  auto& h = *heights;
  const auto half = static_cast<std::ptrdiff_t>(h.size() / 2);
  const auto [lo, hi] = std::minmax_element(h.begin(), h.end());
  r->height_min = *lo;
  r->height_max = *hi;
  std::nth_element(h.begin(), h.begin() + half, h.end());
  r->height_median = h[static_cast<std::size_t>(half)];
  if (!column_top) return;  // left at 0: no model asks for it (a gather and a median saved)
  if (pts.column_top.size() == pts.size()) {
    h.clear();
    for (const std::int32_t i : idx) h.push_back(pts.column_top[static_cast<std::size_t>(i)]);
    std::nth_element(h.begin(), h.begin() + half, h.end());
    r->column_top = std::min(kMaxColumnTop, h[static_cast<std::size_t>(half)]);
  } else {
    r->column_top = r->height_max;  // no grid ground: the returns' own top
  }
}

}  // namespace

ReturnEvidence MeasureReturns(const WorldPoints& pts, const std::vector<std::int32_t>& idx,
                              const std::vector<std::int32_t>& segment_of,
                              const std::vector<float>& segment_extent,
                              const Eigen::Vector2d& sensor_xy, bool three_d, int top_ring,
                              const RangeProfile* profile, std::vector<float>* scratch,
                              std::vector<RingReturn>* roughness, bool column_top) {
  ReturnEvidence r;
  r.three_d = three_d;
  r.num_points = static_cast<int>(idx.size());
  if (idx.empty()) return r;
  double sx = 0.0, sy = 0.0;
  float extent = 0.0f;
  scratch->clear();
  for (const std::int32_t i : idx) {
    const auto k = static_cast<std::size_t>(i);
    sx += pts.x[k];
    sy += pts.y[k];
    scratch->push_back(pts.height[k]);
    if (pts.ring[k] == top_ring) ++r.top_beam;
    const std::int32_t s = k < segment_of.size() ? segment_of[k] : -1;
    if (s >= 0) extent = std::max(extent, segment_extent[static_cast<std::size_t>(s)]);
  }
  const double n = static_cast<double>(idx.size());
  const Eigen::Vector2d centroid(sx / n, sy / n);
  r.range = (centroid - sensor_xy).norm();
  r.segment_extent = extent;
  if (profile != nullptr && !profile->empty()) {
    r.hidden_ends = HiddenEnds(pts, idx, centroid, sensor_xy, *profile);
  }
  if (three_d) MeasureHeights(pts, idx, column_top, &r, scratch);
  // After the heights: it reuses scratch.
  if (roughness != nullptr) {
    r.roughness = SurfaceRoughness(pts, idx, centroid, sensor_xy, three_d, roughness, scratch);
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
  set(EvidenceFeature::kColumnTop, r.column_top);
  set(EvidenceFeature::kTopBeam, std::log1p(static_cast<double>(r.top_beam)));
  // A dimension not estimated yet is missing, not 0: a single face seen says nothing of the
  // width, and 0 would read as a very narrow object. Its own indicator carries the fact.
  constexpr double kMissing = std::numeric_limits<double>::quiet_NaN();
  set(EvidenceFeature::kLength, sel.length_est.value_or(kMissing));
  set(EvidenceFeature::kWidth, sel.width_est.value_or(kMissing));
  set(EvidenceFeature::kLengthUnseen, sel.length_est ? 0.0 : 1.0);
  set(EvidenceFeature::kWidthUnseen, sel.width_est ? 0.0 : 1.0);
  set(EvidenceFeature::kInlierShare,
      sel.has_fit && !sel.fit.point_edge.empty()
          ? static_cast<double>(sel.fit.num_inliers) / static_cast<double>(sel.fit.point_edge.size())
          : kMissing);
  set(EvidenceFeature::kSegmentExtent, r.segment_extent);
  set(EvidenceFeature::kRoughness, r.roughness);
  set(EvidenceFeature::kHiddenEnds, r.hidden_ends);
  // Speed from the reported hypothesis (bounded: a diverging filter says nothing more at 60 m/s).
  set(EvidenceFeature::kSpeed, std::isfinite(speed) ? std::min(30.0, std::abs(speed)) : 0.0);
  set(EvidenceFeature::kMover, t.mover ? 1.0 : 0.0);
  set(EvidenceFeature::kSmall, t.small_object ? 1.0 : 0.0);
  return f;
}

bool UsesFeature(const EvidenceParams& p, bool three_d, EvidenceFeature k) {
  if ((three_d ? p.model_3d : p.model_2d) == EvidenceModel::kTrees) {
    const auto& nodes = three_d ? p.trees_3d : p.trees_2d;
    return std::any_of(nodes.begin(), nodes.end(),
                       [k](const EvidenceNode& n) { return n.left >= 0 && n.feature == k; });
  }
  const auto& terms = three_d ? p.terms_3d : p.terms_2d;
  return std::any_of(terms.begin(), terms.end(),
                     [k](const EvidenceTerm& term) { return term.feature == k && term.weight != 0.0; });
}

namespace {

// The sum of the leaves the scan reaches, one per tree (EvidenceNode; roots: TreeRoots(nodes)),
// tree after tree.
double TreesLogit(const std::vector<EvidenceNode>& nodes, const std::vector<std::int32_t>& roots,
                  const EvidenceFeatures& f) {
  double l = 0.0;
  for (const std::int32_t root : roots) {
    auto i = static_cast<std::size_t>(root);
    while (nodes[i].left >= 0) {
      const EvidenceNode& node = nodes[i];
      const double v = f[static_cast<std::size_t>(node.feature)];
      i = static_cast<std::size_t>(v > node.threshold ? node.right : node.left);  // NaN: left
    }
    l += nodes[i].value;
  }
  return l;
}

// The first node of list whose children are not later nodes of its own tree, or whose tree
// number goes down; "" if none.
std::string TreeProblem(const char* key, const std::vector<EvidenceNode>& list) {
  const int n = static_cast<int>(list.size());
  for (int i = 0; i < n; ++i) {
    const EvidenceNode& node = list[static_cast<std::size_t>(i)];
    const std::string where = std::string(key) + "[" + std::to_string(i) + "]";
    if (i > 0 && node.tree < list[static_cast<std::size_t>(i - 1)].tree) {
      return param::Problem((where + ".tree").c_str(), node.tree, "-",
                            "at least the previous node's (a tree's nodes are contiguous)");
    }
    if ((node.left < 0) != (node.right < 0)) {
      return where + ": left and right must both be -1 (a leaf) or both name children";
    }
    for (const int c : {node.left, node.right}) {
      if (c >= 0 && (c <= i || c >= n || list[static_cast<std::size_t>(c)].tree != node.tree)) {
        return param::Problem((where + ".left/right").c_str(), c, "-",
                              "a later node of the same tree (the list has " + std::to_string(n) + ")");
      }
    }
  }
  return {};
}

}  // namespace

std::string EvidenceParams::CrossProblem() const {
  if (!(keep_probability <= vehicle_probability)) {
    std::ostringstream why;
    why << "<= vehicle_probability (" << vehicle_probability
        << "): a vehicle stays one down to keep_probability (fitted default "
        << evidence_fit::kKeepProbability << "); lower it with vehicle_probability";
    return param::Problem("keep_probability", keep_probability, "-", why.str());
  }
  // The fitted defaults hold the chosen family only: the other one's list is empty, and a model
  // switched to it would be its bias alone, the same probability for every track.
  for (const bool three_d : {true, false}) {
    const EvidenceModel model = three_d ? model_3d : model_2d;
    const bool empty = model == EvidenceModel::kTrees ? (three_d ? trees_3d : trees_2d).empty()
                                                      : (three_d ? terms_3d : terms_2d).empty();
    if (empty) {
      const std::string d = three_d ? "3d" : "2d";
      const bool trees = model == EvidenceModel::kTrees;
      return "model_" + d + " = " + (trees ? "trees" : "logistic") + ": " +
             (trees ? "trees_" : "terms_") + d + " is empty (fit that family: " +
             "scripts/fit-vehicle-evidence --model-" + d + " " + (trees ? "trees" : "logistic") +
             " --write, or give its list)";
    }
  }
  std::string problem = TreeProblem("trees_3d", trees_3d);
  return problem.empty() ? TreeProblem("trees_2d", trees_2d) : problem;
}

std::vector<std::int32_t> TreeRoots(const std::vector<EvidenceNode>& nodes) {
  std::vector<std::int32_t> roots;
  for (std::size_t k = 0; k < nodes.size(); ++k) {
    if (k == 0 || nodes[k].tree != nodes[k - 1].tree) roots.push_back(static_cast<std::int32_t>(k));
  }
  return roots;
}

double ScanLogit(const EvidenceParams& p, bool three_d, const EvidenceFeatures& f) {
  return ScanLogit(p, three_d, f, EvidenceRoots(p));
}

double ScanLogit(const EvidenceParams& p, bool three_d, const EvidenceFeatures& f,
                 const EvidenceRoots& roots) {
  const double bias = three_d ? p.bias_3d : p.bias_2d;
  if ((three_d ? p.model_3d : p.model_2d) == EvidenceModel::kTrees) {
    return bias + TreesLogit(three_d ? p.trees_3d : p.trees_2d, three_d ? roots.three_d : roots.two_d, f);
  }
  double l = bias;
  for (const EvidenceTerm& term : three_d ? p.terms_3d : p.terms_2d) {
    const double v = f[static_cast<std::size_t>(term.feature)];
    if (!std::isfinite(v)) continue;  // missing: at the training mean, z = 0
    const double z = (v - term.center) / term.scale;
    l += term.weight * (term.power == 2 ? z * z : z);
  }
  return l;
}

double PriorLogOdds(const EvidenceParams& p, bool three_d) {
  const double prior = three_d ? p.prior : p.prior_2d;
  return std::log(prior / (1.0 - prior));
}

double AccumulateLogOdds(const EvidenceParams& p, bool three_d, double log_odds, double scan_logit) {
  const double from =
      p.accumulation == EvidenceAccumulation::kSum ? PriorLogOdds(p, three_d) : log_odds;
  const double l = log_odds + p.scan_weight * (scan_logit - from);
  return std::clamp(l, -p.max_log_odds, p.max_log_odds);
}

double VehicleProbability(double log_odds) { return 1.0 / (1.0 + std::exp(-log_odds)); }

bool VehicleByEvidence(const EvidenceParams& p, bool was_vehicle, double log_odds) {
  return VehicleProbability(log_odds) >= (was_vehicle ? p.keep_probability : p.vehicle_probability);
}

}  // namespace vtrack
