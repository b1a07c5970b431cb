#include "tracker/core/life_cycle.h"

#include <algorithm>
#include <cmath>

namespace vtrack {

bool Parked(const Ekf& ekf, double mover_min_speed, const Track& t) {
  if (t.status == TrackStatus::kTentative || t.mover) return false;
  return ekf.Centre(t.hyps[static_cast<std::size_t>(t.selected)].filter).speed < mover_min_speed;
}

bool AdvanceStatus(const Ekf& ekf, const TrackManagerParams& params, std::int64_t utime,
                   const Hypothesis& predicted, Track* t) {
  bool keep = true;
  const bool updated = t->consecutive_misses == 0;
  if (t->status == TrackStatus::kTentative) {
    if (t->consecutive_misses >= params.tentative_max_misses) keep = false;
    else if (t->num_updates >= params.confirm_updates) t->status = TrackStatus::kConfirmed;
  } else {
    t->status = updated || t->seen_this_scan ? TrackStatus::kConfirmed : TrackStatus::kCoasting;
    // A parked object may stay hidden behind stopped traffic for longer than a moving one may
    // go unseen (max_position_std still applies to both).
    const double coast_max =
        Parked(ekf, params.mover_min_speed, *t) ? params.parked_coast_max_s : params.coast_max_s;
    if (static_cast<double>(utime - t->last_update_utime) * 1e-6 > coast_max) keep = false;
  }
  const Hypothesis& h = predicted;
  const auto idx = ekf.model(h.kind).PoseIndices();
  const double a = h.P(idx[0], idx[0]), b = h.P(idx[0], idx[1]), c = h.P(idx[1], idx[1]);
  const double lambda = 0.5 * (a + c) + std::hypot(0.5 * (a - c), b);
  if (!(std::sqrt(std::max(0.0, lambda)) <= params.max_position_std) || !h.x.allFinite()) keep = false;
  return keep;
}

void MarkDuplicates(const TrackManagerParams& params, const std::vector<Track>& tracks,
                    const std::vector<PredictedObject>& boxes, std::vector<char>* remove) {
  std::vector<char>& rm = *remove;
  for (std::size_t i = 0; i < tracks.size(); ++i) {
    if (rm[i]) continue;
    for (std::size_t j = i + 1; j < tracks.size(); ++j) {
      if (rm[j]) continue;
      if ((boxes[i].box.center - boxes[j].box.center).norm() >
          0.5 * (boxes[i].box.length + boxes[j].box.length)) {
        continue;
      }
      if (Overlap(boxes[i].box, boxes[j].box) < params.duplicate_overlap) continue;
      const Track& a = tracks[i];
      const Track& b = tracks[j];
      bool drop_a;
      if (a.small_object != b.small_object) drop_a = a.small_object;
      else if (a.status != TrackStatus::kTentative && b.status != TrackStatus::kTentative &&
               a.evidence_seen && b.evidence_seen && a.vehicle_log_odds != b.vehicle_log_odds)
        drop_a = a.vehicle_log_odds < b.vehicle_log_odds;
      else if (a.num_updates != b.num_updates) drop_a = a.num_updates < b.num_updates;
      else drop_a = a.id > b.id;
      rm[drop_a ? i : j] = 1;
    }
  }
}

double Overlap(const OrientedBox& a, const OrientedBox& b) {
  const OrientedBox& s = a.length * a.width <= b.length * b.width ? a : b;
  const OrientedBox& o = &s == &a ? b : a;
  // OrientedBox::ToWorld and Contains, with each box's axes computed once rather than per
  // point (four cosines and four sines a point): the same operations on the same values.
  const Eigen::Vector2d s_axis = s.Axis(), s_normal = s.Normal();
  const Eigen::Vector2d o_axis = o.Axis(), o_normal = o.Normal();
  const double half_length = 0.5 * o.length, half_width = 0.5 * o.width;
  int inside = 0;
  for (int i = 0; i < 5; ++i) {
    for (int j = 0; j < 3; ++j) {
      const Eigen::Vector2d q((i - 2) * 0.2 * s.length, (j - 1) * 0.33 * s.width);
      const Eigen::Vector2d d = (s.center + q.x() * s_axis + q.y() * s_normal) - o.center;
      inside += std::abs(d.dot(o_axis)) <= half_length && std::abs(d.dot(o_normal)) <= half_width;
    }
  }
  return inside / 15.0;
}

}  // namespace vtrack
