#include "log_tools/eval/clear_mot.h"

#include <algorithm>
#include <cmath>
#include <limits>
#include <map>
#include <set>
#include <sstream>
#include <stdexcept>
#include <unordered_map>

#include "log_tools/eval/gated_assignment.h"

namespace vtrack::eval {
namespace {

constexpr double kNaN = std::numeric_limits<double>::quiet_NaN();
constexpr double kInf = std::numeric_limits<double>::infinity();

void CheckFrame(const ScoringFrame& f) {
  auto fail = [&](const std::string& what) {
    std::ostringstream os;
    os << "scoring frame at utime " << f.utime << ": " << what;
    throw std::invalid_argument(os.str());
  };
  if (f.gt_ids.size() != f.gt_xy.size()) fail("gt_ids and gt_xy differ in size");
  if (f.track_ids.size() != f.track_xy.size()) fail("track_ids and track_xy differ in size");
  std::set<std::int64_t> seen;
  for (const auto id : f.gt_ids) {
    if (!seen.insert(id).second) fail("truth id " + std::to_string(id) + " appears twice");
  }
  seen.clear();
  for (const auto id : f.track_ids) {
    if (!seen.insert(id).second) fail("track id " + std::to_string(id) + " appears twice");
  }
  for (const auto& p : f.gt_xy) {
    if (!p.allFinite()) fail("a truth centre is not finite");
  }
  for (const auto& p : f.track_xy) {
    if (!p.allFinite()) fail("a track centre is not finite");
  }
}

}  // namespace

std::string ClearMotParams::Validate() const {
  std::ostringstream os;
  if (!(gate_m > 0.0) || !std::isfinite(gate_m)) {
    os << "gate_m must be > 0 and finite, got " << gate_m;
  } else if (!(mostly_lost_ratio >= 0.0 && mostly_lost_ratio <= mostly_tracked_ratio &&
               mostly_tracked_ratio <= 1.0)) {
    os << "need 0 <= mostly_lost_ratio <= mostly_tracked_ratio <= 1, got mostly_lost_ratio "
       << mostly_lost_ratio << ", mostly_tracked_ratio " << mostly_tracked_ratio;
  }
  return os.str();
}

std::string HotaParams::Validate() const {
  std::ostringstream os;
  if (!(similarity_gate_m > 0.0) || !std::isfinite(similarity_gate_m)) {
    os << "similarity_gate_m must be > 0 and finite, got " << similarity_gate_m;
  }
  return os.str();
}

double HotaSimilarity(double distance_m, double similarity_gate_m) {
  return std::max(0.0, 1.0 - distance_m / similarity_gate_m);
}

ClearMotResult ComputeClearMot(const std::vector<ScoringFrame>& frames,
                               const ClearMotParams& params) {
  if (const std::string err = params.Validate(); !err.empty()) {
    throw std::invalid_argument("ClearMotParams: " + err);
  }
  ClearMotResult r;
  r.matches.resize(frames.size());

  std::map<std::int64_t, std::int64_t> previous;   // truth id -> track id, matched at t-1
  std::map<std::int64_t, std::int64_t> last_match; // truth id -> track id, last match ever
  struct History {
    std::int64_t scored = 0, matched = 0, runs = 0;
    bool matched_last = false;  // in the previous scan in which the truth was scored
  };
  std::map<std::int64_t, History> history;
  double distance_sum = 0.0;

  for (std::size_t t = 0; t < frames.size(); ++t) {
    const ScoringFrame& f = frames[t];
    CheckFrame(f);
    const int n_gt = static_cast<int>(f.gt_ids.size());
    const int n_tr = static_cast<int>(f.track_ids.size());
    std::map<std::int64_t, int> track_index;
    for (int j = 0; j < n_tr; ++j) track_index[f.track_ids[j]] = j;

    std::vector<int> gt_to_track(n_gt, -1);
    std::vector<bool> track_used(n_tr, false);
    auto dist = [&](int i, int j) { return (f.gt_xy[i] - f.track_xy[j]).norm(); };

    // Step 1: keep the correspondences of the previous scan that are still valid.
    for (int i = 0; i < n_gt; ++i) {
      const auto prev = previous.find(f.gt_ids[i]);
      if (prev == previous.end()) continue;
      const auto j = track_index.find(prev->second);
      if (j == track_index.end()) continue;
      if (dist(i, j->second) < params.gate_m) {
        gt_to_track[i] = j->second;
        track_used[j->second] = true;
      }
    }
    // Step 2: one global assignment of what is left, within the gate.
    std::vector<int> free_gt, free_tr;
    for (int i = 0; i < n_gt; ++i) {
      if (gt_to_track[i] < 0) free_gt.push_back(i);
    }
    for (int j = 0; j < n_tr; ++j) {
      if (!track_used[j]) free_tr.push_back(j);
    }
    Eigen::MatrixXd cost(free_gt.size(), free_tr.size());
    for (std::size_t a = 0; a < free_gt.size(); ++a) {
      for (std::size_t b = 0; b < free_tr.size(); ++b) {
        const double d = dist(free_gt[a], free_tr[b]);
        cost(a, b) = d < params.gate_m ? d : kInf;
      }
    }
    std::vector<bool> is_new(n_gt, false);
    for (const auto& [a, b] : GatedAssignment(cost)) {
      gt_to_track[free_gt[a]] = free_tr[b];
      track_used[free_tr[b]] = true;
      is_new[free_gt[a]] = true;
    }

    // Step 3: count, and detect identity switches.
    std::map<std::int64_t, std::int64_t> current;
    std::int64_t matched = 0;
    for (int i = 0; i < n_gt; ++i) {
      const std::int64_t gid = f.gt_ids[i];
      History& h = history[gid];
      ++h.scored;
      const int j = gt_to_track[i];
      if (j < 0) {
        h.matched_last = false;
        continue;
      }
      const std::int64_t tid = f.track_ids[j];
      Match m;
      m.gt = i;
      m.track = j;
      m.distance_m = dist(i, j);
      const auto last = last_match.find(gid);
      m.id_switch = is_new[i] && last != last_match.end() && last->second != tid;
      if (m.id_switch) ++r.id_switches;
      last_match[gid] = tid;
      current[gid] = tid;
      distance_sum += m.distance_m;
      ++matched;
      ++h.matched;
      if (!h.matched_last) ++h.runs;
      h.matched_last = true;
      r.matches[t].push_back(m);
    }
    previous = std::move(current);
    r.gt_detections += n_gt;
    r.true_positives += matched;
    r.false_negatives += n_gt - matched;
    r.false_positives += n_tr - matched;
  }

  r.gt_objects = static_cast<std::int64_t>(history.size());
  for (const auto& [id, h] : history) {
    if (h.runs > 1) r.fragmentations += h.runs - 1;
    const double ratio = static_cast<double>(h.matched) / static_cast<double>(h.scored);
    if (ratio > params.mostly_tracked_ratio) {
      ++r.mostly_tracked;
    } else if (ratio < params.mostly_lost_ratio) {
      ++r.mostly_lost;
    } else {
      ++r.partially_tracked;
    }
  }
  r.mota = r.gt_detections > 0
               ? 1.0 - static_cast<double>(r.false_negatives + r.false_positives + r.id_switches) /
                           static_cast<double>(r.gt_detections)
               : kNaN;
  r.motp_m = r.true_positives > 0 ? distance_sum / static_cast<double>(r.true_positives) : kNaN;
  return r;
}

HotaResult ComputeHota(const std::vector<ScoringFrame>& frames, const HotaParams& params) {
  if (const std::string err = params.Validate(); !err.empty()) {
    throw std::invalid_argument("HotaParams: " + err);
  }
  HotaResult r;
  for (int k = 1; k <= 19; ++k) r.alphas.push_back(0.05 * k);

  // Dense indices of truth ids, track ids and of the (truth, track) pairs that ever have S > 0.
  std::unordered_map<std::int64_t, int> gt_index, tr_index;
  std::unordered_map<std::int64_t, int> pair_index;  // gt dense * (1 << 32) + track dense
  std::vector<double> gt_count, tr_count;            // frames each id is present in
  struct Candidate {
    int i, j, pair;
    double s;
  };
  std::vector<std::vector<Candidate>> candidates(frames.size());
  for (std::size_t t = 0; t < frames.size(); ++t) {
    const ScoringFrame& f = frames[t];
    CheckFrame(f);
    std::vector<int> gd(f.gt_ids.size()), td(f.track_ids.size());
    for (std::size_t i = 0; i < f.gt_ids.size(); ++i) {
      const auto [it, added] = gt_index.emplace(f.gt_ids[i], static_cast<int>(gt_count.size()));
      if (added) gt_count.push_back(0.0);
      gd[i] = it->second;
      gt_count[gd[i]] += 1.0;
    }
    for (std::size_t j = 0; j < f.track_ids.size(); ++j) {
      const auto [it, added] = tr_index.emplace(f.track_ids[j], static_cast<int>(tr_count.size()));
      if (added) tr_count.push_back(0.0);
      td[j] = it->second;
      tr_count[td[j]] += 1.0;
    }
    for (std::size_t i = 0; i < f.gt_ids.size(); ++i) {
      for (std::size_t j = 0; j < f.track_ids.size(); ++j) {
        const double s = HotaSimilarity((f.gt_xy[i] - f.track_xy[j]).norm(), params.similarity_gate_m);
        if (s <= 0.0) continue;
        const std::int64_t key = (static_cast<std::int64_t>(gd[i]) << 32) + td[j];
        const auto [it, added] = pair_index.emplace(key, static_cast<int>(pair_index.size()));
        candidates[t].push_back({static_cast<int>(i), static_cast<int>(j), it->second, s});
      }
    }
  }
  // The truth and track of each pair, by dense index.
  std::vector<int> pair_gt(pair_index.size()), pair_tr(pair_index.size());
  for (const auto& [key, p] : pair_index) {
    pair_gt[p] = static_cast<int>(key >> 32);
    pair_tr[p] = static_cast<int>(key & 0xffffffff);
  }

  // Lexicographic matching score (Sec. 5): number of pairs >> A_max >> S.
  constexpr double kPairWeight = 1e4;
  constexpr double kSimilarityWeight = 1e-4;
  // A small tolerance so that S exactly at a threshold (0.05 k is not exact in binary) counts.
  constexpr double kAlphaTolerance = 1e-9;

  for (const double alpha : r.alphas) {
    std::vector<double> potential(pair_index.size(), 0.0);  // frames with S >= alpha, per pair
    for (const auto& frame : candidates) {
      for (const Candidate& c : frame) {
        if (c.s >= alpha - kAlphaTolerance) potential[c.pair] += 1.0;
      }
    }
    std::vector<double> tpa(pair_index.size(), 0.0);  // TPs per pair
    double tp = 0.0, fn = 0.0, fp = 0.0, loc_sum = 0.0;
    for (std::size_t t = 0; t < frames.size(); ++t) {
      const ScoringFrame& f = frames[t];
      Eigen::MatrixXd cost = Eigen::MatrixXd::Constant(
          static_cast<Eigen::Index>(f.gt_ids.size()), static_cast<Eigen::Index>(f.track_ids.size()),
          std::numeric_limits<double>::infinity());
      Eigen::MatrixXi which = Eigen::MatrixXi::Constant(cost.rows(), cost.cols(), -1);
      Eigen::MatrixXd sim = Eigen::MatrixXd::Zero(cost.rows(), cost.cols());
      for (const Candidate& c : candidates[t]) {
        if (c.s < alpha - kAlphaTolerance) continue;
        const double n = potential[c.pair];
        const double a_max = n / (gt_count[pair_gt[c.pair]] + tr_count[pair_tr[c.pair]] - n);
        cost(c.i, c.j) = -(kPairWeight + a_max + kSimilarityWeight * c.s);
        which(c.i, c.j) = c.pair;
        sim(c.i, c.j) = c.s;
      }
      const auto pairs = GatedAssignment(cost);
      for (const auto& [i, j] : pairs) {
        tpa[which(i, j)] += 1.0;
        loc_sum += sim(i, j);
      }
      tp += static_cast<double>(pairs.size());
      fn += static_cast<double>(f.gt_ids.size() - pairs.size());
      fp += static_cast<double>(f.track_ids.size() - pairs.size());
    }
    // sum over TPs of A(c) = sum over pairs of TPA * A(pair).
    double ass_sum = 0.0;
    for (std::size_t p = 0; p < tpa.size(); ++p) {
      if (tpa[p] > 0.0) ass_sum += tpa[p] * tpa[p] / (gt_count[pair_gt[p]] + tr_count[pair_tr[p]] - tpa[p]);
    }
    const double denom = tp + fn + fp;
    const double deta = denom > 0.0 ? tp / denom : kNaN;
    const double assa = tp > 0.0 ? ass_sum / tp : (denom > 0.0 ? 0.0 : kNaN);
    r.deta_alpha.push_back(deta);
    r.assa_alpha.push_back(assa);
    r.hota_alpha.push_back(std::sqrt(deta * assa));
    r.loca_alpha.push_back(tp > 0.0 ? loc_sum / tp : kNaN);
  }
  auto mean = [](const std::vector<double>& v) {
    double s = 0.0;
    for (const double x : v) s += x;
    return v.empty() ? kNaN : s / static_cast<double>(v.size());
  };
  r.hota = mean(r.hota_alpha);
  r.deta = mean(r.deta_alpha);
  r.assa = mean(r.assa_alpha);
  // LocA: mean over the thresholds at which there is at least one TP.
  double loc = 0.0;
  int loc_n = 0;
  for (const double l : r.loca_alpha) {
    if (std::isfinite(l)) {
      loc += l;
      ++loc_n;
    }
  }
  r.loca = loc_n > 0 ? loc / loc_n : kNaN;
  return r;
}

}  // namespace vtrack::eval
